// viewer_state_test.cpp - ViewerState actions (scene edits, reparent refusal, backend), the
// unsaved-changes guard, asynchronous loading that keeps the scene on failure, screenshot
// naming, recent files, the frame handed to the renderers and RenderSlot's threaded
// coarse-to-fine rendering.
#include "ui/viewer_state.h"
#include "ui/render_slot.h"

#include "assets/demo.h"
#include "assets/files.h"
#include "renderers/renderer.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <set>
#include <thread>

using namespace ui;
namespace fs = std::filesystem;

namespace {
ViewerState demoState() {
    ViewerState st;
    st.view.viewportWidth = 800;
    st.view.viewportHeight = 600;
    st.setScene(assets::makeDemoScene(), {});
    return st;
}
}   // namespace

TEST(ViewerStateTest, SetSceneStartsCleanAndLooksThroughActiveCamera) {
    ViewerState st = demoState();
    EXPECT_FALSE(st.doc.dirty);
    ASSERT_TRUE(st.doc.scene.valid(st.doc.scene.activeCamera));
    sg::vec3 camEye(st.doc.scene.world(st.doc.scene.activeCamera)[3]);
    sg::vec3 e = st.view.camera.eye();
    EXPECT_NEAR(glm::length(e - camEye), 0.0f, 1e-3f);
}

TEST(ViewerStateTest, AddShapeAddsImplicitNode) {
    ViewerState st = demoState();
    size_t before = st.doc.scene.nodeCount();
    sg::NodeId id = st.addShape(sg::ImplicitType::Sphere);
    ASSERT_TRUE(st.doc.scene.valid(id));
    EXPECT_EQ(st.doc.scene.nodeCount(), before + 1);
    auto* p = std::get_if<sg::ImplicitPayload>(&st.doc.scene.node(id).payload);
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(p->shape.type, sg::ImplicitType::Sphere);
    EXPECT_EQ(st.doc.selected, id);
    EXPECT_TRUE(st.doc.dirty);
    // A second one gets a distinct name.
    sg::NodeId id2 = st.addShape(sg::ImplicitType::Sphere, st.doc.scene.root());
    EXPECT_NE(st.doc.scene.node(id).name, st.doc.scene.node(id2).name);
}

TEST(ViewerStateTest, AddCsgAddsTwoOperands) {
    ViewerState st = demoState();
    sg::NodeId id = st.addCsg(sg::CsgOp::Difference, st.doc.scene.root());
    ASSERT_TRUE(std::holds_alternative<sg::CsgPayload>(st.doc.scene.node(id).payload));
    EXPECT_EQ(st.doc.scene.node(id).children.size(), 2u);
}

TEST(ViewerStateTest, RenameDuplicateRemove) {
    ViewerState st = demoState();
    sg::NodeId crate = st.doc.scene.findByName("crate");
    ASSERT_NE(crate, sg::kNoNode);
    EXPECT_TRUE(st.renameNode(crate, "box of things"));
    EXPECT_EQ(st.doc.scene.node(crate).name, "box of things");
    EXPECT_FALSE(st.renameNode(crate, ""));   // empty names refused
    sg::NodeId copy = st.duplicateNode(crate);
    ASSERT_TRUE(st.doc.scene.valid(copy));
    EXPECT_NE(st.doc.scene.node(copy).name, "box of things");
    EXPECT_TRUE(st.removeNode(copy));
    EXPECT_FALSE(st.doc.scene.valid(copy));
    EXPECT_FALSE(st.removeNode(st.doc.scene.root()));
}

TEST(ViewerStateTest, ReparentKeepsWorldAndRefusesCycles) {
    ViewerState st = demoState();
    sg::NodeId turntable = st.doc.scene.findByName("turntable");
    sg::NodeId torus = st.doc.scene.findByName("torus");
    sg::NodeId crate = st.doc.scene.findByName("crate");
    sg::mat4 before = st.doc.scene.world(crate);
    EXPECT_TRUE(st.reparent(crate, torus));
    sg::mat4 after = st.doc.scene.world(crate);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(after[c][r], before[c][r], 1e-4f);
    st.doc.dirty = false;
    // turntable -> its own descendant: refused, with a reason, nothing changes.
    std::string err;
    EXPECT_FALSE(st.reparent(turntable, torus, &err));
    EXPECT_FALSE(err.empty());
    EXPECT_NE(st.ui.status.find("refused"), std::string::npos);
    EXPECT_FALSE(st.doc.dirty);
    EXPECT_FALSE(st.reparent(st.doc.scene.root(), crate, &err));
}

TEST(ViewerStateTest, BackendKeysAndEditsBumpVersions) {
    ViewerState st = demoState();
    st.setBackendIndex(1);
    EXPECT_EQ(st.view.backend, "raster");
    st.setBackendIndex(2);
    EXPECT_EQ(st.view.backend, "raycast");
    st.setBackendIndex(7);   // ignored
    EXPECT_EQ(st.view.backend, "raycast");
    uint64_t v = st.doc.version, vv = st.view.version;
    sg::Projection p = st.projection();
    p.fovyDeg = 60.0f;
    st.setProjection(p);
    EXPECT_GT(st.doc.version, v);   // the scene camera's projection is scene data
    EXPECT_TRUE(st.doc.dirty);
    EXPECT_EQ(st.projection().fovyDeg, 60.0f);
    st.fitView(false);
    EXPECT_GT(st.view.version, vv);
}

TEST(ViewerStateTest, BuildFrameUsesOrbitCameraAndSceneProjection) {
    ViewerState st = demoState();
    st.view.camera.orbit(120.0f, 30.0f);
    sg::FrameInput f = st.buildFrame(2.0f);
    sg::mat4 w = st.view.camera.world();
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(f.camera.viewInverse[c][r], w[c][r], 1e-5f);
    EXPECT_EQ(f.camera.projection.fovyDeg, st.projection().fovyDeg);
    EXPECT_FLOAT_EQ(f.camera.aspect, 2.0f);
    EXPECT_FALSE(f.meshes.empty());
    // Per-backend AA override changes only that backend's settings.
    st.view.aaOverride["raster"] = "ssaa2";
    EXPECT_EQ(st.settingsFor("raster").aa, sg::AAMode::SSAA);
    EXPECT_EQ(st.settingsFor("gl").aa, st.doc.scene.settings.aa);
}

