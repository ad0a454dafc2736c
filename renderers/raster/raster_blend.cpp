// raster_blend.cpp - blended surfaces (alphaMode BLEND) in the CPU rasterizer's tile stage
// (raster_frame.h), order-correct per pixel: every blended fragment in front of the opaque depth
// is kept (depth is not written), a pixel's fragments are sorted far to near and composited
// "over" in linear light onto the pixel, each step re-encoded to 8-bit sRGB as an SRGB8
// framebuffer blends (with a linear frame, FrameContext::linear: onto its linear colour, neither
// clamped at 1 nor re-encoded, as GL's float target blends). With MSAA a fragment weighs by the
// samples it covers.
#include "raster/raster_fragment.h"
#include "raster/raster_frame.h"

#include <algorithm>

namespace rnd::raster {

using sg::vec3;

namespace {

// The blended triangles of the tile (buf.blendTris, in submission order) rasterized against the
// opaque depth: their fragments with alpha > 0 into buf.blendFrags.
void collectBlendFragments(const FrameContext& fc, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples) {
    const auto& chunks = *fc.chunks;
    std::vector<BlendFrag>& frags = buf.blendFrags;
    frags.clear();
    TriCache tc;
    const int tw = kTileSize;
    for (uint32_t order = 0; order < buf.blendTris.size(); ++order) {
        const uint32_t id = buf.blendTris[order];
        const Tri& t = triById(chunks, id);
        tc.load(id, t, chunks[id >> kChunkBits], fc);
        const int bx0 = std::max(x0, int(t.s.minX)), bx1 = std::min(x1, int(t.s.maxX));
        const int by0 = std::max(y0, int(t.s.minY)), by1 = std::min(y1, int(t.s.maxY));
        if (bx0 > bx1 || by0 > by1) continue;
        auto zAt = [&](float i, float j) {
            return std::clamp(t.pl.zRef + t.pl.zdx * (i - float(t.s.minX)) + t.pl.zdy * (j - float(t.s.minY)), 0.0f, 1.0f);
        };
        auto add = [&](int i, int j, int coverage) {
            const float a = fragmentAlpha(tc, i, j);
            if (!(a > 0.0f)) return;
            frags.push_back(BlendFrag{uint16_t((j - y0) * tw + (i - x0)), uint8_t(coverage), zAt(float(i), float(j)), std::min(a, 1.0f), id, order});
        };
        if (samples == 1) {
            forEachCoveredPixel(t.s, bx0, by0, bx1, by1, [&](int i, int j) {
                if (zAt(float(i), float(j)) < buf.depth[size_t(j - y0) * tw + (i - x0)]) add(i, j, 1);
            });
            continue;
        }
        const PackedEdge& e0 = t.s.e[0];
        const PackedEdge& e1 = t.s.e[1];
        const PackedEdge& e2 = t.s.e[2];
        for (int j = by0; j <= by1; ++j)
            for (int i = bx0; i <= bx1; ++i) {
                int covered = 0;
                const size_t p = (size_t(j - y0) * tw + (i - x0)) * 4;
                for (int s = 0; s < 4; ++s) {
                    int64_t px = int64_t(i) * kSub + kMsaa4X[s], py = int64_t(j) * kSub + kMsaa4Y[s];
                    if (e0.at(px, py) < e0.bias || e1.at(px, py) < e1.bias || e2.at(px, py) < e2.bias) continue;
                    const float z = zAt(float(i) + float(kMsaa4X[s] - kHalf) / kSub, float(j) + float(kMsaa4Y[s] - kHalf) / kSub);
                    if (z < buf.depth[p + s]) ++covered;
                }
                if (covered) add(i, j, covered);
            }
    }
}

// Shades the sorted fragments and composites each onto its pixel, far to near.
void compositeBlendFragments(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int samples) {
    const auto& chunks = *fc.chunks;
    const std::vector<BlendFrag>& frags = buf.blendFrags;
    const int tw = kTileSize;
    const size_t n = frags.size();
    buf.batch.resize(n);
    buf.fogDist.resize(n);
    TriCache tc;
    for (size_t k = 0; k < n; ++k) {
        const uint32_t id = frags[k].tri;
        if (id != tc.id) tc.load(id, triById(chunks, id), chunks[id >> kChunkBits], fc);
        const int p = frags[k].pixel;
        buf.fogDist[k] = prepareFragment(tc, fc, x0 + p % tw, y0 + p / tw, buf.batch, k);
    }
    fillShadowVisibility(fc, buf.batch, n);
    shadeBatch(buf.batch, n, *fc.frame, fc.environment);
    const auto& st = fc.frame->settings;
    const bool fog = st.fog != sg::FogMode::Off;
    const SrgbEncoder& enc = srgbEncoder();
    const ShadeBatch& b = buf.batch;
    for (size_t k = 0; k < n; ++k) {
        vec3 c(b.cr[k], b.cg[k], b.cb[k]);
        if (fog) c = applyFog(st, c, buf.fogDist[k]);
        const int p = frags[k].pixel;
        const float w = frags[k].alpha * float(frags[k].coverage) / float(samples);
        if (fc.linear) {
            vec3& dst = linearAt(fc, x0 + p % tw, y0 + p / tw);
            dst += w * (glm::max(c, vec3(0.0f)) - dst);
            continue;
        }
        c = glm::clamp(c, 0.0f, 1.0f);
        uint8_t* out = target.pixel(x0 + p % tw, fc.height - 1 - (y0 + p / tw));
        const vec3 dst = srgbBytesToLinear(out);
        const vec3 r = dst + w * (c - dst);
        out[0] = enc(r.x);
        out[1] = enc(r.y);
        out[2] = enc(r.z);
    }
}

}   // namespace

void renderBlended(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples) {
    collectBlendFragments(fc, buf, x0, y0, x1, y1, samples);
    std::vector<BlendFrag>& frags = buf.blendFrags;
    if (frags.empty()) return;
    std::sort(frags.begin(), frags.end(), [](const BlendFrag& a, const BlendFrag& b) {
        if (a.pixel != b.pixel) return a.pixel < b.pixel;
        if (a.z != b.z) return a.z > b.z;   // far first
        return a.order < b.order;
    });
    compositeBlendFragments(fc, target, buf, x0, y0, samples);
}

}   // namespace rnd::raster
