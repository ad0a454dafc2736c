// shadow_map_window.h - the window's shadow-map view (renderers/shadow_map_view.h): a backend
// slot's own map answers, asked on its worker between renders, against the shadow rays of a
// reference backend kept for the window. The reference's image is rendered again, on the calling
// (UI) thread, when the frame or the size changes: a diagnostic view's price; its BVHs are kept.
#pragma once

#include "renderers/shadow_map_view.h"
#include "ui/render_slot.h"

#include <memory>
#include <vector>

namespace ui {

// The light the view shows from the window's selection: its first node (taken when a light).
inline sg::NodeId shadowMapSelection(const std::vector<sg::NodeId>& selection) { return selection.empty() ? sg::kNoNode : selection.front(); }

class ShadowMapWindowView {
public:
    // The view of slot's image for the light of node `selected` (or the first with a map).
    // `retry` is set when the slot was busy: ask again once its render is done.
    rnd::DiagnosticImage make(RenderSlot& slot, sg::NodeId selected, bool& retry);

private:
    std::unique_ptr<rnd::Renderer> m_exact;
    rnd::Framebuffer m_exactImage;
    std::shared_ptr<const sg::FrameInput> m_exactFrame;   // what m_exactImage shows
};

}   // namespace ui