// View > Axis view > Isometric is a true isometric view: orthographic (a perspective view at the
// pivot keeps its size), looking along -(1, 1, 1), the world axes equally long on screen and 120
// degrees apart in the frame the renderers get.
TEST(ViewerStateTest, IsometricAxisViewIsOrthographicAlongTheDiagonal) {
    for (sg::ProjectionType start : {sg::ProjectionType::Perspective, sg::ProjectionType::Oblique}) {
        ViewerState st = demoState();
        sg::Projection p = st.projection();
        p.type = start;
        st.setProjection(p);
        st.view.camera.orbit(40.0f, -25.0f);
        const float before = st.view.camera.distance;
        st.viewAlong(AxisView::Isometric);
        EXPECT_EQ(st.projection().type, sg::ProjectionType::Orthographic) << sg::toString(start);
        EXPECT_FLOAT_EQ(st.view.camera.distance, before) << "the pivot and distance stay";
        const sg::vec3 forward = st.view.camera.forward();
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(forward[k], -1.0f / std::sqrt(3.0f), 1e-5f) << k;
        const float aspect = float(st.view.viewportWidth) / float(st.view.viewportHeight);
        const sg::FrameInput f = st.buildFrame(aspect);
        float len[3];
        sg::vec2 axis[3];
        for (int a = 0; a < 3; ++a) {
            sg::vec3 e(0.0f);
            e[a] = 1.0f;
            const sg::vec4 q = f.camera.viewProj * sg::vec4(st.view.camera.pivot + e, 1.0f),
                           o = f.camera.viewProj * sg::vec4(st.view.camera.pivot, 1.0f);
            axis[a] = sg::vec2((q.x / q.w - o.x / o.w) * st.view.viewportWidth, (q.y / q.w - o.y / o.w) * st.view.viewportHeight);   // pixels x 2
            len[a] = glm::length(axis[a]);
        }
        EXPECT_NEAR(len[1] / len[0], 1.0f, 1e-4f);
        EXPECT_NEAR(len[2] / len[0], 1.0f, 1e-4f);
        for (int a = 0; a < 3; ++a)
            EXPECT_NEAR(sg::degrees(std::acos(glm::dot(axis[a], axis[(a + 1) % 3]) / (len[a] * len[(a + 1) % 3]))), 120.0f, 1e-2f) << a;
    }
}

TEST(ViewerStateTest, SceneWithoutCameraGetsFramingView) {
    ViewerState st;
    st.view.viewportWidth = 400;
    st.view.viewportHeight = 300;
    sg::Scene s;
    s.addNode("ball", 0, sg::ImplicitPayload{});
    st.setScene(std::move(s), {});
    EXPECT_NEAR(glm::length(st.view.camera.pivot), 0.0f, 1e-4f);
    EXPECT_GT(st.view.camera.distance, 1.0f);
    sg::FrameInput f = st.buildFrame(4.0f / 3.0f);
    EXPECT_EQ(f.analytics.size(), 1u);
}

TEST(ViewerStateTest, UnsavedChangesAreNeverLostWithoutAsking) {
    ViewerState st = demoState();
    // Clean: quit goes through at once.
    EXPECT_TRUE(st.requestQuit());
    EXPECT_TRUE(st.ui.requests.quit);
    st.ui.requests.quit = false;

    st.addShape(sg::ImplicitType::Box);
    ASSERT_TRUE(st.doc.dirty);
    EXPECT_FALSE(st.requestQuit());
    EXPECT_FALSE(st.ui.requests.quit);
    EXPECT_TRUE(st.ui.confirmOpen);
    st.confirm(ConfirmChoice::Cancel);
    EXPECT_FALSE(st.ui.requests.quit);
    EXPECT_TRUE(st.doc.dirty);

    // Open while dirty: asks; cancel keeps the scene; discard loads.
    size_t nodes = st.doc.scene.nodeCount();
    EXPECT_FALSE(st.requestOpen("/nonexistent/file.obj"));
    EXPECT_FALSE(st.loadInProgress());
    st.confirm(ConfirmChoice::Cancel);
    EXPECT_EQ(st.doc.scene.nodeCount(), nodes);
    EXPECT_FALSE(st.requestNew());
    st.confirm(ConfirmChoice::Discard);
    EXPECT_EQ(st.doc.scene.nodeCount(), 3u);   // new scene: root, a light and a camera
    EXPECT_FALSE(st.doc.dirty);

    // Save with no file name: asks for one instead of quitting; cancelling Save As drops the quit.
    st.addGroup();
    EXPECT_FALSE(st.requestQuit());
    st.confirm(ConfirmChoice::Save);
    EXPECT_FALSE(st.ui.requests.quit);
    EXPECT_TRUE(st.ui.requests.saveAsDialog);
    EXPECT_TRUE(st.doc.dirty);
    st.ui.requests.saveAsDialog = false;
    st.saveAsCancelled();
    EXPECT_FALSE(st.ui.requests.quit);
    EXPECT_TRUE(st.doc.dirty);

    // ... and once Save As has a file, the save goes on with the quit.
    st.config.dir.clear();
    fs::path file = testing_support::outputDir("ui") / "save-then-quit.json";
    fs::remove(file);
    EXPECT_FALSE(st.requestQuit());
    st.confirm(ConfirmChoice::Save);
    EXPECT_EQ(st.saveAs(file), SaveOutcome::Saved);
    EXPECT_TRUE(st.ui.requests.quit);
    EXPECT_FALSE(st.doc.dirty);
    st.ui.requests.quit = false;
    st.addGroup();

    // Discard on quit quits.
    EXPECT_FALSE(st.requestQuit());
    st.confirm(ConfirmChoice::Discard);
    EXPECT_TRUE(st.ui.requests.quit);
}

namespace {
std::string fileText(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}
}   // namespace

