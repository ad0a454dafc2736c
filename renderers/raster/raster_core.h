// raster_core.h - the scan-conversion core of the CPU rasterizer ("raster" backend), shared by
// the renderer and its tests: homogeneous clipping, fixed-point triangle setup with edge
// functions and a top-left fill rule, coverage of one tile, and a DDA line rasterizer.
//
// Conventions (GL): window coordinates have their origin bottom-left, pixel (i, j) has its
// centre at (i + 0.5, j + 0.5); window z = 0.5 * z_ndc + 0.5. Vertex positions are snapped to
// 1/256 pixel (8 sub-pixel bits) and the edge functions are evaluated exactly in 64-bit
// integers, so two triangles sharing an edge cover each pixel centre exactly once.
//
// Sections: 1. fixed-point triangle setup   2. coverage iteration   3. clipping   4. lines
#pragma once

#include "common/window_lines.h"
#include "scenegraph/math.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace rnd::raster {

using rnd::lines::drawLineDDA;
using rnd::lines::GuardBand;
using rnd::lines::guardBand;
using rnd::lines::kGuardPixels;
using rnd::lines::outcode;
using rnd::lines::toWindow;
using namespace rnd::lines::clipbits;

constexpr int kSubBits = 8;           // sub-pixel precision
constexpr int kSub = 1 << kSubBits;   // fixed-point units per pixel
constexpr int kHalf = kSub / 2;       // pixel centre offset
constexpr int kTileSize = 64;         // screen tiles rasterized in parallel

// GL standard 4x MSAA sample positions in fixed-point units from the pixel's lower-left corner
// (y up). Same pattern as D3D's standard 4x, mirrored for the y-up window convention.
constexpr int kMsaa4X[4] = {96, 224, 32, 160};
constexpr int kMsaa4Y[4] = {224, 160, 96, 32};

// ---------------------------------------------------------------------------------------
// 1. Fixed-point triangle setup
// ---------------------------------------------------------------------------------------

// One edge function E(px, py) = a*px + b*py + c over fixed-point sample coordinates. A sample
// is inside when E >= bias (bias = 0 on top/left edges, 1 otherwise: the top-left rule).
// a and b are fixed-point coordinate differences (within the guard band they fit 32 bits).
struct Edge {
    int32_t a = 0, b = 0;
    int64_t c = 0;
    int32_t bias = 0;
    int64_t at(int64_t px, int64_t py) const { return a * px + b * py + c; }
};

// A triangle ready for scan conversion: vertices in counter-clockwise order (window space,
// y up), edges e[i] from v[i] to v[i+1]; the barycentric weight of vertex (i+2)%3 is
// e[i](p) / area2. `flipped` says whether the input was clockwise (two vertices swapped).
struct TriSetup {
    int32_t x[3], y[3];   // fixed point
    Edge e[3];
    int64_t area2 = 0;                              // twice the area in fixed units^2 (> 0)
    int minX = 0, minY = 0, maxX = -1, maxY = -1;   // pixel bbox, inclusive, inside the viewport
    bool flipped = false;
    uint8_t order[3] = {0, 1, 2};   // input vertex index of each setup vertex
};

// The part of a TriSetup that scan conversion needs, as the renderer stores it per triangle
// (56 bytes instead of 128: a large mesh keeps one per triangle, and the tile stage streams
// them from memory). Each edge's top-left bias is folded into c (E(p) - bias >= 0 exactly,
// in integers), so `bias` is 0; the fixed-point vertices and the area are dropped.
struct PackedEdge {
    int32_t a = 0, b = 0;
    int64_t c = 0;   // TriSetup's c - bias
    static constexpr int32_t bias = 0;
    int64_t at(int64_t px, int64_t py) const { return a * px + b * py + c; }
};
struct TriCoverage {
    PackedEdge e[3];
    int16_t minX = 0, minY = 0, maxX = -1, maxY = -1;   // as TriSetup's (pixel indices < 32768: the renderer's maxImageSize)
    void set(const TriSetup& t) {
        for (int k = 0; k < 3; ++k) {
            e[k].a = t.e[k].a;
            e[k].b = t.e[k].b;
            e[k].c = t.e[k].c - t.e[k].bias;
        }
        minX = int16_t(t.minX);
        minY = int16_t(t.minY);
        maxX = int16_t(t.maxX);
        maxY = int16_t(t.maxY);
    }
};

// Round to nearest fixed-point unit (halves away from zero); inputs lie within the guard band.
inline int32_t toFixed(float v) {
    float f = v * float(kSub);
    return int32_t(f + (f >= 0 ? 0.5f : -0.5f));
}

