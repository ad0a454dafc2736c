// scene_defaults_test.cpp - defaults that make the first hour work: a new scene has a
// light and a camera, so the first shape added is lit and in view; a loaded scene's unused fog
// follows its size; a refused setting's message goes once the value is valid; fly speed follows
// the scene's size.
#include "ui/viewer_state.h"

#include "assets/scene_io.h"
#include "headless_ui.h"
#include "renderers/renderer.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace ui;
namespace fs = std::filesystem;

namespace {

// A scene with one implicit box of the given half size at the origin (no camera, no light).
sg::Scene boxScene(float half) {
    sg::Scene s;
    sg::ImplicitShape box;
    box.type = sg::ImplicitType::Box;
    box.halfExtents = sg::vec3(half);
    s.addNode("box", s.root(), sg::ImplicitPayload{box, -1});
    return s;
}

float luminance(const uint8_t* p) { return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; }

}   // namespace

TEST(SceneDefaultsTest, NewSceneHasALightAndACameraSoTheFirstSphereIsLitAndInView) {
    ViewerState st;
    st.view.viewportWidth = st.view.viewportHeight = 96;
    st.addShape(sg::ImplicitType::Torus);   // an edit, so New replaces a dirty document
    st.newScene();
    EXPECT_FALSE(st.doc.dirty);
    EXPECT_FALSE(st.doc.history.canUndo()) << "the light and camera are the new document, not edits";
    ASSERT_TRUE(st.doc.scene.valid(st.doc.scene.activeCamera));
    size_t lights = 0;
    for (sg::NodeId id : st.doc.scene.depthFirstOrder()) lights += std::holds_alternative<sg::Light>(st.doc.scene.node(id).payload);
    EXPECT_EQ(lights, 1u);

    st.addShape(sg::ImplicitType::Sphere);   // Add > Sphere
    sg::FrameInput frame = st.buildFrame(1.0f);
    ASSERT_EQ(frame.lights.size(), 1u);
    std::string err;
    std::unique_ptr<rnd::Renderer> r = rnd::makeRenderer(rnd::rendererNames().back(), &err);
    ASSERT_TRUE(r) << err;
    rnd::Framebuffer fb;
    frame.settings.setAA("none");
    rnd::RenderStats stats = r->render(frame, 96, 96, fb);
    ASSERT_TRUE(stats.ok) << stats.error;
    // The sphere covers the centre and is shaded: bright where the light falls, darker away
    // from it (an unlit sphere is a flat disc of one colour).
    const uint8_t* bg = fb.pixel(0, 0);
    const uint8_t* centre = fb.pixel(48, 48);
    EXPECT_NE(std::memcmp(bg, centre, 3), 0) << "the sphere is in view";
    float lo = 1e9f, hi = -1e9f;
    for (int y = 30; y < 66; ++y)
        for (int x = 30; x < 66; ++x) {
            float l = luminance(fb.pixel(x, y));
            lo = std::min(lo, l);
            hi = std::max(hi, l);
        }
    EXPECT_GT(hi - lo, 40.0f) << "shaded, not a flat disc";
    testing_support::writeImage(fb, "ui", "new-scene-sphere");   // to look at
}

TEST(SceneDefaultsTest, LoadedSceneFogFollowsItsSizeUnlessTheFileSetIt) {
    fs::path dir = testing_support::outputDir("ui") / "fog_defaults";
    fs::remove_all(dir);
    fs::create_directories(dir);
    ASSERT_EQ(assets::saveSceneJson(boxScene(100.0f), dir / "big.json", true), "");
    sg::Scene set = boxScene(100.0f);
    set.settings.fogStart = 1.0f;
    set.settings.fogEnd = 2.0f;
    ASSERT_EQ(assets::saveSceneJson(set, dir / "set.json", true), "");

    ViewerState st;
    st.startLoad(dir / "big.json");
    ASSERT_TRUE(st.pollLoad(true));
    ASSERT_TRUE(st.ui.errorPopup.empty()) << st.ui.errorPopup;
    float r = 100.0f * std::sqrt(3.0f);
    const sg::RenderSettings& s = st.doc.scene.settings;
    EXPECT_EQ(s.fog, sg::FogMode::Off);
    EXPECT_NEAR(s.fogStart, r, 1e-2f * r);
    EXPECT_NEAR(s.fogEnd, 6.0f * r, 1e-2f * r);
    EXPECT_NEAR(std::exp(-s.fogDensity * 3.0f * r), 0.5f, 1e-3f);
    EXPECT_TRUE(s.validate().empty());
    EXPECT_FALSE(st.doc.dirty) << "a default, not an edit";

    st.startLoad(dir / "set.json");
    ASSERT_TRUE(st.pollLoad(true));
    EXPECT_EQ(st.doc.scene.settings.fogStart, 1.0f) << "the file's own values stay";
    EXPECT_EQ(st.doc.scene.settings.fogEnd, 2.0f);
}

TEST(SceneDefaultsTest, RefusedSettingMessageGoesOnceTheValueIsValid) {
    ViewerState st;
    sg::RenderSettings s = st.doc.scene.settings;
    s.fog = sg::FogMode::Linear;
    ASSERT_EQ(st.setSettings(s), "");
    sg::RenderSettings bad = s;
    bad.fogEnd = bad.fogStart - 1.0f;
    EXPECT_NE(st.setSettings(bad), "");
    EXPECT_NE(st.ui.status.find("linear fog needs end > start"), std::string::npos) << st.ui.status;
    // Dragged back to the value it had: valid again, nothing to record, the message goes.
    EXPECT_EQ(st.setSettings(s), "");
    EXPECT_EQ(st.ui.status.find("refused"), std::string::npos) << st.ui.status;
    // Through `set` too, and another valid value.
    EXPECT_NE(st.setByName("fog.end", "-3"), "");
    EXPECT_NE(st.ui.status.find("refused"), std::string::npos) << st.ui.status;
    EXPECT_EQ(st.setByName("fog.end", "50"), "");
    EXPECT_EQ(st.ui.status.find("refused"), std::string::npos) << st.ui.status;
}

TEST(SceneDefaultsTest, FlySpeedFollowsTheSceneSize) {
    auto flown = [](float half) {
        Headless h;
        h.st.setScene(boxScene(half), {});
        h.st.view.camera.distance = 2.0f;   // close to the pivot in either scene: the speed must not follow this
        const ItemRect vp = h.rect("viewport");
        h.moveTo(vp.cx(), vp.cy());
        sg::vec3 eye = h.st.view.camera.eye();
        ImGuiIO& io = ImGui::GetIO();
        io.MouseDown[1] = true;   // right drag + W: fly forwards
        h.frame();
        io.KeysDown[keys::W] = true;
        for (int i = 0; i < 30; ++i) h.frame();
        io.KeysDown[keys::W] = false;
        io.MouseDown[1] = false;
        h.frame();
        return glm::length(h.st.view.camera.eye() - eye);
    };
    float small = flown(1.0f), big = flown(1000.0f);
    ASSERT_GT(small, 0.0f);
    EXPECT_NEAR(big / small, 1000.0f, 50.0f) << "half a second of W crosses the same share of either scene";
}