// Save writes over the document's own .json only; an imported document's first Save opens Save
// As (nothing written beside the import); Save As onto an existing file asks, Cancel keeps the
// file byte for byte, Replace writes it; ".json" is appended for another extension, and the
// existing NAME.gltf.json that makes is asked about too.
TEST(ViewerStateTest, NothingOnDiskIsReplacedWithoutAQuestion) {
    fs::path dir = testing_support::outputDir("ui") / "save_rules";
    fs::remove_all(dir);
    fs::create_directories(dir);
    ViewerState st = demoState();
    st.config.dir.clear();

    // An import: Save asks for a name and writes nothing.
    {
        std::ofstream out(dir / "tri.obj");
        out << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    }
    {
        std::ofstream out(dir / "tri.obj.json");
        out << "precious";
    }
    ASSERT_TRUE(st.requestOpen(dir / "tri.obj"));
    ASSERT_TRUE(st.pollLoad(/*wait=*/true));
    ASSERT_EQ(st.doc.path, dir / "tri.obj");
    st.addGroup();
    EXPECT_EQ(st.save(), SaveOutcome::Asked);
    EXPECT_TRUE(st.ui.requests.saveAsDialog);
    EXPECT_TRUE(st.doc.dirty);
    EXPECT_EQ(fileText(dir / "tri.obj.json"), "precious");
    st.ui.requests.saveAsDialog = false;

    // Save As onto the existing tri.obj.json (typed as tri.obj): asks; Cancel keeps it.
    EXPECT_EQ(st.saveAs(dir / "tri.obj"), SaveOutcome::Asked);
    EXPECT_TRUE(st.ui.replaceOpen);
    EXPECT_EQ(st.ui.replacePath, dir / "tri.obj.json");
    st.confirmReplace(false);
    EXPECT_FALSE(st.ui.replaceOpen);
    EXPECT_EQ(fileText(dir / "tri.obj.json"), "precious");
    EXPECT_TRUE(st.doc.dirty);
    EXPECT_EQ(st.doc.path, dir / "tri.obj");

    // A new name: written at once, and it becomes the document.
    EXPECT_EQ(st.saveAs(dir / "tri-scene.json"), SaveOutcome::Saved);
    EXPECT_EQ(st.doc.path, dir / "tri-scene.json");
    EXPECT_FALSE(st.doc.dirty);
    std::string first = fileText(dir / "tri-scene.json");

    // Save on the document's own .json writes over it without a question.
    st.addGroup();
    EXPECT_EQ(st.save(), SaveOutcome::Saved);
    EXPECT_FALSE(st.ui.replaceOpen);
    EXPECT_NE(fileText(dir / "tri-scene.json"), first);

    // Save As onto an existing file, answered Replace: written.
    EXPECT_EQ(st.saveAs(dir / "tri.obj.json"), SaveOutcome::Asked);
    st.confirmReplace(true);
    EXPECT_NE(fileText(dir / "tri.obj.json"), "precious");
    EXPECT_EQ(st.doc.path, dir / "tri.obj.json");

    // Nothing was ever written over the import itself.
    EXPECT_EQ(fileText(dir / "tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
}

// A file that cannot be opened is refused before the unsaved-changes question.
TEST(ViewerStateTest, UnopenableFilesAreRefusedBeforeAskingAboutUnsavedChanges) {
    ViewerState st = demoState();
    st.addGroup();
    fs::path dir = testing_support::outputDir("ui") / "open_refused";
    fs::create_directories(dir);
    {
        std::ofstream out(dir / "notes.txt");
        out << "hello";
    }
    for (const fs::path& p : {dir / "notes.txt", dir, dir / "missing.gltf"}) {
        st.ui.errorPopup.clear();
        EXPECT_FALSE(st.requestOpen(p));
        EXPECT_FALSE(st.ui.confirmOpen) << p;
        EXPECT_EQ(st.ui.pending, PendingAction::None) << p;
        EXPECT_NE(st.ui.errorPopup.find(p.string()), std::string::npos) << st.ui.errorPopup;
        EXPECT_TRUE(st.doc.dirty);
    }
}

// Regression: edit, Open a file that fails, answer Discard. The load
// fails, so the document must stay exactly as it was: edits, dirty flag, and Quit still asks.
TEST(ViewerStateTest, DiscardThenFailedOrCancelledLoadKeepsEditsAndDirtyFlag) {
    ViewerState st = demoState();
    sg::NodeId added = st.addShape(sg::ImplicitType::Sphere);
    ASSERT_TRUE(st.doc.dirty);
    size_t nodes = st.doc.scene.nodeCount();

    fs::path broken = testing_support::outputDir("ui") / "discard-broken.gltf";
    {
        std::ofstream out(broken);
        out << "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ { \"mesh\": 7 } ] }";   // a mesh that is not there
    }
    EXPECT_FALSE(st.requestOpen(broken));
    st.confirm(ConfirmChoice::Discard);
    EXPECT_TRUE(st.doc.dirty) << "Discard alone must not clear the flag: nothing has replaced the scene yet";
    ASSERT_TRUE(st.loadInProgress());
    EXPECT_TRUE(st.pollLoad(/*wait=*/true));
    EXPECT_FALSE(st.ui.errorPopup.empty());
    EXPECT_TRUE(st.doc.dirty);
    EXPECT_EQ(st.doc.scene.nodeCount(), nodes);
    EXPECT_TRUE(st.doc.scene.valid(added));
    st.ui.errorPopup.clear();

    // Quit still asks.
    EXPECT_FALSE(st.requestQuit());
    EXPECT_TRUE(st.ui.confirmOpen);
    st.confirm(ConfirmChoice::Cancel);
    EXPECT_FALSE(st.ui.requests.quit);

    // Same after a cancelled load (cancel before the importer even starts reading).
    fs::path good = testing_support::outputDir("ui") / "discard-cancel.obj";
    {
        std::ofstream out(good);
        out << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    }
    EXPECT_FALSE(st.requestOpen(good));
    st.confirm(ConfirmChoice::Discard);
    st.cancelLoad();
    EXPECT_TRUE(st.pollLoad(/*wait=*/true));
    EXPECT_TRUE(st.doc.dirty);
    EXPECT_EQ(st.doc.scene.nodeCount(), nodes);

    // A load that succeeds after Discard replaces the scene and starts clean.
    EXPECT_FALSE(st.requestOpen(good));
    st.confirm(ConfirmChoice::Discard);
    EXPECT_TRUE(st.pollLoad(/*wait=*/true));
    EXPECT_TRUE(st.ui.errorPopup.empty()) << st.ui.errorPopup;
    EXPECT_FALSE(st.doc.dirty);
    EXPECT_EQ(st.doc.path, good);
}

TEST(ViewerStateTest, FailedLoadKeepsCurrentSceneAndShowsError) {
    ViewerState st = demoState();
    size_t nodes = st.doc.scene.nodeCount();
    fs::path bad = testing_support::outputDir("ui") / "broken.obj";
    {
        std::ofstream out(bad);
        out << "this is not an obj file\nf 1 2 3 4 5\n";
    }
    st.startLoad("/nonexistent/dir/scene.gltf");
    ASSERT_TRUE(st.loadInProgress());
    EXPECT_TRUE(st.pollLoad(/*wait=*/true));
    EXPECT_FALSE(st.ui.errorPopup.empty());
    EXPECT_NE(st.ui.errorPopup.find("scene.gltf"), std::string::npos);
    EXPECT_EQ(st.doc.scene.nodeCount(), nodes);
    EXPECT_TRUE(st.doc.path.empty());
}

TEST(ViewerStateTest, ScreenshotNamesNeverOverwrite) {
    fs::path dir = testing_support::outputDir("ui") / "shots";
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::path a = screenshotPath(dir, "raster");
    EXPECT_EQ(a.filename(), "screenshot-raster.png");
    ASSERT_EQ(assets::writeFileAtomic(a, "x", false), "");
    fs::path b = screenshotPath(dir, "raster");
    EXPECT_NE(a, b);
    EXPECT_FALSE(fs::exists(b));
    EXPECT_NE(b.filename().string().find("raster"), std::string::npos);
    EXPECT_EQ(b.extension(), ".png");
}

// With exports, a name is free only when the PNG and every file next to it are: a left-over
// screenshot-gl.depth.pfm (its PNG deleted) is never overwritten by the next screenshot.
TEST(ViewerStateTest, ScreenshotNamesWithExportsNeverOverwriteAnExportFile) {
    fs::path dir = testing_support::outputDir("ui") / "shots_exports";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::vector<rnd::Aov> exports = {rnd::Aov::Depth, rnd::Aov::Id};
    EXPECT_EQ(screenshotPath(dir, "gl", "screenshot", exports).filename(), "screenshot-gl.png");
    ASSERT_EQ(assets::writeFileAtomic(dir / "screenshot-gl.depth.pfm", "x", false), "");
    EXPECT_EQ(screenshotPath(dir, "gl").filename(), "screenshot-gl.png") << "without exports only the PNG counts";
    EXPECT_EQ(screenshotPath(dir, "gl", "screenshot", exports).filename(), "screenshot-gl-1.png");
    ASSERT_EQ(assets::writeFileAtomic(dir / "screenshot-gl-1.json", "{}", false), "");
    EXPECT_EQ(screenshotPath(dir, "gl", "screenshot", exports).filename(), "screenshot-gl-2.png") << "the sidecar counts too";
    ScreenshotDialogState dialog;
    EXPECT_TRUE(screenshotExports(dialog).empty());
    dialog.exportId = dialog.exportDepth = true;
    EXPECT_EQ(screenshotExports(dialog), (std::vector<rnd::Aov>{rnd::Aov::Depth, rnd::Aov::Id}));
}

// The screenshot dialog's size option says the size it writes; the status line names
// every file written (the folder once, absolute) and every failure; a folder that cannot be
// made is an error, not a silent "."
TEST(ViewerStateTest, ScreenshotSizeIsTheOneTheLabelNames) {
    View view;
    view.viewportWidth = 1031;
    view.viewportHeight = 644;
    ScreenshotDialogState dialog;   // ticked, with 1920x1080 in the (disabled) fields
    EXPECT_EQ(screenshotSize(dialog, view), std::make_pair(1031, 644));
    EXPECT_EQ(screenshotSizeLabel(dialog, view).rfind("Viewport size (1031x644)", 0), 0u) << screenshotSizeLabel(dialog, view);
    dialog.windowSize = false;
    EXPECT_EQ(screenshotSize(dialog, view), std::make_pair(1920, 1080));
    EXPECT_EQ(screenshotSizeLabel(dialog, view).rfind("Viewport size (1031x644)", 0), 0u) << "the option names the viewport either way";
}

TEST(ViewerStateTest, ScreenshotSummaryNamesEveryFileAndFailure) {
    const fs::path dir = "/home/me/shots";
    EXPECT_EQ(screenshotSummary({{"gl", dir / "screenshot-gl.png", ""}, {"raster", dir / "screenshot-raster.png", ""}}),
              "Saved 2 screenshots in /home/me/shots: screenshot-gl.png, screenshot-raster.png");
    EXPECT_EQ(screenshotSummary({{"gl", dir / "screenshot-gl.png", "OpenGL error 0x502"}, {"raster", dir / "screenshot-raster.png", ""}}),
              "Saved screenshot-raster.png in /home/me/shots; gl failed: OpenGL error 0x502");
    EXPECT_EQ(screenshotSummary({{"gl", dir / "screenshot-gl.png", "no context"}}), "Screenshot failed: gl failed: no context");
    EXPECT_EQ(screenshotSummary({{"gl", dir / "screenshot-gl.png", "gl: no context"}}), "Screenshot failed: gl failed: no context")
        << "the backend named once";
    EXPECT_EQ(screenshotSummary({{"gl", dir / "screenshot-gl.png", "", {rnd::Aov::Depth, rnd::Aov::Id}}}),
              "Saved screenshot-gl.png in /home/me/shots; with depth, id and the camera .json");
}

TEST(ViewerStateTest, ScreenshotFolderIsAbsoluteAndABadOneIsAnError) {
    fs::path base = testing_support::outputDir("ui") / "shot_folder";
    fs::remove_all(base);
    std::string err;
    fs::path made = prepareScreenshotFolder(base / "new" / "", &err);
    EXPECT_EQ(err, "");
    EXPECT_TRUE(made.is_absolute());
    EXPECT_EQ(made.filename(), "new") << "no trailing separator: " << made;
    EXPECT_TRUE(fs::is_directory(made));
    EXPECT_TRUE(prepareScreenshotFolder("", &err).is_absolute()) << "empty = the current folder";
    ASSERT_EQ(assets::writeFileAtomic(base / "file", "x", false), "");
    EXPECT_TRUE(prepareScreenshotFolder(base / "file", &err).empty());
    EXPECT_NE(err.find("cannot use folder"), std::string::npos) << err;
    EXPECT_TRUE(prepareScreenshotFolder(base / "file" / "sub", &err).empty());
}

// The window's rectangle comes from the work area, --window-size or the last
// run, and always fits inside the work area.
TEST(ViewerStateTest, WindowPlacementFitsTheWorkArea) {
    const WindowRect small{0, 0, 1366, 768};
    WindowRect r = placeWindow(small, std::nullopt);
    EXPECT_EQ(r, (WindowRect{102, 58, 1161, 652})) << "85% of the work area, centred";
    EXPECT_EQ(placeWindow(small, std::nullopt, 1600, 900), (WindowRect{0, 0, 1366, 768})) << "a requested size is clamped";
    EXPECT_EQ(placeWindow(small, WindowRect{40, 30, 900, 600}), (WindowRect{40, 30, 900, 600})) << "remembered";
    EXPECT_EQ(placeWindow(small, WindowRect{1000, 500, 900, 600}), (WindowRect{466, 168, 900, 600})) << "moved back on screen";
    EXPECT_EQ(placeWindow(WindowRect{1920, 24, 1280, 776}, WindowRect{-9000, 0, 4000, 3000}), (WindowRect{1920, 24, 1280, 776}))
        << "a second monitor's work area, below a panel";
    EXPECT_EQ(placeWindow(WindowRect{0, 0, 300, 200}, std::nullopt, 1280, 720), (WindowRect{0, 0, 300, 200})) << "smaller than the minimum";
}

TEST(ViewerStateTest, WindowRectPersistsAndBadFilesAreIgnored) {
    fs::path dir = testing_support::outputDir("ui") / "window_rect";
    fs::remove_all(dir);
    std::string error;
    EXPECT_FALSE(loadWindowRect(dir, &error).has_value());
    EXPECT_EQ(error, "") << "no file yet is no error";
    ASSERT_EQ(saveWindowRect(dir, WindowRect{-10, 20, 900, 600}), "");
    EXPECT_EQ(loadWindowRect(dir, &error), (WindowRect{-10, 20, 900, 600}));
    for (const char* bad : {"", "1 2 3", "0 0 0 600", "0 0 -5 600", "x y w h"}) {
        std::ofstream(dir / "window.txt") << bad;
        error.clear();
        EXPECT_FALSE(loadWindowRect(dir, &error).has_value()) << "'" << bad << "'";
        EXPECT_NE(error.find("expected 'x y width height'; ignored"), std::string::npos) << error;
        EXPECT_EQ(error.find('\n'), std::string::npos) << "one line";
    }
}

TEST(ViewerStateTest, RecentFilesPersist) {
    fs::path dir = testing_support::outputDir("ui") / "config";
    fs::remove_all(dir);
    ViewerState st;
    st.config.dir = dir;
    for (int i = 0; i < 12; ++i) st.addRecent("/tmp/scene" + std::to_string(i) + ".json");
    st.addRecent("/tmp/scene3.json");   // moves to the front, no duplicate
    std::vector<std::string> r = loadRecentFiles(dir);
    ASSERT_EQ(r.size(), 10u);
    EXPECT_EQ(r[0], "/tmp/scene3.json");
    EXPECT_EQ(std::count(r.begin(), r.end(), "/tmp/scene3.json"), 1);
}

TEST(ViewerStateTest, ConfigDirFollowsXdg) {
    setenv("XDG_CONFIG_HOME", "/tmp/xdg-test", 1);
    EXPECT_EQ(defaultConfigDir(), fs::path("/tmp/xdg-test/sceneviewer"));
}

// A CPU backend through a RenderSlot: preview first, then full resolution; or a clear error
// (the backend may still be a placeholder). Never hangs: waitIdle returns when done.
TEST(RenderSlotTest, RendersCoarseToFineOrReportsError) {
    ViewerState st = demoState();
    auto frame = std::make_shared<sg::FrameInput>(st.buildFrame(64.0f / 48.0f));
    RenderSlot slot("raster");
    slot.request(frame, 64, 48, 1, /*interacting=*/true);
    slot.waitIdle();
    slot.poll();
    SlotStatus s = slot.status();
    if (!s.error.empty()) {
        EXPECT_EQ(slot.image().width, 0);
        GTEST_FAIL() << "raster backend not available: " << s.error;
    }
    EXPECT_EQ(slot.image().width, 16);   // 1/4 preview while interacting
    EXPECT_EQ(s.level, 4);
    slot.request(frame, 64, 48, 1, /*interacting=*/false);   // same key, idle: refine
    slot.waitIdle();
    slot.poll();
    EXPECT_EQ(slot.image().width, 64);
    EXPECT_EQ(slot.status().level, 1);
}

// An anti-aliased frame refines: the preview, a full-resolution image at one sample per pixel
// (with the visibility), then the anti-aliased image, which equals a direct render with the
// same settings and keeps the one-sample step's visibility. Without anti-aliasing there is no
// middle step.
TEST(RenderSlotTest, AntiAliasedFramesRefineThroughAOneSampleImage) {
    ViewerState st = demoState();
    sg::FrameInput f = st.buildFrame(64.0f / 48.0f);
    f.settings.aa = sg::AAMode::SSAA;
    f.settings.aaRate = 2;
    struct Step {
        int level;
        bool refining;
        int samples;
        bool visibility;
    };
    for (bool antialiased : {true, false}) {
        sg::FrameInput g = f;
        if (!antialiased) g.settings.aa = sg::AAMode::None;
        auto frame = std::make_shared<sg::FrameInput>(g);
        RenderSlot slot("raster");
        std::vector<Step> steps;
        slot.onPublish = [&](const rnd::Framebuffer& fb, const SlotStatus& s) {
            steps.push_back({s.level, s.refining, s.stats.config.samplesPerPixel, fb.has(rnd::Aov::Visibility)});
        };
        slot.request(frame, 64, 48, 1, /*interacting=*/false);
        slot.waitIdle();
        slot.poll();
        ASSERT_EQ(slot.status().error, "");
        ASSERT_EQ(steps.size(), antialiased ? 3u : 2u);
        EXPECT_EQ(steps[0].level, 4);
        EXPECT_TRUE(steps[0].refining);
        EXPECT_EQ(steps[0].samples, 1) << "the preview takes one sample per pixel";
        if (antialiased) {
            EXPECT_TRUE(steps[1].refining);
            EXPECT_EQ(steps[1].level, 1);
            EXPECT_EQ(steps[1].samples, 1);
            EXPECT_TRUE(steps[1].visibility);
        }
        EXPECT_FALSE(steps.back().refining);
        EXPECT_EQ(steps.back().samples, antialiased ? 4 : 1);
        EXPECT_FALSE(slot.status().refining);
        // The image shown is the backend's own, with the visibility of the pixel centres.
        auto direct = rnd::makeRenderer("raster");
        rnd::Framebuffer want;
        rnd::RenderRequest vis;
        vis.aovs.add(rnd::Aov::Visibility);
        ASSERT_TRUE(direct->render(g, 64, 48, want, nullptr, vis).ok);
        EXPECT_EQ(slot.image().color, want.color);
        EXPECT_EQ(slot.image().drawable, want.drawable);
        EXPECT_EQ(slot.image().primitive, want.primitive);
    }
}

// When the camera stops, the preview of that very view is already on screen: the release
// renders only the full-resolution image (and a new view still starts with its preview).
TEST(RenderSlotTest, TheReleaseDoesNotRenderThePreviewShownAgain) {
    ViewerState st = demoState();
    auto frame = std::make_shared<sg::FrameInput>(st.buildFrame(64.0f / 48.0f));
    RenderSlot slot("raster");
    std::vector<int> levels;
    slot.onPublish = [&](const rnd::Framebuffer&, const SlotStatus& s) { levels.push_back(s.level); };
    slot.request(frame, 64, 48, 7, /*interacting=*/true);   // dragging
    slot.waitIdle();
    slot.request(frame, 64, 48, 7, /*interacting=*/false);   // released on the same view
    slot.waitIdle();
    slot.poll();
    ASSERT_EQ(slot.status().error, "");
    EXPECT_EQ(levels, (std::vector<int>{4, 1}));
    EXPECT_EQ(slot.image().width, 64);
    levels.clear();
    slot.request(frame, 64, 48, 8, /*interacting=*/false);   // another view (key): preview first
    slot.waitIdle();
    EXPECT_EQ(levels, (std::vector<int>{4, 1}));
    levels.clear();
    slot.forget();   // a new scene: nothing of the old one counts as shown
    slot.request(frame, 64, 48, 8, /*interacting=*/false);
    slot.waitIdle();
    EXPECT_EQ(levels, (std::vector<int>{4, 1}));
}

// Camera moves render into images the slot already had (no new buffers, zero-filled page by
// page, per frame), and what they show is still each frame's own picture: the same bytes as a
// direct render of that frame.
TEST(RenderSlotTest, MovesRenderIntoImagesTheSlotAlreadyHad) {
    ViewerState st = demoState();
    RenderSlot slot("raster");
    std::set<const uint8_t*> seen;
    int reused = 0;
    for (int move = 0; move < 8; ++move) {
        st.view.camera.orbit(move % 2 ? -20.0f : 20.0f, 3.0f);
        auto frame = std::make_shared<sg::FrameInput>(st.buildFrame(96.0f / 64.0f));
        slot.request(frame, 96, 64, uint64_t(100 + move), /*interacting=*/true);
        slot.waitIdle();
        slot.poll();
        slot.request(frame, 96, 64, uint64_t(100 + move), /*interacting=*/false);
        slot.waitIdle();
        slot.poll();
        ASSERT_EQ(slot.status().error, "");
        ASSERT_EQ(slot.image().width, 96);
        reused += seen.count(slot.image().color.data()) > 0;
        seen.insert(slot.image().color.data());
        auto direct = rnd::makeRenderer("raster");
        rnd::Framebuffer fb;
        rnd::RenderRequest request;
        request.aovs.add(rnd::Aov::Visibility);
        ASSERT_TRUE(direct->render(*frame, 96, 64, fb, nullptr, request).ok);
        EXPECT_TRUE(fb.color == slot.image().color) << "move " << move;
        EXPECT_TRUE(fb.depth == slot.image().depth) << "move " << move;
        EXPECT_TRUE(fb.drawable == slot.image().drawable) << "move " << move;
    }
    EXPECT_GE(reused, 5);   // (malloc may hand a freed block back too: once in 8 here without reuse)
}

// After a load the slot forgets the old scene's picture and figures, and a
// render requested before forget() never shows up afterwards, however far it got.
TEST(RenderSlotTest, ForgetDropsTheImageAndRendersInFlight) {
    ViewerState st = demoState();
    auto frame = std::make_shared<sg::FrameInput>(st.buildFrame(64.0f / 48.0f));
    RenderSlot slot("raster");
    slot.request(frame, 64, 48, 1, /*interacting=*/false);
    slot.waitIdle();
    slot.poll();
    if (!slot.status().error.empty()) GTEST_FAIL() << "raster backend not available: " << slot.status().error;
    ASSERT_TRUE(slot.hasImage());
    ASSERT_GT(slot.status().stats.triangles, 0u);
    uint64_t serial = slot.imageSerial();
    slot.forget();
    EXPECT_FALSE(slot.hasImage());
    EXPECT_EQ(slot.status().stats.triangles, 0u);
    EXPECT_NE(slot.imageSerial(), serial);
    EXPECT_TRUE(slot.needs(1, false)) << "the same key renders again after forget()";
    slot.request(frame, 64, 48, 2, /*interacting=*/false);
    slot.forget();   // pending or in flight: either way it is dropped
    slot.waitIdle();
    slot.poll();
    EXPECT_FALSE(slot.hasImage());
    slot.request(frame, 64, 48, 3, /*interacting=*/false);
    slot.waitIdle();
    slot.poll();
    EXPECT_EQ(slot.image().width, 64);
}

// A new tessellation level rebuilds the shapes first (seconds at the highest levels): the
// slot says so (SlotStatus::shapes) with a percentage that moves with the work done and gets
// to the end, then renders the image as usual.
TEST(RenderSlotTest, ATessellationRebuildShowsItsProgress) {
    ViewerState st = demoState();
    auto frame = std::make_shared<sg::FrameInput>(st.buildFrame(64.0f / 48.0f));
    auto rebuilt = std::make_shared<sg::FrameInput>(*frame);
    rebuilt->settings.tessellation = 160;
    RenderSlot slot("raster");
    slot.request(frame, 64, 48, 1, /*interacting=*/false);
    slot.waitIdle();
    slot.poll();
    ASSERT_EQ(slot.status().error, "");
    slot.request(rebuilt, 64, 48, 2, /*interacting=*/false);
    std::vector<float> shapes;   // the progress shown while rebuilding, as the viewport polls it
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    for (;;) {
        slot.poll();
        const SlotStatus s = slot.status();
        if (s.rendering && s.shapes) shapes.push_back(s.progress);
        if (!s.rendering && s.level == 1 && slot.imageFrame() == rebuilt) break;
        ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "no image";
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    EXPECT_EQ(slot.status().error, "");
    EXPECT_FALSE(slot.status().shapes);
    ASSERT_FALSE(shapes.empty()) << "the rebuild was never shown";
    int moves = 0;
    for (size_t i = 1; i < shapes.size(); ++i) {
        ASSERT_GE(shapes[i], shapes[i - 1]) << "sample " << i;
        moves += shapes[i] > shapes[i - 1];
    }
    EXPECT_GT(moves, 10) << "the percentage moves with the work";
    EXPECT_GT(shapes.back(), 0.9f) << "and gets to the end";
    // The same level again: nothing to rebuild, no Shapes stage.
    auto again = std::make_shared<sg::FrameInput>(*rebuilt);
    slot.request(again, 64, 48, 3, /*interacting=*/false);
    for (;;) {
        slot.poll();
        const SlotStatus s = slot.status();
        ASSERT_FALSE(s.shapes);
        if (!s.rendering && s.level == 1 && slot.imageFrame() == again) break;
        ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "no image";
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
}

// The steps of a job. While interacting: full resolution at one sample when the last such
// frame fitted the budget (82 ms does not fit 50 ms: the preview stays), the preview when it did
// not or nothing was measured yet. When still: what this key has shown already is not redone.
TEST(RenderSlotTest, PlanSkipsThePreviewWhenAFullFrameFits) {
    using Step = RenderSlot::Step;
    RenderSlot::PlanInput in;
    in.width = 640;
    in.interacting = true;
    in.budgetMs = 50;
    in.fullMs = 30;
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{1, true}})) << "fast: full resolution, no preview";
    in.antialiased = true;
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{1, true}})) << "one sample while interacting";
    in.fullMs = 82;
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{4, true}})) << "slow: the preview";
    in.fullMs = 50;
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{4, true}})) << "not under the budget";
    in.fullMs = -1;
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{4, true}})) << "not measured yet";
    in.width = 24;   // too small for a preview
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{1, true}, {1, false}}));
    // Still: preview, one-sample image (anti-aliased, on a worker), the final image.
    in = {};
    in.width = 640;
    in.fullMs = 10;
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{4, true}, {1, false}}));
    in.antialiased = true;
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{4, true}, {1, true}, {1, false}}));
    in.threaded = false;
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{4, true}, {1, false}}));
    in.threaded = true;
    in.shownLevel = 4;   // the camera stopped on the view whose preview is shown
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{1, true}, {1, false}}));
    in.shownLevel = 1;   // its one-sample full-resolution image is shown
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{{1, false}}));
    in.shownFinal = true;   // its final image is shown
    EXPECT_EQ(RenderSlot::planSteps(in), (std::vector<Step>{}));
}

