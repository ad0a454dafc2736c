// raster_shade.cpp - step 4 of the CPU rasterizer's frame (raster_frame.h), its second half:
// shading the visible opaque (and kept masked) fragments of a tile, deferred, each once:
//   1. gather    the visibility buffer, row by row, into runs of equal ids; the fragments
//                grouped by triangle in submission order (a counting sort), each triangle's
//                pixels in row order; depth and visibility to the framebuffer (MSAA:
//                gatherMsaaFragments, raster_msaa.cpp)
//   2. prepare   per run of one triangle: its attributes at the pixel centres into a ShadeBatch
//                (plain materials: the vector kernel preparePlainRun, tile_kernels.h)
//   3. light     shadeBatch (raster_shading.h)
//   4. output    fog, sRGB bytes, into the tile's colour buffer and then the framebuffer (MSAA:
//                resolveMsaa); with a linear frame (FrameContext::linear) the fogged linear
//                colour into it instead, for encodeLinearFrame (below) to encode at the end
// The helpers below were one function; they stay force-inlined into shadeOpaque, the SSE2
// parts in small named functions of their own.
#include "raster/raster_fragment.h"
#include "raster/raster_frame.h"
#include "raster/simd.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>

namespace rnd::raster {

using sg::vec3;

namespace {

// prepareFragment() for a TriCache::simple triangle, inlined into the fragment loop: the same
// operations in the same order (so the same bits), with the per-material values precomputed.
inline __attribute__((always_inline)) float prepareSimple(const TriCache& tc, bool fog, int i, int j, const BatchOut& o, size_t k) {
    const FragBary fb = baryAt(tc, i, j);
    const vec3& bo = fb.bo;
    const vec3 pos = bo[0] * tc.p[0] + bo[1] * tc.p[1] + bo[2] * tc.p[2];
    const vec3 n = tc.normalAt(bo);
    o.px[k] = pos.x;
    o.py[k] = pos.y;
    o.pz[k] = pos.z;
    o.nx[k] = n.x;
    o.ny[k] = n.y;
    o.nz[k] = n.z;
    o.mat[k] = tc.slot;   // albedo, coefficients and ambient + emissive: the material's constant block
    if (!fog) return 0.0f;
    return glm::length(bo[0] * tc.pe[0] + bo[1] * tc.pe[1] + bo[2] * tc.pe[2]);
}

// The pixel's visibility: the drawable and mesh triangle of its front-most kept surface.
inline void writeVisibility(const FrameContext& fc, Framebuffer& target, size_t pixel, const Tri& t) {
    const DrawItem& d = (*fc.draws)[t.draw];
    target.drawable[pixel] = d.drawable;
    target.primitive[pixel] = d.analytic ? kNoPrimitive : t.prim;
}

// --- 1. gather (one sample per pixel) ------------------------------------------------------

// Bit ii of the result: a run of equal ids starts at pixel ii of the row `ids` (pixel 0 always;
// bits at and past tw are left for the caller to mask). SSE2: 4 pixels per step, reading up to
// ids[64] (the next row or the buffer's slack).
[[gnu::always_inline]] inline uint64_t runStartsOfRow(const uint32_t* ids, int tw) {
    uint64_t starts = 1;   // pixel 0 starts a run
#if defined(RASTER_HAVE_SSE2)
    for (int ii = 1; ii < tw; ii += 4) {
        const __m128i cur = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ids + ii));
        const __m128i prev = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ids + ii - 1));
        const int same = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(cur, prev)));
        starts |= uint64_t(~same & 0xF) << ii;
    }
#else
    for (int ii = 1; ii < tw; ++ii) starts |= uint64_t(ids[ii] != ids[ii - 1]) << ii;
#endif
    return starts;
}

// Adds the length of each run of the row (run starts `starts`, ids `ids`) to its triangle's
// counter start[id] (start[nt]: uncovered pixels). Runs, not pixels: an increment per pixel of
// the same counter is a chain of store-to-load forwards.
[[gnu::always_inline]] inline void countRunsOfRow(uint64_t starts, const uint32_t* ids, int tw, uint32_t nt, uint32_t* start) {
    for (uint64_t m = starts; m;) {
        const int ib = __builtin_ctzll(m);
        m &= m - 1;
        const int ie = m ? __builtin_ctzll(m) : tw;
        start[std::min(ids[ib], nt)] += uint32_t(ie - ib);
    }
}

