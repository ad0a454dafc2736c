// skin_morph_import_test.cpp - glTF skins, morph targets and weights animations: the
// "weights" channel sampler (LINEAR, STEP, CUBICSPLINE with per-target in/out tangents) with
// answers worked out by hand; a generated glTF (data URI buffer) whose two-bone skin, morph
// targets, node/mesh weights and animations are checked value by value after import and
// posing; and the sample models of testdata (CesiumMan skinned and walking, the morph models).
#include "import_test_util.h"

#include "assets/animation.h"
#include "assets/files.h"
#include "scenegraph/deform.h"
#include "scenegraph/frame.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <functional>

namespace fs = std::filesystem;
using nlohmann::json;
using namespace import_test;

namespace {

::testing::AssertionResult vecNear(const sg::vec3& a, const sg::vec3& b, float eps = 1e-5f) {
    if (glm::all(glm::lessThanEqual(glm::abs(a - b), sg::vec3(eps)))) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << ") vs expected (" << b.x << ", " << b.y << ", " << b.z << ")";
}

assets::AnimationChannel weightsChannel(assets::AnimationInterpolation interp, std::vector<float> times, std::vector<float> values) {
    assets::AnimationChannel ch;
    ch.path = assets::AnimationPath::Weights;
    ch.interpolation = interp;
    ch.width = 2;
    ch.times = std::move(times);
    ch.weights = std::move(values);
    return ch;
}

}   // namespace

TEST(WeightsAnimationTest, LinearAndStep) {
    using I = assets::AnimationInterpolation;
    // Two targets, keys at 0 and 1: (0, 1) -> (1, 0).
    auto lin = weightsChannel(I::Linear, {0.0f, 1.0f}, {0, 1, 1, 0});
    EXPECT_EQ(assets::sampleWeights(lin, 0.25f), (std::vector<float>{0.25f, 0.75f}));
    EXPECT_EQ(assets::sampleWeights(lin, -3.0f), (std::vector<float>{0.0f, 1.0f}));   // clamps
    EXPECT_EQ(assets::sampleWeights(lin, 7.0f), (std::vector<float>{1.0f, 0.0f}));
    auto step = weightsChannel(I::Step, {0.0f, 1.0f}, {0, 1, 1, 0});
    EXPECT_EQ(assets::sampleWeights(step, 0.99f), (std::vector<float>{0.0f, 1.0f}));
    EXPECT_EQ(assets::sampleWeights(step, 1.0f), (std::vector<float>{1.0f, 0.0f}));
    auto bad = weightsChannel(I::Linear, {0.0f, 1.0f}, {0, 1, 1});   // one value short
    EXPECT_TRUE(assets::sampleWeights(bad, 0.5f).empty());
}

TEST(WeightsAnimationTest, CubicSplineLayoutPerTarget) {
    // glTF layout per key: in-tangents a_1 a_2, values v_1 v_2, out-tangents b_1 b_2.
    // key 0 (t = 0): a = (0, 0)  v = (0, 1)  b = (2, 0)
    // key 1 (t = 2): a = (0, -4) v = (1, 0)  b = (0, 0)
    // At t = 1: u = 0.5, dt = 2; Hermite basis h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125.
    // Target 1: p0 = 0, m0 = b_1(0) dt = 4, p1 = 1, m1 = a_1(1) dt = 0  -> 0.5 + 0.5 = 1.0
    // Target 2: p0 = 1, m0 = 0, p1 = 0, m1 = a_2(1) dt = -8              -> 0.5 + 1.0 = 1.5
    auto ch = weightsChannel(assets::AnimationInterpolation::CubicSpline, {0.0f, 2.0f}, {0, 0, 0, 1, 2, 0, 0, -4, 1, 0, 0, 0});
    std::vector<float> w = assets::sampleWeights(ch, 1.0f);
    ASSERT_EQ(w.size(), 2u);
    EXPECT_NEAR(w[0], 1.0f, 1e-6);
    EXPECT_NEAR(w[1], 1.5f, 1e-6);
    // At the keys: the values, not the tangents.
    EXPECT_EQ(assets::sampleWeights(ch, 0.0f), (std::vector<float>{0.0f, 1.0f}));
    EXPECT_EQ(assets::sampleWeights(ch, 2.0f), (std::vector<float>{1.0f, 0.0f}));
}