// What the plan takes for a full frame's cost: a frame measured while interacting as it is
// (until kProbeAfter previews followed it); a still one (which may carry a scene's one-time
// costs: 188 ms for a first frame whose previews take 1.5 ms) bounded by 16 previews.
TEST(RenderSlotTest, LiveFrameEstimate) {
    EXPECT_EQ(RenderSlot::liveFrameEstimate(188, false, 1.5, 4), 24.0);
    EXPECT_EQ(RenderSlot::liveFrameEstimate(20, false, 1.5, 4), 20.0);
    EXPECT_EQ(RenderSlot::liveFrameEstimate(60, true, 1.5, 4), 60.0) << "measured while interacting: as it is";
    EXPECT_EQ(RenderSlot::liveFrameEstimate(143, true, 1.5, 4, RenderSlot::kProbeAfter - 1), 143.0);
    EXPECT_EQ(RenderSlot::liveFrameEstimate(143, true, 1.5, 4, RenderSlot::kProbeAfter), 24.0) << "tried again after that many previews";
    EXPECT_EQ(RenderSlot::liveFrameEstimate(-1, false, 2, 4), 32.0);
    EXPECT_EQ(RenderSlot::liveFrameEstimate(30, false, -1, 4), 30.0);
    EXPECT_LT(RenderSlot::liveFrameEstimate(-1, false, -1, 4), 0.0) << "unknown";
}

