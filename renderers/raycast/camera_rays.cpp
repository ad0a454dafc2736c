// camera_rays.cpp - CameraRays::grid's rows of four rays with AVX2 (where rt::useAvx2()): the
// four rays of a row in the lanes of 4-double vectors, each lane making the IEEE operations of
// CameraRays::unproject and finish for its ray in their order (sums, reciprocals of w, products,
// the difference, the dot product with the view direction, the rounding to float), so the rays
// are those of CameraRays::ray bit for bit. No FMA: the region is compiled for AVX2 alone, and
// the project builds with -ffp-contract=off.
#include "raycast/camera_rays.h"
#include "renderers/isa_region.h"

#include <immintrin.h>

namespace rnd::rt {

VIEWER_ISA_REGION_BEGIN("avx2")
uint32_t CameraRays::rowsOfFour(const glm::dvec4 cols[4], const glm::dvec4* rows, int ny, Ray* out, glm::dvec4* slow) const {
    static_assert(sizeof(Ray) == 32 && offsetof(Ray, dir) == 16, "Ray: org, tmin, dir, tmax packed");
    // The columns' shares, one component per vector (lane i: column i).
    __m256d c[4];
    for (int a = 0; a < 4; ++a) c[a] = _mm256_setr_pd(cols[0][a], cols[1][a], cols[2][a], cols[3][a]);
    const __m256d one = _mm256_set1_pd(1.0);
    uint32_t slowLanes = 0;
    for (int j = 0; j < ny; ++j) {
        __m256d xy[4], a[4], b[4];
        for (int k = 0; k < 4; ++k) {
            xy[k] = _mm256_add_pd(c[k], _mm256_set1_pd(rows[j][k]));   // glm's col + row
            a[k] = _mm256_add_pd(xy[k], _mm256_set1_pd(m_zw[0][k]));   // the point at NDC z = -1
            b[k] = _mm256_add_pd(xy[k], _mm256_set1_pd(m_zw[1][k]));   // and at z = +1
        }
        const __m256d ra = _mm256_div_pd(one, a[3]), rb = _mm256_div_pd(one, b[3]);
        __m256d d[3], org[3];
        for (int k = 0; k < 3; ++k) {
            org[k] = _mm256_mul_pd(a[k], ra);
            d[k] = _mm256_sub_pd(_mm256_mul_pd(b[k], rb), org[k]);   // far - org
        }
        // glm::dot(far - org, m_forward) = (x fx + y fy) + z fz
        const __m256d dot =
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d[0], _mm256_set1_pd(m_forward.x)), _mm256_mul_pd(d[1], _mm256_set1_pd(m_forward.y))),
                          _mm256_mul_pd(d[2], _mm256_set1_pd(m_forward.z)));
        __m128 o[4] = {_mm256_cvtpd_ps(org[0]), _mm256_cvtpd_ps(org[1]), _mm256_cvtpd_ps(org[2]), _mm_setzero_ps()};
        __m128 v[4] = {_mm256_cvtpd_ps(d[0]), _mm256_cvtpd_ps(d[1]), _mm256_cvtpd_ps(d[2]), _mm_set1_ps(1.0f)};
        // Lanes with a component that is not finite (v - v is NaN) or no far end ahead go the slow way.
        __m128 nonFinite = _mm_setzero_ps();
        for (int k = 0; k < 3; ++k) nonFinite = _mm_or_ps(nonFinite, _mm_cmpunord_ps(_mm_sub_ps(o[k], o[k]), _mm_sub_ps(v[k], v[k])));
        const int notAhead = _mm256_movemask_pd(_mm256_cmp_pd(dot, _mm256_setzero_pd(), _CMP_NGT_UQ));   // !(dot > 0)
        const unsigned lanesSlow = unsigned(_mm_movemask_ps(nonFinite) | notAhead);
        _MM_TRANSPOSE4_PS(o[0], o[1], o[2], o[3]);   // (org, tmin = 0) per ray
        _MM_TRANSPOSE4_PS(v[0], v[1], v[2], v[3]);   // (dir, tmax = 1) per ray
        for (int i = 0; i < 4; ++i) {
            _mm_storeu_ps(&out[4 * j + i].org.x, o[i]);
            _mm_storeu_ps(&out[4 * j + i].dir.x, v[i]);
        }
        if (lanesSlow) {
            alignas(32) double lane[4][4];
            for (int k = 0; k < 4; ++k) _mm256_store_pd(lane[k], xy[k]);
            for (unsigned m = lanesSlow; m; m &= m - 1) {
                const int i = __builtin_ctz(m);
                slow[4 * j + i] = glm::dvec4(lane[0][i], lane[1][i], lane[2][i], lane[3][i]);
            }
            slowLanes |= lanesSlow << (4 * j);
        }
    }
    return slowLanes;
}
VIEWER_ISA_REGION_END

}   // namespace rnd::rt
