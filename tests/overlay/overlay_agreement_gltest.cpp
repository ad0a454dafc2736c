// overlay_agreement_gltest.cpp - the demo scene rendered by every backend (gl, raster,
// raycast), the overlays drawn on each image, and only the overlay pixels compared: the
// gizmos that always show (lights, cameras, selection) must cover exactly the same pixels in
// the same colours; the depth-tested ones (grid, axes, bounds) may differ only where the
// backends' depths differ by about the depth bias (a line lying on a surface), so nearly all
// of their pixels must agree (the figures are printed). Needs a GL context (label gl).
#include "assets/demo.h"
#include "renderers/overlay.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "scenegraph/transforms.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace {

constexpr int kW = 320, kH = 180;

sg::FrameInput demoFrame() {
    sg::FrameInput f = sg::flatten(assets::makeDemoScene(), float(kW) / kH);
    f.settings.aa = sg::AAMode::None;
    return f;
}

// The overlay alone: the backend's depth, colour cleared to transparent, overlays drawn.
rnd::Framebuffer overlayOnly(const std::string& backend, const sg::FrameInput& f, const rnd::OverlayOptions& o) {
    rnd::Framebuffer fb;
    std::string err;
    auto r = rnd::makeRenderer(backend, &err);
    EXPECT_TRUE(r) << backend << ": " << err;
    if (!r) return fb;
    rnd::RenderStats st = r->render(f, kW, kH, fb);
    EXPECT_TRUE(st.ok) << backend << ": " << st.error;
    std::fill(fb.color.begin(), fb.color.end(), uint8_t(0));
    rnd::drawOverlays(f, o, fb);
    testing_support::writeImage(fb, "overlay-agreement", backend);
    return fb;
}

struct Agreement {
    int overlayPixels = 0, disagreeing = 0;   // pixels with an overlay in either image
};
Agreement agreement(const rnd::Framebuffer& a, const rnd::Framebuffer& b) {
    Agreement g;
    for (size_t k = 0; k < a.color.size(); k += 4) {
        if (a.color[k + 3] == 0 && b.color[k + 3] == 0) continue;
        ++g.overlayPixels;
        g.disagreeing += !std::equal(a.color.begin() + k, a.color.begin() + k + 4, b.color.begin() + k);
    }
    return g;
}

TEST(OverlayAgreementGLTest, AlwaysShownGizmosAreTheSamePixels) {
    const sg::FrameInput f = demoFrame();
    ASSERT_FALSE(f.lights.empty());
    ASSERT_FALSE(f.meshes.empty());
    rnd::OverlayOptions o;
    o.lights = o.cameras = o.selection = true;
    o.selected = {f.meshes.front().node};
    o.cameraGizmos.push_back({glm::inverse(sg::lookAt({3, 2, 4}, {0, 0.5f, 0}, {0, 1, 0})), sg::Projection{}, 1.5f});
    const rnd::Framebuffer ref = overlayOnly("raster", f, o);
    for (std::string b : {"raycast", "gl"}) {
        const Agreement g = agreement(ref, overlayOnly(b, f, o));
        std::printf("[overlay] always shown, raster vs %s: %d overlay pixels, %d differ\n", b.c_str(), g.overlayPixels, g.disagreeing);
        EXPECT_GT(g.overlayPixels, 100);
        EXPECT_EQ(g.disagreeing, 0) << b;
    }
}

TEST(OverlayAgreementGLTest, DepthTestedOverlaysAgree) {
    const sg::FrameInput f = demoFrame();
    rnd::OverlayOptions o;
    o.grid = o.axes = o.bounds = true;
    const rnd::Framebuffer ref = overlayOnly("raster", f, o);
    for (std::string b : {"raycast", "gl"}) {
        const Agreement g = agreement(ref, overlayOnly(b, f, o));
        const double fraction = g.overlayPixels ? double(g.disagreeing) / g.overlayPixels : 1.0;
        std::printf("[overlay] depth tested, raster vs %s: %d overlay pixels, %d differ (%.2f%%)\n", b.c_str(), g.overlayPixels, g.disagreeing,
                    100 * fraction);
        EXPECT_GT(g.overlayPixels, 1000);
        EXPECT_LE(fraction, 0.01) << b;
    }
}

}   // namespace
