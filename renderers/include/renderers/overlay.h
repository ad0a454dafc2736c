// overlay.h - grid, axes, light and camera gizmos, bounding boxes and the selection, drawn by
// one CPU pass over a finished Framebuffer (any backend's; GL's is read back), so every
// backend shows the same overlay pixels. Integer algorithms from the rasterization notes
// (docs/math.md, "Overlays"):
//   lines:   3D segments clipped against the near plane in clip space (z >= -w), divided,
//            mapped to pixels, then Bresenham (all octants, both endpoints drawn);
//   circles: the midpoint circle algorithm (8-way symmetry), radius in pixels.
// Depth: grid, axes and bounds are hidden behind geometry (window z interpolated along the
// line, drawn where z <= framebuffer depth + a small bias, so a line lying on a surface, the
// grid on a floor, still shows); light and camera gizmos and the selection always show, and
// so does the grid with gridOnTop. Overlays write colour only, never depth or visibility.
#pragma once

#include "renderers/framebuffer.h"
#include "scenegraph/frame.h"

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace rnd {

// A camera of the scene drawn as a frustum gizmo (eye -> world matrix and its projection).
struct CameraGizmo {
    sg::mat4 world{1.0f};
    sg::Projection projection;
    float aspect = 1.0f;
};

struct OverlayOptions {
    bool grid = false, axes = false, lights = false, cameras = false, bounds = false, selection = false;
    bool gridOnTop = false;                  // the grid over every surface instead of depth-tested (with `grid`)
    std::vector<sg::NodeId> selected;        // selection: the drawables of these nodes (a node and its descendants)
    std::vector<CameraGizmo> cameraGizmos;   // cameras: the scene's cameras other than the viewing one
    bool any() const { return grid || axes || lights || cameras || bounds || selection; }
};

// "grid,axes,lights,cameras,bounds,selection,grid-on-top" (any subset, comma separated) into
// `out`'s flags; grid-on-top is the grid drawn over every surface (grid and gridOnTop). False
// with a one-line error naming the valid names for an unknown or empty name.
bool parseOverlayList(const std::string& list, OverlayOptions& out, std::string& err);
const char* overlayNameList();   // "grid, axes, lights, cameras, bounds, selection, grid-on-top"

void drawOverlays(const sg::FrameInput& frame, const OverlayOptions& options, Framebuffer& fb);
// Fills what the overlays need from the scene: `selected` becomes the `nodes` (a selection;
// invalid ids ignored) and their descendants, each once, `cameraGizmos` the scene's cameras
// (their images' aspect: `aspect`).
void setSceneOverlayInputs(const sg::Scene& scene, const std::vector<sg::NodeId>& nodes, float aspect, OverlayOptions& options);

// The building blocks, public for tests. Pixel coordinates are integers, y up or down as the
// caller likes (the algorithms do not care).
namespace overlay {
using Plot = std::function<void(int x, int y)>;
// Bresenham: every pixel of the line from (x0, y0) to (x1, y1), endpoints included, each once,
// walked from the endpoint with the smaller major coordinate (the same pixels either way).
void bresenham(int x0, int y0, int x1, int y1, const Plot& plot);
std::vector<std::pair<int, int>> bresenhamPixels(int x0, int y0, int x1, int y1);
// Midpoint circle of integer radius r >= 0 about (cx, cy); 8-way symmetric points may repeat.
void midpointCircle(int cx, int cy, int r, const Plot& plot);
std::vector<std::pair<int, int>> midpointCirclePixels(int cx, int cy, int r);   // sorted, unique
// Clips clip-space segment a-b to the near half-space z >= -w (and w > 0); false when nothing is
// left. The parameters of the kept part along the original segment go to t0, t1.
bool clipToNear(sg::vec4& a, sg::vec4& b, float* t0 = nullptr, float* t1 = nullptr);
}   // namespace overlay

}   // namespace rnd