TEST(WeightsAnimationTest, ApplyAnimationSetsInstanceWeights) {
    sg::Scene s;
    auto m = std::make_shared<sg::Mesh>();
    m->positions = {{0, 0, 0}};
    m->indices = {0};
    m->mode = sg::PrimitiveMode::Points;
    m->morphTargets.resize(2);
    m->morphTargets[0].positions.assign(1, sg::vec3(1, 0, 0));
    m->morphTargets[1].positions.assign(1, sg::vec3(0, 1, 0));
    s.meshes.push_back(m);
    sg::NodeId n = s.addNode("morphed", s.root(), sg::MeshInstance{0, -1});
    assets::AnimationClip clip;
    clip.channels.push_back(weightsChannel(assets::AnimationInterpolation::Linear, {0.0f, 1.0f}, {0, 1, 1, 0}));
    clip.channels[0].node = n;
    assets::applyAnimation(s, clip, 0.25f);
    EXPECT_EQ(std::get<sg::MeshInstance>(s.node(n).payload).weights, (std::vector<float>{0.25f, 0.75f}));
    EXPECT_TRUE(vecNear(sg::flatten(s, 1.0f).meshes[0].mesh->positions[0], sg::vec3(0.25f, 0.75f, 0)));
}

namespace {

// Builds a glTF with one base64 data-URI buffer; add() appends an accessor over new data.
struct GltfBuilder {
    std::string bin;
    json views = json::array(), accessors = json::array();
    template <class T>
    int add(const std::vector<T>& data, int componentType, const char* type, size_t count) {
        while (bin.size() % 4) bin.push_back('\0');
        size_t off = bin.size(), bytes = data.size() * sizeof(T);
        bin.append(reinterpret_cast<const char*>(data.data()), bytes);
        views.push_back({{"buffer", 0}, {"byteOffset", off}, {"byteLength", bytes}});
        accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", componentType}, {"count", count}, {"type", type}});
        return int(accessors.size() - 1);
    }
    int positions(const std::vector<float>& xyz) {
        int a = add(xyz, 5126, "VEC3", xyz.size() / 3);
        sg::Aabb b;
        for (size_t i = 0; i + 2 < xyz.size(); i += 3) b.extend(sg::vec3(xyz[i], xyz[i + 1], xyz[i + 2]));
        accessors[size_t(a)]["min"] = {b.min.x, b.min.y, b.min.z};
        accessors[size_t(a)]["max"] = {b.max.x, b.max.y, b.max.z};
        return a;
    }
    fs::path write(json doc, const fs::path& dir) {
        doc["buffers"] =
            json::array({{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + testing_support::base64Encode(bin)}}});
        doc["bufferViews"] = views;
        doc["accessors"] = accessors;
        fs::path p = dir / "skin_morph.gltf";
        writeText(p, doc.dump());
        return p;
    }
};

