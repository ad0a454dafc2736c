// scenegraph_test.cpp - the Scene: world composition under edits, dirty tracking (editing a
// node recomputes exactly its subtree), re-parenting with/without keepWorld, refused cycles,
// remove/duplicate, LocalTransform conversions, a 1M-deep chain, flatten() output, settings,
// fog and the implicit shapes' value/normal.
#include "scenegraph/frame.h"
#include "scenegraph/transforms.h"

#include <gtest/gtest.h>

#include <random>

using namespace sg;

namespace {

::testing::AssertionResult matNear(const mat4& a, const mat4& b, float eps = 1e-4f) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!(std::abs(a[c][r] - b[c][r]) <= eps * (1.0f + std::abs(b[c][r]))))
                return ::testing::AssertionFailure() << "entry (row " << r << ", col " << c << "): " << a[c][r] << " vs " << b[c][r];
    return ::testing::AssertionSuccess();
}

LocalTransform trs(vec3 t, vec3 eulerDeg = vec3(0), vec3 s = vec3(1)) {
    LocalTransform lt = LocalTransform::fromTRS(t, quat(1, 0, 0, 0), s);
    lt.setEulerDegrees(eulerDeg);
    return lt;
}

// root - a - b - c
//          \ d
//      e
struct SmallTree {
    Scene s;
    NodeId a, b, c, d, e;
    SmallTree() {
        a = s.addNode("a");
        b = s.addNode("b", a);
        c = s.addNode("c", b);
        d = s.addNode("d", a);
        e = s.addNode("e");
        s.setLocal(a, trs(vec3(1, 0, 0), vec3(0, 90, 0)));
        s.setLocal(b, trs(vec3(0, 2, 0), vec3(0), vec3(2)));
        s.setLocal(c, trs(vec3(0, 0, 1)));
        s.setLocal(d, trs(vec3(0, 0, -3), vec3(30, 0, 0)));
        s.setLocal(e, trs(vec3(5, 5, 5)));
    }
};

}   // namespace

// --- world matrices ------------------------------------------------------------------------

TEST(SceneTest, RootOnly) {
    Scene s;
    EXPECT_EQ(s.nodeCount(), 1u);
    EXPECT_TRUE(s.valid(s.root()));
    EXPECT_TRUE(matNear(s.world(s.root()), mat4(1.0f)));
}

TEST(SceneTest, WorldIsParentTimesLocal) {
    SmallTree t;
    Scene& s = t.s;
    mat4 wa = s.node(t.a).local.toMatrix();
    mat4 wb = wa * s.node(t.b).local.toMatrix();
    mat4 wc = wb * s.node(t.c).local.toMatrix();
    EXPECT_TRUE(matNear(s.world(t.a), wa));
    EXPECT_TRUE(matNear(s.world(t.b), wb));
    EXPECT_TRUE(matNear(s.world(t.c), wc));
    // c's origin: a rotates +90 about y, so b's offset (0,2,0) stays, c's (0,0,1)*2 -> (2,0,0).
    EXPECT_NEAR(glm::distance(vec3(s.world(t.c)[3]), vec3(1 + 2, 2, 0)), 0.0f, 1e-5f);
    // Edit the middle: the child follows.
    s.setLocal(t.b, trs(vec3(0, 3, 0)));
    EXPECT_TRUE(matNear(s.world(t.c), s.world(t.a) * s.node(t.b).local.toMatrix() * s.node(t.c).local.toMatrix()));
    // Matrix-mode locals (shear) compose the same way.
    s.setLocalMatrix(t.b, shear(0, 1, 0.5f));
    EXPECT_TRUE(matNear(s.world(t.c), s.world(t.a) * shear(0, 1, 0.5f) * s.node(t.c).local.toMatrix()));
}

TEST(SceneTest, EditingOneNodeRecomputesExactlyItsSubtree) {
    SmallTree t;
    Scene& s = t.s;
    EXPECT_EQ(s.updateWorld(), s.nodeCount());   // first update: everything
    EXPECT_EQ(s.updateWorld(), 0u);              // nothing changed
    s.setLocal(t.c, trs(vec3(1, 1, 1)));
    EXPECT_EQ(s.updateWorld(), 1u);   // a leaf
    s.setLocal(t.a, trs(vec3(0, 1, 0)));
    EXPECT_EQ(s.updateWorld(), 4u);   // a, b, c, d
    s.setLocal(t.b, trs(vec3(0, 1, 0)));
    s.setLocal(t.c, trs(vec3(0, 1, 0)));   // nested in b's subtree: counted once
    EXPECT_EQ(s.updateWorld(), 2u);
    s.setLocal(t.d, trs(vec3(0, 1, 0)));
    s.setLocal(t.e, trs(vec3(0, 1, 0)));   // two disjoint subtrees
    EXPECT_EQ(s.updateWorld(), 2u);
    s.setLocal(s.root(), trs(vec3(0, 0, 1)));
    EXPECT_EQ(s.updateWorld(), s.nodeCount());
    // Reading world() updates lazily.
    s.setLocal(t.b, trs(vec3(7, 0, 0)));
    EXPECT_NEAR(s.world(t.c)[3].x, s.world(t.a)[3].x + (s.world(t.a) * vec4(7, 0, 0, 0)).x, 1e-4f);
    EXPECT_EQ(s.updateWorld(), 0u);
    // Structural edits recompute everything once.
    s.addNode("f", t.e);
    EXPECT_EQ(s.updateWorld(), s.nodeCount());
}

