// raycast_test.cpp - RaycastTest: exact analytic hits (distance + normal), CSG carved faces,
// parametric and grid surfaces, BVH4 closest hit == brute force on random soups, primary rays
// lining up with FrameCamera::viewProj for all projections, and the renderer's contract
// (progress, cancellation, BLAS caching across transform edits).
#include "raycast/analytic.h"
#include "raycast/bvh.h"
#include "raycast/camera_rays.h"
#include "raycast/scene_accel.h"
#include "renderers/inspect.h"
#include "renderers/renderer.h"
#include "renderers/shading.h"
#include "scenegraph/frame.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <set>

using namespace sg;
using namespace rnd;
using namespace rnd::rt;

namespace {

Ray mkRay(vec3 o, vec3 d) {
    Ray r;
    r.org = o;
    r.dir = d;
    r.tmin = 0;
    r.tmax = std::numeric_limits<float>::infinity();
    return r;
}

// Closest hit on an implicit shape in its local frame: t and outward normal.
bool hitImplicit(const ImplicitShape& s, const Ray& r, float& t, vec3& n) {
    SpanList l;
    implicitSpans(s, r, l);
    Bound b;
    if (!firstBoundary(l, r.tmin, r.tmax, b)) return false;
    t = b.t;
    n = implicitNormal(s, r.org + t * r.dir, b.tag);
    return true;
}

void expectVec(const vec3& a, const vec3& b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

}   // namespace

// --- implicit shapes ---------------------------------------------------------------------------

TEST(RaycastTest, SphereHitDistanceAndNormal) {
    ImplicitShape s;
    s.type = ImplicitType::Sphere;
    s.radius = 1.5f;
    float t;
    vec3 n;
    ASSERT_TRUE(hitImplicit(s, mkRay({0, 0, 5}, {0, 0, -1}), t, n));
    EXPECT_NEAR(t, 3.5f, 1e-5f);
    expectVec(n, {0, 0, 1}, 1e-5f);
    // From inside: the exit point.
    ASSERT_TRUE(hitImplicit(s, mkRay({0, 0, 0}, {1, 0, 0}), t, n));
    EXPECT_NEAR(t, 1.5f, 1e-5f);
    // Miss.
    EXPECT_FALSE(hitImplicit(s, mkRay({0, 2, 5}, {0, 0, -1}), t, n));
    // Off-centre: hit point lies on the sphere, normal = p / r.
    Ray r = mkRay({0.3f, 0.7f, 5}, {0, 0, -2});
    ASSERT_TRUE(hitImplicit(s, r, t, n));
    vec3 p = r.org + t * r.dir;
    EXPECT_NEAR(glm::length(p), 1.5f, 1e-5f);
    expectVec(n, p / 1.5f, 1e-5f);
}

TEST(RaycastTest, QuadricSphereAndEllipsoid) {
    ImplicitShape q;
    q.type = ImplicitType::Quadric;   // default: x^2 + y^2 + z^2 - 1
    q.quadricBounds = {vec3(-2), vec3(2)};
    float t;
    vec3 n;
    ASSERT_TRUE(hitImplicit(q, mkRay({0, 0, 5}, {0, 0, -1}), t, n));
    EXPECT_NEAR(t, 4.0f, 1e-5f);
    expectVec(n, {0, 0, 1}, 1e-5f);
    // Ellipsoid x^2/4 + y^2 + z^2 = 1: semi-axis 2 along x.
    q.quadric = mat4(1.0f);
    q.quadric[0][0] = 0.25f;
    q.quadric[3][3] = -1.0f;
    q.quadricBounds = {vec3(-3), vec3(3)};
    ASSERT_TRUE(hitImplicit(q, mkRay({5, 0, 0}, {-1, 0, 0}), t, n));
    EXPECT_NEAR(t, 3.0f, 1e-5f);
    expectVec(n, {1, 0, 0}, 1e-5f);
    // Oblique ray: the normal is the normalised gradient (x/2, 2y, 2z) direction.
    Ray r = mkRay({1, 0.5f, 5}, {0, 0, -1});
    ASSERT_TRUE(hitImplicit(q, r, t, n));
    vec3 p = r.org + t * r.dir;
    EXPECT_NEAR(p.x * p.x / 4 + p.y * p.y + p.z * p.z, 1.0f, 1e-5f);
    expectVec(n, glm::normalize(vec3(p.x / 4, p.y, p.z)), 1e-5f);
    // Clipped by quadricBounds: a cylinder x^2 + z^2 = 1 (infinite in y) capped by the box.
    ImplicitShape cyl;
    cyl.type = ImplicitType::Quadric;
    cyl.quadric = mat4(1.0f);
    cyl.quadric[1][1] = 0.0f;
    cyl.quadric[3][3] = -1.0f;
    cyl.quadricBounds = {vec3(-2, -1, -2), vec3(2, 1, 2)};
    ASSERT_TRUE(hitImplicit(cyl, mkRay({0, 5, 0}, {0, -1, 0}), t, n));
    EXPECT_NEAR(t, 4.0f, 1e-5f);   // the box's top face y = 1
    expectVec(n, {0, 1, 0}, 1e-5f);
}

TEST(RaycastTest, TorusIncludingHoleAndGrazing) {
    ImplicitShape s;
    s.type = ImplicitType::Torus;
    s.majorRadius = 1.0f;
    s.minorRadius = 0.25f;
    float t;
    vec3 n;
    // Along x through the middle: four crossings, first at x = -1.25.
    ASSERT_TRUE(hitImplicit(s, mkRay({-5, 0, 0}, {1, 0, 0}), t, n));
    EXPECT_NEAR(t, 3.75f, 1e-4f);
    expectVec(n, {-1, 0, 0}, 1e-4f);
    SpanList l;
    implicitSpans(s, mkRay({-5, 0, 0}, {1, 0, 0}), l);
    ASSERT_EQ(l.n, 2);
    EXPECT_NEAR(l.s[0].out.t, 4.25f, 1e-4f);
    EXPECT_NEAR(l.s[1].in.t, 5.75f, 1e-4f);
    EXPECT_NEAR(l.s[1].out.t, 6.25f, 1e-4f);
    // Straight down through the hole: no hit.
    EXPECT_FALSE(hitImplicit(s, mkRay({0, 5, 0}, {0, -1, 0}), t, n));
    // Down onto the top of the tube.
    ASSERT_TRUE(hitImplicit(s, mkRay({1, 5, 0}, {0, -1, 0}), t, n));
    EXPECT_NEAR(t, 4.75f, 1e-4f);
    expectVec(n, {0, 1, 0}, 1e-4f);
    // From the centre of the hole outward: the inner wall at x = 0.75, normal toward the axis.
    ASSERT_TRUE(hitImplicit(s, mkRay({0, 0, 0}, {1, 0, 0}), t, n));
    EXPECT_NEAR(t, 0.75f, 1e-4f);
    expectVec(n, {-1, 0, 0}, 1e-4f);
    // Grazing the top at height y = 0.249: hits near x = -1 - sqrt(r^2 - y^2).
    float y = 0.249f;
    ASSERT_TRUE(hitImplicit(s, mkRay({-5, y, 0}, {1, 0, 0}), t, n));
    EXPECT_NEAR(-5 + t, -1.0f - std::sqrt(0.0625f - y * y), 2e-3f);
    // Just above: miss.
    EXPECT_FALSE(hitImplicit(s, mkRay({-5, 0.2501f, 0}, {1, 0, 0}), t, n));
    // Random rays: every reported hit lies on the surface.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> U(-1, 1);
    int hits = 0;
    for (int i = 0; i < 500; ++i) {
        vec3 o(U(rng) * 4, U(rng) * 4, U(rng) * 4);
        vec3 target(U(rng) * 1.3f, U(rng) * 0.3f, U(rng) * 1.3f);
        Ray r = mkRay(o, target - o);
        if (!hitImplicit(s, r, t, n)) continue;
        ++hits;
        EXPECT_NEAR(s.value(r.org + t * r.dir), 0.0f, 1e-3f);
    }
    EXPECT_GT(hits, 100);
}

TEST(RaycastTest, BoxCylinderConePlane) {
    float t;
    vec3 n;
    ImplicitShape box;
    box.type = ImplicitType::Box;
    box.halfExtents = vec3(0.5f, 1.0f, 2.0f);
    ASSERT_TRUE(hitImplicit(box, mkRay({-5, 0.1f, 0.2f}, {1, 0, 0}), t, n));
    EXPECT_NEAR(t, 4.5f, 1e-5f);
    expectVec(n, {-1, 0, 0}, 0);
    ASSERT_TRUE(hitImplicit(box, mkRay({0, 0, 9}, {0, 0, -1}), t, n));
    EXPECT_NEAR(t, 7.0f, 1e-5f);
    expectVec(n, {0, 0, 1}, 0);

    ImplicitShape cyl;
    cyl.type = ImplicitType::Cylinder;
    cyl.radius = 0.5f;
    cyl.halfHeight = 0.5f;
    ASSERT_TRUE(hitImplicit(cyl, mkRay({0, 0, -5}, {0, 0, 1}), t, n));
    EXPECT_NEAR(t, 4.5f, 1e-5f);
    expectVec(n, {0, 0, -1}, 1e-5f);
    ASSERT_TRUE(hitImplicit(cyl, mkRay({0.2f, 5, 0}, {0, -1, 0}), t, n));
    EXPECT_NEAR(t, 4.5f, 1e-5f);   // top cap
    expectVec(n, {0, 1, 0}, 0);
    EXPECT_FALSE(hitImplicit(cyl, mkRay({0.6f, 5, 0}, {0, -1, 0}), t, n));

    ImplicitShape cone;
    cone.type = ImplicitType::Cone;
    cone.radius = 0.5f;
    cone.halfHeight = 0.5f;   // apex at y = 0.5, base radius 0.5 at y = -0.5
    ASSERT_TRUE(hitImplicit(cone, mkRay({-5, 0, 0}, {1, 0, 0}), t, n));
    EXPECT_NEAR(t, 4.75f, 1e-5f);   // radius 0.25 at y = 0
    expectVec(n, glm::normalize(vec3(-1, 0.5f, 0)), 1e-5f);
    ASSERT_TRUE(hitImplicit(cone, mkRay({0.1f, -5, 0}, {0, 1, 0}), t, n));
    EXPECT_NEAR(t, 4.5f, 1e-5f);   // base cap
    expectVec(n, {0, -1, 0}, 0);
    EXPECT_FALSE(hitImplicit(cone, mkRay({-5, 0.6f, 0}, {1, 0, 0}), t, n));   // above the apex: the other nappe is clipped

    ImplicitShape plane;
    plane.type = ImplicitType::Plane;
    ASSERT_TRUE(hitImplicit(plane, mkRay({3, 5, -2}, {0, -1, 0}), t, n));
    EXPECT_NEAR(t, 5.0f, 1e-5f);
    expectVec(n, {0, 1, 0}, 0);
    ASSERT_TRUE(hitImplicit(plane, mkRay({3, -2, -2}, {0, 1, 0}), t, n));   // from below
    EXPECT_NEAR(t, 2.0f, 1e-5f);
    EXPECT_FALSE(hitImplicit(plane, mkRay({3, 2, -2}, {1, 0, 0}), t, n));
}

TEST(RaycastTest, PolyRootsQuartic) {
    // (t-1)(t-2)(t-3)(t-4) = t^4 - 10t^3 + 35t^2 - 50t + 24
    double c[5] = {24, -50, 35, -10, 1}, r[4];
    ASSERT_EQ(polyRoots(c, 4, 0, 10, r), 4);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(r[i], i + 1, 1e-9);
    EXPECT_EQ(polyRoots(c, 4, 1.5, 3.5, r), 2);
}

// --- CSG ---------------------------------------------------------------------------------------

namespace {
// An implicit sphere of radius r centred at c.
DrawAnalytic implicitSphere(float r, const vec3& c) {
    DrawAnalytic s;
    s.kind = DrawAnalytic::Kind::Implicit;
    s.implicit.type = ImplicitType::Sphere;
    s.implicit.radius = r;
    s.world = glm::translate(mat4(1.0f), c);
    s.invWorld = glm::inverse(s.world);
    s.normal = normalMatrix(s.world);
    s.worldBounds = s.implicit.localBounds().transformed(s.world);
    return s;
}

FrameInput csgFrame(CsgOp op) {
    auto tree = std::make_shared<CsgTree>();
    CsgTree::Node a, b, root;
    a.shape.type = ImplicitType::Box;
    a.shape.halfExtents = vec3(1.0f);
    a.material.name = "box";
    a.material.baseColor = vec3(1, 0, 0);
    b.shape.type = ImplicitType::Sphere;
    b.shape.radius = 0.6f;
    b.world = glm::translate(mat4(1.0f), vec3(1, 0, 0));
    b.invWorld = glm::inverse(b.world);
    b.normal = normalMatrix(b.world);
    b.material.name = "cutter";
    b.material.baseColor = vec3(0, 0, 1);
    root.op = int(op);
    root.children = {0, 1};
    tree->nodes = {a, b, root};
    tree->root = 2;
    FrameInput f;
    DrawAnalytic d;
    d.kind = DrawAnalytic::Kind::Csg;
    d.csg = tree;
    d.worldBounds = {vec3(-1), vec3(1.6f)};
    f.analytics.push_back(d);
    return f;
}
}   // namespace

TEST(RaycastTest, CsgDifferenceShowsCarvedFace) {
    FrameInput f = csgFrame(CsgOp::Difference);
    SceneAccel acc;
    acc.update(f);
    SceneHit h;
    // Through the carved pocket: the sphere's inner surface at x = 0.4, normal flipped (+x),
    // the cutter's material.
    ASSERT_TRUE(acc.intersect(mkRay({5, 0, 0}, {-1, 0, 0}), h));
    EXPECT_NEAR(h.t, 4.6f, 1e-4f);
    expectVec(h.normal, {1, 0, 0}, 1e-4f);
    ASSERT_GE(h.csgLeaf, 0);
    EXPECT_EQ(f.analytics[0].csg->nodes[size_t(h.csgLeaf)].material.name, "cutter");
    // Beside the pocket: the box face x = 1 with the box material.
    ASSERT_TRUE(acc.intersect(mkRay({5, 0.8f, 0.8f}, {-1, 0, 0}), h));
    EXPECT_NEAR(h.t, 4.0f, 1e-4f);
    expectVec(h.normal, {1, 0, 0}, 1e-4f);
    EXPECT_EQ(f.analytics[0].csg->nodes[size_t(h.csgLeaf)].material.name, "box");
    // Oblique ray into the pocket: lands on the sphere, normal points to the sphere centre.
    Ray r = mkRay({5, 0.2f, 0.1f}, {-1, 0, 0});
    ASSERT_TRUE(acc.intersect(r, h));
    vec3 p = r.org + h.t * r.dir;
    EXPECT_NEAR(glm::length(p - vec3(1, 0, 0)), 0.6f, 1e-4f);
    expectVec(h.normal, glm::normalize(vec3(1, 0, 0) - p), 1e-4f);
}

TEST(RaycastTest, CsgUnionAndIntersection) {
    SceneHit h;
    FrameInput u = csgFrame(CsgOp::Union);
    SceneAccel a1;
    a1.update(u);
    ASSERT_TRUE(a1.intersect(mkRay({5, 0, 0}, {-1, 0, 0}), h));
    EXPECT_NEAR(h.t, 3.4f, 1e-4f);   // sphere pokes out to x = 1.6
    FrameInput in = csgFrame(CsgOp::Intersection);
    SceneAccel a2;
    a2.update(in);
    ASSERT_TRUE(a2.intersect(mkRay({5, 0, 0}, {-1, 0, 0}), h));
    EXPECT_NEAR(h.t, 4.0f, 1e-4f);   // box face inside the sphere
    ASSERT_TRUE(a2.intersect(mkRay({-5, 0, 0}, {1, 0, 0}), h));
    EXPECT_NEAR(h.t, 5.4f, 1e-4f);   // sphere surface inside the box
    expectVec(h.normal, {-1, 0, 0}, 1e-4f);
}

// --- parametric + grid ---------------------------------------------------------------------------

TEST(RaycastTest, ParametricBezierAndTorus) {
    ParametricSurface s = ParametricSurface::defaultPatch();
    ParametricAccel acc(s);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> U(0.02f, 0.98f);
    for (int i = 0; i < 50; ++i) {
        float u = U(rng), v = U(rng);
        vec3 P = s.evaluate(u, v);
        Ray r = mkRay(P + vec3(0, 5, 0), {0, -1, 0});
        float t, hu, hv;
        ASSERT_TRUE(acc.intersect(r, t, hu, hv)) << u << " " << v;
        EXPECT_NEAR(t, 5.0f, 1e-3f);
        vec3 q = s.evaluate(hu, hv);
        EXPECT_LT(glm::length(q - P), 2e-3f);
    }
    ParametricSurface tor;
    tor.type = ParametricType::Torus;
    tor.majorRadius = 1.0f;
    tor.minorRadius = 0.3f;
    ParametricAccel ta(tor);
    float t, u, v;
    ASSERT_TRUE(ta.intersect(mkRay({5, 0, 0}, {-1, 0, 0}), t, u, v));
    EXPECT_NEAR(t, 3.7f, 1e-3f);
    vec3 n = tor.normal(u, v);
    EXPECT_NEAR(std::abs(n.x), 1.0f, 1e-3f);
    EXPECT_FALSE(ta.intersect(mkRay({0, 5, 0}, {0, -1, 0}), t, u, v));   // the hole
    ASSERT_TRUE(ta.intersect(mkRay({0, 5, 1}, {0, -1, 0}), t, u, v));
    EXPECT_NEAR(t, 4.7f, 1e-3f);
}

// Newton's method evaluates the patch through ParametricAccel's SSE evaluator; it must give
// ParametricSurface's bits, or the ray caster's hits would move with the build.
TEST(RaycastTest, PatchEvaluatorGivesTheSurfacesBitsExactly) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> C(-5.0f, 5.0f), U(-0.3f, 1.3f);
    auto sameBits = [](vec3 a, vec3 b) { return std::memcmp(&a, &b, sizeof a) == 0; };
    for (int shape = 0; shape < 40; ++shape) {
        ParametricSurface s = ParametricSurface::defaultPatch();
        if (shape > 0)
            for (vec3& c : s.control) c = vec3(C(rng), C(rng), C(rng)) * std::pow(10.0f, float(shape % 7 - 3));
        if (shape == 1) s.control[5] = vec3(-0.0f, 0.0f, 1e-38f);   // signed zeros, a denormal product
        ParametricAccel acc(s);
        for (int k = 0; k < 200; ++k) {
            float u = k == 0 ? 0.0f : k == 1 ? 1.0f : U(rng), v = k == 0 ? 1.0f : k == 1 ? -0.0f : U(rng);
            vec3 pu, pv, qu, qv;
            vec3 p = s.evaluate(u, v, pu, pv), q = acc.evaluate(u, v, qu, qv);
            ASSERT_TRUE(sameBits(p, q) && sameBits(pu, qu) && sameBits(pv, qv)) << shape << " " << u << " " << v;
        }
    }
    ParametricSurface tor;
    tor.type = ParametricType::Torus;
    ParametricAccel ta(tor);
    vec3 pu, pv, qu, qv;
    EXPECT_TRUE(sameBits(tor.evaluate(0.3f, 0.7f, pu, pv), ta.evaluate(0.3f, 0.7f, qu, qv)) && sameBits(pu, qu) && sameBits(pv, qv));
}