// Nodes: 0 root [1 skinned (moved to x = 10: ignored), 2 joint0 [3 joint1 at x = 1],
// 4 morphed (node weights 0.25 0.75), 5 pair (two primitives, one target each)].
// Animation 0 "walk": joint0 and joint1 turn 0 -> 180 degrees about z over 2 s (LINEAR),
// morphed's weights CUBICSPLINE (the keys of CubicSplineLayoutPerTarget).
// Animation 1 "steps": morphed's weights STEP, pair's weights LINEAR 0 -> 1 over 1 s.
fs::path writeSkinMorphGltf(const fs::path& dir) {
    GltfBuilder g;
    const int skinPos = g.positions({2, 0, 0, 1, 0, 0, 2, 1, 0});
    const int skinNrm = g.add(std::vector<float>{0, 0, 1, 1, 0, 0, 0, 0, 1}, 5126, "VEC3", 3);
    const int joints = g.add(std::vector<uint8_t>{0, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0}, 5121, "VEC4", 3);
    const int weights = g.add(std::vector<float>{0.5f, 0.5f, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0}, 5126, "VEC4", 3);
    const int ibm =
        g.add(std::vector<float>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 1}, 5126, "MAT4", 2);
    const int mPos = g.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const int mNrm = g.add(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}, 5126, "VEC3", 3);
    const int dp0 = g.add(std::vector<float>{1, 0, 0, 0, 0, 0, 0, 0, 0}, 5126, "VEC3", 3);
    const int dn0 = g.add(std::vector<float>{1, 0, -1, 0, 0, 0, 0, 0, 0}, 5126, "VEC3", 3);
    const int dp1 = g.add(std::vector<float>{0, 2, 0, 0, 0, 0, 0, 0, 0}, 5126, "VEC3", 3);
    const int t2 = g.add(std::vector<float>{0, 2}, 5126, "SCALAR", 2);
    const int rot = g.add(std::vector<float>{0, 0, 0, 1, 0, 0, 1, 0}, 5126, "VEC4", 2);   // identity -> 180 about z
    const int cubic = g.add(std::vector<float>{0, 0, 0, 1, 2, 0, 0, -4, 1, 0, 0, 0}, 5126, "SCALAR", 12);
    const int t1 = g.add(std::vector<float>{0, 1}, 5126, "SCALAR", 2);
    const int steps = g.add(std::vector<float>{0.1f, 0.2f, 0.3f, 0.4f}, 5126, "SCALAR", 4);
    const int pairW = g.add(std::vector<float>{0, 1}, 5126, "SCALAR", 2);
    json doc = {
        {"asset", {{"version", "2.0"}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes",
         {{{"name", "root"}, {"children", {1, 2, 4, 5}}},
          {{"name", "skinned"}, {"mesh", 0}, {"skin", 0}, {"translation", {10, 0, 0}}},
          {{"name", "joint0"}, {"children", {3}}},
          {{"name", "joint1"}, {"translation", {1, 0, 0}}},
          {{"name", "morphed"}, {"mesh", 1}, {"weights", {0.25, 0.75}}},
          {{"name", "pair"}, {"mesh", 2}}}},
        {"skins", {{{"name", "bones"}, {"joints", {2, 3}}, {"inverseBindMatrices", ibm}, {"skeleton", 2}}}},
        {"meshes",
         {{{"primitives", {{{"attributes", {{"POSITION", skinPos}, {"NORMAL", skinNrm}, {"JOINTS_0", joints}, {"WEIGHTS_0", weights}}}}}}},
          {{"weights", {1, 0}},
           {"primitives",
            {{{"attributes", {{"POSITION", mPos}, {"NORMAL", mNrm}}}, {"targets", {{{"POSITION", dp0}, {"NORMAL", dn0}}, {{"POSITION", dp1}}}}}}}},
          {{"primitives",
            {{{"attributes", {{"POSITION", mPos}}}, {"targets", {{{"POSITION", dp0}}}}},
             {{"attributes", {{"POSITION", mPos}}}, {"targets", {{{"POSITION", dp1}}}}}}}}}},
        {"animations",
         {{{"name", "walk"},
           {"samplers", {{{"input", t2}, {"output", rot}}, {{"input", t2}, {"output", cubic}, {"interpolation", "CUBICSPLINE"}}}},
           {"channels",
            {{{"sampler", 0}, {"target", {{"node", 2}, {"path", "rotation"}}}},
             {{"sampler", 0}, {"target", {{"node", 3}, {"path", "rotation"}}}},
             {{"sampler", 1}, {"target", {{"node", 4}, {"path", "weights"}}}}}}},
          {{"name", "steps"},
           {"samplers", {{{"input", t1}, {"output", steps}, {"interpolation", "STEP"}}, {{"input", t1}, {"output", pairW}}}},
           {"channels",
            {{{"sampler", 0}, {"target", {{"node", 4}, {"path", "weights"}}}}, {{"sampler", 1}, {"target", {{"node", 5}, {"path", "weights"}}}}}}}}}};
    return g.write(doc, dir);
}

const sg::MeshInstance& instanceOf(const sg::Scene& s, const std::string& name) {
    return std::get<sg::MeshInstance>(s.node(s.findByName(name)).payload);
}

}   // namespace

