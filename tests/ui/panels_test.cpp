// panels_test.cpp - the ImGui panels in headless frames (no window, no renderer backend): real
// clicks at the positions of recorded widgets change the scene and settings; keys switch
// backends; drags in the viewport move the camera; the unsaved-changes modal appears and works.
#include "headless_ui.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <imgui.h>

#include <filesystem>
#include <fstream>

using namespace ui;
namespace fs = std::filesystem;

TEST(PanelsTest, LayoutHasTreeTabsAndViewport) {
    Headless h;
    EXPECT_NO_THROW(h.rect("tab/Rendering"));
    EXPECT_NO_THROW(h.rect("tree/crate"));
    const ItemRect& vp = h.rect("viewport");
    EXPECT_GT(vp.x1 - vp.x0, 500.0f);   // the centre keeps most of the width
    EXPECT_GT(vp.y1 - vp.y0, 600.0f);
    EXPECT_GT(h.st.view.viewportWidth, 500);
}

TEST(PanelsTest, ClickingShadingRadioChangesSettings) {
    Headless h;
    h.click("tab/Rendering");
    ASSERT_EQ(h.st.doc.scene.settings.shading, sg::ShadingModel::Phong);
    h.st.doc.dirty = false;
    h.click("render/shading/Flat");
    EXPECT_EQ(h.st.doc.scene.settings.shading, sg::ShadingModel::Flat);
    EXPECT_TRUE(h.st.doc.dirty);
    h.click("render/shading/Gouraud");
    EXPECT_EQ(h.st.doc.scene.settings.shading, sg::ShadingModel::Gouraud);
    bool wire = h.st.doc.scene.settings.wireframe;
    h.click("render/wireframe");
    EXPECT_NE(h.st.doc.scene.settings.wireframe, wire);
    h.click("render/reflection/Blinn-Phong");
    EXPECT_EQ(h.st.doc.scene.settings.reflection, sg::ReflectionModel::BlinnPhong);
}

TEST(PanelsTest, AddSphereFromMenuAddsImplicitNode) {
    Headless h;
    h.st.selectNode(sg::kNoNode);
    size_t before = h.st.doc.scene.nodeCount();
    h.click("tree/addButton");
    h.click("add/Sphere");
    ASSERT_EQ(h.st.doc.scene.nodeCount(), before + 1);
    ASSERT_TRUE(h.st.doc.scene.valid(h.st.doc.selected));
    EXPECT_TRUE(std::holds_alternative<sg::ImplicitPayload>(h.st.doc.scene.node(h.st.doc.selected).payload));
    EXPECT_EQ(h.st.doc.scene.node(h.st.doc.selected).parent, h.st.doc.scene.root());
}

TEST(PanelsTest, TreeSelectsAndHides) {
    Headless h;
    sg::NodeId crate = h.st.doc.scene.findByName("crate");
    h.click("tree/crate");
    EXPECT_EQ(h.st.doc.selected, crate);
    h.click("tree/vis/crate");
    EXPECT_FALSE(h.st.doc.scene.node(crate).visible);
    EXPECT_TRUE(h.st.doc.dirty);
    // The inspector shows it: the visible checkbox there toggles it back.
    h.click("tab/Inspector");
    h.click("inspector/visible");
    EXPECT_TRUE(h.st.doc.scene.node(crate).visible);
}

TEST(PanelsTest, MatrixEditSwitchesToMatrixModeAndBack) {
    Headless h;
    sg::NodeId crate = h.st.doc.scene.findByName("crate");
    h.st.selectNode(crate);
    h.click("tab/Inspector");
    h.frame();
    ASSERT_EQ(h.st.doc.scene.node(crate).local.mode, sg::LocalTransform::Mode::TRS);
    // Matrix edits (here: the mirror button under the 4x4) switch to Matrix mode.
    sg::vec3 worldX(h.st.doc.scene.world(crate)[0]);
    h.click("inspector/mirrorX");
    EXPECT_EQ(h.st.doc.scene.node(crate).local.mode, sg::LocalTransform::Mode::Matrix);
    h.frame();
    EXPECT_NEAR(glm::dot(sg::vec3(h.st.doc.scene.world(crate)[0]), worldX), -glm::dot(worldX, worldX), 1e-4f);
    // A mirror is still translate * rotate * (negative) scale: convertible back to TRS.
    h.click("inspector/toTRS");
    EXPECT_EQ(h.st.doc.scene.node(crate).local.mode, sg::LocalTransform::Mode::TRS);
    EXPECT_NEAR(glm::dot(sg::vec3(h.st.doc.scene.world(crate)[0]), worldX), -glm::dot(worldX, worldX), 1e-4f);
    // Shear cannot be converted: the button refuses with a message and keeps the matrix.
    h.click("inspector/shear");
    ASSERT_EQ(h.st.doc.scene.node(crate).local.mode, sg::LocalTransform::Mode::Matrix);
    h.click("inspector/toTRS");
    EXPECT_EQ(h.st.doc.scene.node(crate).local.mode, sg::LocalTransform::Mode::Matrix);
    EXPECT_FALSE(h.st.ui.errorPopup.empty());
}