TEST(RaycastTest, DensityGridSphereRadius) {
    auto g = std::make_shared<DensityGrid>();
    const int n = 48;
    g->dims = ivec3(n);
    g->bounds = {vec3(-1), vec3(1)};
    g->isoValue = 0.5f;
    g->values.resize(size_t(n) * n * n);
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                vec3 p = vec3(-1) + 2.0f * vec3(x, y, z) / float(n - 1);
                g->values[(size_t(z) * n + y) * n + x] = 1.0f - glm::length(p);   // inside: value > 0.5 <=> |p| < 0.5
            }
    GridAccel acc(g);
    float t;
    ASSERT_TRUE(acc.intersect(mkRay({0, 0, -5}, {0, 0, 1}), t));
    EXPECT_NEAR(t, 4.5f, 0.02f);
    expectVec(acc.normal(vec3(0, 0, -0.5f)), {0, 0, -1}, 0.02f);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> U(-0.3f, 0.3f);
    for (int i = 0; i < 50; ++i) {
        Ray r = mkRay({U(rng), U(rng), 3}, {U(rng) * 0.1f, U(rng) * 0.1f, -1});
        ASSERT_TRUE(acc.intersect(r, t));
        EXPECT_NEAR(glm::length(r.org + t * r.dir), 0.5f, 0.02f);
    }
    EXPECT_FALSE(acc.intersect(mkRay({0, 0.9f, -5}, {0, 0, 1}), t));
}

// --- BVH ------------------------------------------------------------------------------------------

