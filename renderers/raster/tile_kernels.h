// tile_kernels.h - the vectorised inner loops of the CPU rasterizer's tile stage (step 4:
// raster_tile.cpp and raster_shade.cpp), written once over simd.h's wrappers in tile_kernels.inl
// and compiled for SSE2 and AVX2 (chosen at run time, as the lighting kernel):
//   * rasterizeOpaque: the depth-tested coverage of one opaque triangle in a tile, a row of an
//     8x8 block per vector step (32-bit edge functions relative to the block);
//   * preparePlainRun: the attributes (world position, normal, fog distance) of a run of
//     fragments of one plain lit triangle, a vector of fragments per step, for the lighting
//     kernel (raster_shading.h).
// Both give the bits of the scalar code they replace (raster_core.h's forEachCoveredPixel with
// the renderer's depth test; prepareSimple in raster_shade.cpp): the same IEEE operations in
// the same order per lane. tests/renderers/raster checks them against it.
#pragma once

#include "raster/raster_core.h"
#include "raster/raster_shading.h"
#include "renderers/srgb_encoder.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

namespace rnd::raster {

// The tile's depth and id buffers hold kTileSize * kTileSize values (per sample) plus kTilePad:
// rasterizeOpaque loads and stores whole vectors, which may run past a row's last pixel.
constexpr int kTilePad = 8;

// Screen-linear planes of a triangle, at the centre of pixel (minX, minY) of its bbox and per
// pixel step: window z, and u_k = lambda_k / w_k of its three setup vertices (the perspective-
// correct barycentrics are u_k / sum(u)).
struct TriPlanes {
    float zRef, zdx, zdy;
    float uRef[3], udx[3], udy[3];
};

// The planes of setup s whose vertices (in input order, before setup's reordering) have window z
// and 1/w iw: z = (e1 z0 + e2 z1 + e0 z2) / area2 with e_i linear in the fixed-point sample
// position, and u of setup vertex (k+2)%3 from edge k, in double precision then rounded.
inline TriPlanes makeTriPlanes(const TriSetup& s, const float z[3], const float iw[3]) {
    TriPlanes pl;
    float tz[3], tw[3];   // per setup vertex
    for (int k = 0; k < 3; ++k) {
        tz[k] = z[s.order[k]];
        tw[k] = iw[s.order[k]];
    }
    const double inv = 1.0 / double(s.area2);
    const double ax = (double(s.e[1].a) * tz[0] + double(s.e[2].a) * tz[1] + double(s.e[0].a) * tz[2]) * inv;
    const double ay = (double(s.e[1].b) * tz[0] + double(s.e[2].b) * tz[1] + double(s.e[0].b) * tz[2]) * inv;
    const int64_t px = int64_t(s.minX) * kSub + kHalf, py = int64_t(s.minY) * kSub + kHalf;
    const double zr = (double(s.e[1].at(px, py)) * tz[0] + double(s.e[2].at(px, py)) * tz[1] + double(s.e[0].at(px, py)) * tz[2]) * inv;
    pl.zRef = float(zr);
    pl.zdx = float(ax * kSub);
    pl.zdy = float(ay * kSub);
    for (int k = 0; k < 3; ++k) {
        const Edge& e = s.e[(k + 1) % 3];
        pl.uRef[k] = float(double(e.at(px, py)) * inv * tw[k]);
        pl.udx[k] = float(double(e.a) * kSub * inv * tw[k]);
        pl.udy[k] = float(double(e.b) * kSub * inv * tw[k]);
    }
    return pl;
}

// Whether rasterizeOpaque takes triangle s: its edge functions change by less than 2^30 over an
// 8x8 block (edges shorter than about 1100 pixels in x and y), so that inside a block that is
// neither rejected nor accepted whole they fit 32-bit integers.
inline bool coverageFits32(const TriCoverage& s) {
    for (const PackedEdge& e : s.e) {
        const int64_t span = (std::abs(int64_t(e.a)) + std::abs(int64_t(e.b))) * kSub * 7;
        if (span >= (int64_t(1) << 30)) return false;
    }
    return true;
}

// Rasterizes triangle s into a tile's visibility buffer, one sample per pixel: every pixel
// centre of [x0, x1] x [y0, y1] it covers (pixel indices in the viewport; the rectangle lies in
// the tile with corner (tx0, ty0) and in s's bbox) whose window depth
// clamp(zRef + zdx (i - minX) + zdy (j - minY), 0, 1) is less than depth[] stores that depth and
// `id`. depth and ids are the tile's buffers (row stride kTileSize, kTilePad values of slack).
// The same pixels and values as forEachCoveredPixel with that depth test. Needs coverageFits32.
void rasterizeOpaque(const TriCoverage& s, const TriPlanes& pl, uint32_t id, int tx0, int ty0, int x0, int y0, int x1, int y1, float* depth,
                     uint32_t* ids);

// Output pointers of a ShadeBatch (hoisted out of the per-fragment loops).
struct BatchOut {
    float *px, *py, *pz, *nx, *ny, *nz;
    int32_t* mat;
    explicit BatchOut(ShadeBatch& b)
        : px(b.px.data()), py(b.py.data()), pz(b.pz.data()), nx(b.nx.data()), ny(b.ny.data()), nz(b.nz.data()), mat(b.mat.data()) {}
};

// A plain lit triangle (no textures, vertex colours or maps; Phong or flat shading) as fragment
// preparation reads it.
struct PlainTri {
    const TriPlanes* pl = nullptr;
    int minX = 0, minY = 0;                        // its bbox corner (the planes' origin)
    bool swapped = false;                          // setup vertex order {0, 2, 1} (else {0, 1, 2})
    const std::array<sg::vec3, 3>* cb = nullptr;   // barycentrics of a clipped piece's vertices, or null
    sg::vec3 p[3], pe[3], n[3];                    // world positions, eye positions, normals of the input corners
    bool faceNormal = false;                       // flat (or no normals): n[0] is the normal
    int32_t slot = -1;                             // the material's ShadeBatch constant block
};

// Prepares fragments [k, k + count) of triangle t: fragPixel[i] is fragment i's pixel in the
// tile whose corner is (x0, y0) (index jj * kTileSize + ii); writes slot i of o (position,
// normal, constant block) and fogDist[i] (the eye-space distance, 0 without fog). Works in whole
// vectors: reads fragPixel and writes o and fogDist up to 7 slots past k + count (slack the
// caller provides; a later run overwrites them).
void preparePlainRun(const PlainTri& t, bool fog, const uint16_t* fragPixel, int x0, int y0, size_t k, size_t count, const BatchOut& o,
                     float* fogDist);

// Linear fog as the renderer applies it: vis = clamp((end - d) / (end - start), 0, 1),
// c = vis c + (1 - vis) fogColour. `on` false: no fog.
struct LinearFog {
    bool on = false;
    float end = 0, range = 1;   // range = end - start
    sg::vec3 color{0.0f};
};

// The output of a one-sample tile: fragments [0, n) with linear colour (cr, cg, cb) and eye
// distance fogDist, fogged, encoded to sRGB bytes (srgb's byte, bit for bit) and stored as RGBA8 (alpha 255) at
// color[fragPixel[k]]. Reads the inputs in whole vectors (up to 7 values past n).
void writeFragments(const float* cr, const float* cg, const float* cb, const float* fogDist, const uint16_t* fragPixel, size_t n,
                    const LinearFog& fog, const SrgbEncoder& srgb, uint32_t* color);

}   // namespace rnd::raster