// Row by row: depth copied to the framebuffer as a whole row, the visibility (when asked), the
// runs of equal ids (buf.rowRuns) and each triangle's fragment count (buf.runStart). The tile's
// colours are set to the background first.
[[gnu::always_inline]] inline void scanVisibilityRows(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int tw, int th,
                                                      uint32_t bgWord) {
    const auto& chunks = *fc.chunks;
    const uint32_t* tileTris = buf.tileTris.data();
    const uint32_t nt = uint32_t(buf.tileTris.size());
    buf.runStart.assign(size_t(nt) + 1, 0);   // [nt]: uncovered pixels
    uint32_t* start = buf.runStart.data();
    std::fill(buf.color.begin(), buf.color.end(), bgWord);
    const uint64_t rowMask = tw == 64 ? ~uint64_t(0) : (uint64_t(1) << tw) - 1;
    for (int jj = 0; jj < th; ++jj) {
        const int row = fc.height - 1 - (y0 + jj);
        std::memcpy(&target.depth[size_t(row) * fc.width + x0], &buf.depth[size_t(jj) * kTileSize], size_t(tw) * sizeof(float));
        const uint32_t* ids = &buf.ids[size_t(jj) * kTileSize];
        const uint64_t starts = runStartsOfRow(ids, tw) & rowMask;
        buf.rowRuns[size_t(jj)] = starts;
        countRunsOfRow(starts, ids, tw, nt, start);
        if (fc.visibility)
            for (int ii = 0; ii < tw; ++ii)
                if (ids[ii] != kNoTri) writeVisibility(fc, target, size_t(row) * fc.width + x0 + ii, triById(chunks, tileTris[ids[ii]]));
    }
}

// The counts of scanVisibilityRows become each triangle's slots [runStart, runEnd), in the tile's
// submission order, and buf.runs one run per triangle with fragments. Returns the fragment count.
[[gnu::always_inline]] inline uint32_t assignTriangleSlots(TileBuffers& buf) {
    const uint32_t* tileTris = buf.tileTris.data();
    const uint32_t nt = uint32_t(buf.tileTris.size());
    uint32_t* start = buf.runStart.data();
    buf.runEnd.resize(nt);
    uint32_t* end = buf.runEnd.data();
    uint32_t pos = 0;
    for (uint32_t l = 0; l < nt; ++l) {
        const uint32_t count = start[l];
        start[l] = pos;
        if (count) buf.runs.push_back(FragRun{tileTris[l], pos, count});
        pos += count;
        end[l] = pos;
    }
    return pos;
}

// Writes the tile pixel indices first, first + 1, ... of a run of len fragments to dst. With
// `wholeVectors` (SSE2) 8 at a time, past the run's end: what they write there is rewritten by
// the triangle's later runs (a loop per run mispredicts its exit).
[[gnu::always_inline]] inline void writeRunPixels(uint16_t* dst, uint32_t len, int first, bool wholeVectors) {
#if defined(RASTER_HAVE_SSE2)
    if (wholeVectors) {
        const __m128i iota = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);
        for (uint32_t q = 0; q < len; q += 8)
            _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + q), _mm_add_epi16(iota, _mm_set1_epi16(short(first + int(q)))));
        return;
    }
#else
    (void)wholeVectors;
#endif
    for (uint32_t q = 0; q < len; ++q) dst[q] = uint16_t(first + int(q));
}

// The fragments' pixels (buf.fragPixel), grouped by triangle and each triangle's in row order: the
// preparation loads each triangle once and takes its fragments a vector at a time.
[[gnu::always_inline]] inline void placeFragmentPixels(TileBuffers& buf, int tw, int th) {
    uint32_t* start = buf.runStart.data();
    const uint32_t* end = buf.runEnd.data();
    uint16_t* fragPixel = buf.fragPixel.data();
    for (int jj = 0; jj < th; ++jj) {
        const uint32_t* ids = &buf.ids[size_t(jj) * kTileSize];
        for (uint64_t m = buf.rowRuns[size_t(jj)]; m;) {
            const int ib = __builtin_ctzll(m);
            m &= m - 1;
            const int ie = m ? __builtin_ctzll(m) : tw;
            const uint32_t id = ids[ib];
            if (id == kNoTri) continue;
            const uint32_t slot = start[id], len = uint32_t(ie - ib);
            start[id] = slot + len;
            writeRunPixels(fragPixel + slot, len, jj * kTileSize + ib, slot + ((len + 7) & ~7u) <= end[id]);
        }
    }
}

// --- 2. prepare ----------------------------------------------------------------------------

