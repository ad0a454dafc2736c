// analytic.cpp - exact intersections for implicit shapes, CSG, parametric surfaces and grids.
//
// Sections: helpers (quadratic inside-region, slabs), implicitSpans/implicitNormal, polyRoots
// (root isolation through the derivative chain), CSG interval booleans, ParametricAccel
// (sub-patch boxes + Newton), GridAccel (block min/max + marching + bisection).
#include "raycast/analytic.h"

#include <emmintrin.h>

#include <algorithm>
#include <cmath>

namespace rnd::rt {

using namespace sg;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

Bound bnd(float t, uint8_t tag) {
    Bound b;
    b.t = t;
    b.tag = tag;
    return b;
}

// Region of t where A t^2 + B t + C <= 0, as up to two spans (bounds tagged kTagSurface).
void quadraticInside(double A, double B, double C, SpanList& out) {
    double scale = std::abs(A) + std::abs(B) + std::abs(C);
    if (scale == 0) {
        out.push({bnd(-kInf, 0), bnd(kInf, 0)});
        return;
    }
    if (std::abs(A) <= 1e-12 * scale) {   // linear
        if (B == 0) {
            if (C <= 0) out.push({bnd(-kInf, 0), bnd(kInf, 0)});
            return;
        }
        float r = float(-C / B);
        if (B > 0)
            out.push({bnd(-kInf, 0), bnd(r, 0)});
        else
            out.push({bnd(r, 0), bnd(kInf, 0)});
        return;
    }
    double disc = B * B - 4 * A * C;
    if (disc < 0) {
        if (A < 0) out.push({bnd(-kInf, 0), bnd(kInf, 0)});
        return;
    }
    double sq = std::sqrt(disc);
    double q = -0.5 * (B + (B >= 0 ? sq : -sq));   // stable: no cancellation
    double r1 = q / A, r2 = q != 0 ? C / q : r1;
    if (r1 > r2) std::swap(r1, r2);
    if (A > 0)
        out.push({bnd(float(r1), 0), bnd(float(r2), 0)});
    else {
        out.push({bnd(-kInf, 0), bnd(float(r1), 0)});
        out.push({bnd(float(r2), 0), bnd(kInf, 0)});
    }
}

// Interval of t inside lo <= (o + t d)[axis] <= hi, tagged with the box faces. False if empty.
bool slab(int axis, float o, float d, float lo, float hi, Span& s) {
    if (std::abs(d) < 1e-30f) {
        if (o < lo || o > hi) return false;
        s = {bnd(-kInf, 0), bnd(kInf, 0)};
        return true;
    }
    float t0 = (lo - o) / d, t1 = (hi - o) / d;
    uint8_t tagLo = uint8_t(kTagFace + 2 * axis), tagHi = uint8_t(kTagFace + 2 * axis + 1);
    if (d > 0)
        s = {bnd(t0, tagLo), bnd(t1, tagHi)};
    else
        s = {bnd(t1, tagHi), bnd(t0, tagLo)};
    return true;
}

// Intersects every span of `io` with s (in place).
void clip(SpanList& io, const Span& s) {
    int w = 0;
    for (int i = 0; i < io.n; ++i) {
        Span x = io.s[i];
        if (s.in.t > x.in.t) x.in = s.in;
        if (s.out.t < x.out.t) x.out = s.out;
        if (x.in.t <= x.out.t) io.s[w++] = x;
    }
    io.n = w;
}

// Clips to the box [lo, hi] on the given axes (mask bit a = axis a).
void clipBox(SpanList& io, const Ray& r, const vec3& lo, const vec3& hi, int axes) {
    for (int a = 0; a < 3 && io.n > 0; ++a) {
        if (!(axes & (1 << a))) continue;
        Span s;
        if (!slab(a, r.org[a], r.dir[a], lo[a], hi[a], s)) {
            io.n = 0;
            return;
        }
        clip(io, s);
    }
}

bool boxInterval(const Ray& r, const vec3& lo, const vec3& hi, float& t0, float& t1) {
    SpanList l;
    l.push({bnd(-kInf, 0), bnd(kInf, 0)});
    clipBox(l, r, lo, hi, 7);
    if (l.n == 0) return false;
    t0 = l.s[0].in.t;
    t1 = l.s[0].out.t;
    return true;
}

double evalPoly(const double* c, int deg, double x) {
    double v = c[deg];
    for (int i = deg - 1; i >= 0; --i) v = v * x + c[i];
    return v;
}

}   // namespace

