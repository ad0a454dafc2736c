// params_test.cpp - the parameter tables (scenegraph/params.h) as the one source of every
// editable value: rows complete and their defaults valid; the scene file's writer and reader
// carry every row; every flagged row is a command-line option that takes its text form; a value
// outside a row's range is refused with the range; the size-dependent defaults are the same for
// the command line and the window (assets::loadScene), so `--fog linear` on a mesh shows fog.
#include "scenegraph/params.h"
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "scenegraph/scene_defaults.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>

namespace fs = std::filesystem;
using testing_support::quoted;

namespace {

template <class T>
void expectComplete(std::set<std::string>& flags) {
    std::set<std::string_view> keys;
    const T defaults{};
    for (const sg::Param<T>& p : sg::params<T>()) {
        SCOPED_TRACE(std::string(p.key));
        EXPECT_TRUE(keys.insert(p.key).second) << "duplicate key";
        if (!p.flag.empty()) { EXPECT_TRUE(flags.insert(std::string(p.flag)).second) << "duplicate flag"; }
        EXPECT_FALSE(p.help.empty());
        ASSERT_TRUE(p.get && p.set);
        if (p.kind == sg::ParamKind::Choice) {
            EXPECT_FALSE(p.choices.empty());
        } else if (p.kind != sg::ParamKind::Bool && p.kind != sg::ParamKind::Text) {
            EXPECT_LT(p.min, p.max);
        }
        EXPECT_EQ(sg::checkValue(p, p.get(defaults)), "") << "the default is outside the row's range";
        // The text form round-trips through the parser the CLI and `set` use.
        std::string err;
        std::optional<sg::ParamValue> back = sg::parseParamText(p.kind, sg::formatParamValue(p.get(defaults)), err);
        ASSERT_TRUE(back) << err;
        T copy = defaults;
        EXPECT_TRUE(p.set(copy, *back));
        EXPECT_EQ(p.get(copy), p.get(defaults));
    }
}

// A value of the row's kind, different from `v`, inside the range.
sg::ParamValue another(const sg::ParamKind kind, double lo, double hi, const sg::ParamValue& v, const std::vector<sg::ParamChoice>& choices) {
    switch (kind) {
    case sg::ParamKind::Bool: return !std::get<bool>(v);
    case sg::ParamKind::Int: return std::get<int>(v) == int(hi) ? int(lo) : int(hi);
    case sg::ParamKind::Float: return float(std::get<float>(v) == float(hi) ? lo : (lo + hi) * 0.5);
    case sg::ParamKind::Color: return sg::vec3(float(lo + (hi - lo) * 0.25));
    case sg::ParamKind::Choice:
        for (const sg::ParamChoice& c : choices)
            if (c.name != std::get<std::string>(v)) return std::string(c.name);
        break;
    case sg::ParamKind::Text: return std::get<std::string>(v) == "none" ? std::string("default") : std::string("none");
    }
    return v;
}

}   // namespace

TEST(ParamTablesTest, EveryRowIsCompleteAndItsDefaultValid) {
    std::set<std::string> flags;
    expectComplete<sg::RenderSettings>(flags);
    expectComplete<sg::Projection>(flags);
    std::set<std::string> noFlags;   // materials and lights have no command-line options
    expectComplete<sg::Material>(noFlags);
    expectComplete<sg::Light>(noFlags);
}

// Each render-settings row changed alone survives the scene file's writer and reader.
TEST(ParamTablesTest, TheSceneFileCarriesEveryRenderSetting) {
    for (const sg::Param<sg::RenderSettings>& p : sg::params<sg::RenderSettings>()) {
        SCOPED_TRACE(std::string(p.key));
        sg::Scene s;
        s.settings.fog = sg::FogMode::Exp;   // every fog row means something, linear's rule holds
        sg::ParamValue v = another(p.kind, p.min, p.max, p.get(s.settings), p.choices);
        if (p.key == "aaRate") continue;   // carried, but only meaningful with aa none (below)
        ASSERT_TRUE(p.set(s.settings, v));
        if (!s.settings.validate().empty()) continue;   // a combination the rules refuse (MSAA rate)
        assets::LoadResult r = assets::parseSceneJson(assets::serializeSceneJson(s), "roundtrip");
        ASSERT_TRUE(r.scene) << r.error;
        EXPECT_EQ(p.get(r.scene->settings), v);
    }
}

