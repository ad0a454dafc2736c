// line_overlay.h - points, lines and the wireframe overlay as both CPU backends draw them, so
// they cover the same pixels: after the surfaces (the rasterizer's triangles, the ray
// caster's rays), depth-tested against the image's window-z depth, unlit (base colour x
// vertex colour + emissive, as GL draws lines and points) and fogged per pixel.
//   Lines: clipped in clip space, one pixel per column/row (DDA, half-open), depth LESS.
//   Points: squares of `pointSize` pixels centred on the vertex (GL's point rules).
//   Wireframe (settings.wireframe): every triangle edge in the wireframe colour, depth LEQUAL
//   with a small offset toward the viewer (GL: glPolygonOffset(-1, -1)); culled faces draw
//   no edges.
// When the target has overdraw counters (Framebuffer::overdraw), every pixel written counts one
// fragment, before its depth test (the overdraw diagnostic view).
// Colour: written as bytes through the frame's display transform (renderers/tone_map.h), or,
// when `linear` is given (the rasterizer's linear frame while the transform is not the
// identity: fb.width x fb.height, rows top-down), as linear colour into it, for the caller to
// resolve and encode.
#pragma once

#include "renderers/draw_list.h"
#include "renderers/framebuffer.h"

#include <vector>

namespace rnd {

void drawPointsLinesWireframe(const std::vector<PreparedDraw>& draws, const sg::FrameInput& f, Framebuffer& fb, float pointSize,
                              sg::vec3* linear = nullptr);

}   // namespace rnd