TEST(SkinMorphImportTest, GeneratedFileImportsAndPoses) {
    fs::path file = writeSkinMorphGltf(scratchDir("skin_morph_import"));
    assets::LoadResult r = assets::loadScene(file);
    ASSERT_TRUE(r.scene) << r.error;
    for (const std::string& w : r.warnings) ADD_FAILURE() << "unexpected warning: " << w;
    sg::Scene& s = *r.scene;
    // Skin: joints by node, inverse bind matrices, skeleton.
    ASSERT_EQ(s.skins.size(), 1u);
    EXPECT_EQ(s.skins[0].name, "bones");
    EXPECT_EQ(s.skins[0].joints, (std::vector<sg::NodeId>{s.findByName("joint0"), s.findByName("joint1")}));
    EXPECT_EQ(s.skins[0].inverseBind[1], glm::translate(sg::mat4(1.0f), sg::vec3(-1, 0, 0)));
    EXPECT_EQ(s.skins[0].skeleton, s.findByName("joint0"));
    const sg::MeshInstance& skinned = instanceOf(s, "skinned");
    EXPECT_EQ(skinned.skin, 0);
    const sg::Mesh& sm = *s.meshes[size_t(skinned.mesh)];
    EXPECT_EQ(sm.joints0[0], sg::u16vec4(0, 1, 0, 0));
    EXPECT_EQ(sm.weights0[2], sg::vec4(0.5f, 0.5f, 0, 0));
    // Morph targets, mesh weights (1, 0) overridden by the node's (0.25, 0.75).
    const sg::MeshInstance& morphed = instanceOf(s, "morphed");
    const sg::Mesh& mm = *s.meshes[size_t(morphed.mesh)];
    ASSERT_EQ(mm.morphTargets.size(), 2u);
    EXPECT_EQ(mm.morphWeights, (std::vector<float>{1.0f, 0.0f}));
    EXPECT_EQ(morphed.weights, (std::vector<float>{0.25f, 0.75f}));
    EXPECT_TRUE(mm.morphTargets[1].normals.empty());
    sg::MeshPtr m0 = s.posedMesh(s.findByName("morphed"));
    EXPECT_TRUE(vecNear(m0->positions[0], sg::vec3(0.25f, 1.5f, 0)));
    EXPECT_TRUE(vecNear(m0->normals[0], glm::normalize(sg::vec3(0.25f, 0, 0.75f))));   // (0,0,1) + 0.25 (1,0,-1); target 1 has no normals
    // Bind pose: the skinned vertices where the mesh has them, not at x + 10.
    EXPECT_TRUE(vecNear(s.posedMesh(s.findByName("skinned"))->positions[0], sg::vec3(2, 0, 0)));

    // Animations: "walk" at t = 1 turns both joints 90 degrees (two-bone answer of
    // DeformTest.TwoBoneSkinHalfAndHalf) and sets morphed's weights to the cubic (1, 1.5).
    ASSERT_EQ(r.animations.size(), 2u);
    EXPECT_EQ(r.animations[0].name, "walk");
    assets::applyAnimation(s, r.animations[0], 1.0f);
    sg::FrameInput f = sg::flatten(s, 1.0f);
    sg::MeshPtr posed = s.posedMesh(s.findByName("skinned"));
    EXPECT_TRUE(vecNear(posed->positions[0], sg::vec3(-0.5f, 1.5f, 0)));
    EXPECT_TRUE(vecNear(posed->positions[1], sg::vec3(0, 1, 0)));
    EXPECT_TRUE(vecNear(posed->normals[1], sg::vec3(0, 1, 0)));
    const std::vector<float>& w = instanceOf(s, "morphed").weights;
    ASSERT_EQ(w.size(), 2u);
    EXPECT_NEAR(w[0], 1.0f, 1e-5);
    EXPECT_NEAR(w[1], 1.5f, 1e-5);
    // "steps": STEP weights, and pair's LINEAR weights go to both primitive nodes.
    assets::applyAnimation(s, r.animations[1], 0.5f);
    EXPECT_EQ(instanceOf(s, "morphed").weights, (std::vector<float>{0.1f, 0.2f}));
    EXPECT_EQ(instanceOf(s, "pair#0").weights, (std::vector<float>{0.5f}));
    EXPECT_EQ(instanceOf(s, "pair#1").weights, (std::vector<float>{0.5f}));
    EXPECT_TRUE(vecNear(s.posedMesh(s.findByName("pair#1"))->positions[0], sg::vec3(0, 1, 0)));
}