// Sets up the triangle with window-space vertices (x, y) for a width x height viewport.
// Returns false when it is degenerate (zero area) or its bounding box misses every pixel
// centre (or sample, with `msaa`). Coordinates must lie within the guard band.
__attribute__((always_inline)) inline bool setupTriangle(const float wx[3], const float wy[3], int width, int height, TriSetup& t,
                                                         bool msaa = false) {
    int32_t x[3], y[3];
    for (int i = 0; i < 3; ++i) {
        x[i] = toFixed(wx[i]);
        y[i] = toFixed(wy[i]);
    }
    int64_t area = int64_t(x[1] - x[0]) * (y[2] - y[0]) - int64_t(y[1] - y[0]) * (x[2] - x[0]);
    if (area == 0) return false;
    t.flipped = area < 0;
    if (t.flipped) {   // make it counter-clockwise: swap vertices 1 and 2
        std::swap(x[1], x[2]);
        std::swap(y[1], y[2]);
        t.order[0] = 0;
        t.order[1] = 2;
        t.order[2] = 1;
        area = -area;
    } else {
        t.order[0] = 0;
        t.order[1] = 1;
        t.order[2] = 2;
    }
    t.area2 = area;
    for (int i = 0; i < 3; ++i) {
        t.x[i] = x[i];
        t.y[i] = y[i];
    }
    // Pixel bbox: samples at i*kSub + offset; with MSAA the offsets span [32, 224].
    int32_t lo = msaa ? 32 : kHalf, hi = msaa ? 224 : kHalf;
    int32_t fx0 = std::min({x[0], x[1], x[2]}), fx1 = std::max({x[0], x[1], x[2]});
    int32_t fy0 = std::min({y[0], y[1], y[2]}), fy1 = std::max({y[0], y[1], y[2]});
    // smallest i with i*kSub + hi >= fx0 ; largest i with i*kSub + lo <= fx1. kSub is a power of
    // two: floor division is an arithmetic shift (also for negative values), ceil(a / kSub) =
    // floor((a + kSub - 1) / kSub).
    static_assert((kSub & (kSub - 1)) == 0, "kSub is a power of two");
    auto ceilDiv = [](int64_t a) { return (a + kSub - 1) >> kSubBits; };
    auto floorDiv = [](int64_t a) { return a >> kSubBits; };
    t.minX = int(std::max<int64_t>(0, ceilDiv(int64_t(fx0) - hi)));
    t.maxX = int(std::min<int64_t>(width - 1, floorDiv(int64_t(fx1) - lo)));
    t.minY = int(std::max<int64_t>(0, ceilDiv(int64_t(fy0) - hi)));
    t.maxY = int(std::min<int64_t>(height - 1, floorDiv(int64_t(fy1) - lo)));
    if (t.minX > t.maxX || t.minY > t.maxY) return false;
    for (int i = 0; i < 3; ++i) {
        int j = (i + 1) % 3;
        int64_t dx = int64_t(x[j]) - x[i], dy = int64_t(y[j]) - y[i];
        Edge& e = t.e[i];
        e.a = int32_t(-dy);
        e.b = int32_t(dx);
        e.c = dy * x[i] - dx * y[i];
        // Top-left rule (y up, CCW): left edges run downward, top edges run in -x.
        bool topLeft = dy < 0 || (dy == 0 && dx < 0);
        e.bias = topLeft ? 0 : 1;
    }
    return true;
}

// ---------------------------------------------------------------------------------------
// 2. Coverage iteration
// ---------------------------------------------------------------------------------------

// Calls fn(i, j) for every pixel whose centre the triangle covers inside the rectangle
// [x0, x1] x [y0, y1] (inclusive, pixels), row by row. Hierarchical: 8x8 blocks are first
// tested against each edge at their extreme corners (reject the block when an edge is
// negative everywhere, accept it whole when all edges are non-negative everywhere); only
// partly covered blocks evaluate the edge functions per pixel, incrementally.
// T: TriSetup or TriCoverage.
template <class T, class Fn>
inline void forEachCoveredPixel(const T& t, int x0, int y0, int x1, int y1, Fn&& fn) {
    constexpr int kB = 8;
    x0 = std::max(x0, int(t.minX));
    x1 = std::min(x1, int(t.maxX));
    y0 = std::max(y0, int(t.minY));
    y1 = std::min(y1, int(t.maxY));
    if (x0 > x1 || y0 > y1) return;
    const auto* e = t.e;
    const int64_t sx[3] = {int64_t(e[0].a) * kSub, int64_t(e[1].a) * kSub, int64_t(e[2].a) * kSub};
    const int64_t sy[3] = {int64_t(e[0].b) * kSub, int64_t(e[1].b) * kSub, int64_t(e[2].b) * kSub};
    // Offsets from a block's first sample to the sample that maximises / minimises each edge.
    int64_t hi[3], lo[3];
    for (int k = 0; k < 3; ++k) {
        hi[k] = std::max<int64_t>(sx[k], 0) * (kB - 1) + std::max<int64_t>(sy[k], 0) * (kB - 1);
        lo[k] = std::min<int64_t>(sx[k], 0) * (kB - 1) + std::min<int64_t>(sy[k], 0) * (kB - 1);
    }
    const bool small = (x1 - x0) < kB && (y1 - y0) < kB;
    for (int by = small ? y0 : (y0 & ~(kB - 1)); by <= y1; by += kB) {
        for (int bx = small ? x0 : (x0 & ~(kB - 1)); bx <= x1; bx += kB) {
            int64_t px = int64_t(bx) * kSub + kHalf, py = int64_t(by) * kSub + kHalf;
            int64_t b0 = e[0].at(px, py) - e[0].bias, b1 = e[1].at(px, py) - e[1].bias, b2 = e[2].at(px, py) - e[2].bias;
            if (b0 + hi[0] < 0 || b1 + hi[1] < 0 || b2 + hi[2] < 0) continue;   // block outside an edge
            int ia = std::max(bx, x0), ib = std::min(bx + kB - 1, x1);
            int ja = std::max(by, y0), jb = std::min(by + kB - 1, y1);
            if (b0 + lo[0] >= 0 && b1 + lo[1] >= 0 && b2 + lo[2] >= 0) {   // block fully inside
                for (int j = ja; j <= jb; ++j)
                    for (int i = ia; i <= ib; ++i) fn(i, j);
                continue;
            }
            b0 += sx[0] * (ia - bx) + sy[0] * (ja - by);
            b1 += sx[1] * (ia - bx) + sy[1] * (ja - by);
            b2 += sx[2] * (ia - bx) + sy[2] * (ja - by);
            for (int j = ja; j <= jb; ++j, b0 += sy[0], b1 += sy[1], b2 += sy[2]) {
                int64_t a0 = b0, a1 = b1, a2 = b2;
                for (int i = ia; i <= ib; ++i, a0 += sx[0], a1 += sx[1], a2 += sx[2])
                    if ((a0 | a1 | a2) >= 0) fn(i, j);
            }
        }
    }
}