TEST(RaycastTest, BvhClosestHitEqualsBruteForce) {
    for (int seed = 1; seed <= 4; ++seed) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> U(-1, 1);
        const int ntri = seed == 4 ? 5 : 300 * seed * seed;
        std::vector<vec3> pos;
        std::vector<uint32_t> idx;
        for (int t = 0; t < ntri; ++t) {
            vec3 c(U(rng) * 5, U(rng) * 5, U(rng) * 5);
            float s = seed == 3 ? 0.05f : 0.6f;   // seed 3: many tiny triangles
            for (int k = 0; k < 3; ++k) {
                pos.push_back(c + s * vec3(U(rng), U(rng), U(rng)));
                idx.push_back(uint32_t(pos.size() - 1));
            }
        }
        // A few degenerate triangles must not break anything.
        pos.push_back(vec3(0));
        pos.push_back(vec3(0));
        pos.push_back(vec3(0));
        idx.insert(idx.end(), {uint32_t(pos.size() - 3), uint32_t(pos.size() - 2), uint32_t(pos.size() - 1)});
        const size_t count = idx.size() / 3;
        // Default leaves (SAH-chosen, up to 4 packets), single-packet leaves, and leaves of up
        // to 7 packets with node visits made expensive (many multi-packet leaves).
        // Last: a BVH8 allowed too few nodes, which must come out as a BVH4.
        Bvh4::BuildOptions opts[4] = {TriangleBvh::defaultOptions(), {}, TriangleBvh::defaultOptions(), TriangleBvh::defaultOptions()};
        opts[1].maxLeafBlocks = 1;
        opts[2].maxLeafBlocks = 7;
        opts[2].traversalCost = 20.0f;
        opts[2].parallel = false;
        opts[3].maxWideNodes = 1;
        for (const Bvh4::BuildOptions& opt : opts) {
            TriangleBvh bvh;
            bvh.build(pos.data(), idx.data(), count, opt);
            const TriangleBvh::Stats st = bvh.stats();
            if (opt.maxWideNodes == 1 && ntri > 100) { EXPECT_EQ(bvh.width(), 4) << "seed " << seed; }
            if (opt.maxWideNodes > 1) { EXPECT_EQ(bvh.width(), std::string(kernelName()) == "sse bvh4" ? 4 : 8); }
            EXPECT_LE(st.maxLeafPackets, opt.maxLeafBlocks);
            // Nodes are filled first (any child of more than one packet is split while a node
            // has room), so big leaves appear one level down: 2 packets at 300 triangles,
            // more (a pair test plus a single one) from 1200 on.
            if (ntri > 100 && opt.maxLeafBlocks == 7) { EXPECT_GE(st.maxLeafPackets, ntri >= 1000 ? 3 : 2) << "seed " << seed; }
            EXPECT_EQ(st.lanes, count) << "every triangle in exactly one lane";
            int hits = 0;
            for (int i = 0; i < 3000; ++i) {
                vec3 o(U(rng) * 8, U(rng) * 8, U(rng) * 8);
                vec3 d = i % 3 == 0 ? vec3(U(rng), U(rng), U(rng)) : vec3(U(rng) * 5, U(rng) * 5, U(rng) * 5) - o;
                if (i % 50 == 0) d = vec3(0, 0, i % 100 == 0 ? 1.0f : -1.0f);   // axis-aligned: zero components
                Ray r = mkRay(o, d);
                if (i % 7 == 0) r.tmax = 0.5f;
                if (i % 11 == 0) r.tmin = 0.2f;   // segments starting past the origin
                TriHit a, b;
                bool ha = bvh.intersect(r, a), hb = intersectBruteForce(pos.data(), idx.data(), count, r, b);
                ASSERT_EQ(ha, hb) << "seed " << seed << " ray " << i;
                EXPECT_EQ(bvh.occluded(r), hb);
                if (!ha) continue;
                ++hits;
                EXPECT_EQ(a.t, b.t);
                if (a.prim != b.prim) {   // exact ties between two triangles may pick either
                    EXPECT_EQ(a.t, b.t);
                } else {
                    EXPECT_EQ(a.b1, b.b1);
                    EXPECT_EQ(a.b2, b.b2);
                }
            }
            if (ntri > 100) { EXPECT_GT(hits, seed == 3 ? 10 : 100); }
            // A negative tmin acts as 0 (the box test needs tmin >= 0): the same hits as the
            // brute force with tmin = 0, never a triangle behind the origin.
            for (int i = 0; i < 500; ++i) {
                const vec3 o(U(rng) * 8, U(rng) * 8, U(rng) * 8);
                Ray r = mkRay(o, vec3(U(rng) * 5, U(rng) * 5, U(rng) * 5) - o);
                r.tmin = i % 2 ? -3.0f : -std::numeric_limits<float>::infinity();
                Ray r0 = r;
                r0.tmin = 0.0f;
                TriHit a, b;
                const bool ha = bvh.intersect(r, a), hb = intersectBruteForce(pos.data(), idx.data(), count, r0, b);
                ASSERT_EQ(ha, hb) << "seed " << seed << " negative-tmin ray " << i;
                EXPECT_EQ(bvh.occluded(r), hb);
                if (ha) {
                    EXPECT_EQ(a.t, b.t);
                    EXPECT_GE(a.t, 0.0f);
                }
            }
        }
    }
}

// Boxes of flat, axis-aligned geometry have zero thickness, and the box test's slab distances
// (b * (1/d) - o * (1/d)) lose bits to cancellation when the ray or the box is far from the
// world origin: rays that skim such a ground at shallow angles, from far off, from the world
// origin to the far ground, or exactly along a grid line must still find the same triangle as
// the brute force (no hit lost in the BVH's margins).
TEST(RaycastTest, BvhKeepsGrazingRaysOnFlatFarGeometry) {
    const int n = 64;
    const vec3 base(1000.0f, 0.0f, -500.0f);   // far from the origin: large o * (1/d) terms
    std::vector<vec3> pos;
    std::vector<uint32_t> idx;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) pos.push_back(base + vec3(float(i), 0.0f, float(j)));
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
            idx.insert(idx.end(), {a, c, b, b, c, d});
        }
    const size_t count = idx.size() / 3;
    TriangleBvh bvh;
    bvh.build(pos.data(), idx.data(), count);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> U(0, 1);
    int hits = 0;
    for (int k = 0; k < 4000; ++k) {
        // A target on the ground (every 4th exactly on a grid line), approached from up to
        // 3000 units away at 0.05 to 5 degrees above the ground.
        vec3 target = base + vec3(1 + U(rng) * (n - 2), 0.0f, 1 + U(rng) * (n - 2));
        if (k % 4 == 0) target.x = std::floor(target.x);
        const float elev = glm::radians(0.05f + 4.95f * U(rng) * U(rng)), az = 6.2831853f * U(rng);
        const float dist = k % 2 ? 3000.0f * U(rng) : 20.0f * U(rng) + 1.0f;
        const vec3 dir(std::cos(elev) * std::cos(az), -std::sin(elev), std::cos(elev) * std::sin(az));
        Ray r = mkRay(target - dist * dir, dir);
        if (k % 8 == 0) r.dir = glm::normalize(vec3(0.0f, -1e-3f, 1.0f));   // along the grid line x = target.x
        if (k % 8 == 4) {   // from near the world origin (to a grid line): the ground is ~1100 units away
            r.org = vec3(0.0f, 3.0f * U(rng), 0.0f);
            r.dir = glm::normalize(target - r.org);
        }
        TriHit a, b;
        const bool ha = bvh.intersect(r, a), hb = intersectBruteForce(pos.data(), idx.data(), count, r, b);
        ASSERT_EQ(ha, hb) << "ray " << k << " from " << r.org.x << " " << r.org.y << " " << r.org.z;
        EXPECT_EQ(bvh.occluded(r), hb) << "ray " << k;
        if (!ha) continue;
        ++hits;
        EXPECT_EQ(a.t, b.t) << "ray " << k;
    }
    EXPECT_GT(hits, 3000);
}

