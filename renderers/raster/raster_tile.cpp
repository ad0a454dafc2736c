// raster_tile.cpp - step 4 of the CPU rasterizer's frame (raster_frame.h), its first half: the
// coverage of one tile. The tile's triangles, in submission order, go into its visibility buffer
// (depth LESS, per pixel or per MSAA sample an index into the tile's triangle list): opaque ones
// through the vector kernel (tile_kernels.h) where it applies, masked ones with their alpha
// tested per pixel, blended ones set aside for raster_blend.cpp. Then the overdraw count (when
// asked), the shading (raster_shade.cpp) and the blended surfaces. Tiles that no triangle
// touches get the background straight away.
#include "raster/raster_fragment.h"
#include "raster/raster_frame.h"
#include "raster/simd.h"

#include <algorithm>
#include <cstring>

// rasterizeIntoTile's vector path is compiled only where simd.h says SSE2 is there: without the
// include above it silently fell back to the scalar block walk (a file split lost it once).
#if defined(__SSE2__) && !defined(RASTER_HAVE_SSE2)
#error "raster/simd.h must define RASTER_HAVE_SSE2 here"
#endif

namespace rnd::raster {

std::atomic<int64_t> g_rasterNs{0}, g_prepareNs{0}, g_lightNs{0};

namespace {

// Rasterizes one triangle into the tile's visibility buffer (depth LESS). `samples` is 1 or 4
// (MSAA: sample s of pixel p at index p*4 + s).
// keep(i, j): whether the fragment of pixel (i, j) survives (alpha mask), asked only for
// samples that pass the depth test.
template <class Keep>
inline void rasterizeTri(const Tri& t, uint32_t id, int tx0, int ty0, int tx1, int ty1, int samples, float* depth, uint32_t* ids, Keep&& keep) {
    int x0 = std::max(tx0, int(t.s.minX)), x1 = std::min(tx1, int(t.s.maxX));
    int y0 = std::max(ty0, int(t.s.minY)), y1 = std::min(ty1, int(t.s.maxY));
    if (x0 > x1 || y0 > y1) return;
    const int tw = kTileSize;
    const PackedEdge& e0 = t.s.e[0];
    const PackedEdge& e1 = t.s.e[1];
    const PackedEdge& e2 = t.s.e[2];
    if (samples == 1) {
        auto pixel = [&](int i, int j) {
            float z = t.pl.zRef + t.pl.zdx * float(i - t.s.minX) + t.pl.zdy * float(j - t.s.minY);
            z = std::clamp(z, 0.0f, 1.0f);
            size_t p = size_t(j - ty0) * tw + (i - tx0);
            if (z < depth[p] && keep(i, j)) {
                depth[p] = z;
                ids[p] = id;
            }
        };
        if (x1 - x0 <= 1 && y1 - y0 <= 1) {
            // At most 2x2 pixels (most triangles of a big mesh): the edge functions at each pixel
            // centre directly, as forEachCoveredPixelSimple; the same pixels in the same order
            // as the block walk, without its setup.
            for (int j = y0; j <= y1; ++j)
                for (int i = x0; i <= x1; ++i) {
                    const int64_t px = int64_t(i) * kSub + kHalf, py = int64_t(j) * kSub + kHalf;
                    if (e0.at(px, py) >= e0.bias && e1.at(px, py) >= e1.bias && e2.at(px, py) >= e2.bias) pixel(i, j);
                }
            return;
        }
        forEachCoveredPixel(t.s, x0, y0, x1, y1, pixel);
        return;
    }
    for (int j = y0; j <= y1; ++j)
        for (int i = x0; i <= x1; ++i) {
            int p = ((j - ty0) * tw + (i - tx0)) * 4;
            for (int s = 0; s < 4; ++s) {
                int64_t px = int64_t(i) * kSub + kMsaa4X[s], py = int64_t(j) * kSub + kMsaa4Y[s];
                if (e0.at(px, py) < e0.bias || e1.at(px, py) < e1.bias || e2.at(px, py) < e2.bias) continue;
                float z = t.pl.zRef + t.pl.zdx * (float(i - t.s.minX) + float(kMsaa4X[s] - kHalf) / kSub) +
                          t.pl.zdy * (float(j - t.s.minY) + float(kMsaa4Y[s] - kHalf) / kSub);
                z = std::clamp(z, 0.0f, 1.0f);
                if (z < depth[p + s] && keep(i, j)) {
                    depth[p + s] = z;
                    ids[p + s] = id;
                }
            }
        }
}

__attribute__((noinline)) void rasterizeIntoTile(const Tri& t, uint32_t id, int tx0, int ty0, int tx1, int ty1, int samples, float* depth,
                                                 uint32_t* ids) {
#if defined(RASTER_HAVE_SSE2)
    // One sample per pixel, bigger than 2x2 pixels (rasterizeTri's own short path): a row of an
    // 8x8 block per vector step, the same pixels and depths.
    if (samples == 1) {
        const int x0 = std::max(tx0, int(t.s.minX)), x1 = std::min(tx1, int(t.s.maxX));
        const int y0 = std::max(ty0, int(t.s.minY)), y1 = std::min(ty1, int(t.s.maxY));
        if (x0 > x1 || y0 > y1) return;
        if ((x1 - x0 > 1 || y1 - y0 > 1) && coverageFits32(t.s)) {
            rasterizeOpaque(t.s, t.pl, id, tx0, ty0, x0, y0, x1, y1, depth, ids);
            return;
        }
    }
#endif
    rasterizeTri(t, id, tx0, ty0, tx1, ty1, samples, depth, ids, [](int, int) { return true; });
}

// A cut-out (MASK) triangle: a fragment below the cutoff is discarded before it writes depth,
// as GL's discard; alpha at the pixel centre, shared by its MSAA samples. `masked` caches the
// triangle's attributes between calls.
void rasterizeMasked(const Tri& t, uint32_t id, uint32_t local, const Chunk& ch, const FrameContext& fc, TriCache& masked, int x0, int y0, int x1,
                     int y1, int samples, TileBuffers& buf) {
    if (masked.id != id) masked.load(id, t, ch, fc);
    int li = -1, lj = -1;
    bool lastKeep = false;
    const float cutoff = masked.mat->alphaCutoff;
    rasterizeTri(t, local, x0, y0, x1, y1, samples, buf.depth.data(), buf.ids.data(), [&](int i, int j) {
        if (i != li || j != lj) {
            li = i;
            lj = j;
            lastKeep = fragmentAlpha(masked, i, j) >= cutoff;
        }
        return lastKeep;
    });
}

// The overdraw view (Aov::Overdraw, one sample per pixel): every fragment the tile's
// triangles rasterize, whatever their alpha mode and before any depth or alpha test, adds one
// to its pixel's counter. A pass of its own, so that frames that do not ask pay nothing.
void countOverdraw(int tile, const FrameContext& fc, Framebuffer& target, int x0, int y0, int x1, int y1) {
    const auto& chunks = *fc.chunks;
    for (const Chunk& ch : chunks)
        for (uint32_t k = ch.tileStart[tile]; k < ch.tileStart[tile + 1]; ++k)
            forEachCoveredPixel(ch.tris[ch.items[k]].s, x0, y0, x1, y1,
                                [&](int i, int j) { ++target.overdraw[size_t(fc.height - 1 - j) * fc.width + i]; });
}

// Whether no triangle of any chunk touches the tile.
bool tileIsEmpty(int tile, const std::vector<Chunk>& chunks) {
    bool empty = true;
    for (const Chunk& ch : chunks) empty = empty && ch.tileStart[tile] == ch.tileStart[tile + 1];
    return empty;
}

// An empty tile (sky, margins): background and far depth straight into the framebuffer, without
// the tile's buffers.
void fillEmptyTile(const FrameContext& fc, Framebuffer& target, int x0, int y0, int x1, int y1) {
    if (fc.linear) {   // bytes come from the linear frame at the end (encodeLinearFrame)
        fillLinearBackground(fc, x0, y0, x1, y1);
        for (int j = y0; j <= y1; ++j) std::fill_n(&target.depth[size_t(fc.height - 1 - j) * fc.width + x0], x1 - x0 + 1, 1.0f);
        return;
    }
    const uint32_t bgWord = backgroundWord(fc.frame->settings);
    for (int j = y0; j <= y1; ++j) {
        const int row = fc.height - 1 - j;
        uint8_t* out = target.pixel(x0, row);
        for (int i = x0; i <= x1; ++i, out += 4) std::memcpy(out, &bgWord, 4);
        std::fill_n(&target.depth[size_t(row) * fc.width + x0], x1 - x0 + 1, 1.0f);
    }
}

// The tile's triangles of every chunk, in submission order, into its visibility buffer (opaque
// and masked ones, listed in buf.tileTris; blended ones listed in buf.blendTris).
void rasterizeTileTriangles(int tile, const FrameContext& fc, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples) {
    const auto& chunks = *fc.chunks;
    const size_t n = size_t(kTileSize) * kTileSize * samples;
    buf.depth.assign(n + kTilePad, 1.0f);
    buf.ids.assign(n + kTilePad, kNoTri);
    buf.blendTris.clear();
    buf.tileTris.clear();
    TriCache masked;
    for (size_t c = 0; c < chunks.size(); ++c) {
        const Chunk& ch = chunks[c];
        const uint32_t kEnd = ch.tileStart[tile + 1];
        for (uint32_t k = ch.tileStart[tile]; k < kEnd; ++k) {
            // A tile reads its triangles' records scattered over the chunk (only those that touch
            // it): fetch them ahead, or each one is a miss (most of the coverage time of a mesh of
            // small triangles such as the bunny).
            if (k + 6 < kEnd) {
                const char* ahead = reinterpret_cast<const char*>(&ch.tris[ch.items[k + 6]]);
                __builtin_prefetch(ahead);
                __builtin_prefetch(ahead + sizeof(Tri) - 1);
            }
            uint32_t idx = ch.items[k];
            const Tri& t = ch.tris[idx];
            const uint32_t id = uint32_t(c << kChunkBits) | idx;
            const uint32_t local = uint32_t(buf.tileTris.size());   // what the visibility buffer stores
            if (t.alpha == sg::AlphaMode::Opaque) {
                buf.tileTris.push_back(id);
                rasterizeIntoTile(t, local, x0, y0, x1, y1, samples, buf.depth.data(), buf.ids.data());
            } else if (t.alpha == sg::AlphaMode::Blend) {
                buf.blendTris.push_back(id);   // after the opaque surfaces, in renderBlended
            } else {
                buf.tileTris.push_back(id);
                rasterizeMasked(t, id, local, ch, fc, masked, x0, y0, x1, y1, samples, buf);
            }
        }
    }
}

}   // namespace

void renderTile(int tile, const FrameContext& fc, Framebuffer& target, TileBuffers& buf) {
    int64_t tA = fc.timing ? nowNs() : 0;
    const int tx = tile % fc.tilesX, ty = tile / fc.tilesX;
    const int x0 = tx * kTileSize, y0 = ty * kTileSize;
    const int x1 = std::min(x0 + kTileSize, fc.width) - 1, y1 = std::min(y0 + kTileSize, fc.height) - 1;
    const int samples = fc.msaa ? 4 : 1;
    if (tileIsEmpty(tile, *fc.chunks)) {
        fillEmptyTile(fc, target, x0, y0, x1, y1);
        if (fc.timing) g_rasterNs += nowNs() - tA;
        return;
    }
    rasterizeTileTriangles(tile, fc, buf, x0, y0, x1, y1, samples);
    if (fc.overdraw) countOverdraw(tile, fc, target, x0, y0, x1, y1);
    if (fc.timing) g_rasterNs += nowNs() - tA;
    shadeOpaque(fc, target, buf, x0, y0, x1, y1, samples);
    if (!buf.blendTris.empty()) renderBlended(fc, target, buf, x0, y0, x1, y1, samples);
}

}   // namespace rnd::raster
