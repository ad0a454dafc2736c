// animation_load_test.cpp - ViewerState animation playback and cancellable loading with
// progress.
//   Animation: a tiny glTF written by the test (embedded base64 buffer) with a node "mover"
//   translated linearly from (0,0,0) at t=0 to (4,0,0) at t=2 ("slide") and the same keys
//   with STEP interpolation ("step"); play / pause / scrub / loop move the node, re-render
//   (sceneVersion) and never mark the document dirty. Also the real CesiumMilkTruck.
//   Loading: a ~1M-triangle ASCII OBJ generated into the test output folder; cancel keeps the
//   current scene and says so, progress reaches the UI.
#include "ui/viewer_state.h"

#include "assets/demo.h"
#include "assets/scene_io.h"
#include "scenegraph/frame.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <charconv>
#include <chrono>
#include <cstring>
#include <fstream>

using namespace ui;
namespace fs = std::filesystem;

namespace {

ViewerState demoState() {
    ViewerState st;
    st.view.viewportWidth = 800;
    st.view.viewportHeight = 600;
    st.config.dir.clear();   // never touch the user's recent files
    st.setScene(assets::makeDemoScene(), {});
    return st;
}

std::string base64(const std::vector<unsigned char>& data) {
    return testing_support::base64Encode(std::string_view(reinterpret_cast<const char*>(data.data()), data.size()));
}

// One triangle on node "mover" and two clips over the same keys (LINEAR "slide", STEP "step").
fs::path writeAnimatedGltf() {
    const float floats[] = {
        0, 0, 0, 1, 0, 0, 0, 1, 0,   // positions (36 bytes)
        0, 2,                        // key times (8 bytes)
        0, 0, 0, 4, 0, 0,            // translations (24 bytes)
    };
    std::vector<unsigned char> bytes(sizeof floats);
    std::memcpy(bytes.data(), floats, sizeof floats);
    std::string json = R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"name": "mover", "mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"byteLength": 68, "uri": "data:application/octet-stream;base64,)" +
                       base64(bytes) + R"("}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 36, "target": 34962},
    {"buffer": 0, "byteOffset": 36, "byteLength": 8},
    {"buffer": 0, "byteOffset": 44, "byteLength": 24}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [2]},
    {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3"}],
  "animations": [
    {"name": "slide", "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
     "samplers": [{"input": 1, "output": 2, "interpolation": "LINEAR"}]},
    {"name": "step", "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
     "samplers": [{"input": 1, "output": 2, "interpolation": "STEP"}]}]
})";
    // One file per test: ctest -j runs these tests as separate processes at once, and a shared
    // file could be read while another test is rewriting it (seen: "animated.gltf: empty file").
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::path path = testing_support::outputDir("ui") / ("animated-" + test + ".gltf");
    std::ofstream(path, std::ios::binary) << json;
    return path;
}

// Loads the animated glTF into a demo state (as File > Open does).
ViewerState animatedState() {
    ViewerState st = demoState();
    st.startLoad(writeAnimatedGltf());
    EXPECT_TRUE(st.pollLoad(/*wait=*/true));
    EXPECT_TRUE(st.ui.errorPopup.empty()) << st.ui.errorPopup;
    return st;
}

sg::vec3 localT(const ViewerState& st, sg::NodeId id) { return st.doc.scene.node(id).local.translation; }
sg::vec3 worldT(const ViewerState& st, sg::NodeId id) { return sg::vec3(st.doc.scene.world(id)[3]); }

}   // namespace

TEST(ViewerStateAnimTest, LoadKeepsClipsAndNewSceneDropsThem) {
    ViewerState st = animatedState();
    ASSERT_EQ(st.anim.clips.size(), 2u);
    EXPECT_EQ(st.anim.clips[0].name, "slide");
    EXPECT_EQ(st.anim.clip, 0);
    EXPECT_FALSE(st.anim.playing);
    EXPECT_FLOAT_EQ(st.anim.clips[0].start, 0.0f);
    EXPECT_DOUBLE_EQ(st.animationEnd(), 2.0);
    EXPECT_NE(st.ui.status.find("animation"), std::string::npos) << st.ui.status;
    // The demo / a new scene has no clips.
    st.setScene(assets::makeDemoScene(), {});
    EXPECT_TRUE(st.anim.clips.empty());
    EXPECT_EQ(st.currentAnimation(), nullptr);
    st.setAnimationPlaying(true);   // nothing to play: stays stopped
    EXPECT_FALSE(st.anim.playing);
    st.advanceAnimation(0.5);   // and does nothing
}