// Packets (intersectPacket / occludedPacket) give exactly the single-ray results for every active
// ray and leave inactive lanes alone (also given as world rays with the instance's move and a
// tmax per ray): camera-like packets (one origin, zero direction components
// included), shadow-like packets (many origins, one target), origins inside the boxes, tmin/tmax
// limits, rays that cannot join the packet (other direction signs, non-finite, empty segment), on
// BVH8 (or BVH4 with the SSE kernel) and on a tree forced to BVH4.
TEST(RaycastTest, BvhPacketsEqualSingleRays) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> U(-1, 1);
    std::vector<vec3> pos;
    std::vector<uint32_t> idx;
    for (int t = 0; t < 3000; ++t) {
        const vec3 c(U(rng) * 5, U(rng) * 5, U(rng) * 5);
        for (int k = 0; k < 3; ++k) {
            pos.push_back(c + 0.4f * vec3(U(rng), U(rng), U(rng)));
            idx.push_back(uint32_t(pos.size() - 1));
        }
    }
    // A flat grid with shared edges (rays along its lines meet two triangles at once).
    const uint32_t g0 = uint32_t(pos.size());
    for (int j = 0; j <= 16; ++j)
        for (int i = 0; i <= 16; ++i) pos.push_back(vec3(-4.0f + 0.5f * float(i), -5.5f, -4.0f + 0.5f * float(j)));
    for (int j = 0; j < 16; ++j)
        for (int i = 0; i < 16; ++i) {
            const uint32_t a = g0 + uint32_t(j * 17 + i), b = a + 1, c = a + 17, d = c + 1;
            idx.insert(idx.end(), {a, c, b, b, c, d});
        }
    const size_t count = idx.size() / 3;
    Bvh4::BuildOptions opts[2] = {TriangleBvh::defaultOptions(), TriangleBvh::defaultOptions()};
    opts[1].maxWideNodes = 1;   // BVH4: the packet calls fall back to single rays
    for (const Bvh4::BuildOptions& opt : opts) {
        TriangleBvh bvh;
        bvh.build(pos.data(), idx.data(), count, opt);
        int hits = 0, ties = 0, tested = 0;
        for (int p = 0; p < 400; ++p) {
            const int n = p % 5 == 0 ? 1 + int(rng() % kMaxPacket) : (p % 2 ? 16 : kMaxPacket);
            std::vector<Ray> rays(static_cast<size_t>(n));
            const int kind = p % 4;   // 0, 1: camera-like; 2: shadow-like; 3: random (incoherent)
            const vec3 eye(U(rng) * 8, U(rng) * 8, U(rng) * 8 + (p % 3 == 0 ? 0.0f : 12.0f));
            const vec3 aim(U(rng) * 3, U(rng) * 3, U(rng) * 3), light(U(rng) * 9, 9.0f, U(rng) * 9);
            for (int i = 0; i < n; ++i) {
                Ray& r = rays[size_t(i)];
                if (kind <= 1) {
                    const vec3 d = aim + 0.05f * float(i % 8) * vec3(1, 0, 0) + 0.05f * float(i / 8) * vec3(0, 1, 0) - eye;
                    r = mkRay(eye, kind == 1 ? glm::normalize(d) : d);
                } else if (kind == 2) {
                    const vec3 o = aim + 0.1f * vec3(float(i % 8), U(rng), float(i / 8));
                    r = mkRay(o, light - o);
                    r.tmax = 0.9999f;
                } else {
                    const vec3 o(U(rng) * 6, U(rng) * 6, U(rng) * 6);   // often inside boxes
                    r = mkRay(o, vec3(U(rng), U(rng), U(rng)));
                }
                if (i % 9 == 3) r.dir.x = 0.0f;   // degenerate directions: zero components
                if (i % 13 == 5) r.dir = vec3(0.0f, 0.0f, r.dir.z < 0 ? -1.0f : 1.0f);
                if (i % 13 == 6) r.dir = vec3(0.0f, -1.0f, 0.0f);   // straight down onto the grid
                if (i % 7 == 2) r.tmax = std::min(r.tmax, 3.0f + U(rng));
                if (i % 11 == 4) r.tmin = 1.0f + U(rng);
                if (i % 17 == 8) r.tmin = -2.0f;
                if (p % 10 == 7 && i == n / 2) r.dir = -r.dir;   // other signs than the packet
                if (p % 20 == 9 && i == 1) r.org.x = std::numeric_limits<float>::quiet_NaN();
                if (p % 20 == 19 && i == 2) r.tmax = 0.5f * r.tmin - 1.0f;   // empty segment
            }
            uint64_t active = (uint64_t(rng()) << 32) | rng();
            if (p % 3 == 0) active = ~uint64_t(0);
            std::vector<TriHit> ph(static_cast<size_t>(n));
            for (TriHit& h : ph) h.t = -7.0f;   // inactive lanes and misses: untouched
            const uint64_t found = bvh.intersectPacket(rays.data(), n, active, ph.data());
            const uint64_t occ = bvh.occludedPacket(rays.data(), n, active);
            // The same rays as world rays of an instance (rotated, scaled unevenly, moved), each
            // with a tmax of its own: the kernel moves them itself, as RayTransform::apply does.
            {
                const RayTransform move(
                    glm::translate(glm::rotate(glm::scale(mat4(1.0f), vec3(1.3f, 0.7f, 1.1f)), 0.4f, glm::normalize(vec3(0.3f, 1.0f, 0.2f))),
                                   vec3(0.2f, -0.3f, 0.1f)));
                std::vector<float> bound(static_cast<size_t>(n));
                for (int i = 0; i < n; ++i) bound[size_t(i)] = i % 3 ? rays[size_t(i)].tmax : 0.7f * rays[size_t(i)].tmax;
                std::vector<TriHit> mh(static_cast<size_t>(n));
                const uint64_t movedFound = bvh.intersectPacket(rays.data(), n, active, mh.data(), false, nullptr, &move, bound.data());
                const uint64_t movedOcc = bvh.occludedPacket(rays.data(), n, active, &move);
                for (int i = 0; i < n; ++i) {
                    const bool on = (active >> i) & 1;
                    TriHit a;
                    const bool ha = on && bvh.intersect(move.apply(rays[size_t(i)], bound[size_t(i)]), a);
                    ASSERT_EQ(bool((movedFound >> i) & 1), ha) << "moved packet " << p << " ray " << i;
                    if (ha) { EXPECT_EQ(mh[size_t(i)].t, a.t) << "moved packet " << p << " ray " << i; }
                    EXPECT_EQ(bool((movedOcc >> i) & 1), on && bvh.occluded(move.apply(rays[size_t(i)], rays[size_t(i)].tmax)))
                        << "moved packet " << p << " ray " << i;
                }
            }
            // With ties reported: the same hits, and every ray whose triangle differs from the
            // single ray's among them.
            std::vector<TriHit> pt(static_cast<size_t>(n));
            uint64_t tied = 0;
            EXPECT_EQ(bvh.intersectPacket(rays.data(), n, active, pt.data(), false, &tied), found) << "packet " << p;
            EXPECT_EQ(tied & ~active, 0u);
            for (int i = 0; i < n; ++i) {
                const bool on = (active >> i) & 1;
                TriHit a;
                const bool ha = bvh.intersect(rays[size_t(i)], a);
                const TriHit& b = ph[size_t(i)];
                if (!on || !ha) {
                    EXPECT_FALSE((found >> i) & 1) << "packet " << p << " ray " << i;
                    EXPECT_EQ(b.t, -7.0f) << "packet " << p << " ray " << i;
                    EXPECT_EQ(b.prim, ~0u);
                    if (!on) { EXPECT_FALSE((occ >> i) & 1); }
                    if (on) { EXPECT_EQ(bool((occ >> i) & 1), bvh.occluded(rays[size_t(i)])) << "packet " << p << " ray " << i; }
                    continue;
                }
                ++tested;
                ++hits;
                ASSERT_TRUE((found >> i) & 1) << "packet " << p << " ray " << i;
                EXPECT_EQ(bool((occ >> i) & 1), bvh.occluded(rays[size_t(i)])) << "packet " << p << " ray " << i;
                EXPECT_EQ(b.t, a.t) << "packet " << p << " ray " << i;
                EXPECT_EQ(pt[size_t(i)].t, a.t) << "packet " << p << " ray " << i;
                if (pt[size_t(i)].prim != a.prim) { EXPECT_TRUE((tied >> i) & 1) << "packet " << p << " ray " << i << ": a tie not reported"; }
                if (b.prim != a.prim) {   // exact ties between two triangles may keep either
                    ++ties;
                    continue;
                }
                EXPECT_EQ(b.b1, a.b1);
                EXPECT_EQ(b.b2, a.b2);
            }
        }
        EXPECT_GT(hits, 2000);
        EXPECT_LE(ties, tested / 1000 + 2);
    }
}

TEST(RaycastTest, BvhHandlesEmptyAndNonFinite) {
    TriangleBvh bvh;
    bvh.build(nullptr, nullptr, 0);
    TriHit h;
    EXPECT_FALSE(bvh.intersect(mkRay({0, 0, 0}, {0, 0, 1}), h));
    std::vector<vec3> pos = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {NAN, 0, 0}, {1, 1, 1}, {0, 1, 1}};
    std::vector<uint32_t> idx = {0, 1, 2, 3, 4, 5};
    bvh.build(pos.data(), idx.data(), 2);
    ASSERT_TRUE(bvh.intersect(mkRay({0.2f, 0.2f, 1}, {0, 0, -1}), h));
    EXPECT_EQ(h.prim, 0u);
}

// --- camera rays / images -----------------------------------------------------------------------------

TEST(RaycastTest, PrimaryRaysLineUpWithProjections) {
    const int w = 320, h = 200;
    Projection projs[3];
    projs[0].type = ProjectionType::Perspective;
    projs[1].type = ProjectionType::Orthographic;
    projs[2] = Projection::cabinet();
    mat4 camWorld = glm::inverse(glm::lookAt(vec3(3, 2, 6), vec3(0, 0, 0), vec3(0, 1, 0)));
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> U(-1, 1);
    for (const Projection& p : projs) {
        FrameCamera cam = makeFrameCamera(camWorld, p, float(w) / h, 5.0f);
        CameraRays rays(cam, w, h);
        for (int i = 0; i < 100; ++i) {
            vec3 X(U(rng), U(rng), U(rng));
            vec4 c = cam.viewProj * vec4(X, 1.0f);
            vec2 win((0.5f * c.x / c.w + 0.5f) * w, (0.5f * c.y / c.w + 0.5f) * h);
            Ray r = rays.ray(win.x, win.y);
            // X lies on the ray: distance from the line
            vec3 d = glm::normalize(r.dir);
            vec3 off = X - r.org;
            float dist = glm::length(off - glm::dot(off, d) * d);
            EXPECT_LT(dist, 2e-4f) << toString(p.type);
            // and its depth is the rasterizers' window z
            EXPECT_NEAR(rays.depth(X), 0.5f * c.z / c.w + 0.5f, 1e-6f);
        }
        // Render: a small sphere at X appears at the projected pixel with the right depth.
        vec3 X(0.4f, -0.3f, 0.2f);
        FrameInput f;
        f.camera = cam;
        f.settings.shadows = false;
        DrawAnalytic s;
        s.kind = DrawAnalytic::Kind::Implicit;
        s.implicit.type = ImplicitType::Sphere;
        s.implicit.radius = 0.05f;
        s.world = glm::translate(mat4(1.0f), X);
        s.invWorld = glm::inverse(s.world);
        s.normal = normalMatrix(s.world);
        s.worldBounds = s.implicit.localBounds().transformed(s.world);
        f.analytics.push_back(s);
        auto r = makeRenderer("raycast");
        Framebuffer fb;
        ASSERT_TRUE(r->render(f, w, h, fb).ok);
        vec2 win = rays.project(X);
        int px = int(win.x), row = h - 1 - int(win.y);
        float dep = fb.depth[size_t(row) * w + px];
        EXPECT_LT(dep, 1.0f) << toString(p.type);
        // The sphere's front is at most one radius nearer than its centre.
        EXPECT_LE(dep, rays.depth(X) + 1e-6f);
        EXPECT_EQ(fb.depth[size_t(row) * w + std::min(w - 1, px + 40)], 1.0f);
    }
}

// Far/near ratios of 1e7 and more, seen from hundreds of units from the origin (a CAD model in
// millimetres with a tight near plane): the ray through the window position of a point, as the
// rasterizers map it (the float matrices proj and view, applied exactly), passes within 0.1
// pixel of that point (the float ray origin alone is off by up to 0.05 pixel at 5 cm here), and has its far end where that projection puts the far plane (at
// infinity for 1e-5 and 1e-6: -(f + n) / (f - n) rounds to -1). The float inverse of
// proj * view missed by half a pixel here, and gave no ray at all at infinity.
TEST(RaycastTest, PrimaryRaysStayOnTheirPixelsWithExtremeNearFarRatios) {
    const int w = 320, h = 200;
    const vec3 eye(312.0f, 205.0f, 488.0f);
    const mat4 camWorld = glm::inverse(glm::lookAt(eye, eye + vec3(-0.3f, -0.2f, -1.0f), vec3(0, 1, 0)));
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> U(-0.9f, 0.9f), D(0.05f, 1.0f);
    for (float zNear : {1e-3f, 1e-4f, 1e-5f, 1e-6f}) {
        Projection p;
        p.zNear = zNear;
        p.zFar = 1000.0f;
        FrameCamera cam = makeFrameCamera(camWorld, p, float(w) / h, 5.0f);
        CameraRays rays(cam, w, h);
        const glm::dmat4 viewProj = glm::dmat4(cam.proj) * glm::dmat4(cam.view);
        const glm::dvec3 fwd = -glm::dvec3(camWorld[2]);
        const double tanHalf = std::tan(0.5 * double(radians(p.fovyDeg)));
        double worst = 0.0;
        for (int i = 0; i < 200; ++i) {
            const double d = D(rng);
            const glm::dvec3 X =
                glm::dvec3(eye) + d * (fwd + double(U(rng)) * glm::dvec3(camWorld[0]) + double(U(rng)) * 0.6 * glm::dvec3(camWorld[1]));
            const glm::dvec4 c = viewProj * glm::dvec4(X, 1.0);
            const Ray r = rays.ray(float((0.5 * c.x / c.w + 0.5) * w), float((0.5 * c.y / c.w + 0.5) * h));
            ASSERT_TRUE(isFinite(r.org) && isFinite(r.dir)) << zNear;
            ASSERT_GT(r.tmax, 0.0f) << zNear;
            const glm::dvec3 dir = glm::normalize(glm::dvec3(r.dir)), off = X - glm::dvec3(r.org);
            EXPECT_GT(glm::dot(dir, fwd), 0.0) << zNear;
            const double pixel = 2.0 * glm::dot(off, fwd) * tanHalf / h;   // a pixel's size at X's depth
            worst = std::max(worst, glm::length(off - glm::dot(off, dir) * dir) / pixel);
        }
        EXPECT_LT(worst, 0.1) << "near " << zNear << ": a ray misses its pixel's points by " << worst << " pixels";
        const bool farAtInfinity = -(p.zFar + zNear) / (p.zFar - zNear) == -1.0f;
        EXPECT_EQ(rays.ray(0.5f * w, 0.5f * h).tmax, farAtInfinity ? std::numeric_limits<float>::max() : 1.0f) << zNear;
    }
}

