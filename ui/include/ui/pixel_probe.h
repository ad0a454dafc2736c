// pixel_probe.h - picking, the pixel inspector and the selection outline, from the
// visibility every backend fills (rnd::Framebuffer::drawable/primitive) and the shared
// reconstruction (renderers/inspect.h). No GL and no GLFW: the window passes images in.
#pragma once

#include "renderers/inspect.h"
#include "scenegraph/frame.h"

#include <memory>
#include <string>
#include <vector>

namespace ui {

class RenderSlot;
struct ViewerState;

// One shown backend's answer at the probed pixel.
struct ProbeResult {
    std::string backend;
    bool valid = false;   // the image has visibility (not a preview, not while the camera moves)
    int x = 0, y = 0;     // pixel of its image (top-left origin)
    uint8_t rgb[3] = {0, 0, 0};
    rnd::SurfaceAt surface;
    rnd::PixelTerms terms;
    bool shadowsKnown = false;   // terms use the backend's shadows (else every light counts as visible)
    std::string node, path;      // of surface.node
};

// What the inspector shows: the point (fractions of the viewport, hovered or pinned) and the
// answer of each shown backend there.
struct PixelProbeState {
    bool pinned = false;
    float u = -1, v = -1;   // [0, 1) across / down the viewport; < 0 = none
    std::vector<ProbeResult> results;
    // A click on an image without visibility yet (a preview level): picked when the full image
    // arrives, unless the camera or the scene changed in between (versions at the click).
    bool pickPending = false;
    bool pickAdds = false;   // Ctrl was down: the pick adds to (or takes out of) the selection
    uint64_t pickViewVersion = 0, pickDocVersion = 0;
};

// One image to probe, as the viewport shows it.
struct ProbeImage {
    std::string backend;
    const rnd::Framebuffer* image = nullptr;
    std::shared_ptr<const sg::FrameInput> frame;
    RenderSlot* slot = nullptr;   // for the backend's shadows (may be null)
};

// The probe at viewport fraction (u, v) in `image`.
ProbeResult probeAt(const ViewerState& st, const ProbeImage& image, float u, float v);

// Picking: the node under viewport fraction (u, v) in `image` (kNoNode: nothing there, or no
// visibility yet).
sg::NodeId pickAt(const ProbeImage& image, float u, float v);

// Paints a 2-pixel outline around the pixels of `image` (which must have visibility) that show
// one of `nodes` or a node below one, for the viewport (the selection, in every backend alike;
// several selected nodes side by side get one outline around them all).
void outlineNodes(rnd::Framebuffer& image, const sg::FrameInput& frame, const sg::Scene& scene, const std::vector<sg::NodeId>& nodes);

// One line per result for the automation's `print pixel`.
std::string probeSummary(const PixelProbeState& p);

}   // namespace ui
