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
//   overdraw   (rasterizers, Aov::Overdraw) fragments rasterized per pixel before the
//              depth test, at one sample per pixel: every covered pixel centre of every drawn
//              triangle (opaque, masked and blended alike, after back-face culling; the
//              fragments of clipped triangles once), line, point and wireframe edge counts one,
//              whether it is then hidden, cut out or blended. Heat map: 1 blue, 2 cyan,
//              3-4 green, 5-7 yellow, 8+ red; black: no fragment
//   cost       (ray caster, Aov::TraversalCost) the work of the pixel's primary ray
//              through the centre: BVH nodes visited (the top level over instances and the
//              meshes' BVHs; a node counts when its child boxes are tested) plus primitives
//              tested (triangles of the leaves it opens; an analytic shape counts one),
//              through every cut-out or blended layer it passes, not shadow or reflection
//              rays. Heat map of nodes + primitives, log scale from 1 (blue) to the image's
//              largest (red); the legend gives the range and the means of both
//   shadow-map (rasterizers, Capabilities::shadowMaps) the selected light's shadow map against the
//              ray caster's shadow rays: where the map alone shadows (acne) or alone lets light
//              through (peter-panning, leaks), its texels on screen, and what the light sees
//              (renderers/shadow_map_view.h; diagnosticImage alone shows the texels only: the
//              comparison needs both backends' answers, shadowMapView)
// Background pixels are black (overdraw and cost: a background pixel shows its own count).
#pragma once

#include "renderers/framebuffer.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"

#include <string>
#include <string_view>
#include <vector>

namespace rnd {

enum class DiagnosticView { Shaded, Depth, Normal, Id, Uv, Triangles, Overdraw, Cost, ShadowMap };

std::vector<std::string_view> diagnosticViewNames();   // "shaded", "depth", ...
bool parseDiagnosticView(std::string_view name, DiagnosticView& out);
std::string_view nameOf(DiagnosticView v);

struct DiagnosticImage {
    Framebuffer image;    // colour only
    std::string legend;   // one line: what the colours mean ("depth 2.10 (white) .. 14.30 (dark)")
};

// The AOVs (aov.h) the view is made from: none for shaded, the counters for overdraw and
// cost, the visibility for the others.
AovSet aovsFor(DiagnosticView view);
// Whether a backend with `caps` can make the view (it fills aovsFor(view)).
bool diagnosticViewSupported(DiagnosticView view, const Capabilities& caps);
// What the render behind the view must ask for (adds to `request`; visibility for all but
// shaded, overdraw and cost; the counters for those two).
void requestFor(DiagnosticView view, RenderRequest& request);

// The view of `fb` (which needs visibility for every view but shaded, overdraw and cost, and
// those two their counters) for `frame`.
DiagnosticImage diagnosticImage(DiagnosticView view, const sg::FrameInput& frame, const Framebuffer& fb);

}   // namespace rnd