namespace {
FrameInput triangleScene(int w, int h) {
    FrameInput f;
    auto mesh = std::make_shared<Mesh>(primitives::uvSphere(1.0f, 32, 16));
    DrawMesh d;
    d.mesh = mesh;
    d.world = glm::translate(mat4(1.0f), vec3(0, 1, 0));
    d.normal = normalMatrix(d.world);
    f.meshes.push_back(d);
    auto ground = std::make_shared<Mesh>(primitives::plane(5.0f, 4));
    DrawMesh g;
    g.mesh = ground;
    f.meshes.push_back(g);
    DrawLight l;
    l.position = vec3(3, 5, 2);
    f.lights.push_back(l);
    f.camera = makeFrameCamera(glm::inverse(glm::lookAt(vec3(0, 3, 6), vec3(0, 0.5f, 0), vec3(0, 1, 0))), Projection{}, float(w) / h, 6.0f);
    return f;
}
}   // namespace

// Shadow rays go only where a light can add something (lightReaches): a directional light
// from below reaches hardly any visible point, a narrow spot a small patch, so most hits
// trace one shadow ray (the point light's), not three. The pixels stay what full visibility
// gives: each one matches the inspector's terms with Renderer::lightVisibility (which
// traces every light), shadows of all three lights included.
TEST(RaycastTest, ShadowRaysOnlyWhereALightCanAddSomething) {
    const int w = 160, h = 120;
    FrameInput f = triangleScene(w, h);
    DrawLight below;
    below.type = LightType::Directional;
    below.direction = vec3(0, 1, 0);   // travels upward: lights undersides only
    f.lights.push_back(below);
    DrawLight spot;
    spot.type = LightType::Spot;
    spot.position = vec3(-1.5f, 4, 0.5f);
    spot.direction = glm::normalize(vec3(0.5f, -1, 0));   // at the sphere's left side and the floor
    spot.cosInner = std::cos(glm::radians(12.0f));
    spot.cosOuter = std::cos(glm::radians(18.0f));
    f.lights.push_back(spot);
    const InstanceTable ids = instanceTable(f);
    for (ShadingModel model : {ShadingModel::Phong, ShadingModel::Flat, ShadingModel::Gouraud}) {
        SCOPED_TRACE(std::string(toString(model)));
        f.settings.shading = model;
        auto r = makeRenderer("raycast");
        Framebuffer fb;
        RenderRequest req;
        req.aovs.add(rnd::Aov::Visibility);
        const RenderStats st = r->render(f, w, h, fb, nullptr, req);
        ASSERT_TRUE(st.ok) << st.error;
        size_t hits = 0, reachedBySpot = 0, checked = 0, close = 0, shadowed = 0;
        for (int y = 1; y < h - 1; ++y)
            for (int x = 1; x < w - 1; ++x) {
                const SurfaceAt s = surfaceAt(f, ids, fb, x, y);
                if (!s.hit) continue;
                ++hits;
                reachedBySpot += lightReaches(f.lights[2], s.position, s.normal);
                if (model == ShadingModel::Gouraud) continue;   // the inspector does not reproduce Gouraud
                bool interior = true;
                for (int k = 0; k < 4; ++k) {
                    const int i = x + (k == 0) - (k == 1), j = y + (k == 2) - (k == 3);
                    interior = interior && fb.drawable[size_t(j) * w + i] == s.drawable;
                }
                if (!interior) continue;
                const std::vector<float> vis = r->lightVisibility(f, s.position, s.geometricNormal);
                ASSERT_EQ(vis.size(), 3u);
                shadowed += vis[0] == 0.0f || vis[2] == 0.0f;
                const PixelTerms t = pixelTerms(f, s, vis);
                const uint8_t* px = fb.pixel(x, y);
                int worst = 0;
                for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(px[c]) - int(toByteSRGB(t.predicted[c]))));
                ++checked;
                close += worst <= 2;
            }
        ASSERT_GT(hits, size_t(w * h / 2));
        EXPECT_GT(reachedBySpot, hits / 20);   // the spot lights a real part of the image
        EXPECT_LT(reachedBySpot, hits / 2);
        // Primary rays for every pixel, then per hit: the point light's ray where it reaches,
        // the spot's inside its cone, the light from below almost never.
        EXPECT_GT(st.rays, uint64_t(w * h + hits / 2));
        EXPECT_LT(st.rays, uint64_t(w * h + 2 * hits));
        if (model != ShadingModel::Gouraud) {
            EXPECT_GT(shadowed, checked / 50);   // shadows are in the picture
            EXPECT_GE(double(close) / double(checked), 0.99) << close << " of " << checked;
        }
    }
}

TEST(RaycastTest, RendersProgressCancelAndCaches) {
    const int w = 160, h = 120;
    FrameInput f = triangleScene(w, h);
    auto r = makeRenderer("raycast");
    ASSERT_TRUE(r);
    EXPECT_TRUE(r->capabilities().progressive);
    RenderControl ctl;
    std::atomic<int> tiles{0};
    ctl.onTileDone = [&] { ++tiles; };
    Framebuffer fb;
    RenderStats s = r->render(f, w, h, fb, &ctl);
    ASSERT_TRUE(s.ok) << s.error;
    EXPECT_FLOAT_EQ(ctl.progress.load(), 1.0f);
    EXPECT_GT(tiles.load(), 1);
    EXPECT_GT(s.rays, uint64_t(w * h));
    // The sphere is in the middle of the image, lit (not background).
    const uint8_t* c = fb.pixel(w / 2, h / 2 - 10);
    EXPECT_GT(int(c[0]) + c[1] + c[2], 100);
    testing_support::writeImage(fb, "raycast", "triangle-scene");

    // Cancelled before it starts: reports cancelled, not ok.
    RenderControl cancel;
    cancel.cancel = true;
    RenderStats sc = r->render(f, w, h, fb, &cancel);
    EXPECT_FALSE(sc.ok);
    EXPECT_TRUE(sc.cancelled);

    // Bad size: a clear error, no crash.
    RenderStats sb = r->render(f, 0, 10, fb);
    EXPECT_FALSE(sb.ok);
    EXPECT_FALSE(sb.error.empty());
}

TEST(RaycastTest, TransformEditDoesNotRebuildMeshBvh) {
    FrameInput f = triangleScene(64, 64);
    SceneAccel acc;
    EXPECT_EQ(acc.update(f), 2);
    f.meshes[0].world = glm::translate(mat4(1.0f), vec3(0, 3, 0));
    EXPECT_EQ(acc.update(f), 0);   // moved instance: TLAS only
    SceneHit h;
    ASSERT_TRUE(acc.intersect(mkRay({0, 10, 0}, {0, -1, 0}), h));
    EXPECT_NEAR(h.t, 6.0f, 0.02f);   // top of the moved sphere at y = 4
    auto edited = std::make_shared<Mesh>(*f.meshes[0].mesh);
    edited->touch();
    f.meshes[0].mesh = edited;
    EXPECT_EQ(acc.update(f), 1);   // new version: rebuilt
}

// SceneAccel::intersectPacket: for every ray exactly SceneAccel::intersect's hit, with big meshes (16k triangles)
// traced as packets (one mirrored, one single-sided under culling), a small mesh and an analytic
// sphere traced one ray at a time, and packets that reach only the big meshes.
TEST(RaycastTest, SceneAccelPacketsEqualSingleRays) {
    FrameInput f = triangleScene(64, 64);
    DrawMesh big;
    big.mesh = std::make_shared<Mesh>(primitives::uvSphere(0.8f, 128, 64));
    big.world = glm::translate(mat4(1.0f), vec3(-1.5f, 0.8f, 0.5f));
    big.normal = normalMatrix(big.world);
    f.meshes.push_back(big);
    DrawMesh mirrored = big;
    mirrored.world = glm::scale(glm::translate(mat4(1.0f), vec3(1.6f, 0.9f, -0.4f)), vec3(-1.0f, 1.0f, 1.2f));
    mirrored.normal = normalMatrix(mirrored.world);
    mirrored.mirrored = true;
    mirrored.material.doubleSided = false;
    f.meshes.push_back(mirrored);
    f.analytics.push_back(implicitSphere(0.4f, vec3(0.3f, 1.2f, 1.5f)));
    for (const CullMode culling : {CullMode::Off, CullMode::On, CullMode::Auto}) {
        SceneAccel acc;
        acc.update(f);
        const CameraRays cam(f.camera, 96, 96);
        int hits = 0, ties = 0, occludedHits = 0, occludedMisses = 0;
        for (int ty = 0; ty < 96 + 16; ty += 4)
            for (int tx = 0; tx < 96; tx += 8) {
                Ray rays[32];
                int n = 0;
                for (int y = ty; y < ty + 4; ++y)
                    for (int x = tx; x < tx + 8; ++x) {
                        if (ty < 96) {
                            rays[n++] = cam.ray(float(x) + 0.5f, float(y) + 0.5f);
                        } else {   // level rays from the side at the big sphere: they reach no other instance
                            rays[n++] = mkRay(vec3(-5.0f, 0.2f + 0.1f * float(y - 96), -0.5f + 0.03f * float(x)), vec3(1.0f, 0.01f, 0.0f));
                        }
                    }
                const uint64_t active = (tx / 8 + ty / 4) % 3 ? ~uint64_t(0) : 0xF0F0F0F0F0ull;   // some inactive lanes
                SceneHit ph[32];
                const uint64_t found = acc.intersectPacket(rays, n, active, ph, culling);
                // Any hits: the same rays, and the same rays cut at a third of their length (some
                // then stop short of what they hit), packet against one by one.
                Ray cut[32];
                for (int i = 0; i < n; ++i) {
                    cut[i] = rays[i];
                    cut[i].tmax = rays[i].tmax / 3.0f;
                }
                for (const Ray* set : {static_cast<const Ray*>(rays), static_cast<const Ray*>(cut)}) {
                    const uint64_t blocked = acc.occludedPacket(set, n, active);
                    for (int i = 0; i < n; ++i) {
                        const bool on = (active >> i) & 1;
                        ASSERT_EQ(bool((blocked >> i) & 1), on && acc.occluded(set[i])) << "ray " << i << " tile " << tx << "," << ty;
                        occludedHits += on && acc.occluded(set[i]);
                        occludedMisses += on && !acc.occluded(set[i]);
                    }
                }
                for (int i = 0; i < n; ++i) {
                    SceneHit a;
                    const bool ha = acc.intersect(rays[i], a, culling);
                    const bool on = (active >> i) & 1;
                    ASSERT_EQ(bool((found >> i) & 1), on && ha) << "ray " << i << " tile " << tx << "," << ty;
                    if (!on || !ha) {
                        EXPECT_EQ(ph[i].kind, SceneHit::Kind::None);
                        continue;
                    }
                    ++hits;
                    EXPECT_EQ(ph[i].t, a.t);
                    EXPECT_EQ(ph[i].kind, a.kind);
                    if (ph[i].instance != a.instance || ph[i].prim != a.prim) {   // exact ties may keep either
                        ++ties;
                        continue;
                    }
                    EXPECT_EQ(ph[i].b1, a.b1);
                    EXPECT_EQ(ph[i].b2, a.b2);
                    expectVec(ph[i].normal, a.normal, 0.0f);
                }
            }
        EXPECT_GT(hits, 3000);
        EXPECT_LE(ties, 3);
        EXPECT_GT(occludedHits, 3000);
        EXPECT_GT(occludedMisses, 1000);
    }
}

