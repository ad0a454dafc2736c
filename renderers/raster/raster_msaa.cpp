// raster_msaa.cpp - the CPU rasterizer's 4x MSAA (raster_frame.h): a tile keeps coverage and
// depth per sample (raster_tile.cpp rasterizes at the positions of raster_core.h's kMsaa4X/Y)
// and shades once per pixel and triangle at the pixel centre. Here: gathering those fragments
// from the per-sample visibility buffer (one per pixel and distinct triangle among its samples,
// with the number of samples it covers), and the resolve, which averages the samples of a pixel
// in linear light (into the framebuffer's bytes, or into the linear frame when the display
// transform comes after it).
#include "raster/raster_frame.h"

#include <algorithm>
#include <cstring>
#include <limits>

namespace rnd::raster {

using sg::vec3;

size_t gatherMsaaFragments(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1) {
    const uint32_t bgWord = backgroundWord(fc.frame->settings);
    const int tw = x1 - x0 + 1, th = y1 - y0 + 1;
    const uint32_t* tileTris = buf.tileTris.data();
    size_t nf = 0;
    for (int jj = 0; jj < th; ++jj)
        for (int ii = 0; ii < tw; ++ii) {
            int p = jj * kTileSize + ii;
            int row = fc.height - 1 - (y0 + jj);
            std::memcpy(target.pixel(x0 + ii, row), &bgWord, 4);
            float dmin = 1.0f;
            uint32_t seen[4];
            int nseen = 0;
            size_t first = nf;
            for (int s = 0; s < 4; ++s) {
                dmin = std::min(dmin, buf.depth[p * 4 + s]);
                uint32_t id = buf.ids[p * 4 + s];
                if (id == kNoTri) continue;
                id = tileTris[id];
                int q = 0;
                while (q < nseen && seen[q] != id) ++q;
                if (q == nseen) {
                    seen[nseen++] = id;
                    buf.fragPixel[nf] = uint16_t(p);
                    buf.fragTri[nf] = id;
                    buf.fragCount[nf++] = 1;
                } else {
                    ++buf.fragCount[first + q];
                }
            }
            target.depth[size_t(row) * fc.width + x0 + ii] = dmin;
        }
    for (size_t k = 0; k < nf;) {   // runs of consecutive fragments of one triangle
        size_t e = k + 1;
        while (e < nf && buf.fragTri[e] == buf.fragTri[k]) ++e;
        buf.runs.push_back(FragRun{buf.fragTri[k], uint32_t(k), uint32_t(e - k)});
        k = e;
    }
    return nf;
}

void resolveMsaa(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, size_t nf) {
    const auto& st = fc.frame->settings;
    const SrgbEncoder& enc = srgbEncoder();
    const vec3 bg = st.background;
    const bool fog = st.fog != sg::FogMode::Off;
    const ShadeBatch& b = buf.batch;
    const int tw = x1 - x0 + 1, th = y1 - y0 + 1;
    // Average the samples in linear space (background where uncovered). Into bytes each sample
    // is clamped to [0, 1] first, as GL's sRGB8 samples are; into the linear frame it is not
    // (the display transform comes after the resolve, and exposure or tone mapping may bring
    // values above 1 back into range).
    const float hi = fc.linear ? std::numeric_limits<float>::max() : 1.0f;
    buf.accum.assign(size_t(kTileSize) * kTileSize, vec3(0.0f));
    std::vector<uint8_t> covered(size_t(kTileSize) * kTileSize, 0);
    for (size_t k = 0; k < nf; ++k) {
        vec3 c(b.cr[k], b.cg[k], b.cb[k]);
        if (fog) c = applyFog(st, c, buf.fogDist[k]);
        c = glm::clamp(c, 0.0f, hi);
        buf.accum[buf.fragPixel[k]] += float(buf.fragCount[k]) * c;
        covered[buf.fragPixel[k]] += buf.fragCount[k];
    }
    for (int jj = 0; jj < th; ++jj)
        for (int ii = 0; ii < tw; ++ii) {
            int p = jj * kTileSize + ii;
            if (!covered[p]) continue;
            vec3 c = (buf.accum[p] + float(4 - covered[p]) * bg) * 0.25f;
            if (fc.linear) {   // uncovered pixels hold the background already (shadeOpaque)
                linearAt(fc, x0 + ii, y0 + jj) = c;
                continue;
            }
            uint8_t* out = target.pixel(x0 + ii, fc.height - 1 - (y0 + jj));
            out[0] = enc(c.x);
            out[1] = enc(c.y);
            out[2] = enc(c.z);
        }
}

}   // namespace rnd::raster
