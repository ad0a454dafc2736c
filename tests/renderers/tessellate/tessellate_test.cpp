// tessellate_test.cpp - meshes for analytic drawables: closed where they should be (every
// edge shared by exactly two triangles, in opposite directions, after welding by position),
// outward normals and counter-clockwise winding, vertices on the surface, volumes close to
// the analytic ones, CSG faces carrying their leaf's material, parametric vertices equal to
// evaluate(u, v), the sg::primitives winding, the cache, and a rebuild's progress and cancel.
// Set TESS_DUMP_DIR=/tmp/x to write every tested mesh as an .obj for inspection.
#include "renderers/tessellate.h"

#include "assets/demo.h"
#include "renderers/draw_list.h"
#include "scenegraph/transforms.h"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

using namespace sg;
using rnd::Tessellation;

namespace {

constexpr float kTau = 2.0f * kPi;

void dumpObj(const Mesh& m, const std::string& name) {
    const char* dir = std::getenv("TESS_DUMP_DIR");
    if (!dir) return;
    std::ofstream f(std::string(dir) + "/" + name + ".obj");
    for (const vec3& p : m.positions) f << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    for (const vec3& n : m.normals) f << "vn " << n.x << ' ' << n.y << ' ' << n.z << '\n';
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3)
        f << "f " << m.indices[i] + 1 << "//" << m.indices[i] + 1 << ' ' << m.indices[i + 1] + 1 << "//" << m.indices[i + 1] + 1 << ' '
          << m.indices[i + 2] + 1 << "//" << m.indices[i + 2] + 1 << '\n';
}

struct Topology {
    size_t weldedVertices = 0;
    size_t degenerate = 0;   // triangles with two welded corners equal
    size_t badEdges = 0;     // undirected edges not used exactly twice in opposite directions
    size_t edges = 0;
    long euler = 0;   // V - E + F
};

// Welds by exact position, then checks that every directed edge has exactly one twin.
Topology topology(const Mesh& m) {
    std::map<std::array<float, 3>, uint32_t> weld;
    std::vector<uint32_t> id(m.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
        const vec3& p = m.positions[i];
        id[i] = weld.try_emplace({p.x, p.y, p.z}, uint32_t(weld.size())).first->second;
    }
    Topology t;
    t.weldedVertices = weld.size();
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    size_t faces = 0;
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        uint32_t v[3] = {id[m.indices[i]], id[m.indices[i + 1]], id[m.indices[i + 2]]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
            ++t.degenerate;
            continue;
        }
        ++faces;
        for (int k = 0; k < 3; ++k) ++directed[{v[k], v[(k + 1) % 3]}];
    }
    for (const auto& [e, n] : directed) {
        auto twin = directed.find({e.second, e.first});
        int tn = twin == directed.end() ? 0 : twin->second;
        if (n != 1 || tn != 1) ++t.badEdges;
        if (e.first < e.second || tn == 0) ++t.edges;
    }
    t.euler = long(t.weldedVertices) - long(t.edges) + long(faces);
    return t;
}

::testing::AssertionResult closed(const Mesh& m) {
    Topology t = topology(m);
    if (m.indices.empty()) return ::testing::AssertionFailure() << "empty mesh";
    if (t.degenerate || t.badEdges)
        return ::testing::AssertionFailure() << t.badEdges << " bad edges, " << t.degenerate << " degenerate triangles of " << m.triangleCount();
    return ::testing::AssertionSuccess();
}

double signedVolume(const Mesh& m) {
    double v = 0;
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        glm::dvec3 a(m.positions[m.indices[i]]), b(m.positions[m.indices[i + 1]]), c(m.positions[m.indices[i + 2]]);
        v += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    return v;
}

// Fraction of triangles whose geometric normal agrees with the sum of their vertex normals.
double windingAgreement(const Mesh& m) {
    size_t good = 0, n = 0;
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        uint32_t a = m.indices[i], b = m.indices[i + 1], c = m.indices[i + 2];
        vec3 f = glm::cross(m.positions[b] - m.positions[a], m.positions[c] - m.positions[a]);
        if (glm::length(f) < 1e-12f) continue;
        ++n;
        if (glm::dot(f, m.normals[a] + m.normals[b] + m.normals[c]) > 0) ++good;
    }
    return n ? double(good) / double(n) : 0.0;
}