// Tiny triangles (a big mesh) change every fragment and miss the cache on the triangle, its
// indices and its vertices: prefetch the triangle of run r + 16, the indices of run r + 8 and
// the vertices of run r + 4.
[[gnu::always_inline]] inline void prefetchRunsAhead(const FrameContext& fc, const std::vector<FragRun>& runs, size_t r) {
    const auto& chunks = *fc.chunks;
    const size_t nr = runs.size();
    if (r + 16 < nr) __builtin_prefetch(&triById(chunks, runs[r + 16].tri));
    if (r + 8 < nr) {
        const Tri& tn = triById(chunks, runs[r + 8].tri);
        const DrawItem& dn = (*fc.draws)[tn.draw];
        if (!dn.perCorner && size_t(tn.prim) * 3 < dn.mesh->indices.size()) __builtin_prefetch(&dn.mesh->indices[size_t(tn.prim) * 3]);
    }
    if (r + 4 < nr) {
        const Tri& tn = triById(chunks, runs[r + 4].tri);
        const DrawItem& dn = (*fc.draws)[tn.draw];
        for (int q = 0; q < 3; ++q) {
            const uint32_t vq = dn.vertexOf(tn.prim, q);
            if (vq < dn.wv.size()) {
                __builtin_prefetch(&dn.wv[vq]);
                __builtin_prefetch(reinterpret_cast<const char*>(&dn.wv[vq]) + sizeof(DrawItem::VertexOut) - 1);
            }
        }
    }
}

// Fills the shading batch and buf.fogDist for every fragment, a run of one triangle at a time.
[[gnu::always_inline]] inline void prepareFragments(const FrameContext& fc, TileBuffers& buf, int x0, int y0) {
    const auto& chunks = *fc.chunks;
    const std::vector<FragRun>& runs = buf.runs;
    TriCache tc;
    const BatchOut out(buf.batch);
    const bool fogOn = fc.frame->settings.fog != sg::FogMode::Off;
    const size_t nr = runs.size();
    for (size_t r = 0; r < nr; ++r) {
        prefetchRunsAhead(fc, runs, r);
        const FragRun run = runs[r];
        if (run.tri != tc.id) {
            tc.load(run.tri, triById(chunks, run.tri), chunks[run.tri >> kChunkBits], fc);
            if (tc.simple && tc.slot < 0)   // once per material run: its constants for the kernel
                tc.slot = buf.batch.addConstants(tc.block);
        }
#if defined(RASTER_HAVE_SSE2)
        if (tc.simple) {   // a vector of fragments per step (whole vectors: up to 7 slots past the run, rewritten later)
            preparePlainRun(tc, fogOn, buf.fragPixel.data(), x0, y0, run.begin, run.count, out, buf.fogDist.data());
            continue;
        }
#endif
        for (size_t k = run.begin; k < size_t(run.begin) + run.count; ++k) {
            const int p = buf.fragPixel[k];
            if (tc.simple)
                buf.fogDist[k] = prepareSimple(tc, fogOn, x0 + p % kTileSize, y0 + p / kTileSize, out, k);
            else
                buf.fogDist[k] = prepareFragment(tc, fc, x0 + p % kTileSize, y0 + p / kTileSize, buf.batch, k);
        }
    }
}

// --- 4. output (one sample per pixel) ------------------------------------------------------

// The shaded fragments [0, nf), fogged and encoded, into the tile's colour buffer (contiguous:
// the framebuffer's rows of a tile, 5 KB apart at 1280 pixels, share a few cache sets).
[[gnu::always_inline]] inline void writeFragmentColors(const FrameContext& fc, TileBuffers& buf, size_t nf) {
    const auto& st = fc.frame->settings;
    const SrgbEncoder& enc = srgbEncoder();
    const bool fog = st.fog != sg::FogMode::Off;
    const bool linearFog = st.fog == sg::FogMode::Linear;
    const ShadeBatch& b = buf.batch;
    uint32_t* color = buf.color.data();
    auto packRgba = [](uint8_t r, uint8_t g, uint8_t b) {
        const uint8_t px[4] = {r, g, b, 255};
        uint32_t w;
        std::memcpy(&w, px, 4);
        return w;
    };
    size_t k = 0;
#if defined(RASTER_HAVE_SSE2)
    if (linearFog || !fog) {   // a vector of fragments at a time: the scalar loop's operations per lane
        const LinearFog lf{linearFog, st.fogEnd, st.fogEnd - st.fogStart, st.fogColor};
        writeFragments(b.cr.data(), b.cg.data(), b.cb.data(), buf.fogDist.data(), buf.fragPixel.data(), nf, lf, enc, color);
        k = nf;
    }
#endif
    for (; k < nf; ++k) {
        vec3 c(b.cr[k], b.cg[k], b.cb[k]);
        if (linearFog) {   // applyFog(), inlined: the same operations in the same order
            const float vis = std::clamp((st.fogEnd - buf.fogDist[k]) / (st.fogEnd - st.fogStart), 0.0f, 1.0f);
            c = vis * c + (1.0f - vis) * st.fogColor;
        } else if (fog) {
            c = applyFog(st, c, buf.fogDist[k]);
        }
        color[buf.fragPixel[k]] = packRgba(enc(c.x), enc(c.y), enc(c.z));
    }
}