// The slot measures its full-resolution frames: while interacting it renders full resolution
// when they fit liveBudgetMs and the preview when they do not; the full image rendered while
// interacting is not rendered again when the interaction stops. An interacting frame pending
// or in flight is let finish: needs() says no to the next interacting frame until it is done,
// yes to a still one (which cancels it).
TEST(RenderSlotTest, InteractingRendersFullResolutionWhenAFullFrameFits) {
    ViewerState st = demoState();
    auto frame = std::make_shared<sg::FrameInput>(st.buildFrame(64.0f / 48.0f));
    RenderSlot slot("raster");
    std::vector<int> levels;
    slot.onPublish = [&](const rnd::Framebuffer&, const SlotStatus& s) { levels.push_back(s.level); };
    EXPECT_LT(slot.fullFrameMs(), 0.0) << "nothing measured yet";
    slot.request(frame, 64, 48, 1, /*interacting=*/false);
    slot.waitIdle();
    ASSERT_EQ(slot.status().error, "");
    EXPECT_EQ(levels, (std::vector<int>{4, 1}));
    const double full = slot.fullFrameMs();
    EXPECT_GT(full, 0.0);
    // Fits the budget: the next interacting frame (a camera step) is full resolution.
    slot.liveBudgetMs = 1e9;
    levels.clear();
    slot.request(frame, 64, 48, 2, /*interacting=*/true);
    slot.waitIdle();
    slot.poll();
    EXPECT_EQ(levels, (std::vector<int>{1}));
    EXPECT_EQ(slot.image().width, 64);
    EXPECT_FALSE(slot.status().refining);
    EXPECT_TRUE(slot.image().has(rnd::Aov::Visibility)) << "picking works on it";
    // Released on that view: nothing is rendered again.
    levels.clear();
    slot.request(frame, 64, 48, 2, /*interacting=*/false);
    slot.waitIdle();
    EXPECT_TRUE(levels.empty());
    // Does not fit: the preview.
    slot.liveBudgetMs = 0;
    slot.request(frame, 64, 48, 3, /*interacting=*/true);
    slot.waitIdle();
    slot.poll();
    EXPECT_EQ(levels, (std::vector<int>{4}));
    EXPECT_EQ(slot.status().level, 4);
    // A slow interacting frame (shapes rebuilt at a new level): the next camera step waits for
    // it instead of cancelling it; stopping does not wait.
    auto slow = std::make_shared<sg::FrameInput>(*frame);
    slow->settings.tessellation = 150;
    levels.clear();
    slot.request(slow, 64, 48, 4, /*interacting=*/true);
    EXPECT_FALSE(slot.needs(5, /*interacting=*/true)) << "the frame pending or in flight finishes first";
    slot.request(slow, 64, 48, 5, /*interacting=*/true);   // ignored
    EXPECT_TRUE(slot.needs(5, /*interacting=*/false)) << "a still frame replaces it";
    slot.waitIdle();
    EXPECT_EQ(levels, (std::vector<int>{4})) << "one frame, not cancelled";
    EXPECT_TRUE(slot.needs(5, /*interacting=*/true)) << "done: the newest frame next";
    slot.forget();   // another scene: its frames are measured afresh
    EXPECT_LT(slot.fullFrameMs(), 0.0);
}