DrawAnalytic implicitDrawable(const ImplicitShape& s) {
    DrawAnalytic a;
    a.kind = DrawAnalytic::Kind::Implicit;
    a.implicit = s;
    return a;
}

void expectValidMesh(const Tessellation& t) {
    ASSERT_TRUE(t.mesh);
    EXPECT_EQ(t.mesh->validate(), "");
    EXPECT_EQ(t.mesh->normals.size(), t.mesh->positions.size());
    for (const vec3& n : t.mesh->normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-3f);
}

struct PrimitiveCase {
    const char* name;
    ImplicitShape shape;
    double volume;
    bool convex;
    bool closed;
};

std::vector<PrimitiveCase> primitiveCases() {
    std::vector<PrimitiveCase> c;
    ImplicitShape s;
    s.type = ImplicitType::Sphere;
    s.radius = 0.7f;
    c.push_back({"sphere", s, 4.0 / 3.0 * kPi * 0.343, true, true});
    s = {};
    s.type = ImplicitType::Box;
    s.halfExtents = vec3(0.5f, 1.0f, 1.5f);
    c.push_back({"box", s, 6.0, true, true});
    s = {};
    s.type = ImplicitType::Cylinder;
    s.radius = 0.6f;
    s.halfHeight = 0.8f;
    c.push_back({"cylinder", s, kPi * 0.36 * 1.6, true, true});
    s = {};
    s.type = ImplicitType::Cone;
    s.radius = 0.7f;
    s.halfHeight = 0.9f;
    c.push_back({"cone", s, kPi * 0.49 * 1.8 / 3.0, true, true});
    s = {};
    s.type = ImplicitType::Torus;
    s.majorRadius = 1.0f;
    s.minorRadius = 0.3f;
    c.push_back({"torus", s, 2.0 * kPi * kPi * 1.0 * 0.09, false, true});
    s = {};
    s.type = ImplicitType::Plane;
    s.planeHalfSize = 3.0f;
    c.push_back({"plane", s, 0.0, false, false});
    return c;
}

}   // namespace

// --- analytic primitives ------------------------------------------------------------------

TEST(TessellateTest, PrimitivesAreClosedOutwardAndOnTheSurface) {
    for (int res : {8, 17, 64}) {
        for (const PrimitiveCase& c : primitiveCases()) {
            SCOPED_TRACE(::testing::Message() << c.name << " res " << res);
            Tessellation t = rnd::tessellate(implicitDrawable(c.shape), res);
            expectValidMesh(t);
            const Mesh& m = *t.mesh;
            EXPECT_FALSE(t.worldSpace);
            EXPECT_TRUE(t.triangleMaterial.empty());
            EXPECT_EQ(m.uv0.size(), m.positions.size());
            if (res == 64) dumpObj(m, c.name);
            if (c.closed) {
                EXPECT_TRUE(closed(m));
                EXPECT_EQ(topology(m).euler, c.shape.type == ImplicitType::Torus ? 0 : 2);
                double v = signedVolume(m);
                // Inscribed polyhedra lose O(1/res^2) of the volume.
                double tol = res >= 64 ? 0.01 : res >= 17 ? 0.15 : 0.5;
                EXPECT_NEAR(v / c.volume, 1.0, tol);
            }
            EXPECT_EQ(windingAgreement(m), 1.0);
            for (size_t i = 0; i < m.positions.size(); ++i) {
                const vec3& p = m.positions[i];
                ASSERT_LT(std::abs(c.shape.value(p)), 1e-5f) << "vertex off the surface " << p.x << ' ' << p.y << ' ' << p.z;
                if (c.convex) {
                    ASSERT_GT(glm::dot(m.normals[i], p), 0.0f);
                    // Smooth normals equal the analytic ones (where those are defined everywhere).
                    if (c.shape.type == ImplicitType::Sphere) { ASSERT_GT(glm::dot(m.normals[i], c.shape.normal(p * 0.999f)), 0.99f); }
                }
            }
            if (c.convex) {
                // Face normals point away from the centre too.
                for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
                    vec3 a = m.positions[m.indices[i]], b = m.positions[m.indices[i + 1]], d = m.positions[m.indices[i + 2]];
                    ASSERT_GT(glm::dot(glm::cross(b - a, d - a), (a + b + d) / 3.0f), 0.0f);
                }
            }
        }
    }
}

