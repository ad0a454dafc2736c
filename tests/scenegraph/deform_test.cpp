// deform_test.cpp - skins and morph targets against answers worked out by hand
// (scenegraph/deform.h, docs/math.md "Skinning and morph targets"): a two-bone skin with a
// vertex weighted 0.5/0.5, morph weights 0.25/0.75 on positions, normals and tangents, node
// weights overriding mesh weights, and what flatten() and the pose cache make of them (world
// space draws, one evaluation per pose, a stable Mesh::id, posed bounds).
#include "scenegraph/deform.h"
#include "scenegraph/frame.h"

#include <gtest/gtest.h>

using namespace sg;

namespace {

::testing::AssertionResult vecNear(const vec3& a, const vec3& b, float eps = 1e-5f) {
    if (glm::all(glm::lessThanEqual(glm::abs(a - b), vec3(eps)))) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << ") vs expected (" << b.x << ", " << b.y << ", " << b.z << ")";
}

quat rotZ(float deg) { return glm::angleAxis(radians(deg), vec3(0, 0, 1)); }

// Two bones along x: joint 0 at the origin, joint 1 (its child) at x = 1, both bound with the
// identity rotation (inverse bind matrices I and T(-1, 0, 0)). The mesh node sits under a
// parent moved to x = 10 (a skinned mesh ignores its node's transform). Vertices:
//   0: (2, 0, 0) weights 0.5 / 0.5 on joints 0 / 1, normal +z
//   1: (1, 0, 0) weight 1 on joint 0, normal +x
//   2: (2, 1, 0) weight 0.5 on joint 0 in set 0 and 0.5 on joint 1 in set 1 (JOINTS_1)
struct TwoBones {
    Scene s;
    NodeId j0, j1, meshNode;
    TwoBones() {
        auto m = std::make_shared<Mesh>();
        m->positions = {{2, 0, 0}, {1, 0, 0}, {2, 1, 0}};
        m->normals = {{0, 0, 1}, {1, 0, 0}, {0, 0, 1}};
        m->indices = {0, 1, 2};
        m->joints0 = {u16vec4(0, 1, 0, 0), u16vec4(0, 0, 0, 0), u16vec4(0, 0, 0, 0)};
        m->weights0 = {vec4(0.5f, 0.5f, 0, 0), vec4(1, 0, 0, 0), vec4(0.5f, 0, 0, 0)};
        m->joints1 = {u16vec4(0), u16vec4(0), u16vec4(1, 0, 0, 0)};
        m->weights1 = {vec4(0), vec4(0), vec4(0.5f, 0, 0, 0)};
        s.meshes.push_back(m);
        j0 = s.addNode("joint 0");
        j1 = s.addNode("joint 1", j0);
        s.setLocal(j1, LocalTransform::fromTRS(vec3(1, 0, 0)));
        Skin skin;
        skin.joints = {j0, j1};
        skin.inverseBind = {mat4(1.0f), glm::translate(mat4(1.0f), vec3(-1, 0, 0))};
        s.skins.push_back(skin);
        NodeId parent = s.addNode("moved parent");
        s.setLocal(parent, LocalTransform::fromTRS(vec3(10, 0, 0)));
        MeshInstance mi{0, -1};
        mi.skin = 0;
        meshNode = s.addNode("skinned", parent, mi);
    }
    // Both joints turned 90 degrees about z: world0 = Rz90, world1 = Rz90 T(1,0,0) Rz90.
    void pose() {
        s.setLocal(j0, LocalTransform::fromTRS(vec3(0), rotZ(90)));
        s.setLocal(j1, LocalTransform::fromTRS(vec3(1, 0, 0), rotZ(90)));
    }
};

}   // namespace