TEST(RenderSlotTest, UnknownBackendIsAnError) {
    RenderSlot slot("nope");
    EXPECT_FALSE(slot.status().error.empty());
    slot.request(nullptr, 10, 10, 1, false);   // ignored, no crash
    slot.waitIdle();
    EXPECT_FALSE(slot.poll());
}

TEST(RenderSlotTest, RapidRequestsCancelAndDestroyCleanly) {
    ViewerState st = demoState();
    auto slot = std::make_unique<RenderSlot>("raycast");
    for (int i = 0; i < 20; ++i) {
        st.view.camera.orbit(5.0f, 0.0f);
        slot->request(std::make_shared<sg::FrameInput>(st.buildFrame(1.0f)), 96, 96, uint64_t(i + 10), false);
    }
    slot.reset();   // cancels and joins while busy
    SUCCEED();
}

// Every setting edited in the UI lands in the scene, so saving and reopening restores it,
// including the view (stored into the active camera on save).
TEST(ViewerStateTest, SaveAndReopenKeepsEditsAndView) {
    ViewerState st = demoState();
    st.config.dir.clear();
    st.doc.scene.settings.shading = sg::ShadingModel::Gouraud;
    st.doc.scene.settings.fog = sg::FogMode::Exp;
    st.markEdited();
    sg::Projection p = st.projection();
    p.fovyDeg = 52.0f;
    st.setProjection(p);
    st.view.camera.orbit(80.0f, 20.0f);
    sg::vec3 eye = st.view.camera.eye();
    fs::path file = testing_support::outputDir("ui") / "saved-scene.json";
    fs::remove(file);
    ASSERT_EQ(st.saveAs(file), SaveOutcome::Saved) << st.ui.errorPopup;
    EXPECT_FALSE(st.doc.dirty);
    EXPECT_EQ(st.doc.path, file);

    ViewerState other;
    other.view.viewportWidth = 800;
    other.view.viewportHeight = 600;
    other.startLoad(file);
    ASSERT_TRUE(other.pollLoad(true));
    ASSERT_TRUE(other.ui.errorPopup.empty()) << other.ui.errorPopup;
    EXPECT_EQ(other.doc.scene.settings.shading, sg::ShadingModel::Gouraud);
    EXPECT_EQ(other.doc.scene.settings.fog, sg::FogMode::Exp);
    EXPECT_FLOAT_EQ(other.projection().fovyDeg, 52.0f);
    EXPECT_NEAR(glm::length(other.view.camera.eye() - eye), 0.0f, 1e-3f);
}

