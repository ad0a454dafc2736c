// tessellate.cpp - triangle meshes for analytic drawables (see tessellate.h).
//
// Sections:
//   1. helpers (mesh building, exact trig tables)
//   2. analytic primitives: sphere, box, cylinder, cone, torus, plane (parametric grids whose
//      seams and poles are bit-exact, so the meshes are watertight after welding by position)
//   3. parametric surfaces
//   4. scalar fields: quadric, density grid, CSG tree (with the leaf that owns the surface)
//   5. marching tetrahedra (Freudenthal split of each cube into 6 tetrahedra: no ambiguous
//      cases, so the surface is closed and manifold by construction), vertex refinement by
//      the Illinois variant of regula falsi on the exact function, gradient normals
//   6. tessellate() dispatch and TessellationCache
//
// Progress: marching reports per z slice of the sampling and of the polygonization and per
// block of vertices refined and given normals (the bulk of the work at high resolutions), and
// stops between slices when cancelled (TessellationProgress).
//
// Orientation: every triangle is counter-clockwise seen from outside (its geometric normal
// cross(p1-p0, p2-p0) points out of the solid), and vertex normals point outward.
#include "renderers/tessellate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <array>
#include <functional>
#include <mutex>
#include <unordered_map>

namespace rnd {

namespace {

using sg::ivec3;
using sg::kPi;
using sg::mat3;
using sg::mat4;
using sg::vec2;
using sg::vec3;
using sg::vec4;

// --- 1. helpers -------------------------------------------------------------------------

// The share done of one tessellation, passed on to TessellationProgress: only increases, one
// report at a time (the marching's parallel loops report from their worker threads).
class Meter {
public:
    explicit Meter(const TessellationProgress* p) : m_p(p) {}
    bool cancelled() const { return m_p && m_p->cancelled(); }
    void at(float share) {
        if (!m_p || !m_p->report) return;
        std::lock_guard lock(m_mutex);
        if (!(share > m_last)) return;
        m_last = std::min(share, 1.0f);
        m_p->report(m_last);
    }

private:
    const TessellationProgress* m_p;
    std::mutex m_mutex;
    float m_last = 0.0f;
};

// Where each marching phase ends, as a share of a marched shape's work (the time they took on
// the demo's quadric, CSG and metaballs at 256, averaged: sampling 0.15-0.5, polygonizing up
// to 0.7-0.85, refining the vertices to 0.9, the normals the rest).
constexpr float kSampled = 0.3f, kPolygonized = 0.75f, kRefined = 0.9f, kNormals = 0.99f;

// Counts items done in a parallel loop and reports the share from..to they stand for.
struct PhaseCounter {
    Meter& meter;
    float from, to;
    size_t total;
    std::atomic<size_t> done{0};
    void add(size_t n) { meter.at(from + (to - from) * float(done += n) / float(std::max<size_t>(total, 1))); }
};

// -0.0f -> +0.0f so that equal positions also have equal bits.
inline float clean(float v) { return v + 0.0f; }
inline vec3 clean(const vec3& v) { return vec3(clean(v.x), clean(v.y), clean(v.z)); }

vec3 safeNormalize(const vec3& v, const vec3& fallback = vec3(0, 1, 0)) {
    float l = glm::length(v);
    return l > 1e-30f && std::isfinite(l) ? v / l : fallback;
}

// cos/sin of 2*pi*i/n for i = 0..n with entry n identical to entry 0, and the quarter turns
// exact, so seams close bit-exactly.
struct Circle {
    std::vector<float> c, s;
    explicit Circle(int n) : c(n + 1), s(n + 1) {
        for (int i = 0; i < n; ++i) {
            double a = 2.0 * 3.14159265358979323846 * i / n;
            c[i] = clean(float(std::cos(a)));
            s[i] = clean(float(std::sin(a)));
            if (4 * i == n) {
                c[i] = 0;
                s[i] = 1;
            }
            if (2 * i == n) {
                c[i] = -1;
                s[i] = 0;
            }
            if (4 * i == 3 * n) {
                c[i] = 0;
                s[i] = -1;
            }
        }
        c[0] = 1;
        s[0] = 0;
        c[n] = c[0];
        s[n] = s[0];
    }
};

// A (ns+1) x (nt+1) vertex grid; quads (i,j)-(i+1,j)-(i+1,j+1)-(i,j+1) split along the
// (i,j)-(i+1,j+1) diagonal. The winding makes the geometric normal follow dP/ds x dP/dt, so
// callers pick s and t such that this points outward. Triangles with two coincident
// vertices (at poles and apexes) are dropped.
void addGrid(sg::Mesh& m, int ns, int nt, const std::function<void(int, int, vec3&, vec3&, vec2&)>& vertex) {
    uint32_t base = uint32_t(m.positions.size());
    for (int j = 0; j <= nt; ++j)
        for (int i = 0; i <= ns; ++i) {
            vec3 p, n;
            vec2 uv;
            vertex(i, j, p, n, uv);
            m.positions.push_back(clean(p));
            m.normals.push_back(n);
            m.uv0.push_back(uv);
        }
    auto idx = [&](int i, int j) { return base + uint32_t(j * (ns + 1) + i); };
    auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
        const vec3 &pa = m.positions[a], &pb = m.positions[b], &pc = m.positions[c];
        if (pa == pb || pb == pc || pa == pc) return;
        m.indices.insert(m.indices.end(), {a, b, c});
    };
    for (int j = 0; j < nt; ++j)
        for (int i = 0; i < ns; ++i) {
            uint32_t a = idx(i, j), b = idx(i + 1, j), c = idx(i, j + 1), d = idx(i + 1, j + 1);
            emit(a, b, d);
            emit(a, d, c);
        }
}

// --- 2. analytic primitives ---------------------------------------------------------------

sg::Mesh sphereMesh(float r, int res) {
    sg::Mesh m;
    m.name = "sphere";
    int slices = std::max(res, 3), stacks = std::max(res / 2, 2);
    Circle phi(slices);
    // Latitude from the south pole (t = 0) to the north pole (t = stacks); poles exact.
    std::vector<float> sy(stacks + 1), cy(stacks + 1);
    for (int j = 0; j <= stacks; ++j) {
        double th = 3.14159265358979323846 * (1.0 - double(j) / stacks);   // polar angle from +y
        sy[j] = clean(float(std::sin(th)));
        cy[j] = clean(float(std::cos(th)));
        if (2 * j == stacks) {
            sy[j] = 1;
            cy[j] = 0;
        }
    }
    sy[0] = sy[stacks] = 0;
    cy[0] = -1;
    cy[stacks] = 1;
    // s = longitude phi (x = sin, z = cos), t = up: dP/ds x dP/dt points outward.
    addGrid(m, slices, stacks, [&](int i, int j, vec3& p, vec3& n, vec2& uv) {
        n = vec3(sy[j] * phi.s[i], cy[j], sy[j] * phi.c[i]);
        p = r * n;
        uv = vec2(float(i) / slices, float(j) / stacks);
    });
    return m;
}

// Symmetric subdivision of [-1,1]: t[k] == -t[n-k] exactly.
std::vector<float> symmetricSteps(int n) {
    std::vector<float> t(n + 1);
    for (int k = 0; k <= n; ++k) t[k] = -1.0f + 2.0f * float(k) / float(n);
    for (int k = 0; 2 * k <= n; ++k) {
        t[n - k] = clean(-t[k]);
        if (2 * k == n) t[k] = 0;
    }
    t[0] = -1;
    t[n] = 1;
    return t;
}

sg::Mesh boxMesh(const vec3& h, int res) {
    sg::Mesh m;
    m.name = "box";
    int n = std::clamp(res / 4, 1, 64);   // subdivided so Gouraud and point lights look right
    std::vector<float> t = symmetricSteps(n);
    // Face normal, u axis, v axis with u x v = normal (counter-clockwise from outside).
    const vec3 axes[6][3] = {
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}}, {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}},
        {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}, {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    for (const auto& f : axes)
        addGrid(m, n, n, [&](int i, int j, vec3& p, vec3& nn, vec2& uv) {
            p = (f[0] + t[i] * f[1] + t[j] * f[2]) * h;
            nn = f[0];
            uv = vec2(float(i) / n, float(j) / n);
        });
    return m;
}

