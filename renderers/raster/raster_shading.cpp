#include "raster/raster_shading.h"

#include "renderers/shading.h"

#include <algorithm>
#include <cmath>

#include <cstdlib>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace rnd::raster {

void ShadeBatch::resize(size_t n) {
    size = n;
    size_t cap = (n + 7) & ~size_t(7);   // whole vectors of 8 (the AVX2 kernel)
    for (auto* v : {&px, &py, &pz, &nx, &ny, &nz, &ar, &ag, &ab, &sr, &sg, &sb, &kd, &ks, &shin, &cr, &cg, &cb})
        if (v->size() < cap) v->resize(cap, 0.0f);
    if (mat.size() < cap) mat.resize(cap, -1);
    mats.clear();
    // Padding lanes: harmless values (normal up, zero coefficients).
    for (size_t i = n; i < cap; ++i) {
        px[i] = py[i] = pz[i] = 0;
        nx[i] = nz[i] = 0;
        ny[i] = 1;
        kd[i] = ks[i] = 0;
        shin[i] = 1;
        mat[i] = -1;
    }
}

#if defined(__SSE2__)
// The kernel's vector wrappers, SSE2: 4 lanes.
namespace kern_sse {
using V = __m128;
using VI = __m128i;
constexpr size_t kW = 4;
inline V set1(float x) { return _mm_set1_ps(x); }
inline V add(V a, V b) { return _mm_add_ps(a, b); }
inline V sub(V a, V b) { return _mm_sub_ps(a, b); }
inline V mul(V a, V b) { return _mm_mul_ps(a, b); }
inline V div(V a, V b) { return _mm_div_ps(a, b); }
inline V vmax(V a, V b) { return _mm_max_ps(a, b); }
inline V vmin(V a, V b) { return _mm_min_ps(a, b); }
inline V vsqrt(V a) { return _mm_sqrt_ps(a); }
inline V vand(V a, V b) { return _mm_and_ps(a, b); }
inline V vor(V a, V b) { return _mm_or_ps(a, b); }
inline V sel(V mask, V a, V b) { return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b)); }
inline V cmpgt(V a, V b) { return _mm_cmpgt_ps(a, b); }
inline V cmpge(V a, V b) { return _mm_cmpge_ps(a, b); }
inline int movemask(V a) { return _mm_movemask_ps(a); }
inline V zeroV() { return _mm_setzero_ps(); }
inline V loadu(const float* p) { return _mm_loadu_ps(p); }
inline void storeu(float* p, V a) { _mm_storeu_ps(p, a); }
inline VI castI(V a) { return _mm_castps_si128(a); }
inline V castF(VI a) { return _mm_castsi128_ps(a); }
inline VI srliI(VI a, int n) { return _mm_srli_epi32(a, n); }
inline VI slliI(VI a, int n) { return _mm_slli_epi32(a, n); }
inline VI subI(VI a, VI b) { return _mm_sub_epi32(a, b); }
inline VI addI(VI a, VI b) { return _mm_add_epi32(a, b); }
inline VI andI(VI a, VI b) { return _mm_and_si128(a, b); }
inline VI orI(VI a, VI b) { return _mm_or_si128(a, b); }
inline VI set1I(int x) { return _mm_set1_epi32(x); }
inline V cvtF(VI a) { return _mm_cvtepi32_ps(a); }
inline VI cvttI(V a) { return _mm_cvttps_epi32(a); }
#include "raster/shade_kernel.inl"
}   // namespace kern_sse