TEST(TessellateTest, TorusNormalsPointAwayFromTheTubeCentre) {
    ImplicitShape s;
    s.type = ImplicitType::Torus;
    s.majorRadius = 1.2f;
    s.minorRadius = 0.4f;
    Tessellation t = rnd::tessellate(implicitDrawable(s), 32);
    const Mesh& m = *t.mesh;
    for (size_t i = 0; i < m.positions.size(); ++i) {
        vec3 p = m.positions[i];
        vec3 ring = 1.2f * glm::normalize(vec3(p.x, 0, p.z));
        ASSERT_GT(glm::dot(m.normals[i], glm::normalize(p - ring)), 0.999f);
    }
}

TEST(TessellateTest, PlaneFacesUpAndCoversItsSquare) {
    ImplicitShape s;
    s.type = ImplicitType::Plane;
    s.planeHalfSize = 2.5f;
    Tessellation t = rnd::tessellate(implicitDrawable(s), 10);
    const Mesh& m = *t.mesh;
    EXPECT_EQ(m.triangleCount(), 200u);
    Aabb b = m.bounds();
    EXPECT_EQ(b.min, vec3(-2.5f, 0, -2.5f));
    EXPECT_EQ(b.max, vec3(2.5f, 0, 2.5f));
    double area = 0;
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        vec3 f = glm::cross(m.positions[m.indices[i + 1]] - m.positions[m.indices[i]], m.positions[m.indices[i + 2]] - m.positions[m.indices[i]]);
        EXPECT_GT(f.y, 0.0f);
        area += 0.5 * glm::length(f);
    }
    EXPECT_NEAR(area, 25.0, 1e-3);
}

// The generators in sg::primitives (used by the demo scene): stored normals agree with the
// triangle winding, and the closed ones enclose a positive volume.
TEST(TessellateTest, SgPrimitivesWindingMatchesNormals) {
    struct Case {
        const char* name;
        Mesh m;
        double volume;
    };
    std::vector<Case> cases;
    cases.push_back({"box", primitives::box(vec3(0.5f, 1, 2)), 8.0});
    cases.push_back({"plane", primitives::plane(2, 4), 0});
    cases.push_back({"uvSphere", primitives::uvSphere(1, 32, 16), 4.0 / 3.0 * kPi});
    cases.push_back({"cylinder", primitives::cylinder(1, 1, 32, true), 2 * kPi});
    cases.push_back({"cylinder open", primitives::cylinder(1, 1, 32, false), 0});
    cases.push_back({"cone", primitives::cone(1, 1, 32, true), 2 * kPi / 3});
    cases.push_back({"torus", primitives::torus(1, 0.25f, 32, 16), 2 * kPi * kPi * 0.0625});
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        EXPECT_EQ(c.m.validate(), "");
        EXPECT_EQ(windingAgreement(c.m), 1.0);
        // Each triangle's face normal also agrees with every one of its stored normals
        // (not just their sum), except at the cone apex where normals fan out.
        for (size_t i = 0; i + 2 < c.m.indices.size(); i += 3) {
            uint32_t a = c.m.indices[i], b = c.m.indices[i + 1], d = c.m.indices[i + 2];
            vec3 f = glm::cross(c.m.positions[b] - c.m.positions[a], c.m.positions[d] - c.m.positions[a]);
            if (glm::length(f) < 1e-9f) continue;
            for (uint32_t k : {a, b, d}) { ASSERT_GT(glm::dot(f, c.m.normals[k]), 0.0f) << "triangle " << i / 3; }
        }
        if (c.volume > 0) {
            EXPECT_NEAR(signedVolume(c.m) / c.volume, 1.0, 0.05);   // coarse: 32 segments
        }
    }
}

// --- marched surfaces ---------------------------------------------------------------------

TEST(TessellateTest, QuadricSphereIsClosedAndOnTheSurface) {
    ImplicitShape q;
    q.type = ImplicitType::Quadric;
    float r = 0.8f;
    q.quadric = mat4(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -r * r);
    q.quadricBounds = {vec3(-1.0f), vec3(1.0f)};
    Tessellation t = rnd::tessellate(implicitDrawable(q), 48);
    expectValidMesh(t);
    const Mesh& m = *t.mesh;
    dumpObj(m, "quadric_sphere");
    EXPECT_TRUE(closed(m));
    EXPECT_EQ(topology(m).euler, 2);
    EXPECT_NEAR(signedVolume(m) / (4.0 / 3.0 * kPi * r * r * r), 1.0, 0.01);
    for (size_t i = 0; i < m.positions.size(); ++i) {
        ASSERT_LT(std::abs(glm::length(m.positions[i]) - r), 1e-4f);
        ASSERT_GT(glm::dot(m.normals[i], glm::normalize(m.positions[i])), 0.9999f);
    }
    EXPECT_GT(windingAgreement(m), 0.999);
}

