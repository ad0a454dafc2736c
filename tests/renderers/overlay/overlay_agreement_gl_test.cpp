// overlay_agreement_gl_test.cpp - the demo scene rendered by every backend (gl, raster,
// raycast), the overlays drawn on each image, and only the overlay pixels compared: the
// gizmos that always show (lights, cameras, selection) must cover exactly the same pixels in
// the same colours; the depth-tested ones (grid, axes, bounds) may differ only where the
// backends' depths differ by about the depth bias (a line lying on a surface), so nearly all
// of their pixels must agree (the figures are printed). And the grid against each backend's
// own depth: hidden where a surface stands in front of it, shown where it lies on the floor,
// and over everything with grid-on-top. Needs a GL context (label gl).
#include "assets/demo.h"
#include "renderers/overlay.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "scenegraph/transforms.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
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

// A grey floor at y = 0 (the grid's plane) with a red box standing on it at the origin, unlit,
// seen from above and in front: the grid's x = 0 line runs down the middle of the image, on the
// floor in front of the box and behind the box's faces where the box covers it.
TEST(OverlayGridDepthGLTest, SurfacesHideTheGridUnlessItIsOnTop) {
    sg::FrameInput f = test_scenes::makeFrame(kW, kH, sg::Projection{}, {0.0f, 4.0f, 6.0f}, {0.0f, 0.3f, 0.0f});
    f.settings.aa = sg::AAMode::None;
    f.settings.shadows = false;
    test_scenes::addMesh(f, sg::primitives::plane(3.0f, 4), test_scenes::unlit(sg::vec3(0.5f)));   // drawable 1
    // Half size 0.4: no edge of the box lies along a grid line (spacing 0.5 for the floor's 6 x 6).
    test_scenes::addMesh(f, sg::primitives::box(sg::vec3(0.4f)), test_scenes::unlit(sg::vec3(0.8f, 0.1f, 0.1f)),
                         glm::translate(sg::mat4(1.0f), sg::vec3(0, 0.4f, 0)));   // drawable 2
    constexpr uint32_t kFloor = 1, kBox = 2;
    const uint8_t kGridColour[3] = {20, 175, 190};   // overlay.cpp's kGrid
    for (std::string b : {"gl", "raster", "raycast"}) {
        SCOPED_TRACE(b);
        std::string err;
        auto r = rnd::makeRenderer(b, &err);
        ASSERT_TRUE(r) << err;
        rnd::Framebuffer base;
        rnd::RenderRequest visibility;
        visibility.aovs.add(rnd::Aov::Visibility);
        const rnd::RenderStats st = r->render(f, kW, kH, base, nullptr, visibility);
        ASSERT_TRUE(st.ok) << st.error;
        ASSERT_TRUE(base.has(rnd::Aov::Visibility));
        rnd::OverlayOptions o;
        o.grid = true;
        rnd::Framebuffer tested = base, onTop = base;
        rnd::drawOverlays(f, o, tested);
        std::string parseErr;
        ASSERT_TRUE(rnd::parseOverlayList("grid-on-top", o, parseErr)) << parseErr;
        ASSERT_TRUE(o.grid && o.gridOnTop);
        rnd::drawOverlays(f, o, onTop);
        testing_support::writeImage(tested, "overlay-grid-depth", b + "-tested");
        testing_support::writeImage(onTop, "overlay-grid-depth", b + "-on-top");
        auto isGrid = [&](const rnd::Framebuffer& fb, int x, int y) { return std::equal(kGridColour, kGridColour + 3, fb.pixel(x, y)); };
        // Every grid pixel (where grid-on-top draws one), by the surface under it.
        std::vector<std::pair<int, int>> onBox;
        int onFloor = 0, onFloorShown = 0, onBoxHidden = 0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                if (!isGrid(onTop, x, y) || isGrid(base, x, y)) continue;
                const uint32_t d = base.drawable[size_t(y) * kW + x];
                if (d == kBox) {
                    onBox.emplace_back(x, y);
                    onBoxHidden += std::equal(base.pixel(x, y), base.pixel(x, y) + 4, tested.pixel(x, y));
                } else if (d == kFloor) {
                    ++onFloor;
                    onFloorShown += isGrid(tested, x, y);
                }
            }
        std::printf("[overlay] grid, %s: %zu grid pixels over the box (%d hidden), %d on the floor (%d shown)\n", b.c_str(), onBox.size(),
                    onBoxHidden, onFloor, onFloorShown);
        ASSERT_GT(onBox.size(), 20u) << "the box stands on grid lines";
        ASSERT_GT(onFloor, 500);
        // Hidden behind the box (where the x = 0 line meets the box's bottom edge it may show,
        // within the depth bias) ...
        EXPECT_GE(onBoxHidden, int(0.97 * double(onBox.size())));
        // ... visible where it lies on the floor.
        EXPECT_GE(onFloorShown, int(0.98 * onFloor));
        // One pixel in the middle of the box's face on the x = 0 line: the box's red, and the
        // grid's colour on top.
        const auto [x, y] = onBox[onBox.size() / 2];
        EXPECT_EQ(int(tested.pixel(x, y)[0]), int(base.pixel(x, y)[0])) << x << "," << y;
        EXPECT_GT(int(tested.pixel(x, y)[0]), 150) << "red";
        EXPECT_LT(int(tested.pixel(x, y)[1]), 100);
        EXPECT_TRUE(isGrid(onTop, x, y));
    }
}

}   // namespace