// Ctrl+click's selection set: toggling adds (the new node active) and takes out (the last added
// takes over); a plain select replaces it; Delete removes a selected node and a selected
// descendant of it once, as one undo step that brings both back; an edit never leaves a deleted
// id in the set.
TEST(ViewerStateTest, SelectionSetTogglesAndDeletesAsOneStep) {
    ViewerState st = demoState();
    const sg::Scene& s = st.doc.scene;
    const sg::NodeId turntable = s.findByName("turntable"), torus = s.findByName("torus"), crate = s.findByName("crate");
    ASSERT_TRUE(s.valid(turntable) && s.valid(torus) && s.valid(crate));
    st.selectNode(crate);
    st.toggleSelected(turntable);
    st.toggleSelected(torus);
    EXPECT_EQ(st.selection(), (std::vector<sg::NodeId>{torus, turntable, crate}));
    EXPECT_EQ(st.doc.selected, torus);
    st.toggleSelected(torus);
    EXPECT_EQ(st.selection(), (std::vector<sg::NodeId>{turntable, crate})) << "taken out: the last added is active again";
    st.toggleSelected(sg::kNoNode);
    EXPECT_EQ(st.selection().size(), 2u);
    st.toggleSelected(torus);
    const size_t before = s.nodeCount();
    ASSERT_TRUE(st.removeSelection());
    EXPECT_FALSE(st.doc.scene.valid(turntable));
    EXPECT_FALSE(st.doc.scene.valid(crate));
    EXPECT_TRUE(st.selection().empty());
    EXPECT_EQ(st.doc.history.undoLabel(), "Delete 2 nodes") << "the torus went with the turntable, once";
    ASSERT_TRUE(st.undo());
    EXPECT_EQ(st.doc.scene.nodeCount(), before);
    EXPECT_TRUE(st.doc.scene.valid(torus) && st.doc.scene.valid(turntable) && st.doc.scene.valid(crate));
    st.selectNode(crate);
    EXPECT_EQ(st.selection(), std::vector<sg::NodeId>{crate}) << "a plain select replaces the set";
}