// --- implicit shapes ------------------------------------------------------------------------

void implicitSpans(const ImplicitShape& sh, const Ray& r, SpanList& out) {
    out.n = 0;
    const double ox = r.org.x, oy = r.org.y, oz = r.org.z;
    const double dx = r.dir.x, dy = r.dir.y, dz = r.dir.z;
    switch (sh.type) {
    case ImplicitType::Plane: {   // solid half space y <= 0
        if (std::abs(r.dir.y) < 1e-30f) {
            if (r.org.y <= 0) out.push({bnd(-kInf, 0), bnd(kInf, 0)});
            return;
        }
        float t = -r.org.y / r.dir.y;
        if (r.dir.y > 0)
            out.push({bnd(-kInf, 0), bnd(t, 0)});
        else
            out.push({bnd(t, 0), bnd(kInf, 0)});
        return;
    }
    case ImplicitType::Sphere: {
        double rr = sh.radius;
        quadraticInside(dx * dx + dy * dy + dz * dz, 2 * (ox * dx + oy * dy + oz * dz), ox * ox + oy * oy + oz * oz - rr * rr, out);
        if (out.n > 0 && sh.radius <= 0) out.n = 0;
        // A sphere with A > 0 gives at most one span.
        return;
    }
    case ImplicitType::Box: {
        out.push({bnd(-kInf, 0), bnd(kInf, 0)});
        clipBox(out, r, -sh.halfExtents, sh.halfExtents, 7);
        return;
    }
    case ImplicitType::Cylinder: {
        double rr = sh.radius;
        quadraticInside(dx * dx + dz * dz, 2 * (ox * dx + oz * dz), ox * ox + oz * oz - rr * rr, out);
        clipBox(out, r, vec3(0, -sh.halfHeight, 0), vec3(0, sh.halfHeight, 0), 2);
        return;
    }
    case ImplicitType::Cone: {
        // x^2 + z^2 <= k^2 (h - y)^2, k = r / (2h), apex at y = +h, base at y = -h.
        double h = sh.halfHeight, k = sh.radius / (2.0 * std::max(h, 1e-20)), k2 = k * k;
        double a0 = h - oy;
        quadraticInside(dx * dx + dz * dz - k2 * dy * dy, 2 * (ox * dx + oz * dz) + 2 * k2 * a0 * dy, ox * ox + oz * oz - k2 * a0 * a0, out);
        clipBox(out, r, vec3(0, -sh.halfHeight, 0), vec3(0, sh.halfHeight, 0), 2);
        return;
    }
    case ImplicitType::Torus: {
        const double R = sh.majorRadius, rm = sh.minorRadius;
        Aabb b = sh.localBounds();
        float t0, t1;
        vec3 pad(1e-4f * (sh.majorRadius + sh.minorRadius));
        if (!boxInterval(r, b.min - pad, b.max + pad, t0, t1)) return;
        double L = std::sqrt(dx * dx + dy * dy + dz * dz);
        if (!(L > 0)) return;
        // Shift the origin to the box entry and use a unit direction: small, well-scaled
        // coefficients (the quartic loses digits when the origin is far away).
        double px = ox + t0 * dx, py = oy + t0 * dy, pz = oz + t0 * dz;
        double ux = dx / L, uy = dy / L, uz = dz / L;
        double bq = px * ux + py * uy + pz * uz;
        double c0 = px * px + py * py + pz * pz + R * R - rm * rm;
        double axz = ux * ux + uz * uz, bxz = px * ux + pz * uz, cxz = px * px + pz * pz;
        double c[5];
        c[4] = 1;
        c[3] = 4 * bq;
        c[2] = 4 * bq * bq + 2 * c0 - 4 * R * R * axz;
        c[1] = 4 * bq * c0 - 8 * R * R * bxz;
        c[0] = c0 * c0 - 4 * R * R * cxz;
        double sMax = double(t1 - t0) * L;
        double roots[4];
        int n = polyRoots(c, 4, 0.0, sMax, roots);
        bool inside = c[0] < 0;
        float start = t0;
        for (int i = 0; i < n; ++i) {
            float t = float(t0 + roots[i] / L);
            if (inside)
                out.push({bnd(start, 0), bnd(t, 0)});
            else
                start = t;
            inside = !inside;
        }
        if (inside) out.push({bnd(start, 0), bnd(t1, 0)});
        return;
    }
    case ImplicitType::Quadric: {
        glm::dmat4 Q(sh.quadric);
        glm::dvec4 P(ox, oy, oz, 1.0), D(dx, dy, dz, 0.0);
        glm::dvec4 QP = Q * P, QD = Q * D;
        double A = glm::dot(D, QD), B = glm::dot(D, QP) + glm::dot(P, QD), C = glm::dot(P, QP);
        quadraticInside(A, B, C, out);
        clipBox(out, r, sh.quadricBounds.min, sh.quadricBounds.max, 7);
        return;
    }
    }
}