// The linear frame's path (FrameContext::linear): the shaded fragments [0, nf), fogged, into the
// linear frame; the tile's other pixels keep the background shadeOpaque put there.
[[gnu::always_inline]] inline void writeFragmentLinear(const FrameContext& fc, const TileBuffers& buf, int x0, int y0, size_t nf) {
    const auto& st = fc.frame->settings;
    const bool fog = st.fog != sg::FogMode::Off;
    const ShadeBatch& b = buf.batch;
    for (size_t k = 0; k < nf; ++k) {
        vec3 c(b.cr[k], b.cg[k], b.cb[k]);
        if (fog) c = applyFog(st, c, buf.fogDist[k]);
        const int p = buf.fragPixel[k];
        linearAt(fc, x0 + p % kTileSize, y0 + p / kTileSize) = c;
    }
}

// The tile's colour buffer to the framebuffer, a row at a time.
[[gnu::always_inline]] inline void writeColorRows(const FrameContext& fc, Framebuffer& target, const TileBuffers& buf, int x0, int y0, int tw,
                                                  int th) {
    for (int jj = 0; jj < th; ++jj) std::memcpy(target.pixel(x0, fc.height - 1 - (y0 + jj)), &buf.color[size_t(jj) * kTileSize], size_t(tw) * 4);
}

}   // namespace

void shadeOpaque(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples) {
    int64_t tB = fc.timing ? nowNs() : 0;
    const uint32_t bgWord = backgroundWord(fc.frame->settings);
    // Fragments: one per covered pixel (MSAA: per distinct triangle in the pixel).
    // Sized for the worst case (every sample its own triangle); filled by index, no push_back.
    const size_t maxFrags = size_t(kTileSize) * kTileSize * samples;
    if (buf.fragPixel.size() < maxFrags + kTilePad) {   // slack: preparePlainRun reads whole vectors
        buf.fragPixel.resize(maxFrags + kTilePad);
        buf.fragTri.resize(maxFrags);
        buf.fragCount.resize(maxFrags);
    }
    const int tw = x1 - x0 + 1, th = y1 - y0 + 1;
    if (fc.linear) fillLinearBackground(fc, x0, y0, x1, y1);
    buf.runs.clear();
    size_t nf = 0;
    if (samples == 1) {
        // Colours go to the tile's own buffer, background first.
        scanVisibilityRows(fc, target, buf, x0, y0, tw, th, bgWord);
        nf = assignTriangleSlots(buf);
        placeFragmentPixels(buf, tw, th);
    } else {
        nf = gatherMsaaFragments(fc, target, buf, x0, y0, x1, y1);
    }
    if (nf == 0) {
        if (samples == 1 && !fc.linear) writeColorRows(fc, target, buf, x0, y0, tw, th);
        return;
    }
    buf.batch.resize(nf);
    buf.fogDist.resize(nf + ShadeBatch::kSlack);
    prepareFragments(fc, buf, x0, y0);
    buf.batch.pad();   // the vector stores may have run past nf
    fillShadowVisibility(fc, buf.batch, nf);
    int64_t tC = fc.timing ? nowNs() : 0;
    if (fc.timing) g_prepareNs += tC - tB;
    shadeBatch(buf.batch, nf, *fc.frame, fc.environment);
    if (fc.timing) g_lightNs += nowNs() - tC;
    if (samples == 1 && fc.linear) {
        writeFragmentLinear(fc, buf, x0, y0, nf);
        return;
    }
    if (samples == 1) {
        writeFragmentColors(fc, buf, nf);
        writeColorRows(fc, target, buf, x0, y0, tw, th);
        return;
    }
    resolveMsaa(fc, target, buf, x0, y0, x1, y1, nf);
}

void encodeLinearFrame(const sg::vec3* linear, int factor, const DisplayTransform& display, Framebuffer& target) {
    const SrgbEncoder& enc = srgbEncoder();
    const int w = target.width, r = std::max(factor, 1);
    const size_t stride = size_t(w) * r;   // pixels per row of the linear frame
    const float inv = 1.0f / float(r * r);
    tbb::parallel_for(tbb::blocked_range<int>(0, target.height), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y) {
            uint8_t* out = target.pixel(0, y);
            for (int x = 0; x < w; ++x, out += 4) {
                vec3 c = linear[size_t(y) * r * stride + size_t(x) * r];
                if (r > 1) {   // the mean of the block in linear light, as downsample() averages
                    c = vec3(0.0f);
                    for (int sy = 0; sy < r; ++sy)
                        for (int sx = 0; sx < r; ++sx) c += linear[(size_t(y) * r + sy) * stride + size_t(x) * r + sx];
                    c *= inv;
                }
                c = display(c);
                out[0] = enc(c.x);
                out[1] = enc(c.y);
                out[2] = enc(c.z);
                out[3] = 255;
            }
        }
    });
}

}   // namespace rnd::raster