TEST(ViewerStateAnimTest, PlayInterpolatesPauseStopsScrubSetsNeverDirty) {
    ViewerState st = animatedState();
    sg::NodeId mover = st.doc.scene.findByName("mover");
    ASSERT_TRUE(st.doc.scene.valid(mover));
    ASSERT_FALSE(st.doc.dirty);
    sg::vec3 world0 = worldT(st, mover);

    // Not playing: frames change nothing.
    uint64_t v0 = st.doc.version;
    st.advanceAnimation(0.5);
    EXPECT_EQ(st.doc.version, v0);
    EXPECT_NEAR(glm::length(localT(st, mover)), 0.0f, 1e-6f);

    // Play: halfway between the keys (t = 1) is halfway between (0,0,0) and (4,0,0).
    st.setAnimationPlaying(true);
    st.advanceAnimation(0.5);
    st.advanceAnimation(0.5);
    EXPECT_NEAR(st.anim.time, 1.0, 1e-9);
    EXPECT_NEAR(glm::length(localT(st, mover) - sg::vec3(2, 0, 0)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(worldT(st, mover) - world0 - sg::vec3(2, 0, 0)), 0.0f, 1e-4f);
    EXPECT_GT(st.doc.version, v0);   // re-render ...
    EXPECT_FALSE(st.doc.dirty);      // ... but not an edit

    // Pause: time and pose stay.
    st.setAnimationPlaying(false);
    uint64_t v1 = st.doc.version;
    st.advanceAnimation(0.5);
    EXPECT_NEAR(st.anim.time, 1.0, 1e-9);
    EXPECT_NEAR(localT(st, mover).x, 2.0f, 1e-5f);
    EXPECT_EQ(st.doc.version, v1);

    // Scrub (paused): pose at the given time, clamped to the clip.
    st.setAnimationTime(0.5);
    EXPECT_NEAR(localT(st, mover).x, 1.0f, 1e-5f);
    EXPECT_GT(st.doc.version, v1);
    st.setAnimationTime(10.0);
    EXPECT_DOUBLE_EQ(st.anim.time, 2.0);
    EXPECT_NEAR(localT(st, mover).x, 4.0f, 1e-5f);
    st.setAnimationTime(-1.0);
    EXPECT_DOUBLE_EQ(st.anim.time, 0.0);
    EXPECT_NEAR(localT(st, mover).x, 0.0f, 1e-5f);
    EXPECT_FALSE(st.anim.playing);
    EXPECT_FALSE(st.doc.dirty);

    // An edit still marks dirty; playing afterwards does not clear or set anything else.
    st.renameNode(st.doc.scene.findByName("mover"), "mover 2");
    EXPECT_TRUE(st.doc.dirty);
}

TEST(ViewerStateAnimTest, LoopWrapsAndOneShotStopsAtTheEnd) {
    ViewerState st = animatedState();
    sg::NodeId mover = st.doc.scene.findByName("mover");
    ASSERT_TRUE(st.doc.scene.valid(mover));
    ASSERT_TRUE(st.anim.loop);
    st.setAnimationPlaying(true);
    st.advanceAnimation(2.5);   // 2.5 s in a 2 s loop: t = 0.5
    EXPECT_TRUE(st.anim.playing);
    EXPECT_NEAR(st.anim.time, 0.5, 1e-9);
    EXPECT_NEAR(localT(st, mover).x, 1.0f, 1e-5f);

    st.anim.loop = false;
    st.advanceAnimation(3.0);   // past the end: clamps and stops
    EXPECT_FALSE(st.anim.playing);
    EXPECT_DOUBLE_EQ(st.anim.time, 2.0);
    EXPECT_NEAR(localT(st, mover).x, 4.0f, 1e-5f);
    st.toggleAnimation();   // play again from the end: restarts at the clip start
    EXPECT_TRUE(st.anim.playing);
    EXPECT_DOUBLE_EQ(st.anim.time, 0.0);
    st.advanceAnimation(1.5);
    EXPECT_NEAR(localT(st, mover).x, 3.0f, 1e-5f);
    EXPECT_FALSE(st.doc.dirty);
}

TEST(ViewerStateAnimTest, SelectingAClipRewindsAndUsesItsInterpolation) {
    ViewerState st = animatedState();
    sg::NodeId mover = st.doc.scene.findByName("mover");
    ASSERT_TRUE(st.doc.scene.valid(mover));
    st.setAnimationTime(1.0);
    EXPECT_NEAR(localT(st, mover).x, 2.0f, 1e-5f);
    st.setAnimationPlaying(true);
    st.selectAnimation(1);   // "step": stops and rewinds
    EXPECT_EQ(st.anim.clip, 1);
    EXPECT_FALSE(st.anim.playing);
    EXPECT_DOUBLE_EQ(st.anim.time, 0.0);
    st.setAnimationTime(1.5);
    EXPECT_NEAR(localT(st, mover).x, 0.0f, 1e-5f);   // STEP holds the first key until t = 2
    st.setAnimationTime(2.0);
    EXPECT_NEAR(localT(st, mover).x, 4.0f, 1e-5f);
    st.selectAnimation(7);   // out of range: ignored
    EXPECT_EQ(st.anim.clip, 1);
    EXPECT_FALSE(st.doc.dirty);
}

TEST(ViewerStateAnimTest, CesiumMilkTruckWheelsTurnWithoutDirtying) {
    ASSERT_TRUE(testing_support::requireTestdata());
    ViewerState st = demoState();
    st.startLoad(testing_support::testdataDir() / "gltf/CesiumMilkTruck/glTF/CesiumMilkTruck.gltf");
    ASSERT_TRUE(st.pollLoad(true));
    ASSERT_TRUE(st.ui.errorPopup.empty()) << st.ui.errorPopup;
    ASSERT_EQ(st.anim.clips.size(), 1u);
    sg::NodeId wheel = st.anim.clips[0].channels.at(0).node;
    ASSERT_TRUE(st.doc.scene.valid(wheel));
    st.setAnimationTime(st.anim.clips[0].start);
    sg::mat4 a = st.doc.scene.world(wheel);
    st.setAnimationPlaying(true);
    st.advanceAnimation(0.37 * (st.animationEnd() - st.anim.clips[0].start));
    EXPECT_NE(st.doc.scene.world(wheel), a);
    EXPECT_FALSE(st.doc.dirty);
}

// The animation bar poses skins and morphs through the same code as `viewer render --time`:
// assets::applyAnimation on the document, deformation in flatten.
TEST(ViewerStateAnimTest, AnimationBarPosesSkinsLikeTheCommandLine) {
    ASSERT_TRUE(testing_support::requireTestdata());
    const fs::path file = testing_support::testdataDir() / "gltf/CesiumMan/glTF/CesiumMan.gltf";
    ViewerState st = demoState();
    st.startLoad(file);
    ASSERT_TRUE(st.pollLoad(true));
    ASSERT_TRUE(st.ui.errorPopup.empty()) << st.ui.errorPopup;
    ASSERT_EQ(st.anim.clips.size(), 1u);
    st.setAnimationTime(1.0);
    sg::FrameInput ui = st.buildFrame(1.0f);
    assets::LoadResult r = assets::loadScene(file);
    ASSERT_TRUE(r.scene);
    assets::applyAnimation(*r.scene, r.animations[0], 1.0f);
    sg::FrameInput cli = sg::flatten(*r.scene, 1.0f);
    ASSERT_EQ(ui.meshes.size(), 1u);
    ASSERT_EQ(cli.meshes.size(), 1u);
    EXPECT_EQ(ui.meshes[0].mesh->positions, cli.meshes[0].mesh->positions);
    EXPECT_EQ(ui.meshes[0].world, sg::mat4(1.0f));   // skinned: drawn in world space
    // Scrubbing moves the figure; a still time reuses the posed mesh.
    st.setAnimationTime(1.5);
    sg::FrameInput later = st.buildFrame(1.0f);
    EXPECT_NE(later.meshes[0].mesh->positions, ui.meshes[0].mesh->positions);
    EXPECT_EQ(st.buildFrame(1.0f).meshes[0].mesh, later.meshes[0].mesh);
    EXPECT_FALSE(st.doc.dirty);
}

// --- loading: cancel and progress --------------------------------------------------------------

namespace {

// An N x N quad grid as ASCII OBJ (2*N*N triangles), written once per test run.
fs::path bigObj() {
    static fs::path path;
    if (!path.empty()) return path;
    constexpr int n = 700;   // 490k vertices, 980k triangles, ~30 MB
    std::string text;
    text.reserve(size_t(40) * (n + 1) * (n + 1) + size_t(30) * 2 * n * n);
    char buf[64];
    auto num = [&](auto v) {
        auto r = std::to_chars(buf, buf + sizeof buf, v);
        text.append(buf, r.ptr);
    };
    text += "# generated grid\n";
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x) {
            text += "v ";
            num(float(x) / n);
            text += ' ';
            num(float(y) / n);
            text += " 0\n";
        }
    auto idx = [&](int x, int y) { return (y * (n + 1) + x) + 1; };
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            text += "f ";
            num(idx(x, y));
            text += ' ';
            num(idx(x + 1, y));
            text += ' ';
            num(idx(x + 1, y + 1));
            text += "\nf ";
            num(idx(x, y));
            text += ' ';
            num(idx(x + 1, y + 1));
            text += ' ';
            num(idx(x, y + 1));
            text += '\n';
        }
    // CTest runs each test in its own process and several at once: write a private copy and
    // rename it into place, so no test ever reads a file another one is still writing.
    fs::path p = testing_support::outputDir("ui") / "big-grid.obj";
    fs::path tmp = p;
    tmp += "." + std::to_string(::getpid()) + ".tmp";
    std::ofstream(tmp, std::ios::binary) << text;
    fs::rename(tmp, p);
    path = p;
    return path;
}

}   // namespace