vec3 implicitNormal(const ImplicitShape& sh, const vec3& p, uint8_t tag) {
    if (tag >= kTagFace) {
        int axis = (tag - kTagFace) / 2;
        vec3 n(0.0f);
        n[axis] = ((tag - kTagFace) & 1) ? 1.0f : -1.0f;
        return n;
    }
    vec3 g;
    switch (sh.type) {
    case ImplicitType::Plane: return vec3(0, 1, 0);
    case ImplicitType::Sphere: g = p; break;
    case ImplicitType::Cylinder: g = vec3(p.x, 0, p.z); break;
    case ImplicitType::Cone: {
        float k = sh.radius / (2.0f * std::max(sh.halfHeight, 1e-20f));
        g = vec3(p.x, k * k * (sh.halfHeight - p.y), p.z);
        break;
    }
    case ImplicitType::Quadric: {
        vec4 x(p, 1.0f);
        g = vec3((sh.quadric + glm::transpose(sh.quadric)) * x);
        break;
    }
    default: return sh.normal(p);
    }
    float l = glm::length(g);
    return l > 1e-30f && std::isfinite(l) ? g / l : sh.normal(p);
}

bool firstBoundary(const SpanList& spans, float tmin, float tmax, Bound& hit) {
    for (int i = 0; i < spans.n; ++i) {
        const Span& s = spans.s[i];
        if (s.in.t > tmin && s.in.t < tmax) {
            hit = s.in;
            return true;
        }
        if (s.out.t > tmin && s.out.t < tmax) {
            hit = s.out;
            return true;
        }
        if (s.in.t >= tmax) return false;
    }
    return false;
}

int polyRoots(const double* c, int deg, double lo, double hi, double* roots) {
    while (deg > 0 && c[deg] == 0) --deg;
    if (deg <= 0 || !(lo <= hi)) return 0;
    if (deg == 1) {
        double x = -c[0] / c[1];
        if (x >= lo && x <= hi) {
            roots[0] = x;
            return 1;
        }
        return 0;
    }
    // Critical points (roots of the derivative) split [lo, hi] into monotone pieces; each
    // piece holds at most one root, found by safeguarded Newton/bisection.
    double dc[4];
    for (int i = 0; i < deg; ++i) dc[i] = (i + 1) * c[i + 1];
    double crit[4];
    int nc = polyRoots(dc, deg - 1, lo, hi, crit);
    double pts[6];
    int np = 0;
    pts[np++] = lo;
    for (int i = 0; i < nc; ++i) pts[np++] = crit[i];
    pts[np++] = hi;
    int n = 0;
    for (int i = 0; i + 1 < np; ++i) {
        double a = pts[i], b = pts[i + 1];
        double fa = evalPoly(c, deg, a), fb = evalPoly(c, deg, b);
        if (fa == 0) {
            if (n == 0 || roots[n - 1] != a) roots[n++] = a;
            continue;
        }
        if ((fa < 0) == (fb < 0) || fb == 0) {
            if (fb == 0 && i + 2 == np) roots[n++] = b;
            continue;
        }
        double x = 0.5 * (a + b);
        for (int it = 0; it < 80; ++it) {
            double fx = evalPoly(c, deg, x);
            if (fx == 0) break;
            if ((fx < 0) == (fa < 0))
                a = x;
            else
                b = x;
            double dfx = evalPoly(dc, deg - 1, x);
            double xn = dfx != 0 ? x - fx / dfx : 0.5 * (a + b);
            if (!(xn > a && xn < b)) xn = 0.5 * (a + b);
            if (std::abs(xn - x) <= 1e-14 * (1 + std::abs(x)) || b - a <= 1e-14 * (1 + std::abs(a))) {
                x = xn;
                break;
            }
            x = xn;
        }
        roots[n++] = x;
    }
    return n;
}

