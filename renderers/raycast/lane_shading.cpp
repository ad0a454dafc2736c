// lane_shading.cpp - shadeLanes, hitFrames, shadowRays and encodeLanes (lane_shading.h):
// Tracer::shadeMeshHit's smooth branch, rnd::shadeTerms / sampleLight / lightTerms
// (renderers/common/shading.cpp), meshHitFrame, Tracer::shadowRay and the sRGB bytes for a batch
// of eight hits, with AVX2's 8-float vectors where the CPU has AVX2 and SSE2's 4-float ones
// (twice) elsewhere: lane_kernel.inl, built once over each of raster/simd.h's sets, lane by lane
// the same operations as the scalar functions (see there).
#include "raycast/lane_shading.h"
#include "raster/simd.h"
#include "renderers/isa_region.h"
#include "renderers/srgb_encoder.h"

#include <immintrin.h>

#include <cmath>
#include <limits>

namespace rnd::raycast {

using namespace sg;

namespace {

constexpr int kL = LaneBatch::kLanes;
static_assert(FrameLanes::kLanes == kL && ShadowLanes::kLanes == kL, "one batch width");

namespace sse {
using namespace raster::simd_sse;
#include "raycast/lane_kernel.inl"
}   // namespace sse

VIEWER_ISA_REGION_BEGIN("avx2")
namespace avx2 {
using namespace raster::simd_avx2;
#include "raycast/lane_kernel.inl"
}   // namespace avx2
VIEWER_ISA_REGION_END

const bool kUseAvx2 = rt::useAvx2();

// Lanes count..kL-1 take lane 0's inputs (their results are not used).
void pad(LaneBatch& b) {
    for (int l = b.count; l < kL; ++l) {
        for (int a = 0; a < 3; ++a) {
            b.p[a][l] = b.p[a][0];
            b.ng[a][l] = b.ng[a][0];
            b.w[a][l] = b.w[a][0];
            b.tex[a][l] = b.tex[a][0];
            for (int k = 0; k < 3; ++k) {
                b.vn[k][a][l] = b.vn[k][a][0];
                b.va[k][a][l] = b.va[k][a][0];
            }
        }
        b.smooth[l] = b.smooth[0];
        b.coeff[l] = b.coeff[0];
        b.known[l] = b.known[0];
        b.lit[l] = b.lit[0];
    }
}

}   // namespace

bool laneShadingApplies(const FrameInput& f, bool shadowPackets) {
    const RenderSettings& s = f.settings;
    if (s.shading != ShadingModel::Phong || s.reflection == ReflectionModel::Pbr || f.lights.size() > 64) return false;
    if (!s.shadows || f.lights.empty()) return true;
    if (!shadowPackets) return false;   // shadow rays through cut-outs or blended layers
    for (const DrawLight& L : f.lights)
        if (L.hasSize() && s.shadowRays > 1) return false;   // soft shadows (Tracer::softVisibility)
    return true;
}

unsigned shadeLanes(LaneBatch& b, const FrameInput& f, float rgb[3][kL]) {
    pad(b);
    if (kUseAvx2) return avx2::shadeRun(b, f, rgb, 0);
    unsigned shaded = sse::shadeRun(b, f, rgb, 0);
    if (b.count > 4) shaded |= sse::shadeRun(b, f, rgb, 4);
    return shaded;
}

void encodeLanes(const float rgb[3][kL], int count, uint32_t out[kL]) {
    if (kUseAvx2) return avx2::encodeRun(rgb, out, 0);
    sse::encodeRun(rgb, out, 0);
    if (count > 4) sse::encodeRun(rgb, out, 4);
}

void hitFrames(FrameLanes& b) {
    for (int l = b.count; l < kL; ++l) {   // (unused lanes: lane 0's inputs)
        for (int a = 0; a < 3; ++a) {
            for (int k = 0; k < 3; ++k) b.P[k][a][l] = b.P[k][a][0];
            b.dir[a][l] = b.dir[a][0];
        }
        b.b1[l] = b.b1[0], b.b2[l] = b.b2[0];
    }
    b.back = 0;
    if (kUseAvx2) return avx2::framesRun(b, 0);
    sse::framesRun(b, 0);
    if (b.count > 4) sse::framesRun(b, 4);
}

void shadowRays(ShadowLanes& b, const DrawLight& L) {
    for (int l = b.count; l < kL; ++l)
        for (int a = 0; a < 3; ++a) b.p[a][l] = b.p[a][0], b.ng[a][l] = b.ng[a][0];
    b.reaches = 0;
    if (kUseAvx2) return avx2::shadowRun(b, L, 0);
    sse::shadowRun(b, L, 0);
    if (b.count > 4) sse::shadowRun(b, L, 4);
}

}   // namespace rnd::raycast
