// lane_shading.cpp - shadeLanes, hitFrames and shadowRays (lane_shading.h): Tracer::shadeMeshHit's
// smooth branch, rnd::shadeTerms / sampleLight / lightTerms (renderers/common/shading.cpp),
// meshHitFrame and Tracer::shadowRay for a batch of eight hits, with AVX2's 8-float vectors where
// the CPU has AVX2 and SSE2's 4-float ones (twice) elsewhere: lane_kernel.inl, built once per
// width, lane by lane the same operations as the scalar functions (see there).
#include "raycast/lane_shading.h"
#include "renderers/debug_switches.h"
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
using V = __m128;
inline V set1(float x) { return _mm_set1_ps(x); }
inline V setzero() { return _mm_setzero_ps(); }
inline V add(V a, V b) { return _mm_add_ps(a, b); }
inline V sub(V a, V b) { return _mm_sub_ps(a, b); }
inline V mul(V a, V b) { return _mm_mul_ps(a, b); }
inline V div(V a, V b) { return _mm_div_ps(a, b); }
inline V vsqrt(V a) { return _mm_sqrt_ps(a); }
inline V vmax(V a, V b) { return _mm_max_ps(a, b); }
inline V vand(V a, V b) { return _mm_and_ps(a, b); }
inline V vor(V a, V b) { return _mm_or_ps(a, b); }
inline V vabs(V a) { return _mm_and_ps(a, _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff))); }
inline V negate(V a) { return _mm_xor_ps(a, _mm_set1_ps(-0.0f)); }
inline V sel(V mask, V a, V b) { return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b)); }   // mask ? a : b
inline V cmpgt(V a, V b) { return _mm_cmpgt_ps(a, b); }
inline V cmplt(V a, V b) { return _mm_cmplt_ps(a, b); }
inline V cmpge(V a, V b) { return _mm_cmpge_ps(a, b); }
inline V cmpnle(V a, V b) { return _mm_cmpnle_ps(a, b); }
inline V cmpneq(V a, V b) { return _mm_cmpneq_ps(a, b); }
inline V cmpeq(V a, V b) { return _mm_cmpeq_ps(a, b); }
inline V load(const float* p) { return _mm_load_ps(p); }
inline void store(float* p, V v) { _mm_store_ps(p, v); }
inline V maskOf(unsigned bits) {   // lane l all ones where bit l is set
    const __m128i b = _mm_set1_epi32(int(bits)), lane = _mm_setr_epi32(1, 2, 4, 8);
    return _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(b, lane), lane));
}
inline unsigned bitsOf(V mask) { return unsigned(_mm_movemask_ps(mask)); }
#define LANE_W 4
#include "raycast/lane_kernel.inl"
#undef LANE_W
}   // namespace sse

VIEWER_ISA_REGION_BEGIN("avx2")
namespace avx2 {
using V = __m256;
inline V set1(float x) { return _mm256_set1_ps(x); }
inline V setzero() { return _mm256_setzero_ps(); }
inline V add(V a, V b) { return _mm256_add_ps(a, b); }
inline V sub(V a, V b) { return _mm256_sub_ps(a, b); }
inline V mul(V a, V b) { return _mm256_mul_ps(a, b); }
inline V div(V a, V b) { return _mm256_div_ps(a, b); }
inline V vsqrt(V a) { return _mm256_sqrt_ps(a); }
inline V vmax(V a, V b) { return _mm256_max_ps(a, b); }
inline V vand(V a, V b) { return _mm256_and_ps(a, b); }
inline V vor(V a, V b) { return _mm256_or_ps(a, b); }
inline V vabs(V a) { return _mm256_and_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff))); }
inline V negate(V a) { return _mm256_xor_ps(a, _mm256_set1_ps(-0.0f)); }
inline V sel(V mask, V a, V b) { return _mm256_or_ps(_mm256_and_ps(mask, a), _mm256_andnot_ps(mask, b)); }   // mask ? a : b
inline V cmpgt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OS); }                                         // SSE's predicates (see lane_kernel.inl)
inline V cmplt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LT_OS); }
inline V cmpge(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GE_OS); }
inline V cmpnle(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_NLE_US); }
inline V cmpneq(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_NEQ_UQ); }
inline V cmpeq(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_EQ_OQ); }
inline V load(const float* p) { return _mm256_load_ps(p); }
inline void store(float* p, V v) { _mm256_store_ps(p, v); }
inline V maskOf(unsigned bits) {
    const __m256i b = _mm256_set1_epi32(int(bits)), lane = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(b, lane), lane));
}
inline unsigned bitsOf(V mask) { return unsigned(_mm256_movemask_ps(mask)); }
#define LANE_W 8
#include "raycast/lane_kernel.inl"
#undef LANE_W

// SrgbEncoder::operator() per lane, branch-free with one gathered table word: values clamped to
// [2^-13, the largest float below 1] (those encode to 0 and 255 as smaller values, NaN and values
// >= 1 do), the bucket's packed word gives its byte and the float bits where it steps up (floats
// >= 0 order like their bits).
inline __m256i encodeSrgb(V x, const SrgbEncoder& t) {
    x = _mm256_min_ps(_mm256_max_ps(x, set1(0x1p-13f)), set1(0x1.fffffep-1f));
    const __m256i bits = _mm256_castps_si256(x);
    const __m256i word = _mm256_i32gather_epi32(reinterpret_cast<const int*>(t.packed),
                                                _mm256_srli_epi32(_mm256_sub_epi32(bits, _mm256_set1_epi32(0x39000000)), 15), 4);
    const __m256i step = _mm256_add_epi32(_mm256_and_si256(bits, _mm256_set1_epi32(~0x7FFF)), _mm256_and_si256(word, _mm256_set1_epi32(0xFFFF)));
    return _mm256_sub_epi32(_mm256_srli_epi32(word, 16), _mm256_cmpgt_epi32(bits, _mm256_sub_epi32(step, _mm256_set1_epi32(1))));
}

void encodeRun(const float rgb[3][kL], uint32_t out[kL]) {
    const SrgbEncoder& t = srgbEncoder();
    const V r = load(rgb[0]), g = load(rgb[1]), b = load(rgb[2]);
    // isFinite (x - x is NaN exactly for an infinity or a NaN) of all three channels
    const V finite = cmpeq(add(add(sub(r, r), sub(g, g)), sub(b, b)), setzero());
    const __m256i word = _mm256_or_si256(_mm256_or_si256(encodeSrgb(r, t), _mm256_slli_epi32(encodeSrgb(g, t), 8)),
                                         _mm256_or_si256(_mm256_slli_epi32(encodeSrgb(b, t), 16), _mm256_set1_epi32(int(0xFF000000u))));
    const __m256i magenta = _mm256_set1_epi32(int(0xFFFF00FFu));   // bytes 255, 0, 255, 255
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm256_blendv_epi8(magenta, word, _mm256_castps_si256(finite)));
}
}   // namespace avx2
VIEWER_ISA_REGION_END

const bool kUseAvx2 = [] {
    if (rnd::debugSwitches().raycastForceSse) return false;
    __builtin_cpu_init();
    return bool(__builtin_cpu_supports("avx2"));
}();

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
    if (kUseAvx2) return avx2::encodeRun(rgb, out);
    const SrgbEncoder& t = srgbEncoder();
    for (int l = 0; l < count; ++l) {
        vec3 c(rgb[0][l], rgb[1][l], rgb[2][l]);
        if (!isFinite(c)) c = vec3(1, 0, 1);
        const uint8_t px[4] = {t(c.x), t(c.y), t(c.z), 255};
        std::memcpy(&out[l], px, 4);
    }
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