// --- CSG ---------------------------------------------------------------------------------------

namespace {

// One end of a span: its distance, and which list, span and end it is (a plain struct: the
// array of them is not initialized before it is filled).
struct Event {
    float t;
    uint8_t fromB, enter, span;
};

// Boolean of two sorted span lists by sweeping their ends (CSG: combine the intervals).
// Difference: ends contributed by the cutter B get their normal flipped.
void combine(const SpanList& A, const SpanList& B, CsgOp op, SpanList& out) {
    static_assert(SpanList::kCapacity <= 256, "Event::span is one byte");
    Event ev[2 * 2 * SpanList::kCapacity];
    int ne = 0;
    for (int i = 0; i < A.n; ++i) {
        ev[ne++] = {A.s[i].in.t, 0, 1, uint8_t(i)};
        ev[ne++] = {A.s[i].out.t, 0, 0, uint8_t(i)};
    }
    for (int i = 0; i < B.n; ++i) {
        ev[ne++] = {B.s[i].in.t, 1, 1, uint8_t(i)};
        ev[ne++] = {B.s[i].out.t, 1, 0, uint8_t(i)};
    }
    std::sort(ev, ev + ne, [](const Event& x, const Event& y) { return x.t < y.t; });
    bool inA = false, inB = false, inR = false;
    Bound start;
    out.n = 0;
    for (int i = 0; i < ne; ++i) {
        const Event& e = ev[i];
        (e.fromB ? inB : inA) = e.enter;
        bool r = op == CsgOp::Union ? (inA || inB) : op == CsgOp::Intersection ? (inA && inB) : (inA && !inB);
        if (r == inR) continue;
        const Span& from = (e.fromB ? B : A).s[e.span];
        Bound b = e.enter ? from.in : from.out;
        if (op == CsgOp::Difference && e.fromB) b.flip ^= 1;
        if (r)
            start = b;
        else
            out.push({start, b});
        inR = r;
    }
}

void csgRec(const CsgTree& tree, int index, const Ray& wr, SpanList& out, int depth) {
    out.n = 0;
    if (index < 0 || size_t(index) >= tree.nodes.size() || depth > 64) return;
    const CsgTree::Node& node = tree.nodes[index];
    if (node.op < 0) {
        Ray lr;
        lr.org = vec3(node.invWorld * vec4(wr.org, 1.0f));
        lr.dir = mat3(node.invWorld) * wr.dir;
        implicitSpans(node.shape, lr, out);
        for (int i = 0; i < out.n; ++i) out.s[i].in.leaf = out.s[i].out.leaf = int16_t(index);
        return;
    }
    if (node.children.empty()) return;
    csgRec(tree, node.children[0], wr, out, depth + 1);
    SpanList b, tmp;
    for (size_t k = 1; k < node.children.size(); ++k) {
        csgRec(tree, node.children[k], wr, b, depth + 1);
        combine(out, b, CsgOp(node.op), tmp);
        out = tmp;
    }
}

}   // namespace

void csgSpans(const CsgTree& tree, const Ray& worldRay, SpanList& out) { csgRec(tree, tree.root, worldRay, out, 0); }

// --- parametric -----------------------------------------------------------------------------------