#if defined(__x86_64__) || defined(__i386__)
#define RASTER_HAVE_AVX2 1
// AVX2, 8 lanes (no FMA: the same roundings as SSE); used where the CPU has it.
#pragma GCC push_options
#pragma GCC target("avx2")
namespace kern_avx2 {
using V = __m256;
using VI = __m256i;
constexpr size_t kW = 8;
inline V set1(float x) { return _mm256_set1_ps(x); }
inline V add(V a, V b) { return _mm256_add_ps(a, b); }
inline V sub(V a, V b) { return _mm256_sub_ps(a, b); }
inline V mul(V a, V b) { return _mm256_mul_ps(a, b); }
inline V div(V a, V b) { return _mm256_div_ps(a, b); }
inline V vmax(V a, V b) { return _mm256_max_ps(a, b); }
inline V vmin(V a, V b) { return _mm256_min_ps(a, b); }
inline V vsqrt(V a) { return _mm256_sqrt_ps(a); }
inline V vand(V a, V b) { return _mm256_and_ps(a, b); }
inline V vor(V a, V b) { return _mm256_or_ps(a, b); }
inline V sel(V mask, V a, V b) { return _mm256_or_ps(_mm256_and_ps(mask, a), _mm256_andnot_ps(mask, b)); }
inline V cmpgt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OS); }
inline V cmpge(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GE_OS); }
inline int movemask(V a) { return _mm256_movemask_ps(a); }
inline V zeroV() { return _mm256_setzero_ps(); }
inline V loadu(const float* p) { return _mm256_loadu_ps(p); }
inline void storeu(float* p, V a) { _mm256_storeu_ps(p, a); }
inline VI castI(V a) { return _mm256_castps_si256(a); }
inline V castF(VI a) { return _mm256_castsi256_ps(a); }
inline VI srliI(VI a, int n) { return _mm256_srli_epi32(a, n); }
inline VI slliI(VI a, int n) { return _mm256_slli_epi32(a, n); }
inline VI subI(VI a, VI b) { return _mm256_sub_epi32(a, b); }
inline VI addI(VI a, VI b) { return _mm256_add_epi32(a, b); }
inline VI andI(VI a, VI b) { return _mm256_and_si256(a, b); }
inline VI orI(VI a, VI b) { return _mm256_or_si256(a, b); }
inline VI set1I(int x) { return _mm256_set1_epi32(x); }
inline V cvtF(VI a) { return _mm256_cvtepi32_ps(a); }
inline VI cvttI(V a) { return _mm256_cvttps_epi32(a); }
#include "raster/shade_kernel.inl"
void shadeBatchAvx2(ShadeBatch& b, size_t n, const sg::FrameInput& f) { shadeKernel(b, n, f); }
}   // namespace kern_avx2
#pragma GCC pop_options
#endif

namespace {
#if defined(RASTER_HAVE_AVX2)
// VIEWER_RASTER_SSE=1 forces the SSE2 kernel (tests compare the two).
const bool kUseAvx2 = [] {
    if (const char* e = std::getenv("VIEWER_RASTER_SSE")) return !(e[0] == '1');
    __builtin_cpu_init();
    return bool(__builtin_cpu_supports("avx2"));
}();
#endif
}   // namespace

void shadeBatch(ShadeBatch& b, size_t n, const sg::FrameInput& f) {
#if defined(RASTER_HAVE_AVX2)
    if (kUseAvx2) {
        kern_avx2::shadeBatchAvx2(b, n, f);
        return;
    }
#endif
    kern_sse::shadeKernel(b, n, f);
}

#else

void shadeBatch(ShadeBatch& b, size_t n, const sg::FrameInput& f) {
    for (size_t i = 0; i < n; ++i) {
        if (b.mat[i] >= 0) b.expand(i);
        if (b.kd[i] == 0 && b.ks[i] == 0) continue;
        sg::Material m;
        m.kd = b.kd[i];
        m.ks = b.ks[i];
        m.shininess = b.shin[i];
        m.specularColor = {b.sr[i], b.sg[i], b.sb[i]};
        SurfacePoint s{{b.px[i], b.py[i], b.pz[i]}, {b.nx[i], b.ny[i], b.nz[i]}, {b.ar[i], b.ag[i], b.ab[i]}};
        sg::vec3 v = f.camera.eye - s.position;
        float len = glm::length(v);
        v = len > 0 ? v / len : sg::vec3(0, 0, 1);
        sg::vec3 c(b.cr[i], b.cg[i], b.cb[i]);
        for (const auto& L : f.lights) c += lightTerms(m, s.normal, v, sampleLight(L, s.position), f.settings.reflection).apply(s.albedo);
        b.cr[i] = c.x;
        b.cg[i] = c.y;
        b.cb[i] = c.z;
    }
}

#endif

}   // namespace rnd::raster