TEST(SceneTest, RandomEditsMatchBruteForce) {
    std::mt19937 rng(7);
    Scene s;
    std::vector<NodeId> ids{s.root()};
    for (int i = 0; i < 300; ++i) {
        NodeId parent = ids[rng() % ids.size()];
        ids.push_back(s.addNode("n" + std::to_string(i), parent));
    }
    std::uniform_real_distribution<float> u(-1, 1);
    auto check = [&] {
        for (NodeId id : ids) {
            mat4 w(1.0f);
            std::vector<NodeId> chain;
            for (NodeId p = id; p != kNoNode; p = s.node(p).parent) chain.push_back(p);
            for (auto it = chain.rbegin(); it != chain.rend(); ++it) w = w * s.node(*it).local.toMatrix();
            ASSERT_TRUE(matNear(s.world(id), w, 1e-3f)) << "node " << id;
        }
    };
    for (int round = 0; round < 20; ++round) {
        for (int k = 0; k < 5; ++k)
            s.setLocal(ids[rng() % ids.size()],
                       trs(vec3(u(rng), u(rng), u(rng)), vec3(90 * u(rng), 90 * u(rng), 90 * u(rng)), vec3(1 + 0.5f * u(rng))));
        check();
    }
}

// Large trees take the multi-threaded path (subtrees of >= 16k nodes run in parallel):
// random branching, a caterpillar (chain with a leaf on every link) and a root with two
// long chains all match a straightforward parent-first recomputation.
TEST(SceneTest, LargeTreesMatchSerialRecomputation) {
    for (int shape = 0; shape < 3; ++shape) {
        SCOPED_TRACE(shape);
        Scene s;
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(-1, 1);
        std::vector<NodeId> ids{s.root()};
        const int n = 70000;
        NodeId chainA = s.root(), chainB = s.root(), link = s.root();
        for (int i = 0; i < n; ++i) {
            NodeId parent;
            if (shape == 0)
                parent = ids[rng() % ids.size()];
            else if (shape == 1)
                parent = link;   // even i: a leaf on the link, odd i: the next link
            else
                parent = i % 2 ? chainA : chainB;
            NodeId id = s.addNode({}, parent);
            if (shape == 1 && i % 2 == 1) link = id;
            if (shape == 2) (i % 2 ? chainA : chainB) = id;
            LocalTransform lt = LocalTransform::fromTRS(vec3(u(rng), u(rng), u(rng)) * 1e-3f);
            lt.setEulerDegrees(vec3(u(rng), u(rng), u(rng)));
            s.setLocal(id, lt);
            ids.push_back(id);
        }
        s.setLocal(s.root(), trs(vec3(1, 2, 3), vec3(10, 20, 30)));
        EXPECT_EQ(s.updateWorld(), s.nodeCount());
        std::vector<mat4> expect(s.idCapacity());
        for (NodeId id : s.depthFirstOrder()) {
            NodeId p = s.node(id).parent;
            expect[id] = (p == kNoNode ? mat4(1.0f) : expect[p]) * s.node(id).local.toMatrix();
        }
        for (NodeId id : s.depthFirstOrder()) ASSERT_TRUE(matNear(s.world(id), expect[id], 1e-3f)) << "node " << id;
        // A second full update gives bit-identical results (no dependence on scheduling).
        std::vector<mat4> first;
        for (NodeId id : s.depthFirstOrder()) first.push_back(s.world(id));
        s.setLocal(s.root(), s.node(s.root()).local);
        EXPECT_EQ(s.updateWorld(), s.nodeCount());
        size_t k = 0;
        for (NodeId id : s.depthFirstOrder()) ASSERT_EQ(s.world(id), first[k++]);
    }
}

// --- structure -----------------------------------------------------------------------------

TEST(SceneTest, ReparentKeepWorld) {
    SmallTree t;
    Scene& s = t.s;
    mat4 before = s.world(t.c);
    std::string err;
    ASSERT_TRUE(s.reparent(t.c, t.e, true, &err)) << err;
    EXPECT_EQ(s.node(t.c).parent, t.e);
    EXPECT_TRUE(matNear(s.world(t.c), before));
    EXPECT_EQ(s.node(t.c).local.mode, LocalTransform::Mode::TRS);   // expressible as TRS
    // Without keepWorld the local stays, so the world changes.
    LocalTransform local = s.node(t.d).local;
    ASSERT_TRUE(s.reparent(t.d, t.e, false));
    EXPECT_EQ(s.node(t.d).local, local);
    EXPECT_TRUE(matNear(s.world(t.d), s.world(t.e) * local.toMatrix()));
    // Children lists are updated on both sides.
    const auto& ek = s.node(t.e).children;
    EXPECT_NE(std::find(ek.begin(), ek.end(), t.c), ek.end());
    const auto& bk = s.node(t.b).children;
    EXPECT_EQ(std::find(bk.begin(), bk.end(), t.c), bk.end());
}