TEST(ViewerStateLoadTest, CancelKeepsTheCurrentSceneAndSaysSo) {
    fs::path file = bigObj();
    ViewerState st = demoState();
    st.addShape(sg::ImplicitType::Torus);   // an unsaved edit that must survive
    size_t nodes = st.doc.scene.nodeCount();
    uint64_t version = st.doc.version;
    st.startLoad(file);
    ASSERT_TRUE(st.loadInProgress());
    EXPECT_FALSE(st.loadCancelRequested());
    st.cancelLoad();
    EXPECT_TRUE(st.loadCancelRequested());
    EXPECT_NE(st.ui.status.find("Cancelling"), std::string::npos) << st.ui.status;
    ASSERT_TRUE(st.pollLoad(/*wait=*/true));
    EXPECT_FALSE(st.loadInProgress());
    EXPECT_EQ(st.doc.scene.nodeCount(), nodes);
    EXPECT_EQ(st.doc.version, version);
    EXPECT_TRUE(st.doc.scene.valid(st.doc.scene.findByName("crate")));
    EXPECT_TRUE(st.doc.path.empty());
    EXPECT_TRUE(st.doc.dirty);
    EXPECT_TRUE(st.ui.errorPopup.empty()) << st.ui.errorPopup;   // a cancel is not an error
    EXPECT_NE(st.ui.status.find("big-grid.obj cancelled"), std::string::npos) << st.ui.status;

    // The next load is not affected by the old cancel.
    st.doc.dirty = false;
    st.startLoad(file);
    EXPECT_FALSE(st.loadCancelRequested());
    ASSERT_TRUE(st.pollLoad(true));
    EXPECT_TRUE(st.ui.errorPopup.empty()) << st.ui.errorPopup;
    EXPECT_EQ(st.doc.path, file);
}

TEST(ViewerStateLoadTest, ProgressIsReported) {
    fs::path file = bigObj();
    ViewerState st = demoState();
    EXPECT_EQ(st.loadProgress(), 0.0f);
    st.startLoad(file);
    float maxSeen = 0.0f;
    while (st.load.task.wait_for(std::chrono::milliseconds(2)) != std::future_status::ready) maxSeen = std::max(maxSeen, st.loadProgress());
    maxSeen = std::max(maxSeen, st.loadProgress());
    ASSERT_TRUE(st.pollLoad(true));
    ASSERT_TRUE(st.ui.errorPopup.empty()) << st.ui.errorPopup;
    EXPECT_GT(maxSeen, 0.0f);
    EXPECT_FLOAT_EQ(st.loadProgress(), 1.0f);   // the importer ends at 1
    size_t triangles = 0;
    for (const auto& m : st.doc.scene.meshes)
        if (m) triangles += m->indices.size() / 3;
    EXPECT_EQ(triangles, 2u * 700u * 700u);
}
