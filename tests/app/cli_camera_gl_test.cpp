// cli_camera_gl_test.cpp - cameras of `viewer render` through the real executable: a sidecar's
// camera (--camera-json) reproduces its image bit for bit in every backend, for perspective,
// off-centre (--intrinsics) and oblique cameras; --intrinsics gives back its own K; a camera
// list (--cameras) and a turntable (--turntable) write numbered frames that shards (--shard)
// split without overlap, deterministically; bad requests get one-line errors.
#include "assets/aov_io.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using ViewerRun = testing_support::ProgramRun;
ViewerRun runViewer(const std::string& args) { return testing_support::runProgram(VIEWER_EXE, args); }

using testing_support::quoted;
std::string bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

fs::path dirFor(const std::string& name) {
    fs::path d = testing_support::outputDir("cli-camera") / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

}   // namespace

TEST(CliCamera, SidecarCameraReproducesTheImageExactly) {
    const fs::path dir = dirFor("roundtrip");
    for (const char* backend : {"gl", "raster", "raycast"})
        for (const char* camera : {"--fovy 30", "--projection cabinet", "--intrinsics 250,260,70,60"}) {
            SCOPED_TRACE(std::string(backend) + " " + camera);
            const fs::path a = dir / "a.png", b = dir / "b.png";
            ViewerRun r = runViewer(std::string("render demo --overwrite --size 160x90 --aov depth --backend ") + backend + " " + camera + " --out " +
                                    quoted(a));
            ASSERT_EQ(r.status, 0) << r.output;
            r = runViewer(std::string("render demo --overwrite --backend ") + backend + " --camera-json " + quoted(dir / "a.json") + " --out " +
                          quoted(b));
            ASSERT_EQ(r.status, 0) << r.output;
            EXPECT_NE(r.output.find("160x90"), std::string::npos) << "the sidecar's size is used: " << r.output;
            EXPECT_TRUE(bytes(a) == bytes(b)) << "--camera-json did not reproduce the image";
        }
}

// --projection isometric: the written camera is orthographic and looks along -(1, 1, 1), so the
// world axes land on its image plane equally long (sqrt(2/3) per unit) and 120 degrees apart;
// the scene stays in view (the depth AOV has surface pixels). The demo has a camera of its own;
// the teapot (when the test data is there) gets the default one.
TEST(CliCamera, IsometricProjectionTurnsTheCamera) {
    const fs::path dir = dirFor("isometric");
    std::vector<std::string> scenes = {"demo"};
    const fs::path teapot = testing_support::testdataDir() / "meshes/common-3d-test-models/teapot/teapot.obj";
    if (fs::exists(teapot)) scenes.push_back(teapot.string());
    for (const std::string& scene : scenes) {
        SCOPED_TRACE(scene);
        ViewerRun r = runViewer("render " + (scene == "demo" ? scene : quoted(fs::path(scene))) +
                                " --backend raster --size 160x90 --projection isometric --aov depth --overwrite --out " + quoted(dir / "iso.png"));
        ASSERT_EQ(r.status, 0) << r.output;
        std::ifstream in(dir / "iso.json");
        const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
        ASSERT_TRUE(j.is_object());
        EXPECT_EQ(j["camera"]["projection"], "orthographic");
        const auto& m = j["camera"]["world_to_camera"];   // rows; camera x right, y down, z forward
        double len[3], x[3], y[3];
        for (int a = 0; a < 3; ++a) {
            x[a] = m[0][a].get<double>();
            y[a] = m[1][a].get<double>();
            len[a] = std::hypot(x[a], y[a]);
            EXPECT_NEAR(len[a], std::sqrt(2.0 / 3.0), 1e-4) << "axis " << a;
            EXPECT_NEAR(m[2][a].get<double>(), -1.0 / std::sqrt(3.0), 1e-4) << "looks along -(1, 1, 1)";
        }
        for (int a = 0; a < 3; ++a) {
            const int b = (a + 1) % 3;
            EXPECT_NEAR(std::acos((x[a] * x[b] + y[a] * y[b]) / (len[a] * len[b])) * 180.0 / 3.14159265358979, 120.0, 0.01) << a << ", " << b;
        }
        int w = 0, h = 0;
        std::vector<float> depth;
        ASSERT_EQ(assets::readPfm(dir / "iso.depth.pfm", w, h, depth), "");
        const auto surface = std::count_if(depth.begin(), depth.end(), [](float d) { return d > 0.0f; });
        EXPECT_GT(surface, long(depth.size() / 50)) << "the scene is in view (framed as the perspective view was at its pivot)";
        EXPECT_LT(surface, long(depth.size())) << "and framed with some background around it";
    }
}