TEST(SceneTest, ReparentKeepWorldUnderShearOrMirror) {
    for (const mat4& parentLocal : {shear(0, 2, 0.6f) * scaling(vec3(1, 2, 1)), mirrorX() * rotationZ(0.4f)}) {
        Scene s;
        NodeId p = s.addNode("parent");
        s.setLocalMatrix(p, translation(vec3(1, 2, 3)) * parentLocal);
        NodeId n = s.addNode("n");
        s.setLocal(n, trs(vec3(0.5f, -1, 2), vec3(20, 40, 60), vec3(1, 2, 3)));
        mat4 before = s.world(n);
        ASSERT_TRUE(s.reparent(n, p, true));
        EXPECT_TRUE(matNear(s.world(n), before));
        // A sheared parent: the new local must carry the inverse shear, which TRS cannot.
        if (parentLocal[2][0] != 0) { EXPECT_EQ(s.node(n).local.mode, LocalTransform::Mode::Matrix); }
        // Back under the root: the world still holds.
        ASSERT_TRUE(s.reparent(n, s.root(), true));
        EXPECT_TRUE(matNear(s.world(n), before));
    }
}

TEST(SceneTest, CyclesAndBadMovesAreRefused) {
    SmallTree t;
    Scene& s = t.s;
    std::string err;
    EXPECT_FALSE(s.reparent(t.a, t.c, false, &err));   // under its own descendant
    EXPECT_FALSE(err.empty());
    EXPECT_FALSE(s.reparent(t.a, t.a, false, &err));   // under itself
    EXPECT_FALSE(s.reparent(s.root(), t.e, false, &err));
    EXPECT_FALSE(s.reparent(t.a, 9999, false, &err));
    EXPECT_EQ(s.node(t.a).parent, s.root());
    EXPECT_TRUE(s.isAncestor(t.a, t.c));
    EXPECT_TRUE(s.isAncestor(t.c, t.c));
    EXPECT_FALSE(s.isAncestor(t.c, t.a));
    EXPECT_EQ(s.depthFirstOrder().size(), s.nodeCount());
}

TEST(SceneTest, RemoveAndDuplicateSubtrees) {
    SmallTree t;
    Scene& s = t.s;
    size_t n0 = s.nodeCount();
    NodeId copy = s.duplicate(t.a);
    ASSERT_TRUE(s.valid(copy));
    EXPECT_EQ(s.nodeCount(), n0 + 4);
    EXPECT_EQ(s.node(copy).parent, s.node(t.a).parent);
    EXPECT_EQ(s.node(copy).name, "a copy");
    // The copy's subtree has the same shape and the same world matrices.
    NodeId cb = s.node(copy).children.at(0);
    NodeId cc = s.node(cb).children.at(0);
    EXPECT_EQ(s.node(cc).name, "c");
    EXPECT_TRUE(matNear(s.world(cc), s.world(t.c)));
    EXPECT_NE(s.node(cc).uid, s.node(t.c).uid);
    // Editing the copy leaves the original alone.
    s.setLocal(cb, trs(vec3(9, 9, 9)));
    EXPECT_FALSE(matNear(s.world(cc), s.world(t.c)));
    // Remove the original subtree.
    EXPECT_TRUE(s.removeNode(t.a));
    EXPECT_EQ(s.nodeCount(), n0);
    EXPECT_FALSE(s.valid(t.a));
    EXPECT_FALSE(s.valid(t.c));
    EXPECT_TRUE(s.valid(cc));
    EXPECT_FALSE(s.removeNode(s.root()));
    EXPECT_FALSE(s.removeNode(t.a));                  // already gone
    EXPECT_TRUE(matNear(s.world(t.c), mat4(1.0f)));   // removed ids: identity, not a crash
    EXPECT_TRUE(matNear(s.world(123456), mat4(1.0f)));
    EXPECT_EQ(s.duplicate(s.root()), kNoNode);
    EXPECT_EQ(s.depthFirstOrder().size(), s.nodeCount());
    EXPECT_EQ(s.findByName("c"), cc);
    // Removing the active camera clears it.
    NodeId cam = s.addNode("cam", s.root(), Camera{});
    s.activeCamera = cam;
    s.removeNode(cam);
    EXPECT_EQ(s.activeCamera, kNoNode);
}