TEST(SkinMorphImportTest, BrokenSkinDataIsRefusedWithTheReason) {
    fs::path dir = scratchDir("skin_morph_broken");
    fs::path good = writeSkinMorphGltf(dir);
    std::string text;
    ASSERT_EQ(assets::readFileLimited(good, 1 << 20, text), "");
    json doc = json::parse(text);
    struct Case {
        std::function<void(json&)> edit;
        std::string message;
    };
    const Case cases[] = {
        {[](json& d) { d["meshes"][0]["primitives"][0]["attributes"].erase("WEIGHTS_0"); }, "JOINTS_0 and WEIGHTS_0 must come together"},
        {[](json& d) { d["accessors"][2]["type"] = "VEC3"; }, "JOINTS_0 must be unsigned byte or short VEC4"},
        {[](json& d) {
             d["skins"][0]["joints"] = {2, 3, 99};
         },
         "skin 0: joint 99 does not exist"},
        {[](json& d) {
             d["skins"][0]["joints"] = {2, 3, 1};
         },
         "2 inverse bind matrices for 3 joints"},
        {[](json& d) { d["meshes"][1]["primitives"][0]["targets"][1]["POSITION"] = 11; }, "morph target 1 POSITION: must be VEC3"},
        {[](json& d) { d["meshes"][1]["primitives"][0]["targets"][1]["POSITION"] = 99; }, "morph target 1 POSITION: accessor 99 does not exist"},
    };
    for (const Case& c : cases) {
        json d = doc;
        c.edit(d);
        fs::path p = dir / "broken.gltf";
        writeText(p, d.dump());
        assets::LoadResult r = assets::loadScene(p);
        EXPECT_FALSE(r.scene) << c.message;
        EXPECT_NE(r.error.find(c.message), std::string::npos) << r.error;
        EXPECT_EQ(r.error.find('\n'), std::string::npos);
    }
    // Influences naming a joint the skin does not have: loaded, with a warning (ignored when posed).
    json d = doc;
    d["skins"][0]["joints"] = {2};
    fs::path p = dir / "one_joint.gltf";
    writeText(p, d.dump());
    assets::LoadResult r = assets::loadScene(p);
    ASSERT_TRUE(r.scene) << r.error;
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("names joint 1 of skin 0, which has 1 joints"), std::string::npos) << r.warnings[0];
}

namespace {
fs::path sample(const std::string& rel) { return testing_support::testdataDir() / "gltf" / rel; }

void expectNoDeformWarnings(const assets::LoadResult& r) {
    for (const std::string& w : r.warnings) {
        EXPECT_EQ(w.find("skin"), std::string::npos) << w;
        EXPECT_EQ(w.find("morph"), std::string::npos) << w;
        EXPECT_EQ(w.find("weights"), std::string::npos) << w;
    }
}
}   // namespace

TEST(SkinMorphImportTest, CesiumManWalks) {
    ASSERT_TRUE(testing_support::requireTestdata());
    for (const char* rel : {"CesiumMan/glTF/CesiumMan.gltf", "CesiumMan/glTF-Binary/CesiumMan.glb"}) {
        SCOPED_TRACE(rel);
        assets::LoadResult r = timedLoad(sample(rel), kHangGuardSeconds);
        ASSERT_TRUE(r.scene) << r.error;
        expectNoDeformWarnings(r);
        sg::Scene& s = *r.scene;
        ASSERT_EQ(s.skins.size(), 1u);
        EXPECT_EQ(s.skins[0].joints.size(), 19u);
        sg::NodeId man = sg::kNoNode;
        for (sg::NodeId id : s.depthFirstOrder())
            if (auto* mi = std::get_if<sg::MeshInstance>(&s.node(id).payload); mi && mi->skin == 0) man = id;
        ASSERT_NE(man, sg::kNoNode);
        const sg::Mesh& base = *s.meshes[size_t(std::get<sg::MeshInstance>(s.node(man).payload).mesh)];
        EXPECT_TRUE(base.skinned());
        // The bind pose as it was drawn before skinning: the mesh at its node's matrix.
        sg::Aabb bind = base.bounds().transformed(s.world(man));
        ASSERT_EQ(r.animations.size(), 1u);
        assets::applyAnimation(s, r.animations[0], 1.0f);
        sg::Aabb walk = s.nodeWorldBounds(man);
        sg::vec3 d = glm::abs(walk.min - bind.min) + glm::abs(walk.max - bind.max);
        EXPECT_GT(d.x + d.y + d.z, 0.05f) << "posed bounds equal the bind pose's";
        // A sane pose: about the figure's height (1.5 units), not a collapsed or exploded mesh.
        sg::vec3 e = walk.extent();
        EXPECT_GT(std::max({e.x, e.y, e.z}), 1.0f);
        EXPECT_LT(std::max({e.x, e.y, e.z}), 2.5f);
        // Different times, different poses; the same time, the same mesh object.
        sg::MeshPtr a = sg::flatten(s, 1.0f).meshes[0].mesh;
        EXPECT_EQ(sg::flatten(s, 1.0f).meshes[0].mesh, a);
        assets::applyAnimation(s, r.animations[0], 1.5f);
        EXPECT_NE(s.nodeWorldBounds(man).max, walk.max);
    }
}