ParametricAccel::ParametricAccel(const ParametricSurface& s) : m_surface(s) {
    for (int k = 0; k < 16; ++k) {
        m_control[k][0] = s.control[k].x;
        m_control[k][1] = s.control[k].y;
        m_control[k][2] = s.control[k].z;
        m_control[k][3] = 0.0f;
    }
    if (s.type == ParametricType::Torus) {
        m_nu = 32;
        m_nv = 16;
    } else {
        m_nu = 8;
        m_nv = 8;
    }
    const int k = 4;
    m_boxMin.resize(size_t(m_nu) * m_nv);
    m_boxMax.resize(size_t(m_nu) * m_nv);
    for (int j = 0; j < m_nv; ++j)
        for (int i = 0; i < m_nu; ++i) {
            Aabb b;
            for (int y = 0; y <= k; ++y)
                for (int x = 0; x <= k; ++x) b.extend(s.evaluate((i + float(x) / k) / m_nu, (j + float(y) / k) / m_nv));
            // Pad: the surface bulges between the 5x5 samples; 10% of the box size is ample
            // for these subdivisions (the sag of a sub-patch between samples is far smaller).
            vec3 pad = 0.1f * b.extent() + vec3(0.02f * glm::length(b.extent()) + 1e-5f);
            m_boxMin[size_t(j) * m_nu + i] = b.min - pad;
            m_boxMax[size_t(j) * m_nu + i] = b.max + pad;
        }
    Bvh4::BuildOptions o;
    o.maxLeafSize = 1;
    o.parallel = false;
    m_bvh.build(m_boxMin.data(), m_boxMax.data(), m_boxMin.size(), o);
    // Newton's starts in each sub-patch: its centre first; the two others are tried only when
    // that one fails (it converges from the centre for nearly all rays that hit the sub-patch).
    // The surface there does not depend on the ray, so it is evaluated here once.
    const float starts[kNewtonStarts][2] = {{0.5f, 0.5f}, {0.25f, 0.25f}, {0.75f, 0.75f}};
    m_starts.resize(m_boxMin.size() * kNewtonStarts);
    m_scale.resize(m_boxMin.size());
    for (int j = 0; j < m_nv; ++j)
        for (int i = 0; i < m_nu; ++i) {
            const size_t patch = size_t(j) * m_nu + i;
            m_scale[patch] = glm::length(m_boxMax[patch] - m_boxMin[patch]);
            float u0 = float(i) / m_nu, u1 = float(i + 1) / m_nu, v0 = float(j) / m_nv, v1 = float(j + 1) / m_nv;
            for (int k = 0; k < kNewtonStarts; ++k) {
                NewtonStart& st = m_starts[patch * kNewtonStarts + k];
                st.u = u0 + starts[k][0] * (u1 - u0);
                st.v = v0 + starts[k][1] * (v1 - v0);
                st.P = evaluate(st.u, st.v, st.Pu, st.Pv);
            }
        }
}

namespace {

// cubicBernstein's b[0..3] and db[0..3] in two registers, with its operations lane by lane:
// b = (s s, 3t s, 3t t, t t) * (s, s, s, t) and db = (-3s s, 3s s, 6t s, 3t t) minus
// (0, 6t s, 3t t, 0) (x - 0 is x, -0 included).
void bernstein4(float t, __m128& b, __m128& db) {
    const float s = 1 - t;
    const __m128 sssT = _mm_setr_ps(s, s, s, t);
    b = _mm_mul_ps(_mm_mul_ps(_mm_setr_ps(s, 3 * t, 3 * t, t), _mm_setr_ps(s, s, t, t)), sssT);
    const __m128 a = _mm_mul_ps(_mm_setr_ps(-3 * s, 3 * s, 6 * t, 3 * t), sssT);
    const __m128 sub = _mm_and_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 3, 2, 2)),   // (a2, a2, a3, a3)
                                  _mm_castsi128_ps(_mm_setr_epi32(0, -1, -1, 0)));
    db = _mm_sub_ps(a, sub);
}

template <int I>
__m128 lane(__m128 v) {
    return _mm_shuffle_ps(v, v, _MM_SHUFFLE(I, I, I, I));
}

}   // namespace