// An environment file is read when it is set: one that cannot be read is refused with the
// file and the reason, and the scene keeps its environment (nothing to undo); a good one is
// one undo step.
TEST(ViewerStateTest, EnvironmentFileIsCheckedWhenSet) {
    ViewerState st = demoState();
    const fs::path dir = testing_support::outputDir("ui") / "environment";
    fs::create_directories(dir);
    std::ofstream(dir / "broken.hdr") << "not a radiance file";
    {
        std::ofstream o(dir / "grey.hdr", std::ios::binary);
        o << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n";
        for (int i = 0; i < 32; ++i) o << char(128) << char(128) << char(128) << char(128);
    }
    sg::RenderSettings s = st.doc.scene.settings;
    s.reflection = sg::ReflectionModel::Pbr;
    s.environment = (dir / "broken.hdr").string();
    const std::string err = st.setSettings(s);
    EXPECT_NE(err.find("broken.hdr: "), std::string::npos) << err;
    EXPECT_NE(st.ui.status.find("broken.hdr"), std::string::npos) << st.ui.status;
    EXPECT_EQ(st.doc.scene.settings.environment, "default");
    EXPECT_EQ(st.doc.scene.settings.reflection, sg::ReflectionModel::Phong);
    EXPECT_FALSE(st.doc.dirty);
    s.environment = (dir / "grey.hdr").string();
    EXPECT_EQ(st.setSettings(s), "");
    EXPECT_EQ(st.doc.scene.settings.environment, s.environment);
    EXPECT_TRUE(st.undo());
    EXPECT_EQ(st.doc.scene.settings.environment, "default");
}
