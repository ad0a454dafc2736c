// scene_roundtrip_test.cpp - save, then reopen, gives the same scene to the bit: awkward floats
// (0.1, 1/3, 1e-7, denormals, integers around 2^24, -0, the largest floats, random bit patterns)
// read back exactly, a NaN or an infinity is refused on saving (and the file left alone), and
// the demo and glTF samples (imported, saved as our scene file, reopened) render the same
// image with the CPU rasterizer, colour and depth byte for byte.
#include "assets/demo.h"
#include "assets/scene_io.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "scenegraph/scene_defaults.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <random>

namespace fs = std::filesystem;

namespace {

// Floats whose shortest decimal spelling is long, or tie-prone, or that lose digits on a
// round trip through too few: thirds, tenths, powers of ten below 1, the smallest normal and
// the denormals, integers next to 2^24 (where floats step by 2), neighbours of 1, -0.
std::vector<float> awkwardFloats() {
    std::vector<float> v = {0.1f,
                            0.2f,
                            0.3f,
                            1.0f / 3.0f,
                            2.0f / 3.0f,
                            1e-7f,
                            -1e-7f,
                            1e-5f,
                            3.14159265f,
                            123456.789f,
                            16777215.0f,
                            16777216.0f,
                            float(16777217.0),
                            16777218.0f,
                            33554431.0f,
                            std::nextafter(1.0f, 2.0f),
                            std::nextafter(1.0f, 0.0f),
                            FLT_MIN,
                            -FLT_MIN,
                            std::nextafter(FLT_MIN, 0.0f),   // the largest denormal
                            FLT_TRUE_MIN,                    // the smallest
                            -FLT_TRUE_MIN,
                            1e-40f,
                            1e-45f,
                            1e30f,
                            2.9e38f,
                            3.0e38f,
                            std::nextafter(3.0e38f, FLT_MAX),
                            -3.1e38f,
                            FLT_MAX,   // written as 3.40282347e+38, which reads as a double above FLT_MAX
                            -FLT_MAX,
                            std::nextafter(FLT_MAX, 0.0f),
                            -0.0f,
                            0.0f,
                            FLT_EPSILON,
                            1.0f + FLT_EPSILON};
    // Random bit patterns: every finite float (all exponents, denormals included).
    std::mt19937 rng(20240611);
    while (v.size() < 30000) {
        const float f = std::bit_cast<float>(uint32_t(rng()));
        if (std::isfinite(f)) v.push_back(f);
    }
    while (v.size() % 3) v.push_back(0.5f);
    return v;
}

// The bits of every float of a, against b's.
::testing::AssertionResult sameBits(const std::vector<float>& a, const std::vector<float>& b) {
    if (a.size() != b.size()) return ::testing::AssertionFailure() << a.size() << " floats read back as " << b.size();
    int wrong = 0;
    auto failure = ::testing::AssertionFailure();
    for (size_t i = 0; i < a.size(); ++i)
        if (std::bit_cast<uint32_t>(a[i]) != std::bit_cast<uint32_t>(b[i]) && wrong++ < 10)
            failure << std::hexfloat << a[i] << " read back as " << b[i] << std::defaultfloat << " (" << a[i] << ")\n";
    return wrong ? failure << wrong << " of " << a.size() << " floats changed" : ::testing::AssertionSuccess();
}

std::vector<float> flatPositions(const sg::Mesh& m) {
    std::vector<float> out;
    for (const sg::vec3& p : m.positions) out.insert(out.end(), {p.x, p.y, p.z});
    return out;
}

}   // namespace