TEST(SkinMorphImportTest, MorphSampleModels) {
    ASSERT_TRUE(testing_support::requireTestdata());
    {
        assets::LoadResult r = timedLoad(sample("AnimatedMorphCube/glTF/AnimatedMorphCube.gltf"), kHangGuardSeconds);
        ASSERT_TRUE(r.scene) << r.error;
        expectNoDeformWarnings(r);
        sg::Scene& s = *r.scene;
        ASSERT_EQ(s.meshes.size(), 1u);
        EXPECT_EQ(s.meshes[0]->morphTargets.size(), 2u);
        ASSERT_EQ(r.animations.size(), 1u);
        ASSERT_EQ(r.animations[0].channels.size(), 1u);
        EXPECT_EQ(r.animations[0].channels[0].path, assets::AnimationPath::Weights);
        sg::NodeId n = r.animations[0].channels[0].node;
        sg::Aabb rest = s.nodeWorldBounds(n);
        assets::applyAnimation(s, r.animations[0], 1.0f);   // the file's keys: about (0.68, 0) there
        const auto& w = std::get<sg::MeshInstance>(s.node(n).payload).weights;
        ASSERT_EQ(w.size(), 2u);
        EXPECT_NEAR(w[0], 0.684f, 0.01f);
        EXPECT_NEAR(w[1], 0.0f, 1e-6f);
        sg::Aabb posed = s.nodeWorldBounds(n);   // target 0 pulls one side in: one end of the box moves
        EXPECT_GT(glm::length(posed.min - rest.min) + glm::length(posed.max - rest.max), 0.1f);
    }
    {
        // SimpleMorph: mesh weights (0.5, 0.5) and no node weights: posed from the start.
        assets::LoadResult r = timedLoad(sample("SimpleMorph/glTF/SimpleMorph.gltf"), kHangGuardSeconds);
        ASSERT_TRUE(r.scene) << r.error;
        expectNoDeformWarnings(r);
        const sg::Scene& s = *r.scene;
        ASSERT_EQ(s.meshes.size(), 1u);
        EXPECT_EQ(s.meshes[0]->morphWeights, (std::vector<float>{0.5f, 0.5f}));
        sg::FrameInput f = sg::flatten(s, 1.0f);
        ASSERT_EQ(f.meshes.size(), 1u);
        EXPECT_NE(f.meshes[0].mesh, sg::MeshPtr(s.meshes[0]));
        EXPECT_NE(f.meshes[0].mesh->positions, s.meshes[0]->positions);
    }
    {
        // MorphPrimitivesTest: two primitives (child nodes), one target each, mesh weight 0.5.
        assets::LoadResult r = timedLoad(sample("MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf"), kHangGuardSeconds);
        ASSERT_TRUE(r.scene) << r.error;
        expectNoDeformWarnings(r);
        sg::FrameInput f = sg::flatten(*r.scene, 1.0f);
        ASSERT_EQ(f.meshes.size(), 2u);
        for (const sg::DrawMesh& d : f.meshes) {
            EXPECT_EQ(d.mesh->validate(), "");
            bool same = false;
            for (const auto& m : r.scene->meshes) same = same || d.mesh == sg::MeshPtr(m);
            EXPECT_FALSE(same) << "primitive drawn with its base shape";
        }
    }
}
