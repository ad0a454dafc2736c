// scene_json_test.cpp - the native JSON scene file: round trips (the demo, skins and morph
// targets, edited settings and transforms, an empty scene and a deep chain), saves that never
// overwrite without permission, and bad files: one clear error naming the file and the JSON
// path, nothing loaded (a missing texture is a warning with a placeholder).
#include "assets/demo.h"
#include "assets/scene_io.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <fstream>

namespace fs = std::filesystem;

namespace {

fs::path tempDir(const std::string& name) {
    fs::path d = testing_support::outputDir("scene_json") / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

void writeText(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

}   // namespace

TEST(SceneJsonTest, DemoRoundTripInMemory) {
    sg::Scene demo = assets::makeDemoScene();
    std::string text = assets::serializeSceneJson(demo);
    assets::LoadResult r = assets::parseSceneJson(text, "demo.json");
    ASSERT_TRUE(r.scene) << r.error;
    EXPECT_EQ(sg::sceneDifference(demo, *r.scene), "");
    // Serialising the loaded scene again gives the same text: nothing drifts.
    EXPECT_EQ(assets::serializeSceneJson(*r.scene), text);
}

TEST(SceneJsonTest, SkinsAndMorphTargetsRoundTrip) {
    // A skinned mesh (two influence sets, tangents) with a two-joint skin, and a morphed mesh
    // instanced with its own weights: save, load, compare, and the posed meshes agree.
    sg::Scene s;
    auto skinned = std::make_shared<sg::Mesh>(sg::primitives::box(sg::vec3(0.5f)));
    const size_t n = skinned->positions.size();
    skinned->tangents.assign(n, sg::vec4(1, 0, 0, -1));
    skinned->joints0.assign(n, sg::u16vec4(0, 1, 0, 0));
    skinned->weights0.assign(n, sg::vec4(0.25f, 0.25f, 0, 0));
    skinned->joints1.assign(n, sg::u16vec4(1, 0, 0, 0));
    skinned->weights1.assign(n, sg::vec4(0.5f, 0, 0, 0));
    auto morphed = std::make_shared<sg::Mesh>(sg::primitives::box(sg::vec3(0.5f)));
    morphed->morphTargets.resize(2);
    morphed->morphTargets[0].positions.assign(n, sg::vec3(0, 0.5f, 0));
    morphed->morphTargets[1].normals.assign(n, sg::vec3(0.1f, 0, 0));
    morphed->morphTargets[1].tangents.assign(n, sg::vec3(0, 0.2f, 0));
    morphed->morphWeights = {0.5f, 0.25f};
    s.meshes = {skinned, morphed};
    sg::NodeId j0 = s.addNode("j0");
    sg::NodeId j1 = s.addNode("j1", j0);
    s.setLocal(j1, sg::LocalTransform::fromTRS(sg::vec3(1, 0, 0), glm::angleAxis(0.7f, sg::vec3(0, 0, 1))));
    s.skins.push_back({"bones", {j0, j1}, {sg::mat4(1.0f), glm::translate(sg::mat4(1.0f), sg::vec3(-1, 0, 0))}, j0});
    sg::MeshInstance a{0, -1};
    a.skin = 0;
    sg::NodeId an = s.addNode("skinned", s.root(), a);
    sg::MeshInstance b{1, -1};
    b.weights = {0.75f, 0.0f};
    sg::NodeId bn = s.addNode("morphed", s.root(), b);
    std::string text = assets::serializeSceneJson(s);
    assets::LoadResult r = assets::parseSceneJson(text, "skin.json");
    ASSERT_TRUE(r.scene) << r.error;
    EXPECT_EQ(sg::sceneDifference(s, *r.scene), "");
    EXPECT_EQ(assets::serializeSceneJson(*r.scene), text);
    const sg::Scene& t = *r.scene;
    EXPECT_EQ(t.posedMesh(t.findByName("skinned"))->positions, s.posedMesh(an)->positions);
    EXPECT_EQ(t.posedMesh(t.findByName("morphed"))->positions, s.posedMesh(bn)->positions);
    // sceneDifference notices skin and morph changes.
    sg::Scene c = *r.scene;
    c.skins[0].inverseBind[1][3][0] = -2.0f;
    EXPECT_NE(sg::sceneDifference(s, c), "");
    c = *r.scene;
    c.meshes[1]->morphTargets[0].positions[0].y = 9.0f;
    EXPECT_NE(sg::sceneDifference(s, c), "");
    // A joint that left the scene is saved as null and stays out.
    s.removeNode(j1);
    r = assets::parseSceneJson(assets::serializeSceneJson(s), "skin.json");
    ASSERT_TRUE(r.scene) << r.error;
    EXPECT_EQ(r.scene->skins[0].joints[1], sg::kNoNode);
    EXPECT_EQ(sg::sceneDifference(s, *r.scene), "");
}

TEST(SceneJsonTest, EditedSettingsAndTransformsRoundTripThroughAFile) {
    sg::Scene s = assets::makeDemoScene();
    s.settings.shading = sg::ShadingModel::Gouraud;
    s.settings.reflection = sg::ReflectionModel::BlinnPhong;
    s.settings.fog = sg::FogMode::Exp2;
    s.settings.fogDensity = 0.07f;
    ASSERT_TRUE(s.settings.setAA("ssaa3"));
    s.settings.wireframe = true;
    sg::NodeId crate = s.findByName("crate");
    ASSERT_NE(crate, sg::kNoNode);
    s.setLocalMatrix(crate, glm::mat4(1, 0, 0, 0, 0.5f, 1, 0, 0, 0, 0, -1, 0, 1, 2, 3, 1));   // shear + mirror
    s.setVisible(s.findByName("cone"), false);
    auto& cam = std::get<sg::Camera>(s.editPayload(s.activeCamera));
    cam.projection = sg::Projection::cabinet();

    fs::path file = tempDir("roundtrip") / "scene.json";
    ASSERT_EQ(assets::saveSceneJson(s, file, false), "");
    assets::LoadResult r = assets::loadScene(file);
    ASSERT_TRUE(r.scene) << r.error;
    EXPECT_EQ(sg::sceneDifference(s, *r.scene), "");
    EXPECT_EQ(r.scene->node(r.scene->findByName("crate")).local.mode, sg::LocalTransform::Mode::Matrix);
}

TEST(SceneJsonTest, EmptySceneAndDeepChainRoundTrip) {
    sg::Scene s;
    sg::NodeId parent = s.root();
    for (int i = 0; i < 20000; ++i) parent = s.addNode("n" + std::to_string(i), parent);   // deep, no recursion
    assets::LoadResult r = assets::parseSceneJson(assets::serializeSceneJson(s), "deep.json");
    ASSERT_TRUE(r.scene) << r.error;
    EXPECT_EQ(r.scene->nodeCount(), s.nodeCount());
    EXPECT_EQ(sg::sceneDifference(s, *r.scene), "");
}

TEST(SceneJsonTest, SaveNeverOverwritesWithoutPermission) {
    fs::path dir = tempDir("overwrite");
    fs::path file = dir / "precious.json";
    writeText(file, "not a scene, but precious");
    sg::Scene s = assets::makeDemoScene();
    std::string err = assets::saveSceneJson(s, file, false);
    EXPECT_NE(err.find("exists"), std::string::npos) << err;
    std::ifstream in(file);
    std::string content((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(content, "not a scene, but precious");
    EXPECT_EQ(assets::saveSceneJson(s, file, true), "");
    EXPECT_TRUE(assets::loadScene(file).scene);
    // No temporary files left behind.
    int files = 0;
    for (auto& e : fs::directory_iterator(dir)) {
        (void)e;
        ++files;
    }
    EXPECT_EQ(files, 1);
}

struct BadCase {
    const char* name;
    std::string text;
    const char* expectPath;      // JSON path the error must name ("" = any)
    const char* expectMessage;   // substring of the reason
};

class SceneJsonBadFileTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(SceneJsonBadFileTest, GivesOneClearErrorAndLoadsNothing) {
    const BadCase& c = GetParam();
    fs::path file = tempDir(c.name) / (std::string(c.name) + ".json");
    writeText(file, c.text);
    assets::LoadResult r = assets::loadScene(file);
    EXPECT_FALSE(r.scene);
    EXPECT_NE(r.error.find(file.string()), std::string::npos) << r.error;   // names the file
    EXPECT_NE(r.error.find(c.expectPath), std::string::npos) << r.error;
    EXPECT_NE(r.error.find(c.expectMessage), std::string::npos) << r.error;
    EXPECT_EQ(r.error.find('\n'), std::string::npos) << "one line: " << r.error;
}

std::string deepNesting(int depth) { return std::string(depth, '[') + std::string(depth, ']'); }

INSTANTIATE_TEST_SUITE_P(
    BadFiles, SceneJsonBadFileTest,
    ::testing::Values(
        BadCase{"syntax", R"({"nodes": [ {"name": "root"}, ])", "", "syntax error"},
        BadCase{"not_object", "[1, 2, 3]", "/", "top level must be an object"},
        BadCase{"wrong_format", R"({"format": "gltf"})", "/format", "not a scene-viewer scene"},
        BadCase{"unknown_payload", R"({"nodes": [{"name": "root"}, {"parent": 0, "teapot": {}}]})", "/nodes/1/teapot", "unknown node field"},
        BadCase{"unknown_shape", R"({"nodes": [{}, {"parent": 0, "implicit": {"type": "blob"}}]})", "/nodes/1/implicit/type",
                "unknown value \"blob\""},
        BadCase{"unknown_shading", R"({"settings": {"shading": "toon"}})", "/settings/shading", "valid: flat, gouraud, phong"},
        BadCase{"missing_mesh", R"({"nodes": [{}, {"parent": 0, "mesh": {"mesh": 3}}]})", "/nodes/1/mesh/mesh", "out of range"},
        BadCase{"missing_material", R"({"materials": [{}], "nodes": [{}, {"parent": 0, "implicit": {"type": "sphere", "material": 5}}]})",
                "/nodes/1/implicit/material", "out of range"},
        BadCase{"missing_texture_ref", R"({"materials": [{"diffuseTexture": 0}]})", "/materials/0/diffuseTexture", "out of range"},
        BadCase{"cycle", R"({"nodes": [{}, {"parent": 2}, {"parent": 1}]})", "/parent", "cycle"},
        BadCase{"self_parent", R"({"nodes": [{}, {"parent": 1}]})", "/nodes/1/parent", "own parent"},
        BadCase{"dangling_parent", R"({"nodes": [{}, {"parent": 7}]})", "/nodes/1/parent", "out of range"},
        BadCase{"non_finite", R"({"nodes": [{}, {"parent": 0, "transform": {"translation": [0, 1e999, 0]}}]})", "", "not finite"},
        BadCase{"huge_number", R"({"nodes": [{}, {"parent": 0, "transform": {"translation": [0, 1e300, 0]}}]})", "/nodes/1/transform/translation/1",
                "not finite"},
        BadCase{"non_affine", R"({"nodes": [{}, {"parent": 0, "transform": {"matrix": [1,0,0,1, 0,1,0,0, 0,0,1,0, 0,0,0,1]}}]})",
                "/nodes/1/transform/matrix", "affine"},
        BadCase{"absurd_grid", R"({"nodes": [{}, {"parent": 0, "grid": {"dims": [100000, 100000, 100000], "values": []}}]})", "/nodes/1/grid/dims",
                "[2, 1024]"},
        BadCase{"grid_count", R"({"nodes": [{}, {"parent": 0, "grid": {"dims": [2, 2, 2], "values": [1, 2, 3]}}]})", "/nodes/1/grid/values",
                "expected 8 values"},
        BadCase{"bad_indices", R"({"meshes": [{"positions": [0,0,0, 1,0,0, 0,1,0], "indices": [0, 1, 9]}]})", "/meshes/0", "index 9 out of range"},
        BadCase{"negative_radius", R"({"nodes": [{}, {"parent": 0, "implicit": {"type": "sphere", "radius": -1}}]})", "/nodes/1/implicit/radius",
                "positive"},
        BadCase{"bad_camera", R"({"nodes": [{}, {"parent": 0, "camera": {"near": 5, "far": 1}}]})", "/nodes/1/camera", "0 < near < far"},
        BadCase{"active_not_camera", R"({"nodes": [{}], "activeCamera": 0})", "/activeCamera", "not a camera"},
        BadCase{"two_payloads", R"({"meshes": [], "nodes": [{}, {"parent": 0, "light": {}, "csg": {"op": "union"}}]})", "/nodes/1",
                "at most one payload"},
        BadCase{"absolute_mesh_file", R"({"meshes": [{"file": "/etc/passwd"}]})", "/meshes/0/file", "absolute"},
        BadCase{"escaping_mesh_file", R"({"meshes": [{"file": "../../secret.obj"}]})", "/meshes/0/file", "inside the scene's folder"},
        BadCase{
            "missing_skin",
            R"({"meshes": [{"positions": [0,0,0], "mode": "points", "indices": [0]}], "nodes": [{}, {"parent": 0, "mesh": {"mesh": 0, "skin": 0}}]})",
            "/nodes/1/mesh/skin", "out of range"},
        BadCase{"skin_joint_range", R"({"nodes": [{}], "skins": [{"joints": [4], "inverseBindMatrices": [1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]}]})",
                "/skins/0/joints/0", "out of range"},
        BadCase{"skin_matrix_count", R"({"nodes": [{}], "skins": [{"joints": [0], "inverseBindMatrices": [1, 0]}]})", "/skins/0/inverseBindMatrices",
                "16 numbers per joint"},
        BadCase{"joint_number", R"({"meshes": [{"positions": [0,0,0], "joints0": [0, 0, 70000, 0], "weights0": [1,0,0,0]}]})", "/meshes/0/joints0/2",
                "[0, 65535]"},
        BadCase{"negative_weight", R"({"meshes": [{"positions": [0,0,0], "joints0": [0, 0, 0, 0], "weights0": [-1,0,0,0]}]})", "/meshes/0",
                "weights must be finite and >= 0"},
        BadCase{"morph_count", R"({"meshes": [{"positions": [0,0,0], "morphTargets": [{"positions": [1,0,0, 2,0,0]}]}]})", "/meshes/0",
                "morph target 0: count differs"},
        BadCase{"newer_version", R"({"version": 7})", "/version", "newer"}, BadCase{"deep_nesting", deepNesting(100000), "", "nested deeper"}),
    [](const ::testing::TestParamInfo<BadCase>& i) { return std::string(i.param.name); });

TEST(SceneJsonTest, MissingFileAndFolderAreClearErrors) {
    assets::LoadResult r = assets::loadScene("/nonexistent/scene.json");
    EXPECT_FALSE(r.scene);
    EXPECT_NE(r.error.find("/nonexistent/scene.json"), std::string::npos);
    r = assets::loadScene(testing_support::outputDir("scene_json"));
    EXPECT_FALSE(r.scene);
    EXPECT_NE(r.error.find("folder"), std::string::npos) << r.error;
    r = assets::loadScene("scene.xyz");
    EXPECT_FALSE(r.scene);
}

TEST(SceneJsonTest, MissingTextureFileIsAWarningWithAPlaceholder) {
    fs::path dir = tempDir("missing_texture");
    writeText(dir / "s.json", R"({"textures": [{"file": "nothere.png"}], "materials": [{"diffuseTexture": 0}]})");
    assets::LoadResult r = assets::loadScene(dir / "s.json");
    ASSERT_TRUE(r.scene) << r.error;
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("nothere.png"), std::string::npos);
    EXPECT_EQ(r.scene->textures.size(), 1u);
}
