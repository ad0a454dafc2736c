// polygon.cpp - see polygon.h.
//
// Ear clipping after Eberly ("Triangulation by Ear Clipping"): the remaining polygon is a ring
// of corners; a corner is an ear when it turns left and no reflex or straight corner of the
// ring lies in or on its triangle (for a simple polygon, a triangle holding any corner holds
// a reflex one, so only those need testing). Clipping an ear changes only its two neighbours'
// status, so the whole run is O(n^2). The ear tests are exact up to double rounding (for a
// simple polygon there is always an ear; rounding only makes slivers). When no ear is left
// (a self-intersecting polygon) a corner that is straight up to float noise is dropped
// without a triangle; when there is none either, or the triangles do not add up to the
// polygon's area, the polygon falls back to the fan. Coordinates are projected in double
// relative to the first corner; an axis-aligned polygon projects exactly.
#include "assets/polygon.h"

#include <cmath>

namespace assets {

namespace {

void fanOf(std::span<const uint32_t> c, std::vector<uint32_t>& out) {
    for (size_t i = 1; i + 1 < c.size(); ++i) out.insert(out.end(), {c[0], c[i], c[i + 1]});
}

}   // namespace

PolygonKind triangulatePolygon(std::span<const sg::vec3> positions, std::span<const uint32_t> corners, std::vector<uint32_t>& out) {
    PolygonTriangulator t;
    return t.triangulate(positions, corners, out);
}

// Cross product of (b - a) and (c - b): > 0 when a -> b -> c turns left.
template <class P>
double turn(const P& a, const P& b, const P& c) {
    return (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
}
template <class P>
double dist(const P& a, const P& b) {
    return std::sqrt((b.x - a.x) * (b.x - a.x) + (b.y - a.y) * (b.y - a.y));   // no overflow: coordinates are <= 1e30-ish
}

// -1 reflex, 0 flat (within tol of straight: collinear, repeated, doubling back), +1 convex.
int classify(const PolygonTriangulator::P2& a, const PolygonTriangulator::P2& b, const PolygonTriangulator::P2& c, double tol, double& cross) {
    cross = turn(a, b, c);
    const double flat = tol * (dist(a, b) + dist(b, c));
    return cross > flat ? 1 : cross < -flat ? -1 : 0;
}

// Exact predicates from here on (up to double rounding): a corner that turns left by any
// amount can be an ear, anything on or in an ear's triangle blocks it. For a simple polygon
// that always finds an ear; noise only makes slivers.
bool PolygonTriangulator::isEar(uint32_t i) const {
    if (!(m_turn[i] > 0)) return false;
    const uint32_t ia = m_prev[i], ic = m_next[i];
    const P2 a = m_p[ia], b = m_p[i], c = m_p[ic];
    for (uint32_t k = m_next[ic]; k != ia; k = m_next[k]) {
        if (m_turn[k] > 0) continue;   // convex corners never block alone
        const P2 q = m_p[k];
        // A corner at the same place as one of the ear's (a keyhole's two sides) does not block.
        if ((q.x == a.x && q.y == a.y) || (q.x == b.x && q.y == b.y) || (q.x == c.x && q.y == c.y)) continue;
        if (turn(a, b, q) >= 0 && turn(b, c, q) >= 0 && turn(c, a, q) >= 0) return false;
    }
    return true;
}

void PolygonTriangulator::update(uint32_t i) { m_turn[i] = turn(m_p[m_prev[i]], m_p[i], m_p[m_next[i]]); }

// Ear-clips the ring of the n points of m_p (counter-clockwise) into m_out (indices into
// m_p). False when it gets stuck or the result does not cover the polygon's area.
bool PolygonTriangulator::earClip(size_t n) {
    m_prev.resize(n);
    m_next.resize(n);
    m_turn.resize(n);
    m_ear.resize(n);
    for (size_t i = 0; i < n; ++i) {
        m_prev[i] = uint32_t((i + n - 1) % n);
        m_next[i] = uint32_t((i + 1) % n);
    }
    double area2 = 0, perimeter = 0;   // twice the signed area of the ring
    for (size_t i = 0; i < n; ++i) {
        update(uint32_t(i));
        const P2 a = m_p[i], b = m_p[m_next[i]];
        area2 += a.x * b.y - a.y * b.x;
        perimeter += dist(a, b);
    }
    for (size_t i = 0; i < n; ++i) m_ear[i] = isEar(uint32_t(i));
    m_out.clear();
    double clipped2 = 0;   // twice the area of the triangles made
    uint32_t cur = 0;
    size_t remaining = n;
    auto remove = [&](uint32_t i) {
        const uint32_t a = m_prev[i], c = m_next[i];
        m_next[a] = c;
        m_prev[c] = a;
        --remaining;
        update(a);
        update(c);
        m_ear[a] = isEar(a);
        m_ear[c] = isEar(c);
        cur = c;
    };
    // The first corner from cur on (once round the ring) that satisfies pred, or n.
    auto findFrom = [&](auto pred) {
        uint32_t i = cur;
        for (size_t s = 0; s < remaining; ++s, i = m_next[i])
            if (pred(i)) return i;
        return uint32_t(n);
    };
    while (remaining > 3) {
        uint32_t i = findFrom([&](uint32_t k) { return m_ear[k] != 0; });
        if (i < n) {
            m_out.insert(m_out.end(), {m_prev[i], i, m_next[i]});
            clipped2 += m_turn[i];
            remove(i);
            continue;
        }
        // No ear (a self-intersecting polygon, or rounding): drop a corner that is straight
        // up to float noise (collinear, or a spike doubling back), else give up.
        double cross;
        i = findFrom([&](uint32_t k) { return classify(m_p[m_prev[k]], m_p[k], m_p[m_next[k]], m_tol, cross) == 0; });
        if (i == n) return false;
        remove(i);
    }
    double cross;
    const int last = classify(m_p[m_prev[cur]], m_p[cur], m_p[m_next[cur]], m_tol, cross);
    if (last < 0) return false;   // the last triangle is inside out: the polygon crosses itself
    if (cross > 0) {
        m_out.insert(m_out.end(), {m_prev[cur], cur, m_next[cur]});
        clipped2 += cross;
    }
    // For a simple polygon the ears add up to its area (less the flat corners dropped); a
    // self-intersecting one that clipped "successfully" covers some parts twice.
    return std::fabs(clipped2 - area2) <= 1e-6 * std::fabs(area2) + 4 * m_tol * perimeter;
}

// Quads, the most common polygon, decided in 3D without projecting: each corner's turn
// against the Newell normal (the projected 2D cross product, times the normal's length). Only
// clear cases: all four corners clearly convex (the fan) or one clearly reflex (the diagonal
// through it); anything else (repeated or straight corners, zero area, non-finite) is left to
// the general path, whose thresholds are never larger, so both always agree.
bool quadFastPath(std::span<const sg::vec3> positions, std::span<const uint32_t> c, std::vector<uint32_t>& out, PolygonKind& kind) {
    const glm::dvec3 o(positions[c[0]]);
    const glm::dvec3 p[4] = {glm::dvec3(0.0), glm::dvec3(positions[c[1]]) - o, glm::dvec3(positions[c[2]]) - o, glm::dvec3(positions[c[3]]) - o};
    const glm::dvec3 normal = glm::cross(p[2], p[3] - p[1]);
    double ext = 0.0, mag = 0.0;
    for (int i = 0; i < 4; ++i) {
        const glm::dvec3 q(positions[c[i]]);
        ext = std::max({ext, std::fabs(p[i].x), std::fabs(p[i].y), std::fabs(p[i].z)});
        mag = std::max({mag, std::fabs(q.x), std::fabs(q.y), std::fabs(q.z)});
    }
    const double len2 = glm::dot(normal, normal);
    if (!std::isfinite(len2) || !(len2 > 1e-20 * ext * ext * ext * ext)) return false;
    const double tol = 1e-6 * mag + 1e-12 * ext;
    int reflex = -1;
    for (int i = 0; i < 4; ++i) {
        const glm::dvec3 e = p[i] - p[(i + 3) % 4], f = p[(i + 1) % 4] - p[i];
        const double t = glm::dot(glm::cross(e, f), normal);
        // |t| / |normal| against tol * (|e| + |f|), squared: (|e| + |f|)^2 <= 2 (|e|^2 + |f|^2).
        if (t * t <= 2.0 * tol * tol * (glm::dot(e, e) + glm::dot(f, f)) * len2) return false;   // straight or repeated
        if (t < 0) {
            if (reflex >= 0) return false;
            reflex = i;
        }
    }
    if (reflex == 1 || reflex == 3) {
        const uint32_t r0 = c[size_t(reflex)], r1 = c[size_t(reflex + 1) % 4], r2 = c[size_t(reflex + 2) % 4], r3 = c[size_t(reflex + 3) % 4];
        out.insert(out.end(), {r0, r1, r2, r0, r2, r3});
    } else {
        out.insert(out.end(), {c[0], c[1], c[2], c[0], c[2], c[3]});
    }
    kind = reflex < 0 ? PolygonKind::Convex : PolygonKind::Concave;
    return true;
}

PolygonKind PolygonTriangulator::triangulate(std::span<const sg::vec3> positions, std::span<const uint32_t> corners, std::vector<uint32_t>& out) {
    const size_t n = corners.size();
    if (n < 3) return PolygonKind::TooFew;
    if (n == 3) {
        out.insert(out.end(), corners.begin(), corners.end());
        return PolygonKind::Triangle;
    }
    PolygonKind quad;
    if (n == 4 && quadFastPath(positions, corners, out, quad)) return quad;
    // Newell normal (twice the vector area), relative to the first corner for precision.
    const glm::dvec3 o(positions[corners[0]]);
    glm::dvec3 normal(0.0);
    double ext = 0.0;   // largest coordinate offset from the first corner: the length scale
    double mag = 0.0;   // largest coordinate: the float rounding of the corners scales with it
    for (size_t i = 0; i < n; ++i) {
        const glm::dvec3 p(positions[corners[i]]);
        const glm::dvec3 a = p - o, b = glm::dvec3(positions[corners[(i + 1) % n]]) - o;
        normal += glm::cross(a, b);
        ext = std::max({ext, std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)});
        mag = std::max({mag, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    }
    const double len = glm::length(normal);
    if (!std::isfinite(len) || !std::isfinite(ext) || !(len > 1e-12 * ext * ext)) {
        fanOf(corners, out);
        return PolygonKind::Degenerate;
    }
    // Orthonormal (u, v) with u x v along the normal: the projection turns counter-clockwise.
    const glm::dvec3 nz = normal / len;
    const glm::dvec3 a = glm::abs(nz);
    const glm::dvec3 axis = a.x <= a.y && a.x <= a.z ? glm::dvec3(1, 0, 0) : a.y <= a.z ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
    const glm::dvec3 u = glm::normalize(glm::cross(axis, nz)), v = glm::cross(nz, u);
    // Length tolerance: float rounding moves a corner by up to 2^-24 of the largest coordinate;
    // 1e-6 of it (16 times that) decides what is flat and what touches.
    m_tol = 1e-6 * mag + 1e-12 * ext;

    // The ring without consecutive repeats (same projected point), as positions in `corners`.
    m_p.clear();
    std::vector<uint32_t>& ring = m_ring;
    ring.clear();
    for (size_t i = 0; i < n; ++i) {
        const glm::dvec3 d = glm::dvec3(positions[corners[i]]) - o;
        const P2 p{glm::dot(d, u), glm::dot(d, v)};
        if (!m_p.empty() && p.x == m_p.back().x && p.y == m_p.back().y) continue;
        m_p.push_back(p);
        ring.push_back(uint32_t(i));
    }
    while (m_p.size() > 1 && m_p.back().x == m_p[0].x && m_p.back().y == m_p[0].y) {
        m_p.pop_back();
        ring.pop_back();
    }
    const size_t m = m_p.size();
    if (m < 3) {
        fanOf(corners, out);
        return PolygonKind::Degenerate;
    }

    // Convex (no right turn, no doubling back, winding once): the fan, as always.
    int reflex = -1, reflexCount = 0;
    bool doublesBack = false;
    double turning = 0.0;
    for (size_t j = 0; j < m; ++j) {
        const P2 p = m_p[(j + m - 1) % m], q = m_p[j], r = m_p[(j + 1) % m];
        double cr;
        const int c = classify(p, q, r, m_tol, cr);
        const double dt = (q.x - p.x) * (r.x - q.x) + (q.y - p.y) * (r.y - q.y);
        if (c < 0) {
            reflex = int(j);
            ++reflexCount;
        } else if (c == 0 && dt < 0) {
            doublesBack = true;
        }
        if (m >= 5) turning += std::atan2(cr, dt);
    }
    if (reflexCount == 0 && !doublesBack && (m <= 4 || turning < 3.0 * sg::kPi)) {
        fanOf(corners, out);
        return PolygonKind::Convex;
    }
    // A quad with one reflex corner: the diagonal through it (the fan when that is corner 0 or 2).
    if (m == 4 && reflexCount == 1 && !doublesBack) {
        const uint32_t r0 = ring[size_t(reflex)], r1 = ring[size_t(reflex + 1) % 4], r2 = ring[size_t(reflex + 2) % 4],
                       r3 = ring[size_t(reflex + 3) % 4];
        if (n == 4 && (r0 == 0 || r0 == 2)) {
            fanOf(corners, out);
        } else {
            out.insert(out.end(), {corners[r0], corners[r1], corners[r2], corners[r0], corners[r2], corners[r3]});
        }
        return PolygonKind::Concave;
    }
    if (!earClip(m)) {
        fanOf(corners, out);
        return PolygonKind::Fallback;
    }
    for (uint32_t k : m_out) out.push_back(corners[ring[k]]);
    return PolygonKind::Concave;
}

}   // namespace assets