// Reference version without blocks (tests compare the two).
template <class Fn>
inline void forEachCoveredPixelSimple(const TriSetup& t, int x0, int y0, int x1, int y1, Fn&& fn) {
    x0 = std::max(x0, t.minX);
    x1 = std::min(x1, t.maxX);
    y0 = std::max(y0, t.minY);
    y1 = std::min(y1, t.maxY);
    for (int j = y0; j <= y1; ++j)
        for (int i = x0; i <= x1; ++i) {
            int64_t px = int64_t(i) * kSub + kHalf, py = int64_t(j) * kSub + kHalf;
            if (t.e[0].at(px, py) >= t.e[0].bias && t.e[1].at(px, py) >= t.e[1].bias && t.e[2].at(px, py) >= t.e[2].bias) fn(i, j);
        }
}

// ---------------------------------------------------------------------------------------
// 3. Clipping in homogeneous clip space
// ---------------------------------------------------------------------------------------

// Outcode bits, GuardBand, guardBand(), outcode() and toWindow(): common/window_lines.h.

// A clipped polygon vertex: clip position and barycentric weights w.r.t. the input triangle.
struct ClipVertex {
    sg::vec4 clip;
    sg::vec3 bary;
};

// Clips triangle (c0, c1, c2) against the planes in `planes` (outcode bits) with
// Sutherland-Hodgman; writes up to 9 vertices to out and returns their count (0 = gone).
inline int clipTriangle(const sg::vec4 c[3], uint8_t planes, const GuardBand& g, ClipVertex out[9]) {
    ClipVertex bufA[9], bufB[9];
    ClipVertex* in = bufA;
    ClipVertex* res = bufB;
    int n = 3;
    in[0] = {c[0], {1, 0, 0}};
    in[1] = {c[1], {0, 1, 0}};
    in[2] = {c[2], {0, 0, 1}};
    auto dist = [&](int plane, const sg::vec4& v) -> float {
        switch (plane) {
        case kClipNear: return v.z + v.w;
        case kClipFar: return v.w - v.z;
        case kClipLeft: return v.x + g.gx * v.w;
        case kClipRight: return g.gx * v.w - v.x;
        case kClipBottom: return v.y + g.gy * v.w;
        default: return g.gy * v.w - v.y;
        }
    };
    for (uint8_t plane = 1; plane <= kClipTop && n > 0; plane = uint8_t(plane << 1)) {
        if (!(planes & plane)) continue;
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const ClipVertex& a = in[i];
            const ClipVertex& b = in[(i + 1) % n];
            float da = dist(plane, a.clip), db = dist(plane, b.clip);
            if (da >= 0) res[m++] = a;
            if ((da >= 0) != (db >= 0)) {
                float t = da / (da - db);   // intersection, linear in clip space
                res[m++] = {a.clip + t * (b.clip - a.clip), a.bary + t * (b.bary - a.bary)};
            }
            if (m >= 9) break;
        }
        std::swap(in, res);
        n = m;
    }
    for (int i = 0; i < n; ++i) out[i] = in[i];
    return n < 3 ? 0 : n;
}

// ---------------------------------------------------------------------------------------
// 4. Lines: DDA ("Digital Differential Analyzer") over window coordinates
// ---------------------------------------------------------------------------------------

// drawLineDDA(): common/window_lines.h.

}   // namespace rnd::raster