sg::Mesh planeMesh(float hs, int res) {
    sg::Mesh m;
    m.name = "plane";
    int n = std::clamp(res, 1, 512);
    std::vector<float> t = symmetricSteps(n);
    // s = +x, t = -z: (+x) x (-z) = +y.
    addGrid(m, n, n, [&](int i, int j, vec3& p, vec3& nn, vec2& uv) {
        p = vec3(t[i] * hs, 0, -t[j] * hs);
        nn = vec3(0, 1, 0);
        uv = vec2(float(i) / n, float(j) / n);
    });
    return m;
}

// Disk cap at height y (radius r), normal +y when up. Rings keep triangles well shaped.
void addCap(sg::Mesh& m, float r, float y, const Circle& phi, int slices, int rings, bool up) {
    addGrid(m, slices, rings, [&](int i, int j, vec3& p, vec3& n, vec2& uv) {
        // up: t runs from the rim to the centre; down: from the centre to the rim.
        float rho = up ? r * float(rings - j) / float(rings) : r * float(j) / float(rings);
        if ((up && j == 0) || (!up && j == rings)) rho = r;
        p = vec3(rho * phi.s[i], y, rho * phi.c[i]);
        n = vec3(0, up ? 1.0f : -1.0f, 0);
        uv = r > 0 ? vec2(0.5f + 0.5f * p.x / r, 0.5f + 0.5f * p.z / r) : vec2(0.5f);
    });
}