TEST(TessellateTest, ClippedHyperboloidIsClosed) {
    // The demo's hyperboloid of one sheet x^2 + z^2 - y^2 = r^2, clipped by its box: a closed
    // solid (tube wall plus two caps).
    ImplicitShape q;
    q.type = ImplicitType::Quadric;
    float r2 = 0.16f;
    q.quadric = mat4(1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -r2);
    q.quadricBounds = {vec3(-0.75f, -0.7f, -0.75f), vec3(0.75f, 0.7f, 0.75f)};
    Tessellation t = rnd::tessellate(implicitDrawable(q), 64);
    expectValidMesh(t);
    const Mesh& m = *t.mesh;
    dumpObj(m, "hyperboloid");
    EXPECT_TRUE(closed(m));
    // Volume of x^2+z^2 <= r^2 + y^2 for |y| <= 0.7: pi (r^2 * 1.4 + 2 * 0.7^3 / 3).
    double v = kPi * (r2 * 1.4 + 2.0 * 0.343 / 3.0);
    EXPECT_NEAR(signedVolume(m) / v, 1.0, 0.02);
    for (const vec3& p : m.positions) ASSERT_LT(std::abs(q.value(p)), 1e-4f);
    EXPECT_GT(windingAgreement(m), 0.99);
}

TEST(TessellateTest, MetaballsAreClosed) {
    auto grid = std::make_shared<DensityGrid>(DensityGrid::metaballs(40));
    DrawAnalytic a;
    a.kind = DrawAnalytic::Kind::Grid;
    a.grid = grid;
    Tessellation t = rnd::tessellate(a, 64);
    expectValidMesh(t);
    const Mesh& m = *t.mesh;
    dumpObj(m, "metaballs");
    EXPECT_FALSE(t.worldSpace);
    EXPECT_TRUE(closed(m));
    EXPECT_GT(signedVolume(m), 0.2);
    EXPECT_GT(windingAgreement(m), 0.99);
    for (size_t i = 0; i < m.positions.size(); ++i) {
        const vec3& p = m.positions[i];
        ASSERT_LT(std::abs(grid->sample(p) - grid->isoValue), 1e-3f * grid->isoValue);
        // Outward = towards lower density.
        ASSERT_LT(glm::dot(m.normals[i], grid->gradient(p)), 0.0f);
    }
    // A sparse grid too (the grid's own resolution far below the tessellation).
    a.grid = std::make_shared<DensityGrid>(DensityGrid::metaballs(12));
    EXPECT_TRUE(closed(*rnd::tessellate(a, 50).mesh));
}

TEST(TessellateTest, GridTouchingItsBoundsIsClosedByTheBounds) {
    // Everything inside: the surface is the bounding box itself.
    auto grid = std::make_shared<DensityGrid>();
    grid->dims = ivec3(4);
    grid->values.assign(64, 2.0f);
    grid->isoValue = 1.0f;
    DrawAnalytic a;
    a.kind = DrawAnalytic::Kind::Grid;
    a.grid = grid;
    Tessellation t = rnd::tessellate(a, 16);
    EXPECT_TRUE(closed(*t.mesh));
    EXPECT_NEAR(signedVolume(*t.mesh), 8.0, 0.1);
    // Bad grids give an empty mesh, not a crash.
    grid->values.resize(10);
    EXPECT_EQ(rnd::tessellate(a, 16).mesh->triangleCount(), 0u);
}

