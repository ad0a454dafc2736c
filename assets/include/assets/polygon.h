// polygon.h - triangulation of one polygon face (OBJ `f`, OFF and PLY faces) into triangles.
//
// The polygon is projected onto its best-fit plane (the Newell normal) and triangulated there:
//   * triangles pass through unchanged (even degenerate ones);
//   * a convex polygon (also with collinear or repeated corners) becomes the fan around its
//     first corner: (c0, c1, c2), (c0, c2, c3), ... - what the importers always produced;
//   * a concave quad is split along the diagonal through its reflex corner;
//   * any other polygon (concave, non-planar, with collinear or repeated corners) is
//     ear-clipped: O(n^2) time, every pass removes a corner, so it always terminates;
//   * every triangle keeps the polygon's winding (its normal points the way the polygon's
//     Newell normal does), so normals and back-face culling stay as the file meant them;
//   * a polygon of zero area, with non-finite corners, or one that ear clipping cannot finish
//     (self-intersecting) falls back to the fan: something is drawn, nothing hangs.
#pragma once

#include "scenegraph/math.h"

#include <cstdint>
#include <span>
#include <vector>

namespace assets {

enum class PolygonKind : uint8_t {
    Triangle,     // n == 3, passed through
    Convex,       // fan
    Concave,      // ear clipping or the reflex diagonal of a quad
    Degenerate,   // zero area or non-finite: fan
    Fallback,     // ear clipping got stuck (self-intersecting): fan
    TooFew,       // fewer than 3 corners: nothing
};

// Reusable scratch space: keep one per loop over many faces to avoid allocations.
class PolygonTriangulator {
public:
    // Appends the triangles of the polygon `corners` (indices into `positions`, in order) to
    // `out` (3 indices each, values from `corners`); at most corners.size() - 2 triangles.
    // Every corner index must be < positions.size().
    PolygonKind triangulate(std::span<const sg::vec3> positions, std::span<const uint32_t> corners, std::vector<uint32_t>& out);

    struct P2 {
        double x, y;
    };

private:
    std::vector<P2> m_p;                    // projected corners
    std::vector<uint32_t> m_ring;           // which corner each of m_p is (repeats removed)
    std::vector<uint32_t> m_prev, m_next;   // the remaining polygon as a ring over m_p
    std::vector<double> m_turn;             // cross product at each remaining corner
    std::vector<uint8_t> m_ear;             // ear status of remaining corners
    std::vector<uint32_t> m_out;            // triangles (indices into m_p) before committing
    double m_tol = 0;                       // length below which things touch / are straight
    bool isEar(uint32_t i) const;
    void update(uint32_t i);
    bool earClip(size_t n);
};

// Convenience for one polygon (allocates scratch space).
PolygonKind triangulatePolygon(std::span<const sg::vec3> positions, std::span<const uint32_t> corners, std::vector<uint32_t>& out);

}   // namespace assets
