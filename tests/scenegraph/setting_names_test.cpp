// setting_names_test.cpp - the name tables of the settings enums (scenegraph/setting_names.h):
// every value's name parses back to it, names are unique, the JSON writer writes the table's
// names (and the reader takes the aliases of older files), and the viewer's --help-all and
// errors list every name.
#include "scenegraph/setting_names.h"
#include "assets/demo.h"
#include "assets/scene_io.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <set>
#include <string>

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The number of values of each enum, to catch a value missing from its table.
template <class E>
constexpr int valueCount();
template <>
constexpr int valueCount<sg::ShadingModel>() {
    return 3;
}
template <>
constexpr int valueCount<sg::ReflectionModel>() {
    return 3;
}
template <>
constexpr int valueCount<sg::FogMode>() {
    return 4;
}
template <>
constexpr int valueCount<sg::ToneMapping>() {
    return 3;
}
template <>
constexpr int valueCount<sg::ProjectionType>() {
    return 3;
}
template <>
constexpr int valueCount<sg::ObliquePreset>() {
    return 2;
}
template <>
constexpr int valueCount<sg::AxonometricPreset>() {
    return 1;
}
template <>
constexpr int valueCount<sg::LightType>() {
    return 3;
}
template <>
constexpr int valueCount<sg::WrapMode>() {
    return 3;
}
template <>
constexpr int valueCount<sg::FilterMode>() {
    return 3;
}

template <class E>
class SettingsNameTableTest : public ::testing::Test {};
using NamedEnums = ::testing::Types<sg::ShadingModel, sg::ReflectionModel, sg::FogMode, sg::ToneMapping, sg::AAChoice, sg::ProjectionType,
                                    sg::ObliquePreset, sg::AxonometricPreset, sg::LightType, sg::WrapMode, sg::FilterMode>;
TYPED_TEST_SUITE(SettingsNameTableTest, NamedEnums);