vec3 ParametricAccel::evaluate(float u, float v, vec3& Pu, vec3& Pv) const {
    if (m_surface.type != ParametricType::BezierPatch) return m_surface.evaluate(u, v, Pu, Pv);
    // ParametricSurface::evaluate's sums term by term in its order: each term's weight is one
    // float product (bu * bv, dbu * bv, bu * dbv), then weight * control and the add, per
    // component. The lanes do the same IEEE operations, so the bits are the same: a row's four
    // weights are one product of registers, each term's is broadcast from its lane.
    __m128 bu, dbu, bv, dbv;
    bernstein4(u, bu, dbu);
    bernstein4(v, bv, dbv);
    alignas(16) float bvs[4], dbvs[4];
    _mm_store_ps(bvs, bv);
    _mm_store_ps(dbvs, dbv);
    __m128 p = _mm_setzero_ps(), pu = p, pv = p;
    auto term = [&](const float* control, __m128 wp, __m128 wu, __m128 wv) {
        const __m128 c = _mm_load_ps(control);
        p = _mm_add_ps(p, _mm_mul_ps(wp, c));
        pu = _mm_add_ps(pu, _mm_mul_ps(wu, c));
        pv = _mm_add_ps(pv, _mm_mul_ps(wv, c));
    };
    for (int j = 0; j < 4; ++j) {
        const __m128 wp = _mm_mul_ps(bu, _mm_set1_ps(bvs[j])), wu = _mm_mul_ps(dbu, _mm_set1_ps(bvs[j]));
        const __m128 wv = _mm_mul_ps(bu, _mm_set1_ps(dbvs[j]));
        const float(*row)[4] = m_control + j * 4;
        term(row[0], lane<0>(wp), lane<0>(wu), lane<0>(wv));
        term(row[1], lane<1>(wp), lane<1>(wu), lane<1>(wv));
        term(row[2], lane<2>(wp), lane<2>(wu), lane<2>(wv));
        term(row[3], lane<3>(wp), lane<3>(wu), lane<3>(wv));
    }
    alignas(16) float o[3][4];
    _mm_store_ps(o[0], p);
    _mm_store_ps(o[1], pu);
    _mm_store_ps(o[2], pv);
    Pu = vec3(o[1][0], o[1][1], o[1][2]);
    Pv = vec3(o[2][0], o[2][1], o[2][2]);
    return vec3(o[0][0], o[0][1], o[0][2]);
}