TEST(ParamTablesTest, ValuesOutsideARowsRangeAreRefusedWithTheRange) {
    sg::RenderSettings s;
    const sg::Param<sg::RenderSettings>* tess = sg::findParam<sg::RenderSettings>("tessellation");
    ASSERT_TRUE(tess);
    EXPECT_EQ(sg::setParamFromText(s, *tess, "600"), "tessellation must be in [4, 512]");
    EXPECT_EQ(s.tessellation, sg::RenderSettings{}.tessellation);
    EXPECT_EQ(sg::setParamFromText(s, *tess, "12"), "");
    EXPECT_EQ(s.tessellation, 12);
    EXPECT_NE(sg::setParamFromText(s, *sg::findParam<sg::RenderSettings>("fog.density"), "1e300"), "") << "beyond a float";
    EXPECT_NE(sg::setParamFromText(s, *sg::findParam<sg::RenderSettings>("background"), "0.1,0.2"), "") << "two components";
    s.fogDensity = -1.0f;
    EXPECT_NE(s.validate().find("fog.density"), std::string::npos) << s.validate();
    assets::LoadResult r = assets::parseSceneJson(R"({"settings": {"fog": {"density": -2}}})", "bad.json");
    EXPECT_FALSE(r.scene);
    EXPECT_NE(r.error.find("/settings/fog/density"), std::string::npos) << r.error;
    EXPECT_NE(r.error.find("[0, 10000]"), std::string::npos) << r.error;
}

// Every flagged row is an option of `viewer render` taking its text form (all at once, each at
// its default), and a bad value names the flag and the range.
TEST(ParamTablesTest, EveryFlaggedRowIsACommandLineOption) {
    fs::path dir = testing_support::outputDir("params");
    std::string args;
    auto add = [&](const auto& table, const auto& defaults) {
        for (const auto& p : table)
            if (!p.flag.empty()) args += " --" + std::string(p.flag) + " " + testing_support::quoted(fs::path(sg::formatParamValue(p.get(defaults))));
    };
    add(sg::params<sg::RenderSettings>(), sg::RenderSettings{});
    add(sg::params<sg::Projection>(), sg::Projection{});
    testing_support::ProgramRun ok = testing_support::runProgram(
        quoted(VIEWER_EXE), "render demo --backend raster --size 32x18 --overwrite --out " + quoted(dir / "all-flags.png") + args);
    EXPECT_EQ(ok.status, 0) << ok.output;
    testing_support::ProgramRun bad = testing_support::runProgram(
        quoted(VIEWER_EXE), "render demo --backend raster --size 32x18 --tessellation 600 --out " + quoted(dir / "bad.png"));
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.output.find("--tessellation must be in [4, 512]"), std::string::npos) << bad.output;
}