TYPED_TEST(SettingsNameTableTest, NamesParseBackAndAreUnique) {
    const sg::NameTable<TypeParam>& table = sg::nameTable<TypeParam>();
    ASSERT_FALSE(table.entries.empty());
    std::set<std::string_view> names, labels;
    for (const auto& e : table.entries) {
        EXPECT_FALSE(e.name.empty());
        EXPECT_FALSE(e.label.empty()) << e.name;
        EXPECT_FALSE(e.help.empty()) << e.name;
        EXPECT_TRUE(names.insert(e.name).second) << "duplicate name " << e.name;
        EXPECT_TRUE(labels.insert(e.label).second) << "duplicate label " << e.label;
        TypeParam v{};
        ASSERT_TRUE(sg::parseName(e.name, v)) << e.name;
        EXPECT_TRUE(v == e.value) << e.name;
        EXPECT_EQ(sg::nameOf(e.value), e.name);
        // Names are plain tokens for a command line and a JSON string.
        for (char c : e.name) EXPECT_TRUE((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-') << e.name;
    }
    for (const auto& a : table.aliases) {
        EXPECT_FALSE(names.count(a.name)) << "alias " << a.name << " shadows a name";
        EXPECT_TRUE(names.insert(a.name).second) << "duplicate alias " << a.name;
        TypeParam v{};
        ASSERT_TRUE(sg::parseName(a.name, v)) << a.name;
        EXPECT_TRUE(v == a.value) << a.name;
        EXPECT_NE(table.find(a.value), nullptr) << "alias " << a.name << " names a value without an entry";
    }
    for (std::string_view bad : {"", "?", "none of these", "PHONG"}) {
        TypeParam v{};
        EXPECT_FALSE(sg::parseName(bad, v)) << bad;
    }
    if constexpr (!std::is_same_v<TypeParam, sg::AAChoice>) {
        EXPECT_EQ(table.entries.size(), size_t(valueCount<TypeParam>()));
        for (int i = 0; i < valueCount<TypeParam>(); ++i) EXPECT_NE(table.find(TypeParam(i)), nullptr) << "value " << i << " has no name";
    }
}

TEST(SettingsNameTableTest, ExistingSpellingsStillParse) {
    // Names of saved scenes and command lines before the tables: all must keep working.
    sg::RenderSettings s;
    for (const char* n : {"flat", "gouraud", "phong"}) EXPECT_TRUE(sg::parse(n, s.shading)) << n;
    for (const char* n : {"phong", "blinn", "blinn-phong"}) EXPECT_TRUE(sg::parse(n, s.reflection)) << n;
    EXPECT_EQ(s.reflection, sg::ReflectionModel::BlinnPhong);
    for (const char* n : {"off", "linear", "exp", "exp2"}) EXPECT_TRUE(sg::parse(n, s.fog)) << n;
    for (const char* n : {"none", "off", "msaa2", "msaa4", "msaa8", "ssaa2", "ssaa3", "ssaa4"}) EXPECT_TRUE(s.setAA(n)) << n;
    sg::ProjectionType pt;
    for (const char* n : {"perspective", "orthographic", "oblique"}) EXPECT_TRUE(sg::parse(n, pt)) << n;
    sg::ObliquePreset op;
    for (const char* n : {"cavalier", "cabinet"}) EXPECT_TRUE(sg::parseName(n, op)) << n;
    EXPECT_EQ(sg::obliquePreset(sg::ObliquePreset::Cavalier), sg::Projection::cavalier());
    EXPECT_EQ(sg::obliquePreset(sg::ObliquePreset::Cabinet), sg::Projection::cabinet());
    sg::LightType lt;
    for (const char* n : {"point", "directional", "spot"}) EXPECT_TRUE(sg::parse(n, lt)) << n;
    sg::WrapMode w;
    for (const char* n : {"repeat", "clamp", "mirror"}) EXPECT_TRUE(sg::parseName(n, w)) << n;
    sg::FilterMode f;
    for (const char* n : {"nearest", "bilinear", "trilinear"}) EXPECT_TRUE(sg::parseName(n, f)) << n;
}

TEST(SettingsNameTableTest, AntiAliasingNoneKeepsTheRate) {
    sg::RenderSettings s;
    ASSERT_TRUE(s.setAA("ssaa3"));
    EXPECT_EQ(sg::aaChoice(s), (sg::AAChoice{sg::AAMode::SSAA, 3}));
    ASSERT_TRUE(s.setAA("off"));
    EXPECT_EQ(s.aa, sg::AAMode::None);
    EXPECT_EQ(s.aaRate, 3);
    EXPECT_EQ(s.aaName(), "none");
}

// --- the JSON writer and reader ------------------------------------------------------------------

json written(const sg::Scene& s) { return json::parse(assets::serializeSceneJson(s)); }

sg::Scene reread(const sg::Scene& s) {
    assets::LoadResult r = assets::parseSceneJson(assets::serializeSceneJson(s), "names.json");
    EXPECT_TRUE(r.scene) << r.error;
    return r.scene ? std::move(*r.scene) : sg::Scene();
}

// The first node's payload of the given kind ("camera", "light") in a written scene.
json payloadOf(const json& j, const char* kind) {
    for (const json& n : j["nodes"])
        if (n.contains(kind)) return n[kind];
    ADD_FAILURE() << "no " << kind << " node";
    return json();
}

TEST(SettingsNameTableTest, JsonWriterWritesTheTableNames) {
    sg::Scene demo = assets::makeDemoScene();
    for (const auto& e : sg::nameTable<sg::ShadingModel>().entries) {
        sg::Scene s = demo;
        s.settings.shading = e.value;
        EXPECT_EQ(written(s)["settings"]["shading"], e.name);
        EXPECT_EQ(reread(s).settings.shading, e.value) << e.name;
    }
    for (const auto& e : sg::nameTable<sg::ReflectionModel>().entries) {
        sg::Scene s = demo;
        s.settings.reflection = e.value;
        EXPECT_EQ(written(s)["settings"]["reflection"], e.name);
        EXPECT_EQ(reread(s).settings.reflection, e.value) << e.name;
    }
    for (const auto& e : sg::nameTable<sg::FogMode>().entries) {
        sg::Scene s = demo;
        s.settings.fog = e.value;
        EXPECT_EQ(written(s)["settings"]["fog"]["mode"], e.name);
        EXPECT_EQ(reread(s).settings.fog, e.value) << e.name;
    }
    for (const auto& e : sg::nameTable<sg::ToneMapping>().entries) {
        sg::Scene s = demo;
        s.settings.toneMapping = e.value;
        EXPECT_EQ(written(s)["settings"]["toneMapping"], e.name);
        EXPECT_EQ(reread(s).settings.toneMapping, e.value) << e.name;
    }
    for (const auto& e : sg::nameTable<sg::AAChoice>().entries) {
        sg::Scene s = demo;
        ASSERT_TRUE(s.settings.setAA(e.name));
        EXPECT_EQ(written(s)["settings"]["aa"], e.name);
        EXPECT_EQ(sg::aaChoice(reread(s).settings), e.value) << e.name;
    }
    ASSERT_NE(demo.activeCamera, sg::kNoNode);
    for (const auto& e : sg::nameTable<sg::ProjectionType>().entries) {
        sg::Scene s = demo;
        std::get<sg::Camera>(s.editPayload(s.activeCamera)).projection.type = e.value;
        EXPECT_EQ(payloadOf(written(s), "camera")["type"], e.name);
        sg::Scene r = reread(s);
        EXPECT_EQ(std::get<sg::Camera>(r.node(r.activeCamera).payload).projection.type, e.value) << e.name;
    }
    sg::NodeId light = sg::kNoNode;
    for (sg::NodeId id = 0; id < demo.idCapacity() && light == sg::kNoNode; ++id)
        if (demo.valid(id) && std::holds_alternative<sg::Light>(demo.node(id).payload)) light = id;
    ASSERT_NE(light, sg::kNoNode);
    for (const auto& e : sg::nameTable<sg::LightType>().entries) {
        sg::Scene s = demo;
        std::get<sg::Light>(s.editPayload(light)).type = e.value;
        EXPECT_EQ(payloadOf(written(s), "light")["type"], e.name);
        EXPECT_EQ(sg::sceneDifference(s, reread(s)), "") << e.name;
    }
    ASSERT_FALSE(demo.textures.empty());
    for (const auto& w : sg::nameTable<sg::WrapMode>().entries)
        for (const auto& f : sg::nameTable<sg::FilterMode>().entries) {
            sg::Scene s = demo;
            auto t = std::make_shared<sg::Texture>(*s.textures[0]);
            t->wrapS = w.value;
            t->wrapT = w.value;
            t->filter = f.value;
            s.textures[0] = t;
            json tj = written(s)["textures"][0];
            EXPECT_EQ(tj["wrapS"], w.name);
            EXPECT_EQ(tj["wrapT"], w.name);
            EXPECT_EQ(tj["filter"], f.name);
            const sg::Scene again = reread(s);   // keep the scene alive while its texture is read
            const sg::Texture& back = *again.textures[0];
            EXPECT_EQ(back.wrapS, w.value) << w.name;
            EXPECT_EQ(back.filter, f.value) << f.name;
        }
}

TEST(SettingsNameTableTest, JsonReaderTakesAliasesAndListsTheNames) {
    assets::LoadResult r = assets::parseSceneJson(R"({"format": "sceneviewer", "version": 1, "nodes": [{"name": "root"}],
        "settings": {"reflection": "blinn-phong", "aa": "off"}})",
                                                  "alias.json");
    ASSERT_TRUE(r.scene) << r.error;
    EXPECT_EQ(r.scene->settings.reflection, sg::ReflectionModel::BlinnPhong);
    EXPECT_EQ(r.scene->settings.aa, sg::AAMode::None);
    r = assets::parseSceneJson(R"({"format": "sceneviewer", "version": 1, "nodes": [{"name": "root"}], "settings": {"fog": {"mode": "fgo"}}})",
                               "bad.json");
    ASSERT_FALSE(r.scene);
    EXPECT_NE(r.error.find("/settings/fog/mode"), std::string::npos) << r.error;
    EXPECT_NE(r.error.find("valid: " + sg::nameList<sg::FogMode>()), std::string::npos) << r.error;
}