template <bool AnyHit>
bool ParametricAccel::trace(const Ray& r, float& tOut, float& uOut, float& vOut) const {
    float tmax = r.tmax;
    bool found = false;
    const float dd = glm::dot(r.dir, r.dir);
    if (!(dd > 0)) return false;
    const std::vector<uint32_t>& prims = m_bvh.primIndex();
    m_bvh.traverse<AnyHit>(r, tmax, [&](uint32_t first, uint32_t count, float& tm) {
        for (uint32_t q = 0; q < count; ++q) {
            uint32_t patch = prims[first + q];
            int i = int(patch % uint32_t(m_nu)), j = int(patch / uint32_t(m_nu));
            float u0 = float(i) / m_nu, u1 = float(i + 1) / m_nu, v0 = float(j) / m_nv, v1 = float(j + 1) / m_nv;
            float bt0, bt1;
            if (!boxInterval(r, m_boxMin[patch], m_boxMax[patch], bt0, bt1)) continue;
            const float scale = m_scale[patch];
            // Newton on F(t, u, v) = o + t d - P(u, v) = 0 from a few starts in the patch
            // (kNewtonStarts; the surface at each was evaluated once, in the constructor).
            bool patchHit = false;
            for (int k = 0; k < kNewtonStarts; ++k) {
                if (patchHit) break;
                const NewtonStart& st = m_starts[size_t(patch) * kNewtonStarts + k];
                float u = st.u, v = st.v;
                vec3 Pu = st.Pu, Pv = st.Pv;
                vec3 P = st.P;
                float t = glm::dot(P - r.org, r.dir) / dd;
                bool ok = false;
                float prevErr = std::numeric_limits<float>::infinity();
                for (int it = 0; it < 16; ++it) {
                    if (it > 0) P = evaluate(u, v, Pu, Pv);
                    vec3 F = r.org + t * r.dir - P;
                    const float err = glm::length(F);
                    if (err < 1e-6f * (scale + 1.0f)) {
                        ok = true;
                        break;
                    }
                    if (it >= 4 && err > 0.9f * prevErr) break;   // not converging: give up early
                    prevErr = err;
                    // J = [d, -Pu, -Pv]; solve J x = -F by Cramer's rule.
                    vec3 c0 = r.dir, c1 = -Pu, c2 = -Pv;
                    float det = glm::dot(c0, glm::cross(c1, c2));
                    if (std::abs(det) < 1e-20f) break;
                    vec3 rhs = -F;
                    float dt = glm::dot(rhs, glm::cross(c1, c2)) / det;
                    float du = glm::dot(c0, glm::cross(rhs, c2)) / det;
                    float dv = glm::dot(c0, glm::cross(c1, rhs)) / det;
                    t += dt;
                    u += du;
                    v += dv;
                    if (!std::isfinite(t + u + v)) break;
                    if (u < u0 - 1.0f / m_nu || u > u1 + 1.0f / m_nu || v < v0 - 1.0f / m_nv || v > v1 + 1.0f / m_nv) break;
                }
                if (!ok) continue;
                float eu = 1e-4f, ev = 1e-4f;
                if (u < u0 - eu || u > u1 + eu || v < v0 - ev || v > v1 + ev) continue;
                if (m_surface.type == ParametricType::BezierPatch && (u < 0 || u > 1 || v < 0 || v > 1)) continue;
                if (t > r.tmin && t < tm) {
                    patchHit = true;
                    tm = t;
                    tOut = t;
                    uOut = std::clamp(u, 0.0f, 1.0f);
                    vOut = std::clamp(v, 0.0f, 1.0f);
                    found = true;
                    if constexpr (AnyHit) return true;
                }
            }
        }
        return false;
    });
    return found;
}
template bool ParametricAccel::trace<false>(const Ray&, float&, float&, float&) const;
template bool ParametricAccel::trace<true>(const Ray&, float&, float&, float&) const;

// --- density grids ----------------------------------------------------------------------------------

GridAccel::GridAccel(std::shared_ptr<const DensityGrid> g) : m_grid(std::move(g)) {
    const DensityGrid& d = *m_grid;
    m_valid = d.dims.x >= 2 && d.dims.y >= 2 && d.dims.z >= 2 && d.values.size() == size_t(d.dims.x) * d.dims.y * d.dims.z && !d.bounds.empty() &&
              d.bounds.extent().x > 0 && d.bounds.extent().y > 0 && d.bounds.extent().z > 0;
    if (!m_valid) return;
    ivec3 cells = d.dims - 1;
    m_cell = d.bounds.extent() / vec3(cells);
    for (int a = 0; a < 3; ++a) {
        m_corner4[a] = d.bounds.min[a];
        m_cell4[a] = m_cell[a];
        m_lastCell4[a] = float(d.dims[a] - 2);
    }
    m_blocks = (cells + kBlock - 1) / kBlock;
    size_t nb = size_t(m_blocks.x) * m_blocks.y * m_blocks.z;
    m_blockMin.assign(nb, std::numeric_limits<float>::infinity());
    m_blockMax.assign(nb, -std::numeric_limits<float>::infinity());
    for (int bz = 0; bz < m_blocks.z; ++bz)
        for (int by = 0; by < m_blocks.y; ++by)
            for (int bx = 0; bx < m_blocks.x; ++bx) {
                float mn = std::numeric_limits<float>::infinity(), mx = -mn;
                for (int z = bz * kBlock; z <= std::min((bz + 1) * kBlock, cells.z); ++z)
                    for (int y = by * kBlock; y <= std::min((by + 1) * kBlock, cells.y); ++y)
                        for (int x = bx * kBlock; x <= std::min((bx + 1) * kBlock, cells.x); ++x) {
                            float v = d.at(x, y, z);
                            mn = std::min(mn, v);
                            mx = std::max(mx, v);
                        }
                size_t i = (size_t(bz) * m_blocks.y + by) * m_blocks.x + bx;
                m_blockMin[i] = mn;
                m_blockMax[i] = mx;
            }
}