sg::Mesh cylinderMesh(float r, float hh, int res) {
    sg::Mesh m;
    m.name = "cylinder";
    int slices = std::max(res, 3), stacks = std::max(res / 8, 1), rings = std::max(res / 8, 1);
    Circle phi(slices);
    std::vector<float> t = symmetricSteps(stacks);
    addGrid(m, slices, stacks, [&](int i, int j, vec3& p, vec3& n, vec2& uv) {
        n = vec3(phi.s[i], 0, phi.c[i]);
        p = vec3(r * phi.s[i], t[j] * hh, r * phi.c[i]);
        uv = vec2(float(i) / slices, float(j) / stacks);
    });
    addCap(m, r, hh, phi, slices, rings, true);
    addCap(m, r, -hh, phi, slices, rings, false);
    return m;
}

sg::Mesh coneMesh(float r, float hh, int res) {
    sg::Mesh m;
    m.name = "cone";
    int slices = std::max(res, 3), stacks = std::max(res / 8, 1), rings = std::max(res / 8, 1);
    Circle phi(slices);
    Circle half(2 * slices);   // half steps for the apex normals
    float h = 2 * hh;
    float ny = r / h;   // outward normal ~ radial + (r/h) y
    addGrid(m, slices, stacks, [&](int i, int j, vec3& p, vec3& n, vec2& uv) {
        float f = float(stacks - j) / float(stacks);   // radius fraction, 1 at the base
        float y = j == stacks ? hh : (j == 0 ? -hh : -hh + h * float(j) / float(stacks));
        float rho = j == 0 ? r : r * f;
        p = vec3(rho * phi.s[i], y, rho * phi.c[i]);
        // At the apex the kept triangle of quad i uses vertex i (i+1 for the quad i),
        // so use the mid angle of the slice it closes.
        int k = j == stacks ? (2 * i + 2 * slices - 1) % (2 * slices) : 2 * i;
        n = glm::normalize(vec3(half.s[k], ny, half.c[k]));
        uv = vec2(float(i) / slices, float(j) / stacks);
    });
    addCap(m, r, -hh, phi, slices, rings, false);
    return m;
}

sg::Mesh torusMesh(float R, float r, int res) {
    sg::Mesh m;
    m.name = "torus";
    int nu = std::max(res, 3), nv = std::max(res / 2, 3);
    Circle cu(nu), cv(nv);
    // s = around y (u), t = around the tube (v): dP/du x dP/dv points outward.
    addGrid(m, nu, nv, [&](int i, int j, vec3& p, vec3& n, vec2& uv) {
        vec3 dir(cu.s[i], 0, cu.c[i]);
        n = cv.c[j] * dir + vec3(0, cv.s[j], 0);
        p = R * dir + r * n;
        uv = vec2(float(i) / nu, float(j) / nv);
    });
    return m;
}

sg::Mesh implicitPrimitive(const sg::ImplicitShape& s, int res) {
    switch (s.type) {
    case sg::ImplicitType::Sphere: return sphereMesh(s.radius, res);
    case sg::ImplicitType::Box: return boxMesh(s.halfExtents, res);
    case sg::ImplicitType::Cylinder: return cylinderMesh(s.radius, s.halfHeight, res);
    case sg::ImplicitType::Cone: return coneMesh(s.radius, s.halfHeight, res);
    case sg::ImplicitType::Torus: return torusMesh(s.majorRadius, s.minorRadius, res);
    case sg::ImplicitType::Plane: return planeMesh(s.planeHalfSize, res);
    case sg::ImplicitType::Quadric: break;   // marched
    }
    return {};
}

// --- 3. parametric surfaces ---------------------------------------------------------------

sg::Mesh parametricMesh(const sg::ParametricSurface& surf, int res) {
    sg::Mesh m;
    m.name = "parametric";
    int n = std::clamp(res, 1, 1024);
    bool periodic = surf.type == sg::ParametricType::Torus;
    addGrid(m, n, n, [&](int i, int j, vec3& p, vec3& nn, vec2& uv) {
        float u = float(i) / n, v = float(j) / n;
        // Periodic surfaces: the seam repeats the first row/column bit-exactly.
        float eu = periodic && i == n ? 0.0f : u, ev = periodic && j == n ? 0.0f : v;
        p = surf.evaluate(eu, ev);
        vec3 du, dv;
        surf.partials(eu, ev, du, dv);
        vec3 c = glm::cross(du, dv);
        if (glm::length(c) < 1e-12f) {
            // Degenerate corner (coincident control points): step inward a little.
            float uu = std::clamp(eu, 1e-3f, 1 - 1e-3f), vv = std::clamp(ev, 1e-3f, 1 - 1e-3f);
            surf.partials(uu, vv, du, dv);
            c = glm::cross(du, dv);
        }
        nn = safeNormalize(c);
        uv = vec2(u, v);
    });
    return m;
}

// --- 4. scalar fields ----------------------------------------------------------------------

// A field for marching: value < 0 inside. surface() gives the outward normal at a point on
// the surface and the part (CSG leaf) it belongs to.
struct Field {
    virtual ~Field() = default;
    virtual float value(const vec3& p) const = 0;
    virtual vec3 normal(const vec3& p, int* part) const = 0;
    // Normal of a given part at p (for vertices shared by faces of different parts).
    virtual vec3 partNormal(const vec3& p, int part) const {
        (void)part;
        return normal(p, nullptr);
    }
};

struct QuadricField final : Field {
    const sg::ImplicitShape& s;
    explicit QuadricField(const sg::ImplicitShape& sh) : s(sh) {}
    float value(const vec3& p) const override { return s.value(p); }
    vec3 normal(const vec3& p, int* part) const override {
        if (part) *part = 0;
        return s.normal(p);
    }
};

float boxDistance(const vec3& p, const sg::Aabb& b) {
    vec3 q = glm::abs(p - b.center()) - 0.5f * b.extent();
    return glm::length(glm::max(q, vec3(0.0f))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
}

struct GridField final : Field {
    const sg::DensityGrid& g;
    explicit GridField(const sg::DensityGrid& grid) : g(grid) {}
    // Inside where density > iso, and only within the grid's bounds.
    float value(const vec3& p) const override { return std::max(g.isoValue - g.sample(p), boxDistance(p, g.bounds)); }
    vec3 normal(const vec3& p, int* part) const override {
        if (part) *part = 0;
        if (boxDistance(p, g.bounds) > g.isoValue - g.sample(p)) {
            // Clipped by the bounds: the normal of the nearest box face.
            vec3 q = (p - g.bounds.center()) / glm::max(0.5f * g.bounds.extent(), vec3(1e-30f));
            vec3 a = glm::abs(q);
            int axis = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
            vec3 n(0.0f);
            n[axis] = q[axis] >= 0 ? 1.0f : -1.0f;
            return n;
        }
        return safeNormalize(-g.gradient(p));
    }
};

struct CsgField final : Field {
    const sg::CsgTree& t;
    std::vector<int> leafOf;     // tree node -> leaf ordinal (-1 for operators)
    std::vector<int> leafNode;   // leaf ordinal -> tree node
    std::vector<float> scale;    // per tree node: local distance -> world distance
    explicit CsgField(const sg::CsgTree& tree) : t(tree), leafOf(tree.nodes.size(), -1), scale(tree.nodes.size(), 1.0f) {
        for (size_t i = 0; i < t.nodes.size(); ++i)
            if (t.nodes[i].op < 0) {
                leafOf[i] = int(leafNode.size());
                leafNode.push_back(int(i));
                float det = std::abs(glm::determinant(mat3(t.nodes[i].world)));
                scale[i] = det > 0 && std::isfinite(det) ? std::cbrt(det) : 1.0f;
            }
    }
    struct Eval {
        float v;
        int leaf;
        bool flip;
    };
    Eval eval(int i, const vec3& p) const {
        const sg::CsgTree::Node& n = t.nodes[i];
        if (n.op < 0) {
            vec3 lp = vec3(n.invWorld * vec4(p, 1.0f));
            return {n.shape.value(lp) * scale[i], leafOf[i], false};
        }
        if (n.children.empty()) return {1e30f, -1, false};
        Eval r = eval(n.children[0], p);
        for (size_t k = 1; k < n.children.size(); ++k) {
            Eval c = eval(n.children[k], p);
            switch (sg::CsgOp(n.op)) {
            case sg::CsgOp::Union:
                if (c.v < r.v) r = c;
                break;
            case sg::CsgOp::Intersection:
                if (c.v > r.v) r = c;
                break;
            case sg::CsgOp::Difference:
                c.v = -c.v;
                c.flip = !c.flip;
                if (c.v > r.v) r = c;
                break;
            }
        }
        return r;
    }
    float value(const vec3& p) const override { return t.root >= 0 ? eval(t.root, p).v : 1.0f; }
    vec3 leafNormal(const vec3& p, int leaf, bool flip) const {
        const sg::CsgTree::Node& n = t.nodes[leafNode[leaf]];
        vec3 lp = vec3(n.invWorld * vec4(p, 1.0f));
        vec3 w = safeNormalize(n.normal * n.shape.normal(lp));
        return flip ? -w : w;
    }
    vec3 normal(const vec3& p, int* part) const override {
        Eval e = eval(t.root, p);
        if (part) *part = e.leaf < 0 ? 0 : e.leaf * 2 + (e.flip ? 1 : 0);
        return e.leaf < 0 ? vec3(0, 1, 0) : leafNormal(p, e.leaf, e.flip);
    }
    vec3 partNormal(const vec3& p, int part) const override { return leafNormal(p, part / 2, part & 1); }
};

// Bounds of a CSG subtree (planes count as the half-space clipped to their square).
sg::Aabb csgBounds(const sg::CsgTree& t, int i) {
    const sg::CsgTree::Node& n = t.nodes[i];
    if (n.op < 0) {
        sg::Aabb b = n.shape.localBounds();
        if (n.shape.type == sg::ImplicitType::Plane) b.min.y = -n.shape.planeHalfSize;
        return b.transformed(n.world);
    }
    if (n.children.empty()) return {};
    sg::Aabb b = csgBounds(t, n.children[0]);
    if (sg::CsgOp(n.op) == sg::CsgOp::Difference) return b;
    for (size_t k = 1; k < n.children.size(); ++k) {
        sg::Aabb c = csgBounds(t, n.children[k]);
        if (sg::CsgOp(n.op) == sg::CsgOp::Union)
            b.extend(c);
        else {
            b.min = glm::max(b.min, c.min);
            b.max = glm::min(b.max, c.max);
        }
    }
    return b;
}

// --- 5. marching tetrahedra ----------------------------------------------------------------

// The 6 tetrahedra of the Freudenthal (Kuhn) split of a cube: all share the main diagonal
// 0-7, and each is a monotone path 0 -> e_a -> e_a + e_b -> 7 (corner bits x=1, y=2, z=4).
// Face diagonals then match between neighbouring cubes, so the surface has no cracks, and
// every tetrahedron edge joins a corner to a componentwise larger one.
constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

struct MarchResult {
    std::vector<vec3> positions;
    std::vector<std::array<uint32_t, 3>> triangles;
};

// The sampling grid: field values at nx * ny * nz vertices spaced h apart from origin.
struct MarchGrid {
    vec3 origin{0.0f};
    float h = 1.0f;
    size_t nx = 0, ny = 0, nz = 0;
    std::vector<float> val;
    size_t index(size_t x, size_t y, size_t z) const { return (z * ny + y) * nx + x; }
    vec3 pos(size_t x, size_t y, size_t z) const { return origin + vec3(float(x), float(y), float(z)) * h; }
    vec3 pos(size_t i) const { return pos(i % nx, (i / nx) % ny, i / (nx * ny)); }
};

// The surface inside one tetrahedron: a triangle or a quad of crossing-edge vertices.
struct MarchPoly {
    uint32_t v[4];
    int n;
};

// Cube corner offsets by corner bits (x=1, y=2, z=4).
const vec3 kCornerOffset[8] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};

// Samples the field over `bounds` at `res` cells along the longest side, plus one cell of
// margin on each side whose outermost layer is forced outside, so the surface closes inside
// the grid.
MarchGrid sampleGrid(const Field& field, const sg::Aabb& bounds, int res, Meter& meter) {
    MarchGrid g;
    res = std::clamp(res, 2, 256);
    vec3 ext = glm::max(bounds.extent(), vec3(1e-6f));
    g.h = std::max(ext.x, std::max(ext.y, ext.z)) / float(res);
    ivec3 cells = glm::max(ivec3(glm::ceil(ext / g.h)), ivec3(1)) + 2;
    g.origin = bounds.center() - 0.5f * vec3(cells) * g.h;
    ivec3 dims = cells + 1;
    g.nx = size_t(dims.x);
    g.ny = size_t(dims.y);
    g.nz = size_t(dims.z);
    g.val.resize(g.nx * g.ny * g.nz);
    std::atomic<size_t> slices{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, g.nz), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t z = r.begin(); z < r.end(); ++z) {
            if (meter.cancelled()) return;
            for (size_t y = 0; y < g.ny; ++y)
                for (size_t x = 0; x < g.nx; ++x) {
                    float v = field.value(g.pos(x, y, z));
                    if (!std::isfinite(v)) v = 1.0f;
                    bool border = x == 0 || y == 0 || z == 0 || x == g.nx - 1 || y == g.ny - 1 || z == g.nz - 1;
                    if (border && v < 0) v = 1e-6f;
                    g.val[g.index(x, y, z)] = v;
                }
            meter.at(kSampled * float(++slices) / float(g.nz));
        }
    });
    return g;
}

// The polygon where the surface crosses tetrahedron `tet` (corner bits) of a cube whose
// inside corners are the bits of `inside`; false when it does not cross. edge(ca, cb) gives
// the vertex on the edge between two corners. The polygon normal points from the inside
// corners to the outside ones.
template <class EdgeVertex>
bool tetPolygon(const int (&tet)[4], int inside, EdgeVertex&& edge, MarchPoly& p) {
    int in[4], outv[4], ni = 0, no = 0;
    for (int k = 0; k < 4; ++k) ((inside >> tet[k]) & 1 ? in[ni++] : outv[no++]) = tet[k];
    if (ni == 0 || no == 0) return false;
    auto mid = [&](int ca, int cb) { return 0.5f * (kCornerOffset[ca] + kCornerOffset[cb]); };
    vec3 inC(0.0f), outC(0.0f);
    for (int k = 0; k < ni; ++k) inC += kCornerOffset[in[k]] / float(ni);
    for (int k = 0; k < no; ++k) outC += kCornerOffset[outv[k]] / float(no);
    vec3 dir = outC - inC;
    p = MarchPoly{};
    vec3 m[4];
    if (ni == 1 || no == 1) {
        int apex = ni == 1 ? in[0] : outv[0];
        const int* others = ni == 1 ? outv : in;
        for (int k = 0; k < 3; ++k) {
            p.v[k] = edge(apex, others[k]);
            m[k] = mid(apex, others[k]);
        }
        p.n = 3;
    } else {
        // Cycle around the quad: (i0,o0) (i0,o1) (i1,o1) (i1,o0).
        const int pairs[4][2] = {{in[0], outv[0]}, {in[0], outv[1]}, {in[1], outv[1]}, {in[1], outv[0]}};
        for (int k = 0; k < 4; ++k) {
            p.v[k] = edge(pairs[k][0], pairs[k][1]);
            m[k] = mid(pairs[k][0], pairs[k][1]);
        }
        p.n = 4;
    }
    // Orientation from the edge midpoints (planar and separating): the polygon
    // normal must point from the inside corners to the outside ones.
    vec3 nrm = glm::cross(m[1] - m[0], m[2] - m[0]);
    if (glm::dot(nrm, dir) < 0) std::reverse(p.v, p.v + p.n);
    return true;
}

// Marching tetrahedra over every cell of the grid. Vertices live on crossing edges and are
// shared between the polygons using them: edgeEnds[i] = (inside corner, outside corner) of
// vertex i, as grid indices.
std::vector<MarchPoly> polygonize(const MarchGrid& g, std::vector<std::pair<size_t, size_t>>& edgeEnds, Meter& meter) {
    const size_t nx = g.nx, ny = g.ny, nz = g.nz;
    // Key = lower corner index * 8 + offset bits.
    std::unordered_map<uint64_t, uint32_t> edgeVertex;
    edgeVertex.reserve(size_t(16) * nx * ny);
    auto vertexOn = [&](size_t a, size_t b, size_t lower, int bits) {
        uint64_t key = uint64_t(lower) * 8 + uint64_t(bits);
        auto [it, fresh] = edgeVertex.try_emplace(key, uint32_t(edgeEnds.size()));
        if (fresh) edgeEnds.push_back(g.val[a] < 0 ? std::make_pair(a, b) : std::make_pair(b, a));
        return it->second;
    };
    std::vector<MarchPoly> polys;
    const size_t offs[8] = {0, 1, nx, nx + 1, nx * ny, nx * ny + 1, nx * ny + nx, nx * ny + nx + 1};
    for (size_t z = 0; z + 1 < nz; ++z) {
        if (meter.cancelled()) return {};
        for (size_t y = 0; y + 1 < ny; ++y)
            for (size_t x = 0; x + 1 < nx; ++x) {
                size_t c0 = g.index(x, y, z);
                int inside = 0;
                for (int k = 0; k < 8; ++k) inside |= (g.val[c0 + offs[k]] < 0 ? 1 : 0) << k;
                if (inside == 0 || inside == 255) continue;
                // Edge between two cube corners (bits): the smaller one is the lower end.
                auto edge = [&](int ca, int cb) {
                    int lo = std::min(ca, cb), hi = std::max(ca, cb);   // chains: lo's bits are a subset of hi's
                    return vertexOn(c0 + offs[ca], c0 + offs[cb], c0 + offs[lo], hi & ~lo);
                };
                MarchPoly p;
                for (const auto& tet : kTets)
                    if (tetPolygon(tet, inside, edge, p)) polys.push_back(p);
            }
        meter.at(kSampled + (kPolygonized - kSampled) * float(z + 1) / float(nz - 1));
    }
    return polys;
}

// Where the surface crosses the segment a-b (field values fa < 0 <= fb at the grid), as a
// fraction of the way from a: the linear guess, refined on the exact function by the Illinois
// variant of regula falsi (bracket kept). Kept strictly inside the edge so no two vertices
// coincide.
float surfaceCrossing(const Field& field, vec3 a, vec3 b, float fa, float fb) {
    float t = fa / (fa - fb);
    float ea = field.value(a), eb = field.value(b);
    if (ea < 0 && eb >= 0) {
        // Bracket [ta, tb] with f(ta) < 0 <= f(tb).
        float ta = 0, tb = 1;
        float ga = ea, gb = eb;
        int side = 0;
        for (int it = 0; it < 16 && tb - ta > 2e-5f; ++it) {
            float tm = (ga * tb - gb * ta) / (ga - gb);
            if (!(tm > ta && tm < tb)) tm = 0.5f * (ta + tb);
            float gm = field.value(glm::mix(a, b, tm));
            if (gm == 0) {
                ta = tb = tm;
                break;
            }
            if (gm < 0) {
                ta = tm;
                ga = gm;
                if (side == -1) gb *= 0.5f;
                side = -1;
            } else {
                tb = tm;
                gb = gm;
                if (side == 1) ga *= 0.5f;
                side = 1;
            }
        }
        t = ga == gb ? 0.5f * (ta + tb) : (ga * tb - gb * ta) / (ga - gb);
        if (!(t >= ta && t <= tb)) t = 0.5f * (ta + tb);
    }
    return std::clamp(t, 1e-3f, 1.0f - 1e-3f);
}

// The vertex positions: each crossing edge's point on the exact surface.
std::vector<vec3> refineVertices(const Field& field, const MarchGrid& g, const std::vector<std::pair<size_t, size_t>>& edgeEnds, Meter& meter) {
    std::vector<vec3> positions(edgeEnds.size());
    PhaseCounter counter{meter, kPolygonized, kRefined, edgeEnds.size()};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, edgeEnds.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t e = r.begin(); e < r.end(); ++e) {
            auto [ia, ib] = edgeEnds[e];
            vec3 a = g.pos(ia), b = g.pos(ib);
            positions[e] = glm::mix(a, b, surfaceCrossing(field, a, b, g.val[ia], g.val[ib]));
        }
        counter.add(r.size());
    });
    return positions;
}

// Triangles; quads split along their shorter diagonal.
std::vector<std::array<uint32_t, 3>> triangulate(const std::vector<MarchPoly>& polys, const std::vector<vec3>& positions) {
    std::vector<std::array<uint32_t, 3>> triangles;
    triangles.reserve(polys.size() * 2);
    const vec3* P = positions.data();
    for (const MarchPoly& p : polys) {
        if (p.n == 3) {
            triangles.push_back({p.v[0], p.v[1], p.v[2]});
            continue;
        }
        if (glm::distance(P[p.v[0]], P[p.v[2]]) <= glm::distance(P[p.v[1]], P[p.v[3]])) {
            triangles.push_back({p.v[0], p.v[1], p.v[2]});
            triangles.push_back({p.v[0], p.v[2], p.v[3]});
        } else {
            triangles.push_back({p.v[0], p.v[1], p.v[3]});
            triangles.push_back({p.v[1], p.v[2], p.v[3]});
        }
    }
    return triangles;
}

// Sample, polygonize, refine the vertices onto the surface, triangulate. Cancelled: empty.
MarchResult march(const Field& field, sg::Aabb bounds, int res, Meter& meter) {
    MarchResult out;
    if (bounds.empty() || !sg::isFinite(bounds.min) || !sg::isFinite(bounds.max)) return out;
    MarchGrid grid = sampleGrid(field, bounds, res, meter);
    if (meter.cancelled()) return out;
    std::vector<std::pair<size_t, size_t>> edgeEnds;   // per vertex: (inside corner, outside corner)
    std::vector<MarchPoly> polys = polygonize(grid, edgeEnds, meter);
    if (meter.cancelled()) return out;
    out.positions = refineVertices(field, grid, edgeEnds, meter);
    out.triangles = triangulate(polys, out.positions);
    return out;
}

// Marches the field and builds the mesh. With `parts`, each triangle takes the part at its
// centroid, and vertices shared by triangles of different parts are split so each side gets
// its own part's normal (sharp CSG creases). Returns the per-triangle parts.
std::vector<int> marchedMesh(const Field& field, const sg::Aabb& bounds, int res, bool parts, sg::Mesh& m, Meter& meter) {
    MarchResult r = march(field, bounds, res, meter);
    size_t nv = r.positions.size();
    m.positions = std::move(r.positions);
    m.normals.resize(nv);
    std::vector<int> vertexPart(nv, 0);
    PhaseCounter counter{meter, kRefined, kNormals, nv};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 256), [&](const tbb::blocked_range<size_t>& rr) {
        for (size_t i = rr.begin(); i < rr.end(); ++i) m.normals[i] = field.normal(m.positions[i], &vertexPart[i]);
        counter.add(rr.size());
    });
    std::vector<int> triPart;
    if (parts) {
        triPart.resize(r.triangles.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, r.triangles.size(), 256), [&](const tbb::blocked_range<size_t>& rr) {
            for (size_t t = rr.begin(); t < rr.end(); ++t) {
                const auto& tri = r.triangles[t];
                int a = vertexPart[tri[0]], b = vertexPart[tri[1]], c = vertexPart[tri[2]];
                if (a == b || a == c)
                    triPart[t] = a;   // majority of the vertices
                else if (b == c)
                    triPart[t] = b;
                else {
                    vec3 centroid = (m.positions[tri[0]] + m.positions[tri[1]] + m.positions[tri[2]]) / 3.0f;
                    field.normal(centroid, &triPart[t]);
                }
            }
        });
        std::unordered_map<uint64_t, uint32_t> split;
        for (size_t t = 0; t < r.triangles.size(); ++t)
            for (uint32_t& v : r.triangles[t]) {
                if (vertexPart[v] == triPart[t]) continue;
                uint64_t key = uint64_t(v) << 20 | uint64_t(triPart[t]);
                auto [it, fresh] = split.try_emplace(key, uint32_t(m.positions.size()));
                if (fresh) {
                    vec3 p = m.positions[v];
                    m.positions.push_back(p);
                    m.normals.push_back(field.partNormal(p, triPart[t]));
                }
                v = it->second;
            }
    }
    m.indices.reserve(r.triangles.size() * 3);
    for (const auto& tri : r.triangles) m.indices.insert(m.indices.end(), tri.begin(), tri.end());
    return triPart;
}

}   // namespace

// --- 6. dispatch and cache -----------------------------------------------------------------------

namespace {
// Shapes tessellated by marching tetrahedra over a resolution^3 grid.
bool marched(const sg::DrawAnalytic& a) {
    return a.kind == sg::DrawAnalytic::Kind::Grid || a.kind == sg::DrawAnalytic::Kind::Csg ||
           (a.kind == sg::DrawAnalytic::Kind::Implicit && a.implicit.type == sg::ImplicitType::Quadric);
}
}   // namespace

double tessellationWork(const sg::DrawAnalytic& a, int resolution) {
    const double r = std::clamp(resolution, 3, 1024);
    if (!marched(a)) return r * r;
    const double m = std::min(r, 256.0);   // sampleGrid's limit
    return m * m * m;
}

Tessellation tessellate(const sg::DrawAnalytic& a, int resolution, const TessellationProgress* progress) {
    Tessellation t;
    auto mesh = std::make_shared<sg::Mesh>();
    resolution = std::clamp(resolution, 3, 1024);
    Meter meter(progress);
    // Isolated so that a caller inside a TBB task (holding the cache lock) never picks up an
    // unrelated outer task while waiting here.
    tbb::this_task_arena::isolate([&] {
        switch (a.kind) {
        case sg::DrawAnalytic::Kind::Implicit:
            if (a.implicit.type == sg::ImplicitType::Quadric) {
                QuadricField f(a.implicit);
                marchedMesh(f, a.implicit.quadricBounds, resolution, false, *mesh, meter);
                mesh->name = "quadric";
            } else {
                *mesh = implicitPrimitive(a.implicit, resolution);
            }
            break;
        case sg::DrawAnalytic::Kind::Parametric: *mesh = parametricMesh(a.parametric, resolution); break;
        case sg::DrawAnalytic::Kind::Grid:
            if (a.grid && a.grid->dims.x >= 2 && a.grid->dims.y >= 2 && a.grid->dims.z >= 2 &&
                a.grid->values.size() == size_t(a.grid->dims.x) * a.grid->dims.y * a.grid->dims.z) {
                GridField f(*a.grid);
                marchedMesh(f, a.grid->bounds, resolution, false, *mesh, meter);
                mesh->name = "density grid";
            }
            break;
        case sg::DrawAnalytic::Kind::Csg:
            t.worldSpace = true;
            if (a.csg && a.csg->root >= 0 && size_t(a.csg->root) < a.csg->nodes.size()) {
                CsgField f(*a.csg);
                std::vector<int> parts = marchedMesh(f, csgBounds(*a.csg, a.csg->root), resolution, true, *mesh, meter);
                mesh->name = "csg";
                for (int leaf : f.leafNode) t.materials.push_back(a.csg->nodes[leaf].material);
                t.triangleMaterial.resize(parts.size());
                for (size_t i = 0; i < parts.size(); ++i) t.triangleMaterial[i] = uint16_t(parts[i] / 2);
            }
            break;
        }
    });
    if (meter.cancelled()) return Tessellation{};   // no mesh: incomplete
    // Guarantee valid data for the backends even for unusual input.
    if (!mesh->validate().empty()) *mesh = sg::Mesh{};
    mesh->id = sg::newResourceId();
    t.mesh = std::move(mesh);
    meter.at(1.0f);
    return t;
}

const Tessellation& TessellationCache::get(const sg::DrawAnalytic& a, int resolution, const TessellationProgress* progress) {
    static const Tessellation kNone;
    std::lock_guard lock(m_mutex);
    const uint64_t key = keyOf(a, resolution);
    auto it = m_entries.find(key);
    if (it == m_entries.end()) {
        Tessellation t = tessellate(a, resolution, progress);
        if (!t.mesh) return kNone;   // cancelled
        it = m_entries.emplace(key, Entry{std::move(t), 0}).first;
    }
    it->second.lastUsed = m_frame;
    return it->second.t;
}

bool TessellationCache::contains(const sg::DrawAnalytic& a, int resolution) const {
    std::lock_guard lock(m_mutex);
    return m_entries.count(keyOf(a, resolution)) > 0;
}

void TessellationCache::nextFrame(int maxAge) {
    std::lock_guard lock(m_mutex);
    ++m_frame;
    for (auto it = m_entries.begin(); it != m_entries.end();)
        it = m_frame - it->second.lastUsed > uint64_t(maxAge) ? m_entries.erase(it) : std::next(it);
}

size_t TessellationCache::size() const {
    std::lock_guard lock(m_mutex);
    return m_entries.size();
}

}   // namespace rnd
