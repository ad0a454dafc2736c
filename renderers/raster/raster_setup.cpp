// raster_setup.cpp - step 3 of the CPU rasterizer's frame (raster_frame.h): the triangle stage.
// Per chunk of triangles (submission order), in parallel: trivial rejection by outcodes,
// clipping in homogeneous space (near and far exactly, x/y outside a guard band) with the
// polygon fan-triangulated, fixed-point setup (raster_core.h), back-face culling, the z and 1/w
// planes, and binning into 64x64 tiles: counted as the triangles are made, then a counting sort
// that keeps submission order within each tile.
#include "raster/raster_frame.h"

#include <algorithm>

namespace rnd::raster {

using sg::vec4;

namespace {

// Stores setup `s` into t (coverage, z and 1/w planes).
bool finishTri(Tri& t, const TriSetup& s, const float z[3], const float iw[3]) {
    t.s.set(s);
    for (int k = 0; k < 3; ++k) t.order[k] = s.order[k];
    t.pl = makeTriPlanes(s, z, iw);
    return true;
}

// Binning's first pass for `tri`, the chunk's newest triangle: counts it in every tile its bbox
// touches and keeps that tile range (ch.rects) for the second pass.
[[gnu::always_inline]] inline void countInTiles(Chunk& ch, int tilesX, const Tri& tri) {
    const Chunk::TileRect r{uint16_t(tri.s.minX / kTileSize), uint16_t(tri.s.minY / kTileSize), uint16_t(tri.s.maxX / kTileSize),
                            uint16_t(tri.s.maxY / kTileSize)};
    ch.rects.push_back(r);
    for (int ty = r.y0; ty <= r.y1; ++ty)
        for (int tx = r.x0; tx <= r.x1; ++tx) ++ch.tileStart[size_t(ty) * tilesX + tx + 1];
}

// Triangle t of draw d (index di), vertices v, inside the guard band on every plane: set up
// straight from its window coordinates, culled, stored and counted.
[[gnu::always_inline]] inline void setupWhole(Chunk& ch, const FrameContext& fc, const DrawItem& d, uint32_t di, uint32_t t, const uint32_t v[3],
                                              sg::CullMode culling) {
    const vec4 &w0 = d.win[v[0]], &w1 = d.win[v[1]], &w2 = d.win[v[2]];
    float wx[3] = {w0.x, w1.x, w2.x};
    float wy[3] = {w0.y, w1.y, w2.y};
    TriSetup s;   // full setup on the stack; the record keeps its compact part
    if (!setupTriangle(wx, wy, fc.width, fc.height, s, fc.msaa)) return;
    const bool front = s.flipped == d.mirrored;   // CCW is front; mirrored instances: CW
    if (!front && d.cullsBack(t, culling)) return;
    Tri& tri = ch.tris.emplace_back();   // made in place
    tri.front = front;
    tri.alpha = d.materialOf(t).alphaMode;
    float z[3] = {w0.z, w1.z, w2.z};
    float iw[3] = {w0.w, w1.w, w2.w};
    finishTri(tri, s, z, iw);
    tri.draw = di;
    tri.prim = t;
    countInTiles(ch, fc.tilesX, tri);
}

// The same for a triangle that crosses the planes `planes` (outcode bits): clipped in homogeneous
// space, the polygon fan-triangulated, each piece set up with the barycentrics of its corners
// in the input triangle (ch.clipBary).
[[gnu::always_inline]] inline void setupClipped(Chunk& ch, const FrameContext& fc, const GuardBand& g, const DrawItem& d, uint32_t di, uint32_t t,
                                                const uint32_t v[3], uint8_t planes, sg::CullMode culling) {
    vec4 c[3] = {d.clip[v[0]], d.clip[v[1]], d.clip[v[2]]};
    ClipVertex poly[9];
    int n = clipTriangle(c, planes, g, poly);
    if (n < 3) return;
    vec4 w[9];
    for (int k = 0; k < n; ++k) w[k] = toWindow(poly[k].clip, fc.width, fc.height);
    for (int k = 1; k + 1 < n; ++k) {
        int idx[3] = {0, k, k + 1};
        Tri tri;
        float wx[3], wy[3], z[3], iw[3];
        for (int q = 0; q < 3; ++q) {
            wx[q] = w[idx[q]].x;
            wy[q] = w[idx[q]].y;
            z[q] = w[idx[q]].z;
            iw[q] = w[idx[q]].w;
        }
        TriSetup s;
        if (!setupTriangle(wx, wy, fc.width, fc.height, s, fc.msaa)) continue;
        tri.front = s.flipped == d.mirrored;
        if (!tri.front && d.cullsBack(t, culling)) continue;
        tri.alpha = d.materialOf(t).alphaMode;
        finishTri(tri, s, z, iw);
        tri.draw = di;
        tri.prim = t;
        tri.clip = int32_t(ch.clipBary.size());
        ch.clipBary.push_back({poly[idx[tri.order[0]]].bary, poly[idx[tri.order[1]]].bary, poly[idx[tri.order[2]]].bary});
        countInTiles(ch, fc.tilesX, ch.tris.emplace_back(tri));
    }
}

// Binning's second pass: the per-tile counts become offsets, and every triangle's index goes to
// each tile of its range (a counting sort: submission order within each tile).
void binIntoTiles(Chunk& ch, int tilesX, int nt) {
    for (int i = 0; i < nt; ++i) ch.tileStart[i + 1] += ch.tileStart[i];
    ch.items.resize(ch.tileStart[nt]);
    ch.fill.assign(ch.tileStart.begin(), ch.tileStart.end() - 1);
    std::vector<uint32_t>& fill = ch.fill;
    for (uint32_t i = 0; i < ch.rects.size(); ++i) {
        const Chunk::TileRect r = ch.rects[i];
        for (int ty = r.y0; ty <= r.y1; ++ty)
            for (int tx = r.x0; tx <= r.x1; ++tx) ch.items[fill[size_t(ty) * tilesX + tx]++] = i;
    }
}

}   // namespace

void runTriangleStage(Chunk& ch, const FrameContext& fc) {
    const std::vector<DrawItem>& draws = *fc.draws;
    const auto& st = fc.frame->settings;
    const GuardBand g = guardBand(fc.width, fc.height);
    // Triangles are counted per tile as they are made (binning's first pass); `rects` keeps
    // their tile ranges for the second.
    const int nt = fc.tilesX * fc.tilesY;
    ch.tileStart.assign(size_t(nt) + 1, 0);
    ch.rects.clear();
    // One Tri per input triangle unless clipped: sized once, so a first frame does not grow
    // (and copy) the vectors step by step.
    ch.tris.reserve(size_t(ch.end - ch.begin));
    ch.rects.reserve(size_t(ch.end - ch.begin));
    // First draw containing ch.begin.
    size_t di =
        size_t(std::upper_bound(draws.begin(), draws.end(), ch.begin, [](uint64_t v, const DrawItem& d) { return v < d.firstTri; }) - draws.begin()) -
        1;
    for (uint64_t gi = ch.begin; gi < ch.end; ++gi) {
        while (gi >= draws[di].firstTri + draws[di].triCount) ++di;
        const DrawItem& d = draws[di];
        uint32_t t = uint32_t(gi - d.firstTri);
        uint32_t v[3];
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
            v[k] = d.vertexOf(t, k);
            ok = ok && v[k] < d.clip.size();
        }
        if (!ok) continue;
        uint8_t c0 = d.code[v[0]], c1 = d.code[v[1]], c2 = d.code[v[2]];
        if (c0 & c1 & c2) continue;                // all outside one plane
        if ((c0 | c1 | c2) & kInvalid) continue;   // non-finite vertex
        if ((c0 | c1 | c2) == 0)
            setupWhole(ch, fc, d, uint32_t(di), t, v, st.culling);
        else
            setupClipped(ch, fc, g, d, uint32_t(di), t, v, uint8_t(c0 | c1 | c2), st.culling);
    }
    binIntoTiles(ch, fc.tilesX, nt);
}

}   // namespace rnd::raster
