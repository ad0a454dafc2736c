// simd.h - the CPU rasterizer's vector wrappers, written once for SSE2 (namespace simd_sse, 4
// lanes) and once for AVX2 (namespace simd_avx2, 8 lanes, compiled for AVX2 only inside its own
// target region; callers choose it at run time with useAvx2()). Kernels are written over these
// names (V, VI, kW, set1, add, ...) in .inl files that a .cpp includes once per namespace
// (raster_shading.cpp: the lighting kernel; tile_kernels.cpp: coverage and fragment preparation;
// also common/shadow_map.cpp's depth pass and the ray caster's lanes, raycast/lane_kernel.inl,
// which choose the set by their own CPU check).
//
// Every lane performs the same IEEE operation as the scalar code it replaces, and there is no FMA
// in either set (the AVX2 region enables avx2 only), so SSE2, AVX2 and scalar code give the same
// bits. VIEWER_RASTER_SSE=1 forces the SSE2 kernels (the tests compare the two).
#pragma once

#include "renderers/isa_region.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#define RASTER_HAVE_SSE2 1
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define RASTER_HAVE_AVX2 1
#endif
#endif

#include <cstddef>
#include <cstdint>

namespace rnd::raster {

// Whether the AVX2 kernels run (the CPU has AVX2 and VIEWER_RASTER_SSE is not 1); read once.
bool useAvx2();

#if defined(RASTER_HAVE_SSE2)
namespace simd_sse {
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
inline V cmplt(V a, V b) { return _mm_cmplt_ps(a, b); }
inline V cmpneq(V a, V b) { return _mm_cmpneq_ps(a, b); }
inline V cmpnle(V a, V b) { return _mm_cmpnle_ps(a, b); }   // !(a <= b): true with a NaN
inline V cmpeq(V a, V b) { return _mm_cmpeq_ps(a, b); }
inline V vxor(V a, V b) { return _mm_xor_ps(a, b); }
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
inline VI selI(VI mask, VI a, VI b) { return _mm_or_si128(_mm_and_si128(mask, a), _mm_andnot_si128(mask, b)); }
inline VI cmpgtI(VI a, VI b) { return _mm_cmpgt_epi32(a, b); }
inline VI cmpeqI(VI a, VI b) { return _mm_cmpeq_epi32(a, b); }
inline VI set1I(int x) { return _mm_set1_epi32(x); }
// Whether the kW values at p all equal v.
inline bool allEqualI(const int32_t* p, int32_t v) {
    return _mm_movemask_epi8(_mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)), _mm_set1_epi32(v))) == 0xFFFF;
}
inline VI laneIndex() { return _mm_setr_epi32(0, 1, 2, 3); }
inline VI laneBit() { return _mm_setr_epi32(1, 2, 4, 8); }   // 1 << laneIndex()
inline VI loaduI(const void* p) { return _mm_loadu_si128(static_cast<const __m128i*>(p)); }
inline void storeuI(void* p, VI a) { _mm_storeu_si128(static_cast<__m128i*>(p), a); }
// kW 16-bit values zero-extended to 32-bit lanes.
inline VI loadU16(const uint16_t* p) { return _mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)), _mm_setzero_si128()); }
inline V cvtF(VI a) { return _mm_cvtepi32_ps(a); }
inline VI cvttI(V a) { return _mm_cvttps_epi32(a); }
// Table lookup per lane (SSE2 has no gather: four loads).
inline VI gatherI(const int32_t* table, VI idx) {
    alignas(16) int32_t i[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(i), idx);
    return _mm_setr_epi32(table[i[0]], table[i[1]], table[i[2]], table[i[3]]);
}
inline void storeI(int32_t* p, VI a) { _mm_storeu_si128(reinterpret_cast<__m128i*>(p), a); }
inline V gatherF(const float* table, VI idx) {
    alignas(16) int32_t i[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(i), idx);
    return _mm_setr_ps(table[i[0]], table[i[1]], table[i[2]], table[i[3]]);
}
inline VI mulloI(VI a, VI b) {   // SSE2 has no 32-bit multiply-low: two 64-bit products
    const __m128i even = _mm_mul_epu32(a, b), odd = _mm_mul_epu32(_mm_srli_epi64(a, 32), _mm_srli_epi64(b, 32));
    return _mm_unpacklo_epi32(_mm_shuffle_epi32(even, _MM_SHUFFLE(0, 0, 2, 0)), _mm_shuffle_epi32(odd, _MM_SHUFFLE(0, 0, 2, 0)));
}
inline VI minI(VI a, VI b) { return selI(_mm_cmpgt_epi32(a, b), b, a); }
inline VI maxI(VI a, VI b) { return selI(_mm_cmpgt_epi32(a, b), a, b); }
}   // namespace simd_sse
#endif

#if defined(RASTER_HAVE_AVX2)
VIEWER_ISA_REGION_BEGIN("avx2")
namespace simd_avx2 {
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
// mask ? a : b per lane (masks are all ones or all zeros: blendv reads the sign bit only).
inline V sel(V mask, V a, V b) { return _mm256_blendv_ps(b, a, mask); }
inline V cmpgt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OS); }
inline V cmpge(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GE_OS); }
inline V cmplt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LT_OS); }
inline V cmpneq(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_NEQ_UQ); }
inline V cmpnle(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_NLE_US); }   // SSE's predicates, as above
inline V cmpeq(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_EQ_OQ); }
inline V vxor(V a, V b) { return _mm256_xor_ps(a, b); }
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
inline VI selI(VI mask, VI a, VI b) { return _mm256_blendv_epi8(b, a, mask); }
inline VI cmpgtI(VI a, VI b) { return _mm256_cmpgt_epi32(a, b); }
inline VI cmpeqI(VI a, VI b) { return _mm256_cmpeq_epi32(a, b); }
inline VI set1I(int x) { return _mm256_set1_epi32(x); }
inline bool allEqualI(const int32_t* p, int32_t v) {
    return _mm256_movemask_epi8(_mm256_cmpeq_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)), _mm256_set1_epi32(v))) == -1;
}
inline VI laneIndex() { return _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7); }
inline VI laneBit() { return _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128); }
inline VI loaduI(const void* p) { return _mm256_loadu_si256(static_cast<const __m256i*>(p)); }
inline void storeuI(void* p, VI a) { _mm256_storeu_si256(static_cast<__m256i*>(p), a); }
inline VI loadU16(const uint16_t* p) { return _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))); }
inline V cvtF(VI a) { return _mm256_cvtepi32_ps(a); }
inline VI cvttI(V a) { return _mm256_cvttps_epi32(a); }
// Table lookup per lane.
inline VI gatherI(const int32_t* table, VI idx) { return _mm256_i32gather_epi32(table, idx, 4); }
inline void storeI(int32_t* p, VI a) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), a); }
inline V gatherF(const float* table, VI idx) { return _mm256_i32gather_ps(table, idx, 4); }
inline VI mulloI(VI a, VI b) { return _mm256_mullo_epi32(a, b); }
inline VI minI(VI a, VI b) { return _mm256_min_epi32(a, b); }
inline VI maxI(VI a, VI b) { return _mm256_max_epi32(a, b); }
}   // namespace simd_avx2
VIEWER_ISA_REGION_END
#endif

}   // namespace rnd::raster