namespace {

// CSG tree builder for the tests: leaves in world space.
struct CsgBuilder {
    std::shared_ptr<CsgTree> tree = std::make_shared<CsgTree>();
    int leaf(const ImplicitShape& s, const mat4& world, const std::string& material) {
        CsgTree::Node n;
        n.shape = s;
        n.world = world;
        n.invWorld = glm::inverse(world);
        n.normal = normalMatrix(world);
        n.material.name = material;
        tree->nodes.push_back(n);
        return int(tree->nodes.size() - 1);
    }
    int op(CsgOp o, std::vector<int> children) {
        CsgTree::Node n;
        n.op = int(o);
        n.children = std::move(children);
        tree->nodes.push_back(n);
        return int(tree->nodes.size() - 1);
    }
    DrawAnalytic drawable(int root) {
        tree->root = root;
        DrawAnalytic a;
        a.kind = DrawAnalytic::Kind::Csg;
        a.csg = tree;
        return a;
    }
};

ImplicitShape box(vec3 h) {
    ImplicitShape s;
    s.type = ImplicitType::Box;
    s.halfExtents = h;
    return s;
}
ImplicitShape sphere(float r) {
    ImplicitShape s;
    s.type = ImplicitType::Sphere;
    s.radius = r;
    return s;
}

}   // namespace

TEST(TessellateTest, CsgBoxMinusSphereHasTheCuttersMaterialAndVolume) {
    // Box [-1,1]^3 minus a sphere of radius 0.6 centred on the top face: a hemispherical
    // scoop. The sphere is a scaled leaf (local radius 0.3, world scale 2).
    CsgBuilder b;
    int blk = b.leaf(box(vec3(1.0f)), mat4(1.0f), "block");
    int cut = b.leaf(sphere(0.3f), translation(vec3(0, 1, 0)) * scaling(vec3(2.0f)), "cutter");
    DrawAnalytic a = b.drawable(b.op(CsgOp::Difference, {blk, cut}));
    Tessellation t = rnd::tessellate(a, 64);
    expectValidMesh(t);
    const Mesh& m = *t.mesh;
    dumpObj(m, "csg_box_minus_sphere");
    EXPECT_TRUE(t.worldSpace);
    EXPECT_TRUE(closed(m));
    EXPECT_EQ(topology(m).euler, 2);
    double v = 8.0 - 2.0 / 3.0 * kPi * 0.216;
    EXPECT_NEAR(signedVolume(m) / v, 1.0, 0.01);
    ASSERT_EQ(t.triangleMaterial.size(), m.triangleCount());
    ASSERT_EQ(t.materials.size(), 2u);
    size_t onCutter = 0, onBlock = 0;
    for (size_t i = 0; i < m.triangleCount(); ++i) {
        vec3 p[3];
        for (int k = 0; k < 3; ++k) p[k] = m.positions[m.indices[3 * i + k]];
        vec3 c = (p[0] + p[1] + p[2]) / 3.0f;
        const std::string& mat = t.materials.at(t.triangleMaterial[i]).name;
        float dSphere = std::abs(glm::length(c - vec3(0, 1, 0)) - 0.6f);
        float dBox = std::abs(box(vec3(1.0f)).value(c));
        if (dSphere < 1e-3f && dBox > 0.05f) {
            ++onCutter;
            EXPECT_EQ(mat, "cutter");
            // Normals of the scoop point into the sphere (out of the solid).
            for (int k = 0; k < 3; ++k) {
                vec3 n = m.normals[m.indices[3 * i + k]];
                EXPECT_GT(glm::dot(n, glm::normalize(vec3(0, 1, 0) - p[k])), 0.99f);
            }
        } else if (dBox < 1e-3f && dSphere > 0.05f) {
            ++onBlock;
            EXPECT_EQ(mat, "block");
        }
    }
    EXPECT_GT(onCutter, 100u);
    EXPECT_GT(onBlock, 1000u);
    // Every vertex lies on the solid's surface.
    for (const vec3& p : m.positions) {
        float f = std::max(box(vec3(1.0f)).value(p), -(glm::length(p - vec3(0, 1, 0)) - 0.6f));
        ASSERT_LT(std::abs(f), 1e-4f);
    }
    EXPECT_GT(windingAgreement(m), 0.99);
}