// detach / reattach (undo of a removal or an addition): the same ids, place, transforms,
// world matrices and active camera come back; refused when the parent is gone or ids are taken.
TEST(SceneTest, DetachAndReattachRestoreTheSubtreeExactly) {
    SmallTree t;
    Scene& s = t.s;
    NodeId cam = s.addNode("cam", t.b, Camera{});
    s.activeCamera = cam;
    NodeId sibling = s.addNode("sibling", s.root());
    std::vector<NodeId> order = s.depthFirstOrder();
    mat4 worldC = s.world(t.c);
    size_t n0 = s.nodeCount();
    ASSERT_EQ(s.childIndex(t.a), 0u);

    DetachedSubtree d = s.detach(t.a);
    ASSERT_EQ(d.id, t.a);
    EXPECT_EQ(d.parent, s.root());
    EXPECT_EQ(d.index, 0u);
    EXPECT_EQ(d.activeCamera, cam);
    EXPECT_EQ(d.nodes.front().first, t.a);
    EXPECT_EQ(s.nodeCount(), n0 - d.nodes.size());
    EXPECT_FALSE(s.valid(t.a));
    EXPECT_FALSE(s.valid(cam));
    EXPECT_EQ(s.activeCamera, kNoNode);
    EXPECT_TRUE(s.valid(sibling));
    EXPECT_EQ(s.depthFirstOrder().size(), s.nodeCount());

    NodeId later = s.addNode("later", s.root());   // new ids never collide with detached ones
    EXPECT_EQ(std::find_if(d.nodes.begin(), d.nodes.end(), [&](const auto& p) { return p.first == later; }), d.nodes.end());
    s.removeNode(later);

    ASSERT_TRUE(s.reattach(d));
    EXPECT_EQ(s.nodeCount(), n0);
    EXPECT_EQ(s.depthFirstOrder(), order);
    EXPECT_EQ(s.childIndex(t.a), 0u);
    EXPECT_EQ(s.activeCamera, cam);
    EXPECT_TRUE(matNear(s.world(t.c), worldC));
    EXPECT_FALSE(s.reattach(d)) << "ids already alive";

    // Reattached elsewhere (a move): under e, same ids.
    DetachedSubtree moved = s.detach(t.b);
    moved.parent = t.e;
    moved.index = 99;   // clamped to the end
    ASSERT_TRUE(s.reattach(std::move(moved)));
    EXPECT_EQ(s.node(t.b).parent, t.e);
    EXPECT_TRUE(s.isAncestor(t.e, t.c));
    EXPECT_EQ(s.depthFirstOrder().size(), s.nodeCount());

    // Refusals: nothing detached for the root or bad ids; the parent must be alive.
    EXPECT_EQ(s.detach(s.root()).id, kNoNode);
    EXPECT_EQ(s.detach(123456).id, kNoNode);
    DetachedSubtree gone = s.detach(t.c);
    s.removeNode(t.e);   // c's old parent b is below e: gone too
    EXPECT_FALSE(s.reattach(gone));
    EXPECT_FALSE(s.valid(t.c));
    EXPECT_EQ(s.depthFirstOrder().size(), s.nodeCount());
}

TEST(SceneTest, DepthFirstOrderPutsParentsFirst) {
    SmallTree t;
    const auto& order = t.s.depthFirstOrder();
    ASSERT_EQ(order.size(), 6u);
    EXPECT_EQ(order[0], t.s.root());
    std::vector<NodeId> expect{t.s.root(), t.a, t.b, t.c, t.d, t.e};
    EXPECT_EQ(order, expect);
}

// --- LocalTransform ------------------------------------------------------------------------

TEST(SceneTest, EulerQuaternionRoundTrip) {
    for (vec3 e : {vec3(10, 20, 30), vec3(-45, 80, 170), vec3(0, -30, 0), vec3(120, 10, -60), vec3(0, 0, 0)}) {
        LocalTransform lt;
        lt.setEulerDegrees(e);
        // R = Rz * Ry * Rx (X applied first).
        mat4 r = rotationZ(radians(e.z)) * rotationY(radians(e.y)) * rotationX(radians(e.x));
        EXPECT_TRUE(matNear(glm::mat4_cast(lt.rotation), r));
        vec3 back = lt.eulerDegrees();
        LocalTransform lt2;
        lt2.setEulerDegrees(back);
        EXPECT_TRUE(matNear(glm::mat4_cast(lt2.rotation), r)) << e.x << " " << e.y << " " << e.z;
        if (std::abs(e.y) < 89) { EXPECT_NEAR(glm::length(back - e), 0.0f, 1e-2f); }
    }
    // Gimbal lock: y = +-90 still reproduces the rotation.
    for (float y : {90.0f, -90.0f}) {
        LocalTransform lt;
        lt.setEulerDegrees(vec3(30, y, 20));
        LocalTransform lt2;
        lt2.setEulerDegrees(lt.eulerDegrees());
        EXPECT_TRUE(matNear(glm::mat4_cast(lt2.rotation), glm::mat4_cast(lt.rotation), 1e-3f));
    }
}

TEST(SceneTest, TryMakeTRSAcceptsTRSAndMirrorRefusesShear) {
    mat4 m = translation(vec3(1, 2, 3)) * rotationY(0.5f) * rotationX(0.2f) * scaling(vec3(2, 3, 4));
    LocalTransform lt = LocalTransform::fromMatrix(m);
    ASSERT_TRUE(lt.tryMakeTRS());
    EXPECT_EQ(lt.mode, LocalTransform::Mode::TRS);
    EXPECT_TRUE(matNear(lt.toMatrix(), m));
    EXPECT_TRUE(matNear(lt.toMatrix(), glm::translate(mat4(1.0f), vec3(1, 2, 3)) * glm::mat4_cast(lt.rotation) * glm::scale(mat4(1.0f), lt.scale)));
    // Mirror: a negative scale.
    mat4 mm = translation(vec3(0, 1, 0)) * rotationZ(0.3f) * mirrorX() * scaling(vec3(1, 2, 1));
    LocalTransform lm = LocalTransform::fromMatrix(mm);
    ASSERT_TRUE(lm.tryMakeTRS());
    EXPECT_TRUE(matNear(lm.toMatrix(), mm));
    EXPECT_LT(lm.scale.x * lm.scale.y * lm.scale.z, 0.0f);
    // Shear: refused, unchanged.
    mat4 sh = translation(vec3(1, 0, 0)) * shear(0, 2, 0.5f);
    LocalTransform ls = LocalTransform::fromMatrix(sh);
    EXPECT_FALSE(ls.tryMakeTRS());
    EXPECT_EQ(ls.mode, LocalTransform::Mode::Matrix);
    EXPECT_EQ(ls.matrix, sh);
    // Projective or singular matrices are refused too.
    mat4 proj = mat4(1.0f);
    proj[2][3] = -1;
    LocalTransform lp = LocalTransform::fromMatrix(proj);
    EXPECT_FALSE(lp.tryMakeTRS());
    LocalTransform l0 = LocalTransform::fromMatrix(scaling(vec3(1, 0, 1)));
    EXPECT_FALSE(l0.tryMakeTRS());
}