TEST(CliCamera, IntrinsicsComeBackInTheSidecar) {
    const fs::path dir = dirFor("intrinsics");
    ViewerRun r = runViewer("render demo --backend raster --size 200x100 --intrinsics 180.5,175.25,90,40 --aov depth --out " + quoted(dir / "k.png"));
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(dir / "k.json");
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    ASSERT_TRUE(j.is_object());
    const auto& K = j["camera"]["K"];
    EXPECT_NEAR(K[0][0].get<double>(), 180.5, 1e-3);
    EXPECT_NEAR(K[1][1].get<double>(), 175.25, 1e-3);
    EXPECT_NEAR(K[0][2].get<double>(), 90.0, 1e-3);
    EXPECT_NEAR(K[1][2].get<double>(), 40.0, 1e-3);
    EXPECT_EQ(K[0][1].get<double>(), 0.0);
}

TEST(CliCamera, TurntableShardsSplitTheFramesAndRepeatExactly) {
    const fs::path dir = dirFor("turntable");
    for (const char* shard : {"0/2", "1/2"}) {
        ViewerRun r =
            runViewer(std::string("render demo --backend raster --size 96x54 --turntable 4 --shard ") + shard + " --out " + quoted(dir / "t.png"));
        ASSERT_EQ(r.status, 0) << r.output;
    }
    for (int k = 0; k < 4; ++k) EXPECT_TRUE(fs::exists(dir / ("t_000" + std::to_string(k) + ".png"))) << k;
    EXPECT_FALSE(fs::exists(dir / "t_0004.png"));
    EXPECT_NE(bytes(dir / "t_0000.png"), bytes(dir / "t_0001.png")) << "the camera turns";
    // Frame 0 is the unturned camera; a second run gives the same bytes.
    ViewerRun r = runViewer("render demo --backend raster --size 96x54 --out " + quoted(dir / "plain.png"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(bytes(dir / "t_0000.png"), bytes(dir / "plain.png"));
    r = runViewer("render demo --backend raster --size 96x54 --turntable 4 --shard 1/2 --overwrite --out " + quoted(dir / "again.png"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(bytes(dir / "again_0003.png"), bytes(dir / "t_0003.png"));
}

TEST(CliCamera, CameraListRendersEachCameraAsItsSidecarDid) {
    const fs::path dir = dirFor("list");
    std::ofstream list(dir / "cams.jsonl");
    for (const char* camera : {"--fovy 35", "--projection orthographic"}) {
        const std::string name = camera[2] == 'f' ? "p" : "o";
        ViewerRun r =
            runViewer(std::string("render demo --backend raycast --size 96x54 --aov depth ") + camera + " --out " + quoted(dir / (name + ".png")));
        ASSERT_EQ(r.status, 0) << r.output;
        std::ifstream in(dir / (name + ".json"));
        nlohmann::json j = nlohmann::json::parse(in);
        nlohmann::json cam = j["camera"];
        cam["width"] = j["width"];
        cam["height"] = j["height"];
        list << cam.dump() << "\n\n";   // blank lines are skipped
    }
    list.close();
    ViewerRun r = runViewer("render demo --backend raycast --cameras " + quoted(dir / "cams.jsonl") + " --out " + quoted(dir / "f.png"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(bytes(dir / "f_0000.png"), bytes(dir / "p.png"));
    EXPECT_EQ(bytes(dir / "f_0001.png"), bytes(dir / "o.png"));
}

TEST(CliCamera, BadCameraRequestsGetOneLineErrors) {
    const fs::path dir = dirFor("bad");
    std::ofstream(dir / "bad.jsonl") << "{\"world_to_camera\": [[1,0,0,0],[0,1,0,0]]}\n";
    std::ofstream(dir / "side.json")
        << "{\"width\": 64, \"height\": 64, \"camera\": {\"world_to_camera\": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], "
           "\"K\": [[50,0,32],[0,50,32],[0,0,1]], \"near\": 0.1, \"far\": 50}}\n";
    const std::string out = " --out " + quoted(dir / "x.png");
    struct Case {
        std::string args, message;
    };
    for (const Case& c : {Case{"--turntable 3 --cameras " + quoted(dir / "bad.jsonl"), "give one of them"},
                          Case{"--cameras " + quoted(dir / "bad.jsonl"), "bad.jsonl:1: \"world_to_camera\" must be a 4x4"},
                          Case{"--turntable 4 --shard 4/4", "expected I/N with 0 <= I < N"}, Case{"--shard 0/2", "needs several frames"},
                          Case{"--intrinsics 1,2,3", "expected fx,fy,cx,cy"}, Case{"--intrinsics -5,5,1,1", "focal lengths must be positive"},
                          Case{"--camera-json " + quoted(dir / "side.json") + " --size 100x50", "made for 64x64"},
                          Case{"--camera-json " + quoted(dir / "missing.json"), "missing.json"}}) {
        ViewerRun r = runViewer("render demo --backend raster" + out + " " + c.args);
        EXPECT_NE(r.status, 0) << c.args;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << " -> " << r.output;
        EXPECT_LE(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    }
    // A hand-written sidecar with K (no projection matrix) renders at its own size.
    ViewerRun r = runViewer("render demo --backend raster --camera-json " + quoted(dir / "side.json") + out);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("64x64"), std::string::npos) << r.output;
}