// The display transform's rows on the command line: a negative exposure in EV is a value, not
// an option; the operator by name; bad values name the flag with the range or the names.
TEST(ParamTablesTest, ExposureAndToneMappingOnTheCommandLine) {
    fs::path dir = testing_support::outputDir("params");
    testing_support::ProgramRun ok = testing_support::runProgram(
        quoted(VIEWER_EXE),
        "render demo --backend raster --size 32x18 --overwrite --exposure -1.5 --tone-mapping khr-neutral --out " + quoted(dir / "tone.png"));
    EXPECT_EQ(ok.status, 0) << ok.output;
    testing_support::ProgramRun far =
        testing_support::runProgram(quoted(VIEWER_EXE), "render demo --backend raster --size 32x18 --exposure 11 --out " + quoted(dir / "bad.png"));
    EXPECT_NE(far.status, 0);
    EXPECT_NE(far.output.find("--exposure must be in [-10, 10]"), std::string::npos) << far.output;
    testing_support::ProgramRun name = testing_support::runProgram(
        quoted(VIEWER_EXE), "render demo --backend raster --size 32x18 --tone-mapping filmic --out " + quoted(dir / "bad.png"));
    EXPECT_NE(name.status, 0);
    EXPECT_NE(name.output.find("none, aces, khr-neutral"), std::string::npos) << name.output;
    sg::RenderSettings s;
    EXPECT_EQ(sg::setParamFromText(s, *sg::findParam<sg::RenderSettings>("toneMapping"), "aces"), "");
    EXPECT_EQ(s.toneMapping, sg::ToneMapping::Aces);
    EXPECT_EQ(sg::setParamFromText(s, *sg::findParam<sg::RenderSettings>("exposure"), "-2.5"), "");
    EXPECT_EQ(s.exposure, -2.5f);
}

// The isometric preset of the projection row: orthographic (the command line turns the camera).
TEST(ParamTablesTest, IsometricPresetIsOrthographic) {
    sg::Projection p;
    const sg::Param<sg::Projection>* type = sg::findParam<sg::Projection>("type");
    ASSERT_TRUE(type);
    EXPECT_EQ(sg::setParamFromText(p, *type, "isometric"), "");
    EXPECT_EQ(p.type, sg::ProjectionType::Orthographic);
    EXPECT_TRUE(std::any_of(type->choices.begin(), type->choices.end(), [](const sg::ParamChoice& c) { return c.name == "isometric"; }));
}

// A mesh file's fog follows its size wherever it is opened: loadScene fits it (the window's
// load and every command call it), so `viewer render FILE --fog linear` shows fog.
TEST(SceneDefaultsTest, FogFollowsTheFilesSizeOnTheCommandLineAsInTheWindow) {
    fs::path dir = testing_support::outputDir("params");
    fs::path obj = dir / "big-quad.obj";
    {
        std::ofstream out(obj);
        out << "v -500 -500 0\nv 500 -500 0\nv 500 500 0\nv -500 500 0\nf 1 2 3 4\n";   // a 1 km quad
    }
    assets::LoadResult r = assets::loadScene(obj);
    ASSERT_TRUE(r.scene) << r.error;
    const float radius = sg::sceneRadius(*r.scene);
    EXPECT_NEAR(radius, 707.1f, 0.5f);
    EXPECT_FLOAT_EQ(r.scene->settings.fogStart, radius);
    EXPECT_FLOAT_EQ(r.scene->settings.fogEnd, 6.0f * radius);
    EXPECT_EQ(r.scene->settings.fog, sg::FogMode::Off) << "fitted, not turned on";
    EXPECT_EQ(r.scene->settings.fogColor, r.scene->settings.background) << "fog fades into the background";

    auto render = [&](const std::string& name, const std::string& flags) {
        testing_support::ProgramRun run = testing_support::runProgram(
            quoted(VIEWER_EXE), "render " + quoted(obj) + " --backend raster --size 64x48 --overwrite --out " + quoted(dir / name) + flags);
        EXPECT_EQ(run.status, 0) << run.output;
        assets::ImageLoad img = assets::loadImage(dir / name);
        return img.texture ? img.texture->rgba : std::vector<uint8_t>{};
    };
    std::vector<uint8_t> off = render("fog-off.png", ""), on = render("fog-linear.png", " --fog linear --fog-color 1,0,0");
    ASSERT_EQ(off.size(), on.size());
    ASSERT_FALSE(off.empty());
    // The centre pixel (the quad, ~2.4 r away) is pulled toward the red fog.
    const size_t c = (24 * 64 + 32) * 4;
    EXPECT_GE(int(on[c]), int(off[c])) << "red fog adds red";
    EXPECT_GT(int(off[c + 1]) - int(on[c + 1]), 25) << "no fog on the command line (green should fall toward the red fog's 0)";
}