TEST(SceneRoundTripTest, AwkwardFloatsReadBackBitForBit) {
    const std::vector<float> values = awkwardFloats();
    sg::Scene s;
    auto mesh = std::make_shared<sg::Mesh>();
    mesh->mode = sg::PrimitiveMode::Points;
    for (size_t i = 0; i + 2 < values.size(); i += 3) mesh->positions.emplace_back(values[i], values[i + 1], values[i + 2]);
    s.meshes = {mesh};
    s.addNode("points", s.root(), sg::MeshInstance{0, -1});
    // A node's matrix (affine: the last row stays 0 0 0 1) goes through the same writer.
    sg::mat4 m(1.0f);
    for (int k = 0; k < 12; ++k) m[k / 3][k % 3] = values[size_t(k) + 1];
    const sg::NodeId n = s.addNode("matrix", s.root());
    s.setLocalMatrix(n, m);
    // As every opened scene has them (loadScene applies them to what it reads: a scene made in
    // memory would get them on reopening, its fog distances fitted to its size).
    sg::applySceneDefaults(s);
    const fs::path file = testing_support::outputDir("scene_roundtrip") / "AwkwardFloatsReadBackBitForBit.json";
    fs::remove(file);
    ASSERT_EQ(assets::saveSceneJson(s, file, false), "");
    const assets::LoadResult r = assets::loadScene(file);
    ASSERT_TRUE(r.scene) << r.error;
    ASSERT_EQ(r.scene->meshes.size(), 1u);
    EXPECT_TRUE(sameBits(flatPositions(*mesh), flatPositions(*r.scene->meshes[0])));
    const sg::mat4 back = r.scene->node(r.scene->findByName("matrix")).local.matrix;
    std::vector<float> want, got;
    for (int k = 0; k < 16; ++k) {
        want.push_back(m[k / 4][k % 4]);
        got.push_back(back[k / 4][k % 4]);
    }
    EXPECT_TRUE(sameBits(want, got));
    EXPECT_EQ(sg::sceneDifference(s, *r.scene), "");
    // And saving what was read gives the same text: nothing drifts.
    EXPECT_EQ(assets::serializeSceneJson(*r.scene), assets::serializeSceneJson(s));
}

// The reader takes every spelling of the largest float (the writer's 3.40282347e+38 reads as a
// double a hair above FLT_MAX), and refuses a number that would round to infinity as a float.
TEST(SceneRoundTripTest, LargestFloatReadsBackAndBeyondItIsRefused) {
    auto translationX = [](const std::string& x, std::string& error) {
        const assets::LoadResult r =
            assets::parseSceneJson(R"({"nodes": [{}, {"parent": 0, "transform": {"translation": [)" + x + ", 0, 0]}}]}", "big.json");
        error = r.error;
        return r.scene ? std::optional<float>(r.scene->node(1).local.translation.x) : std::nullopt;
    };
    std::string error;
    for (const char* text : {"3.40282347e+38", "3.4028235e38", "340282346638528859811704183484516925440.0", "3.4028235677973e38"}) {
        for (const std::string sign : {"", "-"}) {
            const std::optional<float> x = translationX(sign + text, error);
            ASSERT_TRUE(x) << sign << text << ": " << error;
            EXPECT_EQ(std::bit_cast<uint32_t>(*x), std::bit_cast<uint32_t>(sign.empty() ? FLT_MAX : -FLT_MAX)) << sign << text;
        }
    }
    // 2^128 - 2^103, halfway between FLT_MAX and 2^128, rounds (to even) to infinity.
    for (const char* text : {"3.4028235677973366e38", "-3.4028235677973366e38", "3.5e38", "-1e39", "1e300"}) {
        EXPECT_FALSE(translationX(text, error)) << text;
        EXPECT_NE(error.find("big.json: /nodes/1/transform/translation/0"), std::string::npos) << error;
        EXPECT_NE(error.find("not finite"), std::string::npos) << error;
    }
}

