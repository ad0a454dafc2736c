// analytic.h - exact ray intersection with the analytic drawables (docs/math.md, ray casting):
// implicit shapes as solids (ray intervals inside the solid, with which surface bounds each
// end), CSG by combining leaf intervals, parametric surfaces by Newton iteration from bounded
// starts, density grids by marching + bisection on the trilinear field.
//
// Sections: Span (intervals), implicit shapes, CSG, parametric, density grid.
// All functions take rays in the shape's local frame unless they say "world".
#pragma once

#include "raycast/bvh.h"
#include "scenegraph/frame.h"

#include <algorithm>
#include <memory>
#include <vector>

namespace rnd::rt {

// One end of an interval: distance, and which surface it lies on (for the normal).
struct Bound {
    float t = 0;
    uint8_t tag = 0;     // kTagSurface: the curved surface (gradient); kTagFace + 2*axis + (positive): box face
    uint8_t flip = 0;    // CSG: 1 = the normal points into the solid (carved face of a cutter)
    int16_t leaf = -1;   // CSG leaf index (else -1)
};
constexpr uint8_t kTagSurface = 0;
constexpr uint8_t kTagFace = 1;

// [in, out] along the ray where the point is inside the solid (in.t may be -inf, out.t +inf).
struct Span {
    Bound in, out;
};

// Small fixed-capacity interval list (a torus gives 2, a quadric 2 after clipping, CSG more).
// Only s[0, n) is ever read: the storage past n stays uninitialized, and copies take the first n
// (one is made per ray and shape, and filling all 32 spans cost more than most intersections).
struct SpanList {
    static constexpr int kCapacity = 32;
    union {
        Span s[kCapacity];
    };
    int n = 0;
    SpanList() {}
    SpanList(const SpanList& o) : n(o.n) { std::copy_n(o.s, o.n, s); }
    SpanList& operator=(const SpanList& o) {
        n = o.n;
        std::copy_n(o.s, o.n, s);
        return *this;
    }
    void push(const Span& x) {
        if (n < kCapacity) s[n++] = x;
    }
};

// --- implicit shapes -----------------------------------------------------------------------

// Intervals where the (local) ray is inside the solid, sorted, for t in (-inf, inf).
// Plane: the half space y <= 0. Returns the number of spans.
void implicitSpans(const sg::ImplicitShape& shape, const Ray& localRay, SpanList& out);
// Outward local normal at local point p for a boundary with the given tag.
sg::vec3 implicitNormal(const sg::ImplicitShape& shape, const sg::vec3& p, uint8_t tag);

// Closest surface crossing in (ray.tmin, ray.tmax): the first span end in range.
// Returns false when none; sets t and the bound.
bool firstBoundary(const SpanList& spans, float tmin, float tmax, Bound& hit);

// Real roots of sum c[i] t^i (degree <= 4) in [lo, hi], ascending (sign changes only, so a
// tangent double root may be missed). Returns the count. Used for the torus quartic.
int polyRoots(const double* c, int degree, double lo, double hi, double* roots);

// --- CSG -------------------------------------------------------------------------------------

// Intervals of the world-space ray inside the CSG tree (leaves intersected in their own frames).
void csgSpans(const sg::CsgTree& tree, const Ray& worldRay, SpanList& out);

// --- parametric surfaces --------------------------------------------------------------------

// Precomputed sub-patches with bounding boxes (in a Bvh4) for Newton starts.
class ParametricAccel {
public:
    explicit ParametricAccel(const sg::ParametricSurface& s);
    // Closest hit of the local ray in (tmin, tmax): t and (u, v).
    bool intersect(const Ray& localRay, float& t, float& u, float& v) const { return trace<false>(localRay, t, u, v); }
    // Any hit in (tmin, tmax), for shadow rays: true exactly when intersect() finds one, but
    // stops at the first sub-patch that has one.
    bool occluded(const Ray& localRay) const {
        float t, u, v;
        return trace<true>(localRay, t, u, v);
    }
    const sg::ParametricSurface& surface() const { return m_surface; }
    // surface().evaluate(u, v, Pu, Pv), bit for bit; a Bezier patch's x, y and z in one SSE
    // register (Newton's method evaluates the patch several times per ray and sub-patch).
    sg::vec3 evaluate(float u, float v, sg::vec3& Pu, sg::vec3& Pv) const;

private:
    template <bool AnyHit>
    bool trace(const Ray& localRay, float& t, float& u, float& v) const;
    sg::ParametricSurface m_surface;
    alignas(16) float m_control[16][4];   // the patch's control points, x y z 0
    struct NewtonStart {
        float u, v;
        sg::vec3 P, Pu, Pv;   // evaluate(u, v, Pu, Pv)
    };
    static constexpr int kNewtonStarts = 3;
    std::vector<NewtonStart> m_starts;   // kNewtonStarts per sub-patch
    std::vector<float> m_scale;          // per sub-patch: its box's diagonal
    int m_nu = 8, m_nv = 8;
    std::vector<sg::vec3> m_boxMin, m_boxMax;
    Bvh4 m_bvh;
};

// --- density grids ---------------------------------------------------------------------------

// Min/max of the field per block of cells, to skip blocks that cannot hold the iso-surface.
class GridAccel {
public:
    explicit GridAccel(std::shared_ptr<const sg::DensityGrid> g);
    // First crossing of the iso-surface along the local ray in (tmin, tmax).
    bool intersect(const Ray& localRay, float& t) const;
    // Outward normal (-gradient: inside is value > iso).
    sg::vec3 normal(const sg::vec3& p) const;
    const sg::DensityGrid& grid() const { return *m_grid; }

private:
    std::shared_ptr<const sg::DensityGrid> m_grid;
    bool m_valid = false;
    static constexpr int kBlock = 4;
    sg::ivec3 m_blocks{0};
    std::vector<float> m_blockMin, m_blockMax;
    sg::vec3 m_cell{1.0f};
    // blockMayCross's operands, x y z and a harmless fourth lane: the grid's corner, its cell
    // size and the highest cell index (dims - 2).
    alignas(16) float m_corner4[4] = {0, 0, 0, 0}, m_cell4[4] = {1, 1, 1, 1}, m_lastCell4[4] = {0, 0, 0, 0};
    bool blockMayCross(const sg::vec3& p) const;
};

}   // namespace rnd::rt