TEST(TessellateTest, CsgUnionAndIntersectionVolumes) {
    {   // Two disjoint spheres.
        CsgBuilder b;
        int s1 = b.leaf(sphere(0.5f), translation(vec3(-1, 0, 0)), "a");
        int s2 = b.leaf(sphere(0.5f), translation(vec3(1, 0, 0)), "b");
        Tessellation t = rnd::tessellate(b.drawable(b.op(CsgOp::Union, {s1, s2})), 64);
        EXPECT_TRUE(closed(*t.mesh));
        EXPECT_EQ(topology(*t.mesh).euler, 4);   // two spheres
        EXPECT_NEAR(signedVolume(*t.mesh) / (2 * 4.0 / 3.0 * kPi * 0.125), 1.0, 0.02);
    }
    {   // Box [-1,1]^3 intersected with the sphere of radius 1.2: a rounded cube.
        CsgBuilder b;
        int bx = b.leaf(box(vec3(1.0f)), mat4(1.0f), "box");
        int sp = b.leaf(sphere(1.2f), mat4(1.0f), "sphere");
        Tessellation t = rnd::tessellate(b.drawable(b.op(CsgOp::Intersection, {bx, sp})), 64);
        dumpObj(*t.mesh, "csg_intersection");
        EXPECT_TRUE(closed(*t.mesh));
        // Sphere volume minus 6 caps of height 0.2: V_cap = pi h^2 (3R - h) / 3.
        double cap = kPi * 0.04 * (3.6 - 0.2) / 3.0;
        double v = 4.0 / 3.0 * kPi * 1.728 - 6 * cap;
        EXPECT_NEAR(signedVolume(*t.mesh) / v, 1.0, 0.01);
    }
    {   // Nested: (box - sphere) - cylinder, with a rotated cylinder leaf.
        CsgBuilder b;
        int bx = b.leaf(box(vec3(1.0f)), mat4(1.0f), "box");
        int sp = b.leaf(sphere(0.5f), mat4(1.0f), "sphere");
        ImplicitShape cyl;
        cyl.type = ImplicitType::Cylinder;
        cyl.radius = 0.3f;
        cyl.halfHeight = 2.0f;
        int cy = b.leaf(cyl, rotationX(kPi / 2), "drill");
        int inner = b.op(CsgOp::Difference, {bx, sp});
        Tessellation t = rnd::tessellate(b.drawable(b.op(CsgOp::Difference, {inner, cy})), 64);
        dumpObj(*t.mesh, "csg_nested");
        EXPECT_TRUE(closed(*t.mesh));
        EXPECT_GT(signedVolume(*t.mesh), 8.0 - 4.0 / 3.0 * kPi * 0.125 - kPi * 0.09 * 2.0 - 0.05);
        EXPECT_LT(signedVolume(*t.mesh), 8.0 - 4.0 / 3.0 * kPi * 0.125);
        std::set<std::string> mats;
        for (uint16_t i : t.triangleMaterial) mats.insert(t.materials.at(i).name);
        EXPECT_EQ(mats, (std::set<std::string>{"box", "sphere", "drill"}));
    }
}

// --- parametric ---------------------------------------------------------------------------

TEST(TessellateTest, ParametricPatchVerticesAreEvaluations) {
    DrawAnalytic a;
    a.kind = DrawAnalytic::Kind::Parametric;
    a.parametric = ParametricSurface::defaultPatch();
    const int res = 20;
    Tessellation t = rnd::tessellate(a, res);
    expectValidMesh(t);
    const Mesh& m = *t.mesh;
    ASSERT_EQ(m.positions.size(), size_t((res + 1) * (res + 1)));
    EXPECT_EQ(m.triangleCount(), size_t(2 * res * res));
    for (size_t i = 0; i < m.positions.size(); ++i) {
        vec2 uv = m.uv0[i];
        vec3 p = a.parametric.evaluate(uv.x, uv.y);
        ASSERT_LT(glm::distance(p, m.positions[i]), 1e-6f);
        ASSERT_GT(glm::dot(m.normals[i], a.parametric.normal(uv.x, uv.y)), 0.9999f);
    }
    // The grid's corners are the patch's corners, and every (i/res, j/res) appears.
    std::set<std::pair<int, int>> seen;
    for (vec2 uv : m.uv0) seen.insert({int(std::lround(uv.x * res)), int(std::lround(uv.y * res))});
    EXPECT_EQ(seen.size(), size_t((res + 1) * (res + 1)));
    EXPECT_EQ(windingAgreement(m), 1.0);
}

TEST(TessellateTest, ParametricTorusIsClosedAndOutward) {
    DrawAnalytic a;
    a.kind = DrawAnalytic::Kind::Parametric;
    a.parametric.type = ParametricType::Torus;
    a.parametric.majorRadius = 1.0f;
    a.parametric.minorRadius = 0.3f;
    Tessellation t = rnd::tessellate(a, 48);
    EXPECT_TRUE(closed(*t.mesh));
    EXPECT_NEAR(signedVolume(*t.mesh) / (2 * kPi * kPi * 0.09), 1.0, 0.01);
    for (size_t i = 0; i < t.mesh->positions.size(); ++i)
        ASSERT_LT(glm::distance(t.mesh->positions[i], a.parametric.evaluate(t.mesh->uv0[i].x, t.mesh->uv0[i].y)), 1e-5f);
}