// NaN and infinity have no JSON spelling (printf's "nan" made files nobody could open). A save
// is refused, naming the value by its JSON path, and the file on disk is left as it was; no file
// is made where there was none.
TEST(SceneRoundTripTest, NonFiniteNumbersAreRefusedAndLeaveTheFileAlone) {
    struct Case {
        const char* name;
        std::function<void(sg::Scene&)> spoil;
        const char* path;
        const char* what;
    };
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const std::vector<Case> cases = {
        {"translation_nan", [&](sg::Scene& s) { s.setLocal(s.findByName("crate"), sg::LocalTransform::fromTRS(sg::vec3(0, nan, 0))); },
         "/transform/translation/1", "NaN"},
        {"fog_inf", [&](sg::Scene& s) { s.settings.fogDensity = inf; }, "/settings/fog/density", "+infinity"},
        {"position_minus_inf", [&](sg::Scene& s) { s.meshes.at(0)->positions.at(0).z = -inf; }, "/meshes/0/positions/2", "-infinity"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        sg::Scene s = assets::makeDemoScene();
        ASSERT_FALSE(s.meshes.empty());
        ASSERT_NE(s.findByName("crate"), sg::kNoNode);
        c.spoil(s);
        std::string error;
        EXPECT_EQ(assets::serializeSceneJson(s, &error), "");
        EXPECT_NE(error.find(c.path), std::string::npos) << error;
        EXPECT_NE(error.find(c.what), std::string::npos) << error;

        const fs::path dir = testing_support::outputDir("scene_roundtrip") / c.name;
        fs::remove_all(dir);
        fs::create_directories(dir);
        const fs::path file = dir / "scene.json";
        std::ofstream(file, std::ios::binary) << "the previous save";
        const std::string err = assets::saveSceneJson(s, file, true);
        EXPECT_NE(err.find(file.string()), std::string::npos) << err;
        EXPECT_NE(err.find(c.path), std::string::npos) << err;
        EXPECT_NE(err.find("cannot be saved"), std::string::npos) << err;
        std::ifstream in(file, std::ios::binary);
        EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "the previous save");
        EXPECT_NE(assets::saveSceneJson(s, dir / "new.json", false), "");
        EXPECT_FALSE(fs::exists(dir / "new.json"));
    }
}

// A scene saved as our file and reopened renders the same image, byte for byte.
class SceneRoundTripRender : public ::testing::TestWithParam<std::string> {};

TEST_P(SceneRoundTripRender, SameImageBitForBit) {
    const std::string name = GetParam();
    assets::LoadResult original;
    if (name == "demo") {
        original.scene = assets::makeDemoScene();
    } else {
        ASSERT_TRUE(testing_support::requireTestdata());
        original = assets::loadScene(testing_support::testdataDir() / "gltf" / name / "glTF" / (name + ".gltf"));
    }
    ASSERT_TRUE(original.scene) << original.error;
    const fs::path file = testing_support::outputDir("scene_roundtrip") / ("SameImageBitForBit-" + name + ".json");
    fs::remove(file);
    ASSERT_EQ(assets::saveSceneJson(*original.scene, file, false), "");
    const assets::LoadResult reopened = assets::loadScene(file);
    ASSERT_TRUE(reopened.scene) << reopened.error;
    EXPECT_EQ(sg::sceneDifference(*original.scene, *reopened.scene), "");
    constexpr int kW = 200, kH = 150;
    rnd::Framebuffer image[2];
    const sg::Scene* scenes[2] = {&*original.scene, &*reopened.scene};
    for (int i = 0; i < 2; ++i) {
        std::string err;
        auto raster = rnd::makeRenderer("raster", &err);   // a fresh one each: no cache shared
        ASSERT_TRUE(raster) << err;
        const rnd::RenderStats st = raster->render(sg::flatten(*scenes[i], float(kW) / kH), kW, kH, image[i]);
        ASSERT_TRUE(st.ok) << st.error;
    }
    testing_support::writeImage(image[0], "scene_roundtrip", name + "-original");
    testing_support::writeImage(image[1], "scene_roundtrip", name + "-reopened");
    EXPECT_TRUE(image[0].color == image[1].color) << "colour differs";
    EXPECT_TRUE(image[0].depth.size() == image[1].depth.size() &&
                std::memcmp(image[0].depth.data(), image[1].depth.data(), image[0].depth.size() * sizeof(float)) == 0)
        << "depth differs";
    size_t drawn = 0;
    for (float d : image[0].depth) drawn += d < 1.0f;
    EXPECT_GT(drawn, size_t(kW * kH / 20)) << "something is in view";
}

// The demo (every kind of shape, textures, lights), and glTF samples with textures, a node
// hierarchy, glTF's material models (metal-rough, spec-gloss, texture transforms), a skin and
// morph targets.
INSTANTIATE_TEST_SUITE_P(Scenes, SceneRoundTripRender,
                         ::testing::Values("demo", "BoxTextured", "CesiumMilkTruck", "SpecGlossVsMetalRough", "TextureTransformTest", "CesiumMan",
                                           "AnimatedMorphCube"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });
