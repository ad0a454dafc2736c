// polygon_test.cpp - assets::PolygonTriangulator against a scan-line polygon fill.
//
// The oracle: a scan-line fill of the polygon (even-odd rule, samples at pixel centres of a
// grid). The triangles are filled with the same scan-line rule, signed by their winding; with
// shared edges computed identically from either side, the triangles of an exact triangulation
// cover every sample inside the polygon exactly once and every sample outside not at all.
// Then: total triangle area = the polygon's shoelace area, every triangle keeps the polygon's
// orientation, convex polygons keep the fan, and bad input terminates.
#include "assets/polygon.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

using assets::PolygonKind;
using assets::PolygonTriangulator;
using sg::vec3;

namespace {

struct V2 {
    double x, y;
};
using Poly = std::vector<V2>;

double shoelace(const Poly& p) {
    double a = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        const V2 &u = p[i], &v = p[(i + 1) % p.size()];
        a += u.x * v.y - u.y * v.x;
    }
    return 0.5 * a;
}

// The crossings of an edge with the scan line at height y (half-open in y), at x; the edge is
// taken lower end first so that both triangles sharing it compute the same x.
bool crossing(V2 a, V2 b, double y, double& x, int& dir) {
    if ((a.y <= y) == (b.y <= y)) return false;
    dir = b.y > a.y ? 1 : -1;
    if (dir < 0) std::swap(a, b);
    x = a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y);
    return true;
}

// Signed scan-line crossings of the ray from s to +x: +1 for an edge going up, -1 down.
int windingAt(const Poly& p, V2 s) {
    int w = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        double x;
        int dir;
        if (crossing(p[i], p[(i + 1) % p.size()], s.y, x, dir) && s.x < x) w += dir;
    }
    return w;
}
bool evenOddInside(const Poly& p, V2 s) { return (windingAt(p, s) & 1) != 0; }

// Scan-line polygon fill, even-odd rule: which pixel centres (i + 0.5, j + 0.5) of the grid
// [x0, x0 + w) x [y0, y0 + h) lie inside. Per row: the edges' crossings, sorted; a sample is
// inside when an odd number of crossings lie to its right.
std::vector<uint8_t> scanlineFill(const Poly& p, int x0, int y0, int w, int h) {
    std::vector<uint8_t> in(size_t(w) * size_t(h), 0);
    std::vector<double> xs;
    for (int j = 0; j < h; ++j) {
        const double y = y0 + j + 0.5;
        xs.clear();
        for (size_t e = 0; e < p.size(); ++e) {
            double x;
            int dir;
            if (crossing(p[e], p[(e + 1) % p.size()], y, x, dir)) xs.push_back(x);
        }
        std::sort(xs.begin(), xs.end());
        size_t right = xs.size();   // crossings with s.x < x, as i grows
        size_t k = 0;
        for (int i = 0; i < w; ++i) {
            const double sx = x0 + i + 0.5;
            while (k < xs.size() && !(sx < xs[k])) ++k;
            right = xs.size() - k;
            in[size_t(j) * size_t(w) + size_t(i)] = right & 1;
        }
    }
    return in;
}

// The polygon placed in 3D: in the plane spanned by ex, ey through o.
struct Placement {
    std::string name;
    vec3 o, ex, ey;
};
std::vector<Placement> placements() {
    const vec3 tx = glm::normalize(vec3(1.0f, 0.3f, -0.4f));
    const vec3 ty = glm::normalize(glm::cross(glm::normalize(vec3(0.2f, -0.5f, 1.0f)), tx));
    return {{"xy", vec3(0), vec3(1, 0, 0), vec3(0, 1, 0)},
            {"zx-offset", vec3(100, -40, 7), vec3(0, 0, 1), vec3(1, 0, 0)},
            {"tilted", vec3(3, 2, 1), tx, ty},
            {"mirrored-yz", vec3(0), vec3(0, 0, 1), vec3(0, 1, 0)}};
}

struct Result {
    std::vector<uint32_t> tris;
    PolygonKind kind;
};

Result triangulate(const Poly& p, const Placement& pl, PolygonTriangulator& t) {
    std::vector<vec3> pos;
    for (const V2& v : p) pos.push_back(pl.o + float(v.x) * pl.ex + float(v.y) * pl.ey);
    std::vector<uint32_t> corners(p.size());
    std::iota(corners.begin(), corners.end(), 0u);
    Result r;
    r.kind = t.triangulate(pos, corners, r.tris);
    return r;
}

// The triangulation `tris` (indices into p) covers exactly the polygon p on a grid of unit
// pixels over its bounds, with p's orientation, and adds up to its area.
void expectExactCover(const Poly& p, const std::vector<uint32_t>& tris, const std::string& what) {
    SCOPED_TRACE(what);
    ASSERT_EQ(tris.size() % 3, 0u);
    const double area = shoelace(p);
    const int sign = area > 0 ? 1 : -1;
    double sum = 0;
    std::vector<Poly> t;
    for (size_t i = 0; i < tris.size(); i += 3) {
        ASSERT_LT(std::max({tris[i], tris[i + 1], tris[i + 2]}), p.size());
        t.push_back({p[tris[i]], p[tris[i + 1]], p[tris[i + 2]]});
        const double a = shoelace(t.back());
        EXPECT_GE(a * sign, -1e-9) << "triangle " << i / 3 << " is inside out";
        sum += a;
    }
    EXPECT_NEAR(sum, area, 1e-6 * std::fabs(area)) << "triangle areas do not add up to the polygon's";
    EXPECT_LE(t.size(), p.size() - 2);
    double bx0 = 1e30, by0 = 1e30, bx1 = -1e30, by1 = -1e30;
    for (const V2& v : p) {
        bx0 = std::min(bx0, v.x);
        by0 = std::min(by0, v.y);
        bx1 = std::max(bx1, v.x);
        by1 = std::max(by1, v.y);
    }
    const int x0 = int(std::floor(bx0)) - 1, y0 = int(std::floor(by0)) - 1;
    const int w = int(std::ceil(bx1)) + 2 - x0, h = int(std::ceil(by1)) + 2 - y0;
    const std::vector<uint8_t> want = scanlineFill(p, x0, y0, w, h);
    // Each triangle over the samples of its bounds, signed by its winding there.
    std::vector<int> covered(want.size(), 0);
    int bad = 0;
    for (const Poly& tri : t) {
        double tx0 = 1e30, ty0 = 1e30, tx1 = -1e30, ty1 = -1e30;
        for (const V2& v : tri) {
            tx0 = std::min(tx0, v.x);
            ty0 = std::min(ty0, v.y);
            tx1 = std::max(tx1, v.x);
            ty1 = std::max(ty1, v.y);
        }
        for (int j = std::max(0, int(std::floor(ty0)) - y0 - 1); j < std::min(h, int(std::ceil(ty1)) - y0 + 1); ++j)
            for (int i = std::max(0, int(std::floor(tx0)) - x0 - 1); i < std::min(w, int(std::ceil(tx1)) - x0 + 1); ++i) {
                const int wn = windingAt(tri, {x0 + i + 0.5, y0 + j + 0.5});
                if (wn != 0 && wn != sign && bad++ < 5)
                    ADD_FAILURE() << "sample " << x0 + i + 0.5 << "," << y0 + j + 0.5 << " covered by a flipped triangle";
                covered[size_t(j) * size_t(w) + size_t(i)] += wn != 0;
            }
    }
    int inside = 0;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const size_t k = size_t(j) * size_t(w) + size_t(i);
            inside += want[k];
            if (covered[k] != want[k] && bad++ < 5)
                ADD_FAILURE() << "sample " << x0 + i + 0.5 << "," << y0 + j + 0.5 << ": covered " << covered[k] << " times, polygon says "
                              << (want[k] ? "inside" : "outside");
        }
    EXPECT_EQ(bad, 0);
    EXPECT_GT(inside, 0);
}

Poly reversed(Poly p) {
    std::reverse(p.begin(), p.end());
    return p;
}
Poly rotated(Poly p, size_t k) {
    std::rotate(p.begin(), p.begin() + std::ptrdiff_t(k % p.size()), p.end());
    return p;
}
Poly scaled(Poly p, double s) {
    for (V2& v : p) v = {v.x * s, v.y * s};
    return p;
}

// The shapes, counter-clockwise, on a grid of unit pixels.
Poly uShape() { return {{0, 0}, {30, 0}, {30, 30}, {20, 30}, {20, 10}, {10, 10}, {10, 30}, {0, 30}}; }
Poly lShape() { return {{0, 0}, {24, 0}, {24, 8}, {8, 8}, {8, 30}, {0, 30}}; }
Poly star(int points, double r0, double r1, double phase) {
    Poly p;
    for (int k = 0; k < 2 * points; ++k) {
        const double a = phase + sg::kPi * k / points, r = k % 2 ? r1 : r0;
        p.push_back({20 + r * std::cos(a), 20 + r * std::sin(a)});
    }
    return p;
}
Poly comb(int teeth) {   // a spine y in [0, 4], teeth x in [4k, 4k + 2] up to y = 20
    Poly p{{0, 0}, {4.0 * teeth - 2, 0}};
    for (int k = teeth - 1; k >= 0; --k) {
        p.push_back({4.0 * k + 2, 20});
        p.push_back({4.0 * k, 20});
        if (k == 0) break;
        p.push_back({4.0 * k, 4});
        p.push_back({4.0 * k - 2, 4});
    }
    return p;
}
// A spiral band: deeply concave, most corners reflex from some side.
Poly spiral(int turnsTimes8) {
    Poly outer, inner;
    for (int k = 0; k <= turnsTimes8; ++k) {
        const double a = k * sg::kPi / 4, r = 4 + 1.5 * k;
        outer.push_back({40 + (r + 1.2) * std::cos(a), 40 + (r + 1.2) * std::sin(a)});
        inner.push_back({40 + r * std::cos(a), 40 + r * std::sin(a)});
    }
    Poly p = inner;
    for (auto it = outer.rbegin(); it != outer.rend(); ++it) p.push_back(*it);
    if (shoelace(p) < 0) p = reversed(p);
    return p;
}

struct Shape {
    std::string name;
    Poly poly;
};
std::vector<Shape> concaveShapes() {
    return {{"U", uShape()},
            {"L", lShape()},
            {"star5", star(5, 18, 7, 0.1)},
            {"star12", star(12, 19, 9, 0.05)},
            {"comb", comb(6)},
            {"U-fine", scaled(uShape(), 0.37)},
            {"spiral", spiral(20)}};
}

std::vector<uint32_t> fanOf(size_t n) {
    std::vector<uint32_t> f;
    for (uint32_t i = 1; i + 1 < n; ++i) f.insert(f.end(), {0u, i, i + 1});
    return f;
}

}   // namespace

// Scan-line oracle self-check: it agrees with the shoelace area on the U (30x30 minus the
// 10x20 notch = 700 samples) and with the per-sample crossing count.
TEST(PolygonTriangulatorTest, OracleSelfCheck) {
    const std::vector<uint8_t> in = scanlineFill(uShape(), -2, -2, 35, 35);
    int inside = 0;
    for (int j = 0; j < 35; ++j)
        for (int i = 0; i < 35; ++i) {
            inside += in[size_t(j * 35 + i)];
            EXPECT_EQ(in[size_t(j * 35 + i)] != 0, evenOddInside(uShape(), {i - 2 + 0.5, j - 2 + 0.5}));
        }
    EXPECT_EQ(inside, 700);
    EXPECT_DOUBLE_EQ(shoelace(uShape()), 700.0);
    EXPECT_FALSE(evenOddInside(uShape(), {15, 20}));   // the notch
}

// U, L, stars, comb, spiral: every start corner, both windings, four placements in space.
TEST(PolygonTriangulatorTest, ConcaveShapesCoverExactly) {
    PolygonTriangulator t;
    for (const Shape& s : concaveShapes())
        for (bool cw : {false, true})
            for (const Placement& pl : placements())
                for (size_t k = 0; k < s.poly.size(); k += (s.poly.size() > 12 ? 5 : 1)) {
                    Poly p = rotated(cw ? reversed(s.poly) : s.poly, k);
                    Result r = triangulate(p, pl, t);
                    EXPECT_EQ(r.kind, PolygonKind::Concave);
                    expectExactCover(p, r.tris, s.name + (cw ? " cw" : " ccw") + " start " + std::to_string(k) + " in " + pl.name);
                    if (HasFailure()) return;
                }
}

// The fan of a concave polygon is wrong (that is what this replaces): the oracle says so.
TEST(PolygonTriangulatorTest, FanOfConcaveIsCaughtByTheOracle) {
    Poly u = rotated(uShape(), 4);   // start at an inner corner of the notch: fan spills
    std::vector<uint32_t> f = fanOf(u.size());
    std::vector<Poly> tris;
    int multiple = 0;
    for (int j = 0; j < 30; ++j)
        for (int i = 0; i < 30; ++i) {
            int c = 0;
            for (size_t q = 0; q < f.size(); q += 3) c += windingAt({u[f[q]], u[f[q + 1]], u[f[q + 2]]}, {i + 0.5, j + 0.5}) != 0;
            multiple += c != (evenOddInside(u, {i + 0.5, j + 0.5}) ? 1 : 0);
        }
    EXPECT_GE(multiple, 100);   // the notch (10 x 20 samples) is half filled, at least
}

// Normals: each 3D triangle's normal points the way the polygon's Newell normal does.
TEST(PolygonTriangulatorTest, OrientationKeptIn3D) {
    PolygonTriangulator t;
    for (const Shape& s : concaveShapes())
        for (bool cw : {false, true})
            for (const Placement& pl : placements()) {
                Poly p = cw ? reversed(s.poly) : s.poly;
                std::vector<vec3> pos;
                for (const V2& v : p) pos.push_back(pl.o + float(v.x) * pl.ex + float(v.y) * pl.ey);
                glm::dvec3 newell(0.0);
                for (size_t i = 0; i < pos.size(); ++i) newell += glm::cross(glm::dvec3(pos[i]), glm::dvec3(pos[(i + 1) % pos.size()]));
                std::vector<uint32_t> corners(p.size()), out;
                std::iota(corners.begin(), corners.end(), 0u);
                t.triangulate(pos, corners, out);
                for (size_t i = 0; i < out.size(); i += 3) {
                    glm::dvec3 n = glm::cross(glm::dvec3(pos[out[i + 1]] - pos[out[i]]), glm::dvec3(pos[out[i + 2]] - pos[out[i]]));
                    EXPECT_GT(glm::dot(n, newell), 0.0) << s.name << " " << pl.name << (cw ? " cw" : " ccw") << " triangle " << i / 3;
                }
            }
}

// Convex polygons (also with collinear and repeated corners, and non-planar ones whose
// projection is convex) keep exactly the fan the importers always made: renders do not change.
TEST(PolygonTriangulatorTest, ConvexKeepsTheFan) {
    PolygonTriangulator t;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    for (int iter = 0; iter < 300; ++iter) {
        const int n = 4 + iter % 9;
        Poly p;
        for (int k = 0; k < n; ++k) {
            const double a = 2 * sg::kPi * (k + 0.4 * U(rng)) / n;   // on a circle: convex
            p.push_back({15 + 10 * std::cos(a), 15 + 10 * std::sin(a)});
        }
        const V2 mid{(p[1].x + p[2].x) / 2, (p[1].y + p[2].y) / 2}, again = p[1];
        if (iter % 3 == 1) p.insert(p.begin() + 2, mid);     // collinear
        if (iter % 3 == 2) p.insert(p.begin() + 1, again);   // repeated
        for (bool cw : {false, true}) {
            Poly q = cw ? reversed(p) : p;
            Result r = triangulate(q, placements()[size_t(iter) % 4], t);
            EXPECT_EQ(r.kind, PolygonKind::Convex) << iter;
            EXPECT_EQ(r.tris, fanOf(q.size())) << iter;
        }
    }
    // Unit cube faces as the OBJ/OFF/PLY test files have them.
    std::vector<vec3> cube = {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}, {-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}};
    std::vector<std::vector<uint32_t>> faces = {{0, 1, 2, 3}, {5, 4, 7, 6}, {4, 0, 3, 7}, {1, 5, 6, 2}, {3, 2, 6, 7}, {4, 5, 1, 0}};
    for (auto& f : faces) {
        std::vector<uint32_t> out;
        EXPECT_EQ(t.triangulate(cube, f, out), PolygonKind::Convex);
        EXPECT_EQ(out, (std::vector<uint32_t>{f[0], f[1], f[2], f[0], f[2], f[3]}));
    }
    // A twisted (non-planar) quad: still the fan, both triangles facing the Newell side.
    std::vector<vec3> twisted = {{0, 0, 0}, {1, 0, 0.3f}, {1, 1, 0}, {0, 1, 0.3f}};
    std::vector<uint32_t> out;
    EXPECT_EQ(t.triangulate(twisted, std::vector<uint32_t>{0, 1, 2, 3}, out), PolygonKind::Convex);
    EXPECT_EQ(out, fanOf(4));
}

TEST(PolygonTriangulatorTest, TrianglesPassThrough) {
    PolygonTriangulator t;
    std::vector<vec3> pos = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}};
    std::vector<uint32_t> out;
    EXPECT_EQ(t.triangulate(pos, std::vector<uint32_t>{3, 1, 0}, out), PolygonKind::Triangle);
    EXPECT_EQ(t.triangulate(pos, std::vector<uint32_t>{0, 1, 2}, out), PolygonKind::Triangle);   // degenerate: kept as is
    EXPECT_EQ(out, (std::vector<uint32_t>{3, 1, 0, 0, 1, 2}));
    EXPECT_EQ(t.triangulate(pos, std::vector<uint32_t>{0, 1}, out), PolygonKind::TooFew);
    EXPECT_EQ(out.size(), 6u);
}

// A concave quad (dart) is split along the diagonal through its reflex corner; when that
// corner is the first or third the result is the fan, as before.
TEST(PolygonTriangulatorTest, ConcaveQuadUsesTheReflexDiagonal) {
    PolygonTriangulator t;
    const Poly dart = {{0, 0}, {10, 4}, {20, 0}, {10, 20}};   // reflex at corner 1
    for (size_t k = 0; k < 4; ++k)
        for (bool cw : {false, true})
            for (const Placement& pl : placements()) {
                Poly p = rotated(cw ? reversed(dart) : dart, k);
                Result r = triangulate(p, pl, t);
                EXPECT_EQ(r.kind, PolygonKind::Concave);
                ASSERT_EQ(r.tris.size(), 6u);
                expectExactCover(p, r.tris, "dart start " + std::to_string(k) + (cw ? " cw " : " ccw ") + pl.name);
                size_t reflex = 0;
                for (size_t j = 0; j < 4; ++j)
                    if (p[j].x == 10 && p[j].y == 4) reflex = j;
                if (reflex % 2 == 0) {
                    EXPECT_EQ(r.tris, fanOf(4));
                } else {
                    EXPECT_EQ(r.tris[0], reflex);
                    EXPECT_EQ(r.tris[3], reflex);
                }
            }
}

// Random simple quads (convex and concave, both windings, in space): the quad fast path
// covers each exactly, and the fan when convex.
TEST(PolygonTriangulatorTest, RandomQuadsCoverExactly) {
    PolygonTriangulator t;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(0.0, 40.0);
    auto crosses = [](V2 a, V2 b, V2 c, V2 d) {   // segments ab and cd cross properly
        auto side = [](V2 p, V2 q, V2 r) { return (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x); };
        return side(a, b, c) * side(a, b, d) < 0 && side(c, d, a) * side(c, d, b) < 0;
    };
    int concave = 0, convex = 0;
    for (int iter = 0; iter < 2000 && !HasFailure(); ++iter) {
        Poly q = {{U(rng), U(rng)}, {U(rng), U(rng)}, {U(rng), U(rng)}, {U(rng), U(rng)}};
        if (crosses(q[0], q[1], q[2], q[3]) || crosses(q[1], q[2], q[3], q[0]) || std::fabs(shoelace(q)) < 20.0) continue;
        Result r = triangulate(q, placements()[size_t(iter) % 4], t);
        ASSERT_TRUE(r.kind == PolygonKind::Convex || r.kind == PolygonKind::Concave) << iter;
        (r.kind == PolygonKind::Convex ? convex : concave)++;
        if (r.kind == PolygonKind::Convex) { EXPECT_EQ(r.tris, fanOf(4)); }
        expectExactCover(q, r.tris, "random quad " + std::to_string(iter));
    }
    EXPECT_GT(concave, 100);
    EXPECT_GT(convex, 100);
}

// Collinear runs, repeated corners, a spike doubling back: still an exact cover.
TEST(PolygonTriangulatorTest, CollinearAndRepeatedCorners) {
    PolygonTriangulator t;
    Poly u = {{0, 0},   {10, 0},  {20, 0},  {30, 0},  {30, 15}, {30, 30}, {20, 30}, {20, 20},
              {20, 10}, {15, 10}, {10, 10}, {10, 30}, {5, 30},  {0, 30},  {0, 15}};
    Poly repeated = u;
    repeated.insert(repeated.begin() + 9, repeated[9]);
    repeated.insert(repeated.begin() + 3, repeated[3]);
    repeated.push_back(repeated[0]);   // closing corner repeated, as some exporters write it
    for (const Poly& p0 : {u, repeated})
        for (bool cw : {false, true})
            for (size_t k = 0; k < p0.size(); ++k) {
                Poly p = rotated(cw ? reversed(p0) : p0, k);
                Result r = triangulate(p, placements()[k % 4], t);
                EXPECT_EQ(r.kind, PolygonKind::Concave);
                expectExactCover(p, r.tris, "collinear U (" + std::to_string(p0.size()) + " corners) start " + std::to_string(k));
                if (HasFailure()) return;
            }
    // An L with a zero-width spike sticking out of its inner corner.
    Poly spike = {{0, 0}, {24, 0}, {24, 8}, {8, 8}, {16, 16}, {8, 8}, {8, 30}, {0, 30}};
    Result r = triangulate(spike, placements()[0], t);
    EXPECT_NE(r.kind, PolygonKind::Fallback);
    expectExactCover(spike, r.tris, "spike");
}

// Non-planar polygons: a U bent out of its plane still comes out as the U seen along the
// Newell normal, facing that way.
TEST(PolygonTriangulatorTest, NonPlanarConcave) {
    PolygonTriangulator t;
    for (bool cw : {false, true}) {
        Poly p = cw ? reversed(uShape()) : uShape();
        std::vector<vec3> pos;
        for (const V2& v : p) pos.push_back(vec3(float(v.x), float(v.y), 0.15f * float(v.x) + 0.1f * float(std::sin(v.y))));   // sheared + wavy
        std::vector<uint32_t> corners(p.size()), out;
        std::iota(corners.begin(), corners.end(), 0u);
        EXPECT_EQ(t.triangulate(pos, corners, out), PolygonKind::Concave);
        expectExactCover(p, out, cw ? "bent U cw" : "bent U ccw");   // seen from +z, the xy coordinates
    }
    // A non-planar pentagon (a house roof folded up): n - 2 triangles, all facing one side.
    std::vector<vec3> house = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0.5f}, {1, 2, 1.0f}, {0, 1, 0.5f}};
    std::vector<uint32_t> out;
    EXPECT_EQ(t.triangulate(house, std::vector<uint32_t>{0, 1, 2, 3, 4}, out), PolygonKind::Convex);
    EXPECT_EQ(out.size(), 9u);
}

// Zero area, non-finite corners, self-intersections: terminate with something sensible.
TEST(PolygonTriangulatorTest, DegenerateAndSelfIntersecting) {
    PolygonTriangulator t;
    std::vector<uint32_t> out;
    std::vector<vec3> line = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {5, 5, 5}, {3, 3, 3}};
    EXPECT_EQ(t.triangulate(line, std::vector<uint32_t>{0, 1, 2, 3, 4}, out), PolygonKind::Degenerate);
    EXPECT_EQ(out, fanOf(5));
    out.clear();
    std::vector<vec3> point(6, vec3(1, 2, 3));
    EXPECT_EQ(t.triangulate(point, std::vector<uint32_t>{0, 1, 2, 3, 4, 5}, out), PolygonKind::Degenerate);
    out.clear();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<vec3> bad = {{0, 0, 0}, {1, 0, 0}, {nan, 1, 0}, {0, 1, 0}};
    EXPECT_EQ(t.triangulate(bad, std::vector<uint32_t>{0, 1, 2, 3}, out), PolygonKind::Degenerate);
    EXPECT_EQ(out.size(), 6u);

    // Bow tie: zero or non-zero area, any start.
    for (float skew : {0.0f, 0.3f}) {
        std::vector<vec3> bow = {{0, 0, 0}, {1, 1 + skew, 0}, {1, 0, 0}, {0, 1, 0}};
        out.clear();
        t.triangulate(bow, std::vector<uint32_t>{0, 1, 2, 3}, out);
        EXPECT_EQ(out.size(), 6u);
    }
    // Pentagram {5/2}: all turns the same way but it winds twice: not convex, not a simple
    // polygon; whatever comes out has n - 2 triangles at most.
    std::vector<vec3> pentagram;
    for (int k = 0; k < 5; ++k) pentagram.push_back(vec3(std::cos(k * 4 * sg::kPi / 5), std::sin(k * 4 * sg::kPi / 5), 0));
    out.clear();
    EXPECT_NE(t.triangulate(pentagram, std::vector<uint32_t>{0, 1, 2, 3, 4}, out), PolygonKind::Convex);
    EXPECT_LE(out.size(), 9u);
    EXPECT_GT(out.size(), 0u);

    // Random self-intersecting polygons, up to 300 corners: all terminate, indices in range.
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f);
    for (int iter = 0; iter < 200; ++iter) {
        const size_t n = 4 + size_t(iter) * 3 % 300;
        std::vector<vec3> pos(n);
        for (vec3& v : pos) v = vec3(U(rng), U(rng), iter % 2 ? 0.0f : 0.1f * U(rng));
        std::vector<uint32_t> corners(n);
        std::iota(corners.begin(), corners.end(), 0u);
        if (iter % 5 == 0) corners[n / 2] = corners[0];   // a corner used twice
        out.clear();
        t.triangulate(pos, corners, out);
        EXPECT_EQ(out.size() % 3, 0u);
        EXPECT_LE(out.size(), 3 * (n - 2));
        for (uint32_t i : out) ASSERT_LT(i, n);
    }
}

// Large polygons: O(n^2) keeps a 3000-corner star and a 4000-corner comb fast, and exact.
TEST(PolygonTriangulatorTest, LargePolygonsAreFastAndExact) {
    PolygonTriangulator t;
    for (const Shape& s : {Shape{"star1500", scaled(star(1500, 18, 16, 0.01), 3.0)}, Shape{"comb1000", comb(1000)}}) {
        std::vector<vec3> pos;
        for (const V2& v : s.poly) pos.push_back(vec3(float(v.x), float(v.y), 0));
        std::vector<uint32_t> corners(pos.size()), out;
        std::iota(corners.begin(), corners.end(), 0u);
        auto t0 = std::chrono::steady_clock::now();
        EXPECT_EQ(t.triangulate(pos, corners, out), PolygonKind::Concave) << s.name;
        double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::printf("%s: %zu corners in %.1f ms\n", s.name.c_str(), pos.size(), dt * 1e3);
        EXPECT_LT(dt, 2.0) << s.name;
        EXPECT_EQ(out.size(), 3 * (pos.size() - 2)) << s.name;
        expectExactCover(s.poly, out, s.name);
    }
}