TEST(PanelsTest, NumberKeysSwitchBackends) {
    Headless h;
    h.moveTo(800, 450);
    h.press(keys::Num2);
    EXPECT_EQ(h.st.view.backend, "raster");
    h.press(keys::Num3);
    EXPECT_EQ(h.st.view.backend, "raycast");
    h.press(keys::Num1);
    EXPECT_EQ(h.st.view.backend, "gl");
    h.st.ui.requests.screenshot = false;
    h.press(keys::F12);
    EXPECT_TRUE(h.st.ui.requests.screenshot);
}

TEST(PanelsTest, ViewportDragOrbitsWheelZooms) {
    Headless h;
    const ItemRect vp = h.rect("viewport");
    float yaw = h.st.view.camera.yaw, dist = h.st.view.camera.distance;
    sg::vec3 pivot = h.st.view.camera.pivot;
    h.moveTo(vp.cx(), vp.cy());
    ImGui::GetIO().MouseDown[0] = true;
    h.frame();
    for (int i = 1; i <= 5; ++i) h.moveTo(vp.cx() + 10.0f * i, vp.cy());
    ImGui::GetIO().MouseDown[0] = false;
    h.frame();
    EXPECT_NE(h.st.view.camera.yaw, yaw);
    EXPECT_NEAR(h.st.view.camera.distance, dist, 1e-4f);
    EXPECT_NEAR(glm::length(h.st.view.camera.pivot - pivot), 0.0f, 1e-5f);
    ImGui::GetIO().MouseWheel = 2.0f;
    h.frame();
    ImGui::GetIO().MouseWheel = 0.0f;
    EXPECT_LT(h.st.view.camera.distance, dist);
    // Middle drag pans: the pivot moves.
    ImGui::GetIO().MouseDown[2] = true;
    h.frame();
    for (int i = 1; i <= 5; ++i) h.moveTo(vp.cx() - 10.0f * i, vp.cy() + 4.0f * i);
    ImGui::GetIO().MouseDown[2] = false;
    h.frame();
    EXPECT_GT(glm::length(h.st.view.camera.pivot - pivot), 1e-3f);
}

TEST(PanelsTest, QuitWithUnsavedChangesShowsModal) {
    Headless h;
    h.st.addShape(sg::ImplicitType::Torus);
    EXPECT_FALSE(h.st.requestQuit());
    h.frame();
    h.frame();
    ASSERT_NO_THROW(h.rect("confirm/cancel"));
    h.click("confirm/cancel");
    EXPECT_FALSE(h.st.ui.requests.quit);
    EXPECT_TRUE(h.st.doc.dirty);
    EXPECT_FALSE(h.st.requestQuit());
    h.frame();
    h.frame();
    h.click("confirm/discard");
    EXPECT_TRUE(h.st.ui.requests.quit);
}

TEST(PanelsTest, SplitViewDividerDrags) {
    Headless h;
    h.click("tab/Compare");
    h.click("compare/split");
    EXPECT_EQ(h.st.view.compare.mode, ViewMode::Split);
    h.view.slots.resize(2);
    h.view.slots[1].status.backend = "raster";
    h.frame();
    const ItemRect vp = h.rect("viewport");
    float x = vp.x0 + 0.5f * (vp.x1 - vp.x0);
    float yaw = h.st.view.camera.yaw;
    h.moveTo(x, vp.cy());
    ImGui::GetIO().MouseDown[0] = true;
    h.frame();
    for (int i = 1; i <= 5; ++i) h.moveTo(x + 20.0f * i, vp.cy());
    ImGui::GetIO().MouseDown[0] = false;
    h.frame();
    EXPECT_GT(h.st.view.compare.dividers[0], 0.55f);
    EXPECT_EQ(h.st.view.camera.yaw, yaw);   // the divider took the drag, not the camera
    EXPECT_EQ(visibleBackends(h.st).size(), 2u);
}