// --- a 1M-deep chain -------------------------------------------------------------------------

TEST(SceneTest, MillionDeepChain) {
    Scene s;
    const int n = 1000000;
    NodeId prev = s.root();
    for (int i = 0; i < n; ++i) {
        prev = s.addNode("", prev);
        s.setLocal(prev, LocalTransform::fromTRS(vec3(0, 1, 0)));   // integers: exact in float
    }
    EXPECT_EQ(s.updateWorld(), size_t(n) + 1);
    EXPECT_EQ(s.world(prev)[3].y, float(n));
    NodeId mid = prev;   // depth n
    for (int i = 0; i < n / 2; ++i) mid = s.node(mid).parent;
    s.setLocal(mid, LocalTransform::fromTRS(vec3(1, 1, 0)));   // depth n/2: subtree of n/2 + 1 nodes
    EXPECT_EQ(s.updateWorld(), size_t(n / 2) + 1);
    EXPECT_EQ(s.world(prev)[3].y, float(n));
    EXPECT_NEAR(s.world(prev)[3].x, 1.0f, 1e-4f);
    FrameInput f = flatten(s, 1.0f);
    EXPECT_TRUE(f.meshes.empty());
    EXPECT_TRUE(isFinite(f.camera.viewProj));
    Scene copy = s;   // copying and destroying are iterative too
    EXPECT_EQ(copy.nodeCount(), s.nodeCount());
    EXPECT_TRUE(s.removeNode(s.node(s.root()).children[0]));
    EXPECT_EQ(s.nodeCount(), 1u);
}

// --- flatten -----------------------------------------------------------------------------------