namespace {
// triangleScene with a sphere of 16k triangles beside its small meshes: a mesh traced as packets.
// A spot (cones of 20 and 30 degrees) over the left of triangleSceneWithBigSphere's spheres.
DrawLight spotOverTheSphere() {
    DrawLight spot;
    spot.type = LightType::Spot;
    spot.position = vec3(-1.5f, 4, 0.5f);
    spot.direction = glm::normalize(vec3(0.5f, -1, 0));
    spot.cosInner = std::cos(glm::radians(20.0f));
    spot.cosOuter = std::cos(glm::radians(30.0f));
    return spot;
}

// f rendered by the ray caster with the environment variable `name` (a debug switch) set to
// value, the visibility asked for; rays: the rays it counted.
Framebuffer renderWithSwitch(const FrameInput& f, int w, int h, const char* name, const char* value, uint64_t& rays) {
    setenv(name, value, 1);
    auto r = makeRenderer("raycast");
    Framebuffer fb;
    RenderRequest req;
    req.aovs.add(Aov::Visibility);
    const RenderStats st = r->render(f, w, h, fb, nullptr, req);
    unsetenv(name);
    EXPECT_TRUE(st.ok) << st.error;
    rays = st.rays;
    return fb;
}

// The same bytes, depth, drawables and primitives.
void expectSameImage(const Framebuffer& a, const Framebuffer& b) {
    ASSERT_EQ(a.color.size(), b.color.size());
    EXPECT_TRUE(a.color == b.color);
    EXPECT_TRUE(a.depth == b.depth);
    EXPECT_TRUE(a.drawable == b.drawable);
    EXPECT_TRUE(a.primitive == b.primitive);
}

FrameInput triangleSceneWithBigSphere(int w, int h) {
    FrameInput f = triangleScene(w, h);
    DrawMesh big;
    big.mesh = std::make_shared<Mesh>(primitives::uvSphere(0.6f, 128, 64));
    big.world = glm::translate(mat4(1.0f), vec3(-1.2f, 0.7f, 0.3f));
    big.normal = normalMatrix(big.world);
    f.meshes.push_back(big);
    return f;
}
}   // namespace

// The renderer's shadow rays traced as packets (after the tile's camera packets) give the image
// they give one by one, byte for byte: shading models, a big mesh (packets) beside small ones
// and analytic shapes, a point light, a spot, a sun, and a light with a size (soft: one by one).
TEST(RaycastTest, ShadowPacketsGiveTheSameImageAsSingleShadowRays) {
    const int w = 160, h = 120;
    FrameInput f = triangleSceneWithBigSphere(w, h);
    DrawLight spot = spotOverTheSphere();
    f.lights.push_back(spot);
    spot.position = vec3(2.0f, 3.0f, 2.0f);   // a second spot with a size: soft, its rays one by one
    spot.direction = glm::normalize(vec3(-0.5f, -1, -0.5f));
    spot.radius = 0.3f;
    f.lights.push_back(spot);
    f.settings.shadowRays = 4;
    DrawLight sun;
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(vec3(0.3f, -1.0f, -0.4f));
    f.lights.push_back(sun);
    f.settings.shadows = true;
    auto render = [&](const char* packets) {
        setenv("VIEWER_RAYCAST_SHADOW_PACKETS", packets, 1);
        auto r = makeRenderer("raycast");
        Framebuffer fb;
        const RenderStats st = r->render(f, w, h, fb, nullptr, RenderRequest{});
        unsetenv("VIEWER_RAYCAST_SHADOW_PACKETS");
        EXPECT_TRUE(st.ok) << st.error;
        return fb;
    };
    for (ShadingModel model : {ShadingModel::Phong, ShadingModel::Flat, ShadingModel::Gouraud}) {
        SCOPED_TRACE(std::string(toString(model)));
        f.settings.shading = model;
        const Framebuffer one = render("0"), packets = render("1");
        ASSERT_EQ(one.color.size(), packets.color.size());
        EXPECT_TRUE(one.color == packets.color);
        EXPECT_TRUE(one.depth == packets.depth);
        f.settings.shadows = false;
        const Framebuffer unshadowed = render("1");
        f.settings.shadows = true;
        size_t darker = 0;   // shadows are in the picture
        for (size_t i = 0; i + 3 < one.color.size(); i += 4)
            darker +=
                one.color[i] + one.color[i + 1] + one.color[i + 2] + 6 < unshadowed.color[i] + unshadowed.color[i + 1] + unshadowed.color[i + 2];
        EXPECT_GT(darker, size_t(w * h / 50));
    }
}

// Camera rays traced as packets give the image, depth, visibility and (without shadows) ray count
// that they give one by one, with and without shadows, pixels that meet nothing included (those
// take a shortcut when what they see is the plain background colour, and packets whose pixels
// lie outside every box's window rectangle are not traced): with the display transform off and
// on, a background with a negative zero, the environment drawn behind the scene (no shortcut),
// an orthographic and an oblique camera, and the whole scene far from the origin under a
// squashed instance.
TEST(RaycastTest, CameraPacketsGiveTheSameImageAsSingleRays) {
    const int w = 160, h = 120;
    FrameInput f = triangleSceneWithBigSphere(w, h);
    auto render = [&](const char* packets, uint64_t& rays) { return renderWithSwitch(f, w, h, "VIEWER_RAYCAST_PACKETS", packets, rays); };
    struct Case {
        const char* name;
        float exposure;
        ToneMapping op;
        vec3 background;
        ReflectionModel model;
        bool environmentBehind;
        int view;   // 0: the scene's camera; 1: orthographic; 2: cabinet; 3: everything moved far off and squashed
    };
    const Case cases[] = {
        {"plain", 0.0f, ToneMapping::None, vec3(0.08f, 0.09f, 0.11f), ReflectionModel::Phong, false, 0},
        {"exposed, tone-mapped", 1.5f, ToneMapping::Aces, vec3(0.6f, -0.0f, 0.3f), ReflectionModel::Phong, false, 0},
        {"environment behind", 0.0f, ToneMapping::None, vec3(0.08f, 0.09f, 0.11f), ReflectionModel::Pbr, true, 0},
        {"orthographic", 0.0f, ToneMapping::None, vec3(0.08f, 0.09f, 0.11f), ReflectionModel::Phong, false, 1},
        {"cabinet", 0.0f, ToneMapping::None, vec3(0.08f, 0.09f, 0.11f), ReflectionModel::Phong, false, 2},
        {"far off, squashed", 0.0f, ToneMapping::None, vec3(0.08f, 0.09f, 0.11f), ReflectionModel::Phong, false, 3},
    };
    const FrameInput scene = f;
    for (const Case& c : cases)
        for (bool shadows : {false, true}) {
            SCOPED_TRACE(std::string(c.name) + (shadows ? ", shadows" : ""));
            f = scene;
            const mat4 camWorld = glm::inverse(glm::lookAt(vec3(0, 3, 6), vec3(0, 0.5f, 0), vec3(0, 1, 0)));
            if (c.view == 1 || c.view == 2) {
                Projection p = c.view == 1 ? Projection{} : Projection::cabinet();
                p.type = c.view == 1 ? ProjectionType::Orthographic : p.type;
                p.orthoHalfHeight = 4.0f;   // the scene with room around it
                f.camera = makeFrameCamera(camWorld, p, float(w) / h, 6.0f);
            } else if (c.view == 3) {
                const mat4 away = glm::translate(mat4(1.0f), vec3(4000.0f, -3000.0f, 2500.0f));
                for (DrawMesh& d : f.meshes) {
                    d.world = away * d.world * glm::scale(mat4(1.0f), vec3(1.0f, 0.05f, 1.0f));
                    d.normal = normalMatrix(d.world);
                }
                for (DrawLight& l : f.lights) l.position = vec3(away * vec4(l.position, 1.0f));
                f.camera = makeFrameCamera(away * camWorld, Projection{}, float(w) / h, 6.0f);
            }
            f.settings.shadows = shadows;
            f.settings.exposure = c.exposure;
            f.settings.toneMapping = c.op;
            f.settings.background = c.background;
            f.settings.reflection = c.model;
            f.settings.environmentBackground = c.environmentBehind;
            uint64_t raysOne = 0, raysPackets = 0;
            const Framebuffer one = render("0", raysOne), packets = render("1", raysPackets);
            expectSameImage(one, packets);
            if (!shadows) {   // (shadow packets count their rays by their own rule)
                EXPECT_EQ(raysOne, raysPackets);
            }
            size_t empty = 0;   // pixels that meet nothing are in the picture
            for (float d : packets.depth) empty += d == 1.0f;
            EXPECT_GT(empty, size_t(w * h / 10));
        }
}