namespace {
// A clip moving the demo's crate along x: (0,0,0) at t=0 to (4,0,0) at t=2.
assets::AnimationClip crateClip(const sg::Scene& s) {
    assets::AnimationClip clip;
    clip.name = "crate slide";
    clip.start = 0.0f;
    clip.duration = 2.0f;
    assets::AnimationChannel ch;
    ch.node = s.findByName("crate");
    ch.path = assets::AnimationPath::Translation;
    ch.times = {0.0f, 2.0f};
    ch.values = {sg::vec4(0.0f), sg::vec4(4, 0, 0, 0)};
    clip.channels.push_back(ch);
    return clip;
}
}   // namespace

TEST(PanelsTest, AnimationBarOnlyWithClipsPlayButtonAndSpaceToggle) {
    Headless h;
    EXPECT_EQ(h.st.hooks.itemRects.count("anim/play"), 0u);   // the demo has no clips: no bar
    h.st.anim.clips.push_back(crateClip(h.st.doc.scene));
    h.frame();
    ASSERT_NO_THROW(h.rect("anim/play"));
    EXPECT_NO_THROW(h.rect("anim/time"));
    EXPECT_NO_THROW(h.rect("anim/loop"));
    EXPECT_NO_THROW(h.rect("anim/clip"));
    ASSERT_FALSE(h.st.anim.playing);
    h.click("anim/play");
    EXPECT_TRUE(h.st.anim.playing);
    h.st.advanceAnimation(1.0);   // the window's main loop does this every frame
    sg::NodeId crate = h.st.doc.scene.findByName("crate");
    EXPECT_NEAR(h.st.doc.scene.node(crate).local.translation.x, 2.0f, 1e-5f);
    h.click("anim/play");   // now "Pause"
    EXPECT_FALSE(h.st.anim.playing);
    bool loop = h.st.anim.loop;
    h.click("anim/loop");
    EXPECT_NE(h.st.anim.loop, loop);
    // Space toggles while the viewport has focus (a click in it gives it focus).
    h.click("viewport");
    h.press(keys::Space);
    EXPECT_TRUE(h.st.anim.playing);
    h.press(keys::Space);
    EXPECT_FALSE(h.st.anim.playing);
    // Scrub: a click at the slider's left end goes to the clip start.
    const ItemRect r = h.rect("anim/time");
    h.moveTo(r.x0 + 2.0f, r.cy());
    ImGui::GetIO().MouseDown[0] = true;
    h.frame();
    ImGui::GetIO().MouseDown[0] = false;
    h.frame();
    EXPECT_NEAR(h.st.anim.time, 0.0, 0.05);
    EXPECT_NEAR(h.st.doc.scene.node(crate).local.translation.x, 2.0f * float(h.st.anim.time), 1e-4f);
    EXPECT_FALSE(h.st.doc.dirty);
}

TEST(PanelsTest, LoadShowsProgressAndCancelButtonKeepsScene) {
    Headless h;
    size_t nodes = h.st.doc.scene.nodeCount();
    EXPECT_EQ(h.st.hooks.itemRects.count("status/cancelLoad"), 0u);
    // The panels never finish loads (the main loop's pollLoad does), so the bar stays up.
    h.st.startLoad("/nonexistent/dir/scene.obj");
    h.frame();
    ASSERT_NO_THROW(h.rect("status/loadProgress"));
    h.click("status/cancelLoad");
    EXPECT_TRUE(h.st.loadCancelRequested());
    ASSERT_TRUE(h.st.pollLoad(true));
    EXPECT_EQ(h.st.doc.scene.nodeCount(), nodes);
    EXPECT_TRUE(h.st.ui.errorPopup.empty());
    EXPECT_NE(h.st.ui.status.find("scene.obj cancelled"), std::string::npos) << h.st.ui.status;
}

// The panels keep their own state (dialogs, toggles, in-place rename) in the viewer's
// PanelState, not in globals: each viewer starts fresh, and File > Open, the screenshot dialog
// and F2 rename go through it.
TEST(PanelsTest, PanelStateBelongsToTheViewer) {
    {
        Headless h;
        EXPECT_TRUE(h.st.ui.panels.showOverlay);
        h.st.ui.panels.showOverlay = false;
        h.st.ui.panels.showHelp = true;   // before the modal: ImGui 1.86 asserts when a new window appears under one
        h.frame();
        h.st.ui.requests.openDialog = true;
        h.frame();
        h.frame();
        EXPECT_TRUE(h.st.ui.panels.browser.open);
        EXPECT_FALSE(h.st.ui.panels.browser.saving);
        EXPECT_FALSE(h.st.ui.panels.browser.dir.empty());
        EXPECT_NO_THROW(h.rect("browser/accept"));
    }
    Headless h;
    EXPECT_TRUE(h.st.ui.panels.showOverlay);
    EXPECT_FALSE(h.st.ui.panels.showHelp);
    EXPECT_FALSE(h.st.ui.panels.browser.open);
    h.st.ui.requests.screenshotDialog = true;
    h.frame();
    h.frame();   // an auto-resizing modal takes its size on its second frame
    EXPECT_TRUE(h.st.ui.panels.shotDialog.open);
    h.click("shot/take");
    EXPECT_TRUE(h.st.ui.requests.screenshot);
    EXPECT_EQ(h.st.ui.requests.screenshotWidth, h.st.view.viewportWidth);   // the viewport's size by default, as the option's label says
    EXPECT_EQ(h.st.ui.requests.screenshotHeight, h.st.view.viewportHeight);
}

