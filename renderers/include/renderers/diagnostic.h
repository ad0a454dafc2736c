// diagnostic.h - diagnostic views of a rendered image, made from its visibility
// (Framebuffer::drawable/primitive) and the frame, the same way for every backend:
//   shaded     the image itself
//   depth      depth along the optical axis, grey: nearest white .. farthest dark (legend: range)
//   normal     world normal as 0.5 n + 0.5
//   id         a distinct colour per instance (sg::instanceTable)
//   uv         TEXCOORD_0 as (frac u, frac v, 0); magenta where a surface has none
//   triangles  triangle density: how many of the seen triangle fit in a pixel (1 / its
//              projected area in pixels), log heat map: blue 0.001, cyan 0.006, green 0.03,
//              yellow 0.18, red >= 1 (one triangle or more per pixel); grey: analytic shapes
// Background pixels are black.
#pragma once

#include "renderers/framebuffer.h"
#include "scenegraph/frame.h"

#include <string>
#include <string_view>
#include <vector>

namespace rnd {

enum class DiagnosticView { Shaded, Depth, Normal, Id, Uv, Triangles };

std::vector<std::string_view> diagnosticViewNames();   // "shaded", "depth", ...
bool parseDiagnosticView(std::string_view name, DiagnosticView& out);
std::string_view nameOf(DiagnosticView v);

struct DiagnosticImage {
    Framebuffer image;    // colour only
    std::string legend;   // one line: what the colours mean ("depth 2.10 (white) .. 14.30 (dark)")
};

// The view of `fb` (which needs visibility for every view but shaded) for `frame`.
DiagnosticImage diagnosticImage(DiagnosticView view, const sg::FrameInput& frame, const Framebuffer& fb);

}   // namespace rnd