TEST(FlattenTest, LightsCamerasAndVisibility) {
    Scene s;
    s.meshes.push_back(std::make_shared<Mesh>(primitives::box(vec3(0.5f))));
    s.materials.push_back(Material{});
    s.materials[0].name = "red";
    NodeId g = s.addNode("group");
    s.setLocal(g, trs(vec3(0, 0, -2)));
    NodeId m1 = s.addNode("mesh", g, MeshInstance{0, 0});
    s.setLocalMatrix(m1, mirrorX());
    NodeId hidden = s.addNode("hidden group", g);
    s.addNode("hidden mesh", hidden, MeshInstance{0, 0});
    s.setVisible(hidden, false);
    NodeId badMesh = s.addNode("bad", g, MeshInstance{5, 0});
    (void)badMesh;
    Light spot;
    spot.type = LightType::Spot;
    spot.color = vec3(1, 0.5f, 0.25f);
    spot.intensity = 4;
    spot.inverseSquare = true;
    spot.spotInnerDeg = 10;
    spot.spotOuterDeg = 20;
    NodeId l = s.addNode("spot", g, spot);
    s.setLocal(l, trs(vec3(1, 2, 0), vec3(-90, 0, 0)));   // -z rotated by -90 about x -> -y
    NodeId dl = s.addNode("sun", s.root(), Light{LightType::Directional});
    s.setLocal(dl, trs(vec3(0), vec3(0, 90, 0)));   // -z rotated by 90 about y -> -x

    FrameInput f = flatten(s, 2.0f);
    ASSERT_EQ(f.meshes.size(), 1u);
    EXPECT_EQ(f.meshes[0].node, m1);
    EXPECT_EQ(f.meshes[0].material.name, "red");
    EXPECT_TRUE(f.meshes[0].mirrored);
    EXPECT_TRUE(matNear(f.meshes[0].world, translation(vec3(0, 0, -2)) * mirrorX()));
    EXPECT_TRUE(matNear(mat4(f.meshes[0].normal), mat4(normalMatrix(f.meshes[0].world))));
    EXPECT_EQ(f.triangleCount(), 12u);
    ASSERT_EQ(f.lights.size(), 2u);
    const DrawLight& L = f.lights[0];
    EXPECT_EQ(L.type, LightType::Spot);
    EXPECT_NEAR(glm::distance(L.position, vec3(1, 2, -2)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(L.direction, vec3(0, -1, 0)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(L.radiance, vec3(4, 2, 1)), 0.0f, 1e-5f);
    EXPECT_TRUE(L.inverseSquare);
    EXPECT_NEAR(L.cosInner, std::cos(radians(10.0f)), 1e-6f);
    EXPECT_NEAR(L.cosOuter, std::cos(radians(20.0f)), 1e-6f);
    EXPECT_NEAR(glm::distance(f.lights[1].direction, vec3(-1, 0, 0)), 0.0f, 1e-5f);
    // Attenuation off in the settings switches inverse-square off for all lights.
    s.settings.attenuation = false;
    EXPECT_FALSE(flatten(s, 2.0f).lights[0].inverseSquare);
    // Hiding a light's ancestor hides the light.
    s.setVisible(g, false);
    FrameInput f2 = flatten(s, 2.0f);
    EXPECT_TRUE(f2.meshes.empty());
    EXPECT_EQ(f2.lights.size(), 1u);

    // No camera: a default one framing the geometry, looking at it, without changing the scene.
    s.setVisible(g, true);
    size_t count = s.nodeCount();
    EXPECT_TRUE(s.cameras().empty());
    EXPECT_EQ(f.camera.aspect, 2.0f);
    EXPECT_TRUE(isFinite(f.camera.viewProj));
    vec4 c = f.camera.viewProj * vec4(0, 0, -2, 1);
    EXPECT_GT(c.w, 0.0f);
    EXPECT_LT(std::abs(c.x / c.w), 1.0f);
    EXPECT_LT(std::abs(c.y / c.w), 1.0f);
    EXPECT_EQ(s.nodeCount(), count);
    EXPECT_TRUE(matNear(f.camera.view * f.camera.viewInverse, mat4(1.0f)));

    // With a camera: its world matrix is the inverse view.
    Camera cam;
    cam.projection.fovyDeg = 60;
    NodeId cn = s.addNode("cam", s.root(), cam);
    s.lookAt(cn, vec3(0, 0, 5), vec3(0, 0, -2));
    s.activeCamera = cn;
    FrameInput f3 = flatten(s, 1.5f);
    EXPECT_TRUE(matNear(f3.camera.view, lookAt(vec3(0, 0, 5), vec3(0, 0, -2), vec3(0, 1, 0))));
    EXPECT_TRUE(matNear(f3.camera.proj, perspective(radians(60.0f), 1.5f, cam.projection.zNear, cam.projection.zFar)));
    EXPECT_TRUE(matNear(f3.camera.viewProj, f3.camera.proj * f3.camera.view));
    EXPECT_NEAR(glm::distance(f3.camera.eye, vec3(0, 0, 5)), 0.0f, 1e-5f);
    EXPECT_NEAR(std::get<Camera>(s.node(cn).payload).focusDistance, 7.0f, 1e-5f);
}

TEST(FlattenTest, CsgChildrenAreCollectedNotDrawn) {
    Scene s;
    s.materials.resize(2);
    s.materials[0].name = "body";
    s.materials[1].name = "cut";
    NodeId csg = s.addNode("csg", s.root(), CsgPayload{CsgNode{CsgOp::Difference}, 0});
    s.setLocal(csg, trs(vec3(0, 1, 0)));
    ImplicitShape box;
    box.type = ImplicitType::Box;
    box.halfExtents = vec3(1);
    NodeId b = s.addNode("box", csg, ImplicitPayload{box, -1});
    ImplicitShape sph;
    sph.radius = 0.5f;
    NodeId sp = s.addNode("sphere", csg, ImplicitPayload{sph, 1});
    s.setLocal(sp, trs(vec3(0, 1, 0)));
    ImplicitShape lone;
    s.addNode("lone sphere", s.root(), ImplicitPayload{lone, -1});

    FrameInput f = flatten(s, 1.0f);
    ASSERT_EQ(f.analytics.size(), 2u);   // the CSG and the lone sphere; not the CSG's leaves
    const DrawAnalytic* c = nullptr;
    for (const auto& a : f.analytics)
        if (a.kind == DrawAnalytic::Kind::Csg) c = &a;
    ASSERT_NE(c, nullptr);
    ASSERT_TRUE(c->csg);
    const CsgTree& t = *c->csg;
    ASSERT_GE(t.root, 0);
    EXPECT_EQ(t.nodes[t.root].op, int(CsgOp::Difference));
    ASSERT_EQ(t.nodes[t.root].children.size(), 2u);
    const CsgTree::Node& lb = t.nodes[t.nodes[t.root].children[0]];
    const CsgTree::Node& ls = t.nodes[t.nodes[t.root].children[1]];
    EXPECT_EQ(lb.material.name, "body");   // inherited from the CSG node
    EXPECT_EQ(ls.material.name, "cut");
    // Leaves in world space: the sphere's centre at (0, 2, 0).
    EXPECT_NEAR(glm::distance(vec3(ls.world[3]), vec3(0, 2, 0)), 0.0f, 1e-5f);
    EXPECT_TRUE(matNear(ls.invWorld * ls.world, mat4(1.0f)));
    EXPECT_TRUE(matNear(lb.world, s.world(b)));
    // Bounds of a difference are the first operand's.
    EXPECT_NEAR(glm::distance(c->worldBounds.min, vec3(-1, 0, -1)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(c->worldBounds.max, vec3(1, 2, 1)), 0.0f, 1e-5f);
    // The geometry key changes when a leaf moves.
    uint64_t key = c->geometryKey;
    s.setLocal(sp, trs(vec3(0, 1.2f, 0)));
    FrameInput f2 = flatten(s, 1.0f);
    for (const auto& a : f2.analytics)
        if (a.kind == DrawAnalytic::Kind::Csg) { EXPECT_NE(a.geometryKey, key); }
    // Hidden leaves drop out of the tree.
    s.setVisible(sp, false);
    FrameInput f3 = flatten(s, 1.0f);
    for (const auto& a : f3.analytics)
        if (a.kind == DrawAnalytic::Kind::Csg) {
            const CsgTree& t3 = *a.csg;
            EXPECT_EQ(t3.nodes[t3.root].children.size(), 1u);
        }
}

// --- settings, fog, shapes -----------------------------------------------------------------------

TEST(SettingsTest, AntiAliasingNamesAndValidation) {
    RenderSettings r;
    EXPECT_EQ(r.validate(), "");
    for (const char* name : {"none", "msaa2", "msaa4", "msaa8", "ssaa2", "ssaa3", "ssaa4"}) {
        ASSERT_TRUE(r.setAA(name)) << name;
        EXPECT_EQ(r.aaName(), name);
        EXPECT_EQ(r.validate(), "");
    }
    EXPECT_TRUE(r.setAA("off"));
    EXPECT_EQ(r.aa, AAMode::None);
    r.setAA("ssaa3");
    for (const char* bad : {"msaa3", "msaa", "ssaa5", "ssaa1", "msaa4x", "fxaa", ""}) {
        EXPECT_FALSE(r.setAA(bad)) << bad;
        EXPECT_EQ(r.aaName(), "ssaa3");   // unchanged
    }
    RenderSettings v;
    v.aa = AAMode::MSAA;
    v.aaRate = 3;
    EXPECT_NE(v.validate(), "");
    v = {};
    v.fog = FogMode::Linear;
    v.fogStart = 10;
    v.fogEnd = 5;
    EXPECT_NE(v.validate(), "");
    v = {};
    v.tessellation = 2;
    EXPECT_NE(v.validate(), "");
    v = {};
    v.fogDensity = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NE(v.validate(), "");
    v = {};
    v.maxBounces = -1;
    EXPECT_NE(v.validate(), "");
}

TEST(SettingsTest, FogVisibilityFormulas) {
    RenderSettings s;
    EXPECT_EQ(fogVisibility(s, 100.0f), 1.0f);   // off
    s.fog = FogMode::Linear;
    s.fogStart = 5;
    s.fogEnd = 25;
    EXPECT_FLOAT_EQ(fogVisibility(s, 5), 1.0f);
    EXPECT_FLOAT_EQ(fogVisibility(s, 15), 0.5f);   // (end - d)/(end - start)
    EXPECT_FLOAT_EQ(fogVisibility(s, 25), 0.0f);
    EXPECT_FLOAT_EQ(fogVisibility(s, 0), 1.0f);   // clamped
    EXPECT_FLOAT_EQ(fogVisibility(s, 40), 0.0f);
    s.fog = FogMode::Exp;
    s.fogDensity = 0.1f;
    EXPECT_NEAR(fogVisibility(s, 10), std::exp(-1.0f), 1e-6f);
    EXPECT_NEAR(fogVisibility(s, 0), 1.0f, 1e-6f);
    s.fog = FogMode::Exp2;
    EXPECT_NEAR(fogVisibility(s, 10), std::exp(-1.0f), 1e-6f);
    EXPECT_NEAR(fogVisibility(s, 20), std::exp(-4.0f), 1e-6f);
    FogMode m;
    EXPECT_TRUE(parse("exp2", m));
    EXPECT_EQ(m, FogMode::Exp2);
    EXPECT_FALSE(parse("haze", m));
}

TEST(ShapesTest, ImplicitValueAndNormal) {
    ImplicitShape s;
    s.type = ImplicitType::Sphere;
    s.radius = 2;
    EXPECT_FLOAT_EQ(s.value(vec3(3, 0, 0)), 1.0f);
    EXPECT_FLOAT_EQ(s.value(vec3(0, 0, 0)), -2.0f);
    EXPECT_NEAR(glm::distance(s.normal(vec3(0, 0, 2)), vec3(0, 0, 1)), 0.0f, 1e-6f);
    s.type = ImplicitType::Box;
    s.halfExtents = vec3(1, 2, 3);
    EXPECT_FLOAT_EQ(s.value(vec3(2, 0, 0)), 1.0f);
    EXPECT_FLOAT_EQ(s.value(vec3(0, 0, 0)), -1.0f);
    EXPECT_NEAR(s.value(vec3(2, 3, 0)), std::sqrt(2.0f), 1e-6f);   // corner region: Euclidean
    EXPECT_EQ(s.normal(vec3(0, 2, 0.5f)), vec3(0, 1, 0));
    EXPECT_EQ(s.normal(vec3(0, 0, -3)), vec3(0, 0, -1));
    s.type = ImplicitType::Cylinder;
    s.radius = 1;
    s.halfHeight = 2;
    EXPECT_FLOAT_EQ(s.value(vec3(0, 0, 3)), 2.0f);
    EXPECT_FLOAT_EQ(s.value(vec3(0, 2.5f, 0)), 0.5f);
    EXPECT_LT(s.value(vec3(0.5f, 1.5f, 0)), 0.0f);
    EXPECT_EQ(s.normal(vec3(0, 2, 0.2f)), vec3(0, 1, 0));
    EXPECT_NEAR(glm::distance(s.normal(vec3(1, 0.3f, 0)), vec3(1, 0, 0)), 0.0f, 1e-6f);
    s.type = ImplicitType::Cone;
    s.radius = 1;
    s.halfHeight = 1;                                      // apex at y = 1, base radius 1 at y = -1
    EXPECT_NEAR(s.value(vec3(0.5f, 0, 0)), 0.0f, 1e-6f);   // on the slanted side
    EXPECT_LT(s.value(vec3(0, 0, 0)), 0.0f);
    EXPECT_GT(s.value(vec3(0, 1.5f, 0)), 0.0f);
    vec3 cn = s.normal(vec3(0.5f, 0, 0));
    EXPECT_NEAR(glm::distance(cn, glm::normalize(vec3(2, 1, 0))), 0.0f, 1e-5f);   // radial + (r/h) y
    EXPECT_EQ(s.normal(vec3(0.2f, -1, 0)), vec3(0, -1, 0));
    s.type = ImplicitType::Torus;
    s.majorRadius = 2;
    s.minorRadius = 0.5f;
    EXPECT_NEAR(s.value(vec3(2.5f, 0, 0)), 0.0f, 1e-6f);
    EXPECT_NEAR(s.value(vec3(0, 0, 2)), -0.5f, 1e-6f);
    EXPECT_NEAR(glm::distance(s.normal(vec3(0, 0.5f, 2)), vec3(0, 1, 0)), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::distance(s.normal(vec3(-1.5f, 0, 0)), vec3(1, 0, 0)), 0.0f, 1e-6f);   // inner rim faces the hole
    s.type = ImplicitType::Plane;
    EXPECT_FLOAT_EQ(s.value(vec3(3, -2, 1)), -2.0f);
    EXPECT_EQ(s.normal(vec3(0)), vec3(0, 1, 0));
    s.type = ImplicitType::Quadric;   // default: unit sphere in [-1,1]^3
    EXPECT_LT(s.value(vec3(0.5f, 0, 0)), 0.0f);
    EXPECT_GT(s.value(vec3(0.8f, 0.8f, 0)), 0.0f);   // outside the sphere, inside the box
    EXPECT_GT(s.value(vec3(0, 0, 1.2f)), 0.0f);      // clipped by the box
    EXPECT_NEAR(s.value(vec3(1, 0, 0)), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::distance(s.normal(vec3(0, 0.6f, 0.8f)), vec3(0, 0.6f, 0.8f)), 0.0f, 1e-5f);
    // Normals agree with the numerical gradient direction away from edges.
    for (ImplicitType t : {ImplicitType::Sphere, ImplicitType::Torus, ImplicitType::Quadric}) {
        ImplicitShape q;
        q.type = t;
        vec3 p(0.3f, 0.2f, 0.7f);
        vec3 g;
        for (int a = 0; a < 3; ++a) {
            vec3 d(0.0f);
            d[a] = 1e-3f;
            g[a] = (q.value(p + d) - q.value(p - d)) / 2e-3f;
        }
        EXPECT_GT(glm::dot(glm::normalize(g), q.normal(p)), 0.999f) << toString(t);
    }
    // Bounds contain the surface.
    ImplicitShape b;
    b.type = ImplicitType::Torus;
    Aabb lb = b.localBounds();
    EXPECT_EQ(lb.max, vec3(1.25f, 0.25f, 1.25f));
}

TEST(ShapesTest, ParametricAndGrid) {
    ParametricSurface p = ParametricSurface::defaultPatch();
    EXPECT_NEAR(glm::distance(p.evaluate(0, 0), p.control[0]), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::distance(p.evaluate(1, 1), p.control[15]), 0.0f, 1e-6f);
    vec3 du, dv;
    p.partials(0.3f, 0.6f, du, dv);
    vec3 nd = (p.evaluate(0.301f, 0.6f) - p.evaluate(0.299f, 0.6f)) / 0.002f;
    EXPECT_NEAR(glm::distance(du, nd), 0.0f, 1e-2f);
    EXPECT_GT(p.normal(0.5f, 0.5f).y, 0.9f);   // the hill faces up
    ParametricSurface t;
    t.type = ParametricType::Torus;
    EXPECT_NEAR(glm::distance(t.evaluate(0, 0), vec3(0, 0, 1.3f)), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::distance(t.normal(0, 0), vec3(0, 0, 1)), 0.0f, 1e-5f);
    // The one-pass evaluate (Newton's method in the ray caster) gives evaluate()'s and
    // partials()' values bit for bit, so switching to it changes no image.
    for (const ParametricSurface& s : {p, t})
        for (float u : {0.0f, 0.13f, 0.5f, 0.77f, 1.0f})
            for (float v : {0.0f, 0.31f, 0.62f, 1.0f}) {
                vec3 pu, pv, qu, qv;
                s.partials(u, v, pu, pv);
                EXPECT_EQ(s.evaluate(u, v, qu, qv), s.evaluate(u, v));
                EXPECT_EQ(qu, pu);
                EXPECT_EQ(qv, pv);
            }
    DensityGrid g = DensityGrid::metaballs(16);
    EXPECT_EQ(g.values.size(), 16u * 16 * 16);
    EXPECT_GT(g.sample(vec3(-0.35f, -0.1f, 0)), g.isoValue);   // blob centre inside
    EXPECT_LT(g.sample(vec3(0.95f, 0.95f, 0.95f)), g.isoValue);
    EXPECT_FLOAT_EQ(g.sample(g.bounds.min), g.at(0, 0, 0));
    EXPECT_FLOAT_EQ(g.sample(g.bounds.max), g.at(15, 15, 15));
}