TEST(PanelsTest, F2RenamesTheSelectionInPlace) {
    Headless h;
    sg::NodeId crate = h.st.doc.scene.findByName("crate");
    h.click("tree/crate");
    ASSERT_EQ(h.st.doc.selected, crate);
    h.press(keys::F2);
    EXPECT_EQ(h.st.ui.panels.renaming, crate);
    EXPECT_EQ(h.st.ui.panels.renameBuffer, "crate");
}

// The screenshot dialog shows the folder (absolute) and takes another one; a
// folder that cannot be made keeps the dialog open with the reason and takes nothing.
TEST(PanelsTest, ScreenshotDialogFolderIsShownAndChecked) {
    fs::path base = testing_support::outputDir("ui") / "shot_dialog";
    fs::remove_all(base);
    fs::create_directories(base);
    std::ofstream(base / "file") << "x";
    Headless h;
    h.st.ui.requests.screenshotDialog = true;
    h.frame();
    h.frame();
    EXPECT_TRUE(fs::path(h.st.ui.panels.shotDialog.dirText).is_absolute()) << h.st.ui.panels.shotDialog.dirText;
    h.st.ui.panels.shotDialog.dirText = (base / "file" / "sub").string();
    h.click("shot/take");
    EXPECT_FALSE(h.st.ui.requests.screenshot);
    EXPECT_NE(h.st.ui.panels.shotDialog.error.find("cannot use folder"), std::string::npos) << h.st.ui.panels.shotDialog.error;
    EXPECT_TRUE(ImGui::IsPopupOpen(nullptr, ImGuiPopupFlags_AnyPopupId)) << "the dialog stays open";
    fs::create_directories(base / "picked");
    h.st.ui.panels.shotDialog.dirText = base.string();
    h.frame();
    h.click("shot/dir/picked");   // chosen by clicking, not typing
    EXPECT_EQ(h.st.ui.panels.shotDialog.dirText, (fs::absolute(base).lexically_normal() / "picked").string());
    h.click("shot/up");
    EXPECT_EQ(h.st.ui.panels.shotDialog.dirText, fs::absolute(base).lexically_normal().string());
    h.st.ui.panels.shotDialog.dirText = (base / "shots").string();
    h.click("shot/take");
    EXPECT_TRUE(h.st.ui.requests.screenshot);
    EXPECT_EQ(h.st.ui.panels.shotDialog.dir, fs::absolute(base / "shots").lexically_normal());
    EXPECT_TRUE(fs::is_directory(base / "shots"));
}

// File > Open: a folder typed into the name field opens in the list (relative to the listed
// folder or absolute) instead of being taken as a file; a file name is still opened.
TEST(PanelsTest, TypingAFolderInTheFileDialogOpensIt) {
    fs::path base = testing_support::outputDir("ui") / "browse_typed";
    fs::remove_all(base);
    fs::create_directories(base / "models" / "deep");
    Headless h;
    h.st.ui.requests.openDialog = true;
    h.frame();
    h.frame();
    ASSERT_TRUE(h.st.ui.panels.browser.open);
    h.st.ui.panels.browser.dir = base;
    h.st.ui.panels.browser.fileName = "models";
    h.click("browser/accept");
    EXPECT_TRUE(h.st.ui.panels.browser.open) << "a folder is not a file to open";
    EXPECT_EQ(h.st.ui.panels.browser.dir, fs::weakly_canonical(base / "models"));
    EXPECT_TRUE(h.st.ui.panels.browser.fileName.empty());
    h.st.ui.panels.browser.fileName = (base / "models" / "deep").string();   // absolute
    h.click("browser/accept");
    EXPECT_EQ(h.st.ui.panels.browser.dir, fs::weakly_canonical(base / "models" / "deep"));
    h.st.ui.panels.browser.fileName = "missing.obj";   // not a folder: taken as the file (the load then reports it)
    h.click("browser/accept");
    EXPECT_FALSE(h.st.ui.panels.browser.open);
}