TEST(DeformTest, TwoBoneSkinHalfAndHalf) {
    TwoBones t;
    // Bind pose: J_i = I, so the vertices stay where the mesh has them (not at x + 10).
    bool worldSpace = false;
    MeshPtr bind = t.s.posedMesh(t.meshNode, &worldSpace);
    ASSERT_TRUE(bind);
    EXPECT_TRUE(worldSpace);
    EXPECT_TRUE(vecNear(bind->positions[0], vec3(2, 0, 0)));

    t.pose();
    MeshPtr posed = t.s.posedMesh(t.meshNode);
    ASSERT_TRUE(posed);
    // Vertex 0: J0 (2,0,0) = (0,2,0); J1 (2,0,0) = Rz90 T(1,0,0) Rz90 (1,0,0) = (-1,1,0); half each.
    EXPECT_TRUE(vecNear(posed->positions[0], vec3(-0.5f, 1.5f, 0)));
    EXPECT_TRUE(vecNear(posed->normals[0], vec3(0, 0, 1)));
    // Vertex 1 follows joint 0 alone: (1,0,0) -> (0,1,0), normal +x -> +y.
    EXPECT_TRUE(vecNear(posed->positions[1], vec3(0, 1, 0)));
    EXPECT_TRUE(vecNear(posed->normals[1], vec3(0, 1, 0)));
    // Vertex 2, influences split over JOINTS_0 and JOINTS_1: J0 (2,1,0) = (-1,2,0);
    // J1 (2,1,0) = Rz90 T(1,0,0) Rz90 (1,1,0) = Rz90 (0,1,0) = (-1,0,0). Half each: (-1, 1, 0).
    EXPECT_TRUE(vecNear(posed->positions[2], vec3(-1, 1, 0)));
    EXPECT_EQ(posed->indices, bind->indices);
    EXPECT_TRUE(posed->joints0.empty() && posed->morphTargets.empty());   // a plain mesh
}

TEST(DeformTest, SkinWeightsAreNormalisedAndBadJointsIgnored) {
    Mesh m;
    m.positions = {{2, 0, 0}};
    m.joints0 = {u16vec4(0, 1, 7, 0)};             // joint 7 does not exist: ignored
    m.weights0 = {vec4(2.0f, 2.0f, 5.0f, 0.0f)};   // 2 + 2 after dropping it: half each
    mat4 j0 = glm::mat4_cast(rotZ(90));
    mat4 j1 = glm::translate(mat4(1.0f), vec3(0, 0, 4));
    Mesh out = deformMesh(m, {}, {j0, j1});
    EXPECT_TRUE(vecNear(out.positions[0], 0.5f * vec3(0, 2, 0) + 0.5f * vec3(2, 0, 4)));
    m.weights0 = {vec4(0.0f)};   // no weight left: the vertex stays put
    EXPECT_TRUE(vecNear(deformMesh(m, {}, {j0, j1}).positions[0], vec3(2, 0, 0)));
}

TEST(DeformTest, FlattenDrawsSkinnedMeshesInWorldSpace) {
    TwoBones t;
    t.pose();
    FrameInput f = flatten(t.s, 1.0f);
    ASSERT_EQ(f.meshes.size(), 1u);
    EXPECT_EQ(f.meshes[0].world, mat4(1.0f));   // not the parent's T(10, 0, 0)
    EXPECT_FALSE(f.meshes[0].mirrored);
    EXPECT_TRUE(vecNear(f.meshes[0].mesh->positions[0], vec3(-0.5f, 1.5f, 0)));
    // Framing and bounds use the posed vertices: around the origin, not around x = 10.
    Aabb b = t.s.worldBounds();
    EXPECT_TRUE(vecNear(b.min, vec3(-1, 1, 0)));
    EXPECT_TRUE(vecNear(b.max, vec3(0, 1.5f, 0)));
    EXPECT_TRUE(vecNear(t.s.nodeWorldBounds(t.meshNode).max, b.max));
}