// A textured hit's mip level comes from its footprint: the rays through the pixels to its right
// and above. With camera packets those are the neighbours' own packet rays (a strip of packets'
// own, and the row above a strip kept from the strip before); at a tile's right edge, at the
// image's edges and beside packets that were not traced (they meet no box) they are made as for
// a single ray. The same bytes as one by one: a minified checker on the ground (its level changes
// across the image) and on a card in the air, with empty packets around it, shaded in lanes
// (Phong), through trace() (pbr) and flat, at sizes that are not multiples of the 32-pixel tile.
// Against level 0 only, the images differ (so the footprints are what this compares).
TEST(RaycastTest, PacketFootprintsGiveTheSameTexelsAsSingleRays) {
    for (const auto& [w, h] : {std::pair{150, 100}, std::pair{97, 203}}) {
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
        FrameInput f = triangleScene(w, h);
        auto ground = std::make_shared<Mesh>(*f.meshes[1].mesh);
        for (vec2& uv : ground->uv0) uv *= 16.0f;
        f.meshes[1].mesh = ground;
        f.meshes[1].texture = test_scenes::minificationChecker();
        f.meshes[1].material.baseColor = vec3(1.0f);
        DrawMesh card = f.meshes[1];   // tilted toward the camera, above the sphere's right
        card.world =
            glm::translate(mat4(1.0f), vec3(1.7f, 2.6f, 0.5f)) * glm::rotate(mat4(1.0f), 1.1f, vec3(1, 0, 0)) * glm::scale(mat4(1.0f), vec3(0.2f));
        card.normal = normalMatrix(card.world);
        f.meshes.push_back(card);
        for (ReflectionModel model : {ReflectionModel::Phong, ReflectionModel::Pbr})
            for (ShadingModel shading : {ShadingModel::Phong, ShadingModel::Flat}) {
                SCOPED_TRACE(std::string(toString(model)) + ", " + std::string(toString(shading)));
                f.settings.reflection = model;
                f.settings.shading = shading;
                uint64_t rays = 0;
                const Framebuffer one = renderWithSwitch(f, w, h, "VIEWER_RAYCAST_PACKETS", "0", rays);
                const Framebuffer packets = renderWithSwitch(f, w, h, "VIEWER_RAYCAST_PACKETS", "1", rays);
                expectSameImage(one, packets);
                std::set<uint32_t> seen(packets.drawable.begin(), packets.drawable.end());   // the card is in the picture
                EXPECT_TRUE(seen.count(uint32_t(f.meshes.size()))) << "the card";
            }
        FrameInput level0 = f;   // the same checker sampled at level 0 (bilinear, no mip levels)
        auto flat = std::make_shared<Texture>(*f.meshes[1].texture);
        flat->filter = FilterMode::Bilinear;
        level0.meshes[1].texture = level0.meshes.back().texture = flat;
        uint64_t rays = 0;
        const Framebuffer mipmapped = renderWithSwitch(f, w, h, "VIEWER_RAYCAST_PACKETS", "1", rays);
        const Framebuffer unfiltered = renderWithSwitch(level0, w, h, "VIEWER_RAYCAST_PACKETS", "1", rays);
        size_t differ = 0;
        for (size_t i = 0; i < mipmapped.color.size(); i += 4) differ += std::memcmp(&mipmapped.color[i], &unfiltered.color[i], 3) != 0;
        EXPECT_GT(differ, size_t(w * h / 20)) << "the checker is not minified enough for the footprint to matter";
    }
}

// Plain Phong hits of the tile's camera packets are shaded eight at a time in lanes (AVX2, or SSE2 twice)
// (lane_shading.h); every pixel keeps the bytes, depth, visibility and ray count that
// Tracer::trace gives it one by one: Phong and Blinn-Phong, with and without shadows and fog,
// a point light with and without 1/r^2, a spot and a sun; tinted and coloured specular, an
// emissive material, vertex colours on a mesh without normals, a mirrored instance, a plane
// seen from its back, a small mesh, a textured mesh (its texel sampled with
// the pixel's footprint, as trace() does), and one with an emissive map (never in lanes) beside
// them; analytic shapes (never in lanes: their shading is a small share of a frame, measured no
// faster in lanes) beside them: an implicit sphere, an unlit one and a CSG difference. Each light reaches hits whose shading normal faces it while their face does not (the
// lanes leave those to trace()).
TEST(RaycastTest, LaneShadingGivesTheSameImageAsTrace) {
    const int w = 160, h = 120;
    FrameInput f = triangleSceneWithBigSphere(w, h);
    f.meshes[0].material.specularTinted = true;
    f.meshes[2].material.emissive = vec3(0.05f, 0.0f, 0.1f);
    f.meshes[2].material.specularColor = vec3(1.0f, 0.6f, 0.2f);
    f.meshes[2].material.shininess = 90.0f;
    auto coloured = std::make_shared<Mesh>(primitives::uvSphere(0.5f, 48, 24));
    coloured->normals.clear();
    coloured->colors.resize(coloured->positions.size());
    for (size_t i = 0; i < coloured->colors.size(); ++i) coloured->colors[i] = vec4(0.5f + 0.5f * glm::normalize(coloured->positions[i]), 1.0f);
    DrawMesh c;
    c.mesh = coloured;
    c.world = glm::translate(mat4(1.0f), vec3(1.4f, 0.6f, 0.8f)) * glm::scale(mat4(1.0f), vec3(-1.0f, 1.2f, 1.0f));   // mirrored
    c.normal = normalMatrix(c.world);
    c.mirrored = true;
    f.meshes.push_back(c);
    DrawMesh back;   // a plane turned over above the floor: the camera sees its back
    back.mesh = std::make_shared<Mesh>(primitives::plane(1.0f, 2));
    back.world = glm::translate(mat4(1.0f), vec3(0.9f, 2.3f, -1.0f)) * glm::rotate(mat4(1.0f), 2.8f, vec3(1, 0, 0));
    back.normal = normalMatrix(back.world);
    f.meshes.push_back(back);
    DrawMesh textured = back;
    textured.world = glm::translate(mat4(1.0f), vec3(-1.8f, 0.02f, 1.2f));
    textured.normal = normalMatrix(textured.world);
    auto tex = std::make_shared<Texture>();
    tex->width = tex->height = 64;   // a fine checker: minified, so the footprint picks the level
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x)
            for (uint8_t c : {uint8_t((x ^ y) & 1 ? 230 : 20), uint8_t(x * 4), uint8_t(y * 4), uint8_t(255)}) tex->rgba.push_back(c);
    textured.texture = tex;
    f.meshes.push_back(textured);
    DrawMesh mapped = textured;
    mapped.world = glm::translate(mat4(1.0f), vec3(1.9f, 0.02f, 1.6f)) * glm::scale(mat4(1.0f), vec3(0.6f));
    mapped.normal = normalMatrix(mapped.world);
    mapped.maps.emissive = tex;
    mapped.material.emissive = vec3(0.3f);
    f.meshes.push_back(mapped);
    // Analytic shapes: an implicit sphere, an unlit one, a box with a sphere cut out of it (its
    // two leaves' materials).
    DrawAnalytic ball = implicitSphere(0.35f, vec3(0.6f, 0.35f, 1.9f));
    ball.material.baseColor = vec3(0.2f, 0.7f, 0.3f);
    ball.material.shininess = 12.0f;
    f.analytics.push_back(ball);
    DrawAnalytic unlit = implicitSphere(0.35f, vec3(-0.5f, 0.35f, 2.2f));
    unlit.material = ball.material;
    unlit.material.unlit = true;
    f.analytics.push_back(unlit);
    f.analytics.push_back(csgFrame(CsgOp::Difference).analytics[0]);
    for (CsgTree::Node& node : std::const_pointer_cast<CsgTree>(f.analytics.back().csg)->nodes) {   // smaller, off to the right
        node.world = glm::translate(mat4(1.0f), vec3(2.3f, 0.4f, -0.8f)) * glm::scale(mat4(1.0f), vec3(0.4f)) * node.world;
        node.invWorld = glm::inverse(node.world);
        node.normal = normalMatrix(node.world);
    }
    f.analytics.back().worldBounds = {vec3(1.8f, -0.1f, -1.3f), vec3(3.0f, 0.9f, -0.3f)};
    f.lights[0].inverseSquare = true;
    f.lights[0].radiance = vec3(30.0f);
    f.lights.push_back(spotOverTheSphere());
    DrawLight sun;
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(vec3(0.3f, -1.0f, -0.4f));
    sun.radiance = vec3(0.5f, 0.45f, 0.4f);
    f.lights.push_back(sun);
    DrawLight low;   // grazing: many hits where it reaches the shading normal but not the face
    low.position = vec3(-4.0f, 0.8f, 2.0f);
    low.radiance = vec3(0.3f, 0.4f, 0.9f);
    f.lights.push_back(low);
    auto render = [&](const char* lanes, uint64_t& rays) { return renderWithSwitch(f, w, h, "VIEWER_RAYCAST_LANES", lanes, rays); };
    for (ReflectionModel model : {ReflectionModel::Phong, ReflectionModel::BlinnPhong})
        for (bool shadows : {false, true})
            for (FogMode fog : {FogMode::Off, FogMode::Exp2}) {
                SCOPED_TRACE(std::string(toString(model)) + (shadows ? ", shadows" : "") + (fog != FogMode::Off ? ", fog" : ""));
                f.settings.reflection = model;
                f.settings.shadows = shadows;
                f.settings.fog = fog;
                f.settings.fogDensity = 0.08f;
                uint64_t raysOne = 0, raysLanes = 0;
                const Framebuffer one = render("0", raysOne), lanes = render("1", raysLanes);
                expectSameImage(one, lanes);
                EXPECT_EQ(raysOne, raysLanes);
                std::set<uint32_t> seen(lanes.drawable.begin(), lanes.drawable.end());   // every drawable is in the picture
                for (uint32_t d = 1; d <= f.meshes.size() + f.analytics.size(); ++d) EXPECT_TRUE(seen.count(d)) << "drawable " << d;
            }
}

// The ray caster keeps its meshes' vertices in world space across frames (WorldVertexCache):
// the same values the shading would compute per hit, so the image is the same bit for bit,
// under a rotated, non-uniformly scaled and a mirrored instance, a degenerate vertex normal and
// a mesh without normals; and a kept copy follows edits of the mesh and of its instance's matrix.
TEST(RaycastTest, WorldVertexCopiesGiveTheSameImageAndFollowEdits) {
    const int w = 160, h = 120;
    FrameInput f = triangleScene(w, h);
    auto sphere = std::make_shared<Mesh>(primitives::uvSphere(0.6f, 64, 32));   // 4k triangles: copied
    sphere->normals[100] = vec3(0.0f);                                          // the face normal there
    DrawMesh big;
    big.mesh = sphere;
    big.world = glm::translate(mat4(1.0f), vec3(-1.2f, 0.7f, 0.3f)) * glm::rotate(mat4(1.0f), 0.7f, glm::normalize(vec3(1, 2, 3))) *
                glm::scale(mat4(1.0f), vec3(1.3f, 0.6f, 0.9f));
    big.normal = normalMatrix(big.world);
    f.meshes.push_back(big);
    DrawMesh mirrored = big;   // the same mesh, mirrored: a second copy
    mirrored.world = glm::translate(mat4(1.0f), vec3(1.3f, 0.8f, 0.0f)) * glm::scale(mat4(1.0f), vec3(-1.0f, 1.0f, 1.0f));
    mirrored.normal = normalMatrix(mirrored.world);
    mirrored.mirrored = true;
    f.meshes.push_back(mirrored);
    auto bare = std::make_shared<Mesh>(primitives::uvSphere(0.3f, 32, 16));   // no vertex normals: positions only
    bare->normals.clear();
    DrawMesh noNormals;
    noNormals.mesh = bare;
    noNormals.world = glm::translate(mat4(1.0f), vec3(0.2f, 0.4f, 1.5f));
    noNormals.normal = normalMatrix(noNormals.world);
    f.meshes.push_back(noNormals);
    f.settings.shadows = true;
    auto render = [&](Renderer& r, const char* copies) {
        setenv("VIEWER_RAYCAST_WORLD_VERTICES", copies, 1);
        Framebuffer fb;
        const RenderStats st = r.render(f, w, h, fb, nullptr, RenderRequest{});
        unsetenv("VIEWER_RAYCAST_WORLD_VERTICES");
        EXPECT_TRUE(st.ok) << st.error;
        return fb;
    };
    auto kept = makeRenderer("raycast");   // keeps its copies from frame to frame
    // Two frames of the kept renderer (copies are made for instances seen unchanged in the frame
    // before, so the second one reads them), each against a new renderer's without copies.
    auto expectSame = [&](const char* what) -> Framebuffer {
        SCOPED_TRACE(what);
        auto fresh = makeRenderer("raycast");
        const Framebuffer perHit = render(*fresh, "0");
        Framebuffer copied;
        for (int frame = 0; frame < 2; ++frame) {
            copied = render(*kept, "1");
            EXPECT_EQ(perHit.color.size(), copied.color.size());
            EXPECT_TRUE(perHit.color == copied.color) << "frame " << frame;
            EXPECT_TRUE(perHit.depth == copied.depth) << "frame " << frame;
        }
        return copied;
    };
    for (ShadingModel model : {ShadingModel::Phong, ShadingModel::Gouraud, ShadingModel::Flat}) {
        SCOPED_TRACE(std::string(toString(model)));
        f.settings.shading = model;
        expectSame("first frame");
        expectSame("kept copies");
    }
    f.settings.shading = ShadingModel::Phong;
    const Framebuffer before = expectSame("before the edits");
    for (vec3& p : sphere->positions) p *= 0.8f;   // the mesh edited in place
    sphere->touch();
    const Framebuffer edited = expectSame("mesh edited");
    f.meshes[3].world = glm::translate(f.meshes[3].world, vec3(0.0f, 0.3f, 0.0f));   // an instance moved
    f.meshes[3].normal = normalMatrix(f.meshes[3].world);
    expectSame("instance moved");
    EXPECT_FALSE(before.color == edited.color);   // the edit shows
}