bool GridAccel::blockMayCross(const vec3& p) const {
    // The cell of p, (p - corner) / cell clamped to [0, dims - 2] (before float -> int), all
    // three axes in one register. glm::clamp is min(max(x, 0), hi) with glm's max(x, y) =
    // x < y ? y : x and min(x, y) = y < x ? y : x, which are _mm_max_ps(0, x) and
    // _mm_min_ps(hi, x) lane by lane (a NaN x kept, -0 kept); a NaN lane then sends every axis
    // to cell 0, as the scalar isFinite test did (the clamp leaves no infinity).
    const __m128 x = _mm_setr_ps(p.x, p.y, p.z, 0.0f);
    __m128 g = _mm_div_ps(_mm_sub_ps(x, _mm_load_ps(m_corner4)), _mm_load_ps(m_cell4));
    g = _mm_min_ps(_mm_load_ps(m_lastCell4), _mm_max_ps(_mm_setzero_ps(), g));
    if (_mm_movemask_ps(_mm_cmpunord_ps(g, g)) & 7) g = _mm_setzero_ps();
    alignas(16) int cell[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(cell), _mm_cvttps_epi32(g));
    const DensityGrid& d = *m_grid;
    ivec3 c = ivec3(cell[0], cell[1], cell[2]) / kBlock;
    c = glm::clamp(c, ivec3(0), m_blocks - 1);
    size_t i = (size_t(c.z) * m_blocks.y + c.y) * m_blocks.x + c.x;
    return m_blockMin[i] <= d.isoValue && m_blockMax[i] >= d.isoValue;
}

bool GridAccel::intersect(const Ray& r, float& tOut) const {
    if (!m_valid) return false;
    const DensityGrid& d = *m_grid;
    float t0, t1;
    if (!boxInterval(r, d.bounds.min, d.bounds.max, t0, t1)) return false;
    t0 = std::max(t0, r.tmin);
    t1 = std::min(t1, r.tmax);
    if (!(t0 < t1)) return false;
    float len = glm::length(r.dir);
    if (!(len > 0)) return false;
    float step = 0.5f * std::min(m_cell.x, std::min(m_cell.y, m_cell.z)) / len;
    auto f = [&](float t) { return d.sample(r.org + t * r.dir) - d.isoValue; };
    float ta = t0, fa = f(ta);
    bool blockA = blockMayCross(r.org + ta * r.dir);
    while (ta < t1) {
        float tb = std::min(ta + step, t1);
        bool blockB = blockMayCross(r.org + tb * r.dir);
        if (!blockA && !blockB) {   // neither end is in a block that straddles the iso value
            // The sign cannot change inside such a block; keep fa's sign, skip sampling.
            ta = tb;
            blockA = blockB;
            continue;
        }
        float fb = f(tb);
        if ((fa > 0) != (fb > 0)) {
            // Bisection on the bracket (secant would be faster; bisection cannot fail). A step
            // depends only on a, b and fA's sign; once one leaves all three as they were (a and
            // b adjacent floats, m one of them), every later step repeats it, so stop there.
            float a = ta, b = tb, fA = fa;
            for (int it = 0; it < 30; ++it) {
                const float m = 0.5f * (a + b), fm = f(m);
                const float a0 = a, b0 = b;
                const bool sign0 = fA > 0;
                if ((fm > 0) == (fA > 0)) {
                    a = m;
                    fA = fm;
                } else
                    b = m;
                if (a == a0 && b == b0 && (fA > 0) == sign0) break;
            }
            tOut = 0.5f * (a + b);
            if (tOut <= r.tmin) tOut = b;
            return true;
        }
        ta = tb;
        fa = fb;
        blockA = blockB;
    }
    return false;
}

vec3 GridAccel::normal(const vec3& p) const {
    vec3 g = -m_grid->gradient(p);
    float l = glm::length(g);
    return l > 1e-30f && std::isfinite(l) ? g / l : vec3(0, 1, 0);
}

}   // namespace rnd::rt