TEST(DeformTest, PoseCacheComputesOncePerPoseAndKeepsTheMeshId) {
    TwoBones t;
    t.pose();
    FrameInput a = flatten(t.s, 1.0f);
    const uint64_t evals = t.s.poseEvaluations();
    FrameInput b = flatten(t.s, 1.0f);   // still pose: the same object, nothing recomputed
    EXPECT_EQ(a.meshes[0].mesh, b.meshes[0].mesh);
    EXPECT_EQ(t.s.poseEvaluations(), evals);
    // Moving a node that is no joint changes nothing either (skinned: world space already).
    t.s.setLocal(t.s.node(t.meshNode).parent, LocalTransform::fromTRS(vec3(-3, 0, 0)));
    EXPECT_EQ(flatten(t.s, 1.0f).meshes[0].mesh, a.meshes[0].mesh);
    // A new pose: a new object with the same id and the next version (backend caches replace
    // their entry), while the old frame's mesh is untouched.
    t.s.setLocal(t.j1, LocalTransform::fromTRS(vec3(1, 0, 0)));
    FrameInput c = flatten(t.s, 1.0f);
    EXPECT_NE(c.meshes[0].mesh, a.meshes[0].mesh);
    EXPECT_EQ(c.meshes[0].mesh->id, a.meshes[0].mesh->id);
    EXPECT_EQ(c.meshes[0].mesh->version, a.meshes[0].mesh->version + 1);
    EXPECT_EQ(t.s.poseEvaluations(), evals + 1);
    EXPECT_TRUE(vecNear(a.meshes[0].mesh->positions[0], vec3(-0.5f, 1.5f, 0)));
    // Editing the base mesh (touch) is a new pose too.
    t.s.meshes[0]->positions[1] = vec3(3, 0, 0);
    t.s.meshes[0]->touch();
    EXPECT_TRUE(vecNear(flatten(t.s, 1.0f).meshes[0].mesh->positions[1], vec3(0, 3, 0)));
    // A copy of the scene starts with its own cache.
    Scene copy = t.s;
    EXPECT_EQ(copy.poseEvaluations(), 0u);
    EXPECT_TRUE(vecNear(flatten(copy, 1.0f).meshes[0].mesh->positions[1], vec3(0, 3, 0)));
}