TEST(RaycastTest, AntiAliasingAndShadingModelsRun) {
    const int w = 64, h = 48;
    FrameInput f = triangleScene(w, h);
    auto r = makeRenderer("raycast");
    Framebuffer a, b;
    for (ShadingModel m : {ShadingModel::Flat, ShadingModel::Gouraud, ShadingModel::Phong}) {
        f.settings.shading = m;
        f.settings.aa = AAMode::None;
        ASSERT_TRUE(r->render(f, w, h, a).ok);
        f.settings.aa = AAMode::SSAA;
        f.settings.aaRate = 4;
        ASSERT_TRUE(r->render(f, w, h, b).ok);
        auto d = compareImages(a, b, 8);
        EXPECT_GT(d.fractionWithin, 0.8) << d.describe();   // AA only changes edges
    }
}

// --- shadows and reflections ---------------------------------------------------------------------

namespace {
// Mirror floor (y = 0, black unless it reflects) and a red unlit sphere at (0, 1, -3); the
// camera at (0, 1, 3) looks at the origin, whose mirror ray goes straight to the sphere.
FrameInput mirrorScene() {
    FrameInput f;
    f.settings.shadows = false;
    auto ground = std::make_shared<Mesh>(primitives::plane(10.0f, 1));
    DrawMesh g;
    g.mesh = ground;
    g.material.ka = g.material.kd = g.material.ks = 0.0f;
    g.material.reflectivity = 1.0f;
    f.meshes.push_back(g);
    DrawAnalytic s;
    s.kind = DrawAnalytic::Kind::Implicit;
    s.implicit.type = ImplicitType::Sphere;
    s.implicit.radius = 0.5f;
    s.world = glm::translate(mat4(1.0f), vec3(0, 1, -3));
    s.invWorld = glm::inverse(s.world);
    s.normal = normalMatrix(s.world);
    s.worldBounds = s.implicit.localBounds().transformed(s.world);
    s.material.unlit = true;
    s.material.baseColor = vec3(1, 0, 0);
    f.analytics.push_back(s);
    f.settings.background = vec3(0.0f);
    f.camera = makeFrameCamera(glm::inverse(glm::lookAt(vec3(0, 1, 3), vec3(0, 0, 0), vec3(0, 1, 0))), Projection{}, 1.0f, 3.0f);
    return f;
}
}   // namespace

TEST(RaycastTest, MirrorReflectionShowsTheSphere) {
    FrameInput f = mirrorScene();
    auto r = makeRenderer("raycast");
    Framebuffer on, off;
    f.settings.reflections = true;
    ASSERT_TRUE(r->render(f, 65, 65, on).ok);
    f.settings.reflections = false;
    ASSERT_TRUE(r->render(f, 65, 65, off).ok);
    const uint8_t* a = on.pixel(32, 32);
    const uint8_t* b = off.pixel(32, 32);
    EXPECT_GT(a[0], 200);   // red sphere seen in the mirror
    EXPECT_LT(a[1], 30);
    EXPECT_LT(b[0], 30);   // without reflections the floor is black
    f.settings.reflections = true;
    f.settings.maxBounces = 0;   // no bounce allowed: black again
    ASSERT_TRUE(r->render(f, 65, 65, on).ok);
    EXPECT_LT(on.pixel(32, 32)[0], 30);
}

TEST(RaycastTest, ShadowRaysDarkenOccludedPoints) {
    FrameInput f;
    auto ground = std::make_shared<Mesh>(primitives::plane(5.0f, 1));
    DrawMesh g;
    g.mesh = ground;
    g.material.ka = 0.0f;
    f.meshes.push_back(g);
    auto box = std::make_shared<Mesh>(primitives::box(vec3(0.5f)));
    DrawMesh b;
    b.mesh = box;
    b.world = glm::translate(mat4(1.0f), vec3(0, 1.5f, 0));
    b.normal = normalMatrix(b.world);
    f.meshes.push_back(b);
    DrawLight l;
    l.position = vec3(0, 5, 0);
    f.lights.push_back(l);
    f.camera = makeFrameCamera(glm::inverse(glm::lookAt(vec3(0, 2.5f, 6), vec3(0, 0, 0), vec3(0, 1, 0))), Projection{}, 1.0f, 6.0f);
    auto r = makeRenderer("raycast");
    Framebuffer with, without;
    f.settings.shadows = true;
    ASSERT_TRUE(r->render(f, 96, 96, with).ok);
    f.settings.shadows = false;
    ASSERT_TRUE(r->render(f, 96, 96, without).ok);
    // Compare the sums over the image: the shadow removes light from part of the floor only.
    testing_support::writeImage(with, "raycast", "shadow-on");
    testing_support::writeImage(without, "raycast", "shadow-off");
    long sw = 0, so = 0;
    for (size_t i = 0; i < with.color.size(); i += 4) {
        sw += with.color[i];
        so += without.color[i];
    }
    EXPECT_LT(sw, so);
    // The floor right in front of the box's foot is in its shadow (light straight above).
    rt::CameraRays rays(f.camera, 96, 96);
    vec2 w = rays.project(vec3(0, 0, 0.45f));
    int px = int(w.x), row = 96 - 1 - int(w.y);
    EXPECT_LT(int(with.pixel(px, row)[0]) + 10, int(without.pixel(px, row)[0]));
}

TEST(RaycastTest, BadMeshIsSkippedNotCrashed) {
    FrameInput f = triangleScene(32, 32);
    auto bad = std::make_shared<Mesh>(primitives::box(vec3(0.5f)));
    bad->indices[5] = 100000;   // out of range
    DrawMesh d;
    d.mesh = bad;
    f.meshes.push_back(d);
    auto nanMesh = std::make_shared<Mesh>(primitives::box(vec3(0.5f)));
    nanMesh->positions[0] = vec3(NAN);
    d.mesh = nanMesh;
    f.meshes.push_back(d);
    auto r = makeRenderer("raycast");
    Framebuffer fb;
    RenderStats s = r->render(f, 32, 32, fb);
    EXPECT_TRUE(s.ok) << s.error;
}

// --- skinned / morphed meshes ----------------------------------------------------------------

TEST(RaycastTest, PosedMeshesRebuildOnlyWhatMoved) {
    // A static box, a box skinned to one joint and a morphed box: the first update builds three
    // BVHs; a new pose rebuilds only the posed mesh that changed; a still pose builds none; and
    // rays hit the posed surface, not the bind pose.
    Scene s;
    s.meshes.push_back(std::make_shared<Mesh>(primitives::box(vec3(0.5f))));
    auto skinned = std::make_shared<Mesh>(primitives::box(vec3(0.5f)));
    skinned->joints0.assign(skinned->positions.size(), u16vec4(0));
    skinned->weights0.assign(skinned->positions.size(), vec4(1, 0, 0, 0));
    s.meshes.push_back(skinned);
    auto morphed = std::make_shared<Mesh>(primitives::box(vec3(0.5f)));
    morphed->morphTargets.resize(1);
    morphed->morphTargets[0].positions.assign(morphed->positions.size(), vec3(0, 3, 0));
    s.meshes.push_back(morphed);
    NodeId joint = s.addNode("joint");
    s.skins.push_back(Skin{"skin", {joint}, {mat4(1.0f)}, kNoNode});
    s.addNode("static", s.root(), MeshInstance{0, -1});
    MeshInstance si{1, -1};
    si.skin = 0;
    NodeId parked = s.addNode("parked far away");   // the skinned node's own transform is ignored
    s.setLocal(parked, LocalTransform::fromTRS(vec3(100, 0, 0)));
    s.addNode("skinned", parked, si);
    MeshInstance mi{2, -1};
    mi.weights = {0.0f};
    NodeId morphNode = s.addNode("morphed", s.root(), mi);
    s.setLocal(morphNode, LocalTransform::fromTRS(vec3(0, 0, -10)));

    SceneAccel acc;
    s.setLocal(joint, LocalTransform::fromTRS(vec3(5, 0, 0)));
    std::get<MeshInstance>(s.editPayload(morphNode)).weights = {1.0f};
    FrameInput f1 = flatten(s, 1.0f);
    EXPECT_EQ(acc.update(f1), 3);
    SceneHit h;
    ASSERT_TRUE(acc.intersect(mkRay({5, 10, 0}, {0, -1, 0}), h));   // skinned box moved to x = 5
    EXPECT_NEAR(h.t, 9.5f, 1e-4f);
    EXPECT_FALSE(acc.intersect(mkRay({100, 10, 0}, {0, -1, 0}), h));
    ASSERT_TRUE(acc.intersect(mkRay({0, 10, -10}, {0, -1, 0}), h));   // morphed box lifted by 3
    EXPECT_NEAR(h.t, 6.5f, 1e-4f);

    FrameInput f2 = flatten(s, 1.0f);   // still pose
    EXPECT_EQ(acc.update(f2), 0);
    s.setLocal(joint, LocalTransform::fromTRS(vec3(-5, 0, 0)));   // only the skin moves
    FrameInput f3 = flatten(s, 1.0f);
    EXPECT_EQ(acc.update(f3), 1);
    ASSERT_TRUE(acc.intersect(mkRay({-5, 10, 0}, {0, -1, 0}), h));
    EXPECT_NEAR(h.t, 9.5f, 1e-4f);
    s.setLocal(morphNode, LocalTransform::fromTRS(vec3(0, 0, -20)));   // a morphed node moving is a transform
    EXPECT_EQ(acc.update(flatten(s, 1.0f)), 0);
}