// --- demo scene and cache -----------------------------------------------------------------

TEST(TessellateTest, DemoSceneAnalyticsTessellate) {
    Scene s = assets::makeDemoScene();
    FrameInput f = flatten(s, 1.0f);
    ASSERT_FALSE(f.analytics.empty());
    int csgCount = 0;
    for (const DrawAnalytic& a : f.analytics) {
        Tessellation t = rnd::tessellate(a, 64);
        SCOPED_TRACE(s.node(a.node).name);
        expectValidMesh(t);
        EXPECT_GT(t.mesh->triangleCount(), 0u);
        dumpObj(*t.mesh, (std::ostringstream() << "demo_" << a.node).str());
        bool closedKind = !(a.kind == DrawAnalytic::Kind::Parametric && a.parametric.type == ParametricType::BezierPatch) &&
                          !(a.kind == DrawAnalytic::Kind::Implicit && a.implicit.type == ImplicitType::Plane);
        if (closedKind) {
            EXPECT_TRUE(closed(*t.mesh));
            EXPECT_GT(signedVolume(*t.mesh), 0.0);
        }
        if (a.kind == DrawAnalytic::Kind::Csg) {
            ++csgCount;
            EXPECT_TRUE(t.worldSpace);
            EXPECT_EQ(t.triangleMaterial.size(), t.mesh->triangleCount());
            // The mesh lies within the CSG's world bounds (up to the marching tolerance).
            Aabb mb = t.mesh->bounds();
            EXPECT_TRUE(glm::all(glm::greaterThanEqual(mb.min, a.worldBounds.min - vec3(1e-3f))));
            EXPECT_TRUE(glm::all(glm::lessThanEqual(mb.max, a.worldBounds.max + vec3(1e-3f))));
        }
    }
    EXPECT_EQ(csgCount, 1);
}

TEST(TessellateTest, CacheReusesAndEvicts) {
    rnd::TessellationCache cache;
    DrawAnalytic a = implicitDrawable(sphere(1.0f));
    a.geometryKey = 42;
    const Tessellation& t1 = cache.get(a, 16);
    const Tessellation& t2 = cache.get(a, 16);
    EXPECT_EQ(t1.mesh.get(), t2.mesh.get());
    EXPECT_NE(cache.get(a, 32).mesh.get(), t1.mesh.get());
    EXPECT_EQ(cache.size(), 2u);
    for (int i = 0; i < 3; ++i) cache.nextFrame(2);
    EXPECT_EQ(cache.size(), 0u);
    // Concurrent users get the same tessellation.
    std::vector<std::thread> threads;
    std::vector<const sg::Mesh*> got(8);
    for (int i = 0; i < 8; ++i) threads.emplace_back([&, i] { got[i] = cache.get(a, 24).mesh.get(); });
    for (auto& th : threads) th.join();
    for (auto* p : got) EXPECT_EQ(p, got[0]);
    EXPECT_EQ(cache.size(), 1u);
}

// A rebuild at a high level takes seconds (marching is resolution^3): each shape reports the
// share of its work done, strictly increasing and ending at 1, many times for the marched
// ones (per slice of the sampling and of the polygonization), and the cached mesh is the one
// made without a report.
TEST(TessellateTest, RebuildReportsItsProgress) {
    Scene s = assets::makeDemoScene();
    FrameInput f = flatten(s, 1.0f);
    constexpr int kLevel = 48;
    int marchedShapes = 0;
    for (const DrawAnalytic& a : f.analytics) {
        SCOPED_TRACE(s.node(a.node).name);
        std::vector<float> shares;
        rnd::TessellationProgress progress;
        progress.report = [&](float share) { shares.push_back(share); };
        rnd::TessellationCache cache;
        const Tessellation& t = cache.get(a, kLevel, &progress);
        ASSERT_TRUE(t.mesh);
        EXPECT_EQ(t.mesh->positions, rnd::tessellate(a, kLevel).mesh->positions);
        ASSERT_FALSE(shares.empty());
        for (size_t i = 1; i < shares.size(); ++i) ASSERT_GT(shares[i], shares[i - 1]) << "report " << i;
        EXPECT_GT(shares.front(), 0.0f);
        EXPECT_EQ(shares.back(), 1.0f);
        const bool marched = rnd::tessellationWork(a, kLevel) > double(kLevel) * kLevel;
        if (marched) {
            ++marchedShapes;
            EXPECT_GT(shares.size(), size_t(kLevel)) << "per slice";
        }
        EXPECT_TRUE(cache.contains(a, kLevel));
        EXPECT_FALSE(cache.contains(a, kLevel + 1));
    }
    EXPECT_EQ(marchedShapes, 3) << "the demo's quadric, CSG and metaballs";
}