// --- the viewer's command line -------------------------------------------------------------------

using ViewerRun = testing_support::ProgramRun;
ViewerRun runViewer(const std::string& args) { return testing_support::runProgram(VIEWER_EXE, args); }

template <class E>
void expectAllNames(const std::string& text) {
    for (const auto& e : sg::nameTable<E>().entries) {
        EXPECT_NE(text.find(std::string(e.name)), std::string::npos) << e.name;
        EXPECT_NE(text.find(std::string(e.help)), std::string::npos) << e.help;
    }
}

TEST(CliSettingNamesTest, HelpAllListsEveryName) {
    ViewerRun r = runViewer("--help-all");
    ASSERT_EQ(r.status, 0) << r.output;
    expectAllNames<sg::ShadingModel>(r.output);
    expectAllNames<sg::ReflectionModel>(r.output);
    expectAllNames<sg::FogMode>(r.output);
    expectAllNames<sg::AAChoice>(r.output);
    expectAllNames<sg::ProjectionType>(r.output);
    expectAllNames<sg::ObliquePreset>(r.output);
    expectAllNames<sg::AxonometricPreset>(r.output);
    expectAllNames<sg::ToneMapping>(r.output);
}

TEST(CliSettingNamesTest, BadValuesListTheValidNames) {
    fs::path out = testing_support::outputDir("setting_names") / "never.png";
    std::string base = "render demo --backend raycast --size 8x8 --overwrite --out \"" + out.string() + "\" ";
    struct Case {
        std::string args, message;
    };
    for (const Case& c : {Case{"--fog fgo", "--fog: 'fgo' is not one of " + sg::nameList<sg::FogMode>()},
                          Case{"--shading toon", "--shading: 'toon' is not one of " + sg::nameList<sg::ShadingModel>()},
                          Case{"--reflection cook", "--reflection: 'cook' is not one of " + sg::nameList<sg::ReflectionModel>()},
                          Case{"--aa fxaa", "--aa: 'fxaa' is not one of " + sg::nameList<sg::AAChoice>()},
                          Case{"--tone-mapping reinhard", "--tone-mapping: 'reinhard' is not one of " + sg::nameList<sg::ToneMapping>()},
                          Case{"--projection fisheye", "--projection: 'fisheye' is not one of " + sg::nameList<sg::ProjectionType>() + ", " +
                                                           sg::nameList<sg::ObliquePreset>() + ", " + sg::nameList<sg::AxonometricPreset>()}}) {
        ViewerRun r = runViewer(base + c.args);
        EXPECT_NE(r.status, 0) << c.args;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
    }
}

TEST(CliSettingNamesTest, OldSpellingsAndAliasesStillRender) {
    fs::path out = testing_support::outputDir("setting_names") / "aliases.png";
    ViewerRun r = runViewer(
        "render demo --backend raycast --size 8x8 --overwrite --reflection blinn-phong --aa off --shading gouraud --fog exp2 "
        "--projection cabinet --out \"" +
        out.string() + "\"");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(out)) << r.output;
}

}   // namespace
