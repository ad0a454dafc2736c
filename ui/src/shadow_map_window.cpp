// shadow_map_window.cpp - the window's shadow-map view (see shadow_map_window.h).
#include "shadow_map_window.h"

#include <optional>
#include <vector>

namespace ui {

rnd::DiagnosticImage ShadowMapWindowView::make(RenderSlot& slot, sg::NodeId selected, bool& retry) {
    const std::shared_ptr<const sg::FrameInput>& frame = slot.imageFrame();
    const rnd::Framebuffer& img = slot.image();
    const rnd::ShadowMapViewPoints pts = rnd::shadowMapViewPoints(*frame, img, rnd::shadowMapViewLight(*frame, selected));
    std::vector<float> map, rays;
    retry = false;
    if (pts.light >= 0 && !pts.pixel.empty()) {
        std::optional<std::vector<float>> asked = slot.lightVisibilityMany(pts.light, pts.position, pts.normal);
        if (!asked) {   // asked again once the render in flight is done
            retry = true;
            rnd::DiagnosticImage waiting = rnd::shadowMapViewImage(*frame, img, pts, {}, {});
            waiting.legend = "shadow-map: waiting for the backend between renders";
            return waiting;
        }
        map = std::move(*asked);
        if (m_exactFrame != frame || m_exactImage.width != img.width || m_exactImage.height != img.height) {
            m_exactFrame.reset();
            if (!m_exact) m_exact = rnd::makeExactShadowBackend();
            if (m_exact && rnd::renderShadowReference(*m_exact, *frame, img.width, img.height, m_exactImage)) m_exactFrame = frame;
        }
        if (m_exactFrame) rays = rnd::referenceVisibility(*frame, img, *m_exact, m_exactImage, pts.light);
    }
    return rnd::shadowMapViewImage(*frame, img, pts, map, rays);
}

}   // namespace ui