// A rebuild stopped part-way (a newer setting replaced it) returns no mesh and caches none;
// the next request tessellates in full.
TEST(TessellateTest, CancelledRebuildKeepsNothing) {
    Scene s = assets::makeDemoScene();
    FrameInput f = flatten(s, 1.0f);
    const DrawAnalytic* csg = nullptr;
    for (const DrawAnalytic& a : f.analytics)
        if (a.kind == DrawAnalytic::Kind::Csg) csg = &a;
    ASSERT_NE(csg, nullptr);
    std::atomic<bool> cancel{false};
    rnd::TessellationProgress progress;
    progress.cancel = &cancel;
    float last = 0.0f;
    progress.report = [&](float share) {
        last = share;
        if (share > 0.2f) cancel = true;   // part-way through the sampling
    };
    rnd::TessellationCache cache;
    EXPECT_FALSE(cache.get(*csg, 64, &progress).mesh);
    EXPECT_LT(last, 0.85f) << "stopped before polygonizing it all";
    EXPECT_FALSE(cache.contains(*csg, 64));
    EXPECT_EQ(cache.size(), 0u);
    EXPECT_FALSE(rnd::tessellate(*csg, 64, &progress).mesh) << "still cancelled";
    const Tessellation& t = cache.get(*csg, 64);
    ASSERT_TRUE(t.mesh);
    EXPECT_GT(t.mesh->triangleCount(), 0u);
}

// prepareDraws tessellates the shapes missing from the cache as the render's Shapes stage,
// its progress weighed over all of them, then hands the progress back to the image at 0; a
// cancel part-way stops it with the rest left out of the cache.
TEST(TessellateTest, PrepareDrawsReportsTheShapesStage) {
    Scene s = assets::makeDemoScene();
    FrameInput f = flatten(s, 1.0f);
    rnd::TessellationCache cache;
    rnd::RenderControl control;
    std::atomic<bool> done{false};
    std::vector<std::pair<rnd::RenderStage, float>> seen;
    std::thread watch([&] {   // as the viewer's UI thread polls a render in flight
        while (!done) {
            seen.emplace_back(control.stage.load(), control.progress.load());
            std::this_thread::sleep_for(std::chrono::microseconds(50));
        }
    });
    const std::vector<rnd::PreparedDraw> draws = rnd::prepareDraws(f, 96, cache, &control);
    done = true;
    watch.join();
    EXPECT_EQ(draws.size(), f.meshes.size() + f.analytics.size());
    EXPECT_EQ(control.stage.load(), rnd::RenderStage::Image);
    EXPECT_EQ(control.progress.load(), 0.0f);
    float last = 0.0f;
    int distinct = 0;
    for (auto [stage, p] : seen) {
        if (stage != rnd::RenderStage::Shapes) continue;
        ASSERT_GE(p, last) << "the shapes' progress never goes back";
        distinct += p > last;
        last = p;
    }
    EXPECT_GT(distinct, 5) << seen.size() << " samples";
    // Everything cached now: no Shapes stage, the progress left alone.
    control.progress = 0.5f;
    rnd::prepareDraws(f, 96, cache, &control);
    EXPECT_EQ(control.stage.load(), rnd::RenderStage::Image);
    EXPECT_EQ(control.progress.load(), 0.5f);
    // Cancelled before it starts: nothing more is cached, the list stops short.
    rnd::RenderControl cancelled;
    cancelled.cancel = true;
    const size_t before = cache.size();
    EXPECT_LT(rnd::prepareDraws(f, 97, cache, &cancelled).size(), f.meshes.size() + f.analytics.size());
    EXPECT_EQ(cache.size(), before);
}