namespace {
// One vertex at the origin with normal +z and tangent +x (w = -1), two morph targets.
std::shared_ptr<Mesh> morphMesh() {
    auto m = std::make_shared<Mesh>();
    m->positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m->normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    m->tangents = {{1, 0, 0, -1}, {1, 0, 0, -1}, {1, 0, 0, -1}};
    m->indices = {0, 1, 2};
    MorphTarget a, b;
    a.positions = {{1, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    a.normals = {{1, 0, -1}, {0, 0, 0}, {0, 0, 0}};
    a.tangents = {{0, 1, 0}, {0, 0, 0}, {0, 0, 0}};
    b.positions = {{0, 2, 0}, {0, 0, 0}, {0, 0, 0}};
    b.normals = {{0, 1, -1}, {0, 0, 0}, {0, 0, 0}};
    m->morphTargets = {a, b};
    return m;
}
}   // namespace

TEST(DeformTest, MorphWeightsQuarterAndThreeQuarters) {
    auto m = morphMesh();
    EXPECT_EQ(m->validate(), "");
    Mesh out = deformMesh(*m, {0.25f, 0.75f}, {});
    // p = 0.25 (1,0,0) + 0.75 (0,2,0); n = normalize((0,0,1) + 0.25 (1,0,-1) + 0.75 (0,1,-1)).
    EXPECT_TRUE(vecNear(out.positions[0], vec3(0.25f, 1.5f, 0)));
    EXPECT_TRUE(vecNear(out.normals[0], glm::normalize(vec3(0.25f, 0.75f, 0))));
    EXPECT_TRUE(vecNear(vec3(out.tangents[0]), glm::normalize(vec3(1, 0.25f, 0))));
    EXPECT_EQ(out.tangents[0].w, -1.0f);
    EXPECT_TRUE(vecNear(out.positions[1], vec3(1, 0, 0)));
    EXPECT_TRUE(vecNear(out.normals[1], vec3(0, 0, 1)));
}

TEST(DeformTest, NodeWeightsOverrideMeshWeights) {
    Scene s;
    auto m = morphMesh();
    m->morphWeights = {1.0f, 0.0f};
    s.meshes.push_back(m);
    NodeId meshWeights = s.addNode("mesh weights", s.root(), MeshInstance{0, -1});
    MeshInstance own{0, -1};
    own.weights = {0.25f, 0.75f};
    NodeId nodeWeights = s.addNode("node weights", s.root(), own);
    MeshInstance shortW{0, -1};
    shortW.weights = {0.5f};   // the missing second weight is 0, not the mesh's
    NodeId partial = s.addNode("partial", s.root(), shortW);
    EXPECT_EQ(instanceMorphWeights(*m, own), (std::vector<float>{0.25f, 0.75f}));
    EXPECT_TRUE(vecNear(s.posedMesh(meshWeights)->positions[0], vec3(1, 0, 0)));
    EXPECT_TRUE(vecNear(s.posedMesh(nodeWeights)->positions[0], vec3(0.25f, 1.5f, 0)));
    EXPECT_TRUE(vecNear(s.posedMesh(partial)->positions[0], vec3(0.5f, 0, 0)));
    // Morphed meshes stay in object space: flatten draws them with the node's matrix.
    s.setLocal(nodeWeights, LocalTransform::fromTRS(vec3(0, 0, 5)));
    bool worldSpace = true;
    s.posedMesh(nodeWeights, &worldSpace);
    EXPECT_FALSE(worldSpace);
    FrameInput f = flatten(s, 1.0f);
    ASSERT_EQ(f.meshes.size(), 3u);
    EXPECT_EQ(f.meshes[1].world, glm::translate(mat4(1.0f), vec3(0, 0, 5)));
    // All weights zero: the scene's own mesh, no copy.
    MeshInstance zero{0, -1};
    zero.weights = {0.0f, 0.0f};
    NodeId z = s.addNode("zero", s.root(), zero);
    EXPECT_EQ(s.posedMesh(z), MeshPtr(s.meshes[0]));
}

TEST(DeformTest, MorphThenSkin) {
    // glTF order: the morphed position is skinned. Target moves the vertex from (1,0,0) to
    // (2,0,0); joint 0 is turned 90 degrees: (0, 2, 0).
    Scene s;
    auto m = std::make_shared<Mesh>();
    m->positions = {{1, 0, 0}};
    m->indices = {0};
    m->mode = PrimitiveMode::Points;
    m->joints0 = {u16vec4(0)};
    m->weights0 = {vec4(1, 0, 0, 0)};
    MorphTarget t;
    t.positions = {{1, 0, 0}};
    m->morphTargets = {t};
    m->morphWeights = {1.0f};
    s.meshes.push_back(m);
    NodeId j = s.addNode("joint");
    s.setLocal(j, LocalTransform::fromTRS(vec3(0), rotZ(90)));
    s.skins.push_back(Skin{"skin", {j}, {mat4(1.0f)}, kNoNode});
    MeshInstance mi{0, -1};
    mi.skin = 0;
    NodeId n = s.addNode("both", s.root(), mi);
    EXPECT_TRUE(vecNear(s.posedMesh(n)->positions[0], vec3(0, 2, 0)));
    // A removed joint poses as the identity.
    s.removeNode(j);
    EXPECT_TRUE(vecNear(s.posedMesh(n)->positions[0], vec3(2, 0, 0)));
}

TEST(DeformTest, ValidateChecksSkinAndMorphData) {
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}};
    m.indices = {0, 1};
    m.mode = PrimitiveMode::Lines;
    EXPECT_EQ(m.validate(), "");
    m.joints0 = {u16vec4(0)};
    EXPECT_NE(m.validate(), "");   // count differs
    m.joints0 = {u16vec4(0), u16vec4(0)};
    EXPECT_NE(m.validate(), "");   // joints without weights
    m.weights0 = {vec4(1, 0, 0, 0), vec4(-1, 0, 0, 0)};
    EXPECT_NE(m.validate(), "");   // negative weight
    m.weights0[1] = vec4(1, 0, 0, 0);
    EXPECT_EQ(m.validate(), "");
    m.morphTargets.resize(1);
    m.morphTargets[0].positions = {vec3(0)};
    EXPECT_NE(m.validate(), "");
    m.morphTargets[0].positions = {vec3(0), vec3(std::nanf(""))};
    EXPECT_NE(m.validate(), "");
    m.morphTargets[0].positions = {vec3(0), vec3(1)};
    m.morphWeights = {0.5f, 0.5f};
    EXPECT_NE(m.validate(), "");   // two weights, one target
    m.morphWeights = {0.5f};
    EXPECT_EQ(m.validate(), "");
    m.tangents = {vec4(1, 0, 0, 1)};
    EXPECT_NE(m.validate(), "");
}
