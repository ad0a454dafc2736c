// bvh_trace.cpp - tracing rays through a TriangleBvh: the SSE (BVH4), AVX2+FMA (BVH8) and
// AVX-512 (its packet leaves) builds of tri_kernel.inl, chosen once at run time, the entry
// points that dispatch to them, the top level's packet node test 8 or 16 rays wide (bvh4Reach),
// and the brute-force reference the tests compare against.
#include "raycast/bvh.h"
#include "renderers/debug_switches.h"
#include "renderers/isa_region.h"

#include <immintrin.h>

#include <algorithm>
#include <cstring>
#include <type_traits>

namespace rnd::rt {

using sg::vec3;

// One triangle into lane k of a packet, compiled for the baseline target in bvh.cpp (the AVX2
// brute force must build lanes bit-identically to the build).
void setLane(TriPacket4& p, int k, const vec3& p0, const vec3& p1, const vec3& p2);

// --- kernels: SSE and AVX2+FMA builds of tri_kernel.inl, chosen once at run time ------------

#define RT_AVX512 0
namespace kern_sse {
#define RT_FMA 0
#include "raycast/tri_kernel.inl"
#undef RT_FMA
}   // namespace kern_sse

VIEWER_ISA_REGION_BEGIN("avx2,fma")
namespace kern_avx2 {
#define RT_FMA 1
#include "raycast/tri_kernel.inl"
#undef RT_FMA
}   // namespace kern_avx2
VIEWER_ISA_REGION_END
#undef RT_AVX512

// The packet kernel on AVX-512: at a leaf, each triangle against a block of 16 rays per test,
// and the rays' own box tests 16 at a time (packet_kernel_avx512.inl), lane by lane the AVX2
// kernel's operations, so the same hits. Only the packets use it; single rays stay on the AVX2
// kernel.
VIEWER_ISA_REGION_BEGIN("avx512f,avx512dq,avx2,fma")
namespace kern_avx512 {
#define RT_FMA 1
#define RT_AVX512 1
#include "raycast/tri_kernel.inl"
#undef RT_AVX512
#undef RT_FMA
}   // namespace kern_avx512
VIEWER_ISA_REGION_END

bool useAvx2() {
    static const bool use = [] {
        if (rnd::debugSwitches().raycastForceSse) return false;   // force the SSE path
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    }();
    return use;
}

namespace {
const bool kUseAvx2 = useAvx2();
const bool kUseAvx512 = [] {
    if (!kUseAvx2 || rnd::debugSwitches().raycastForceAvx2) return false;
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
}();
}   // namespace

const char* kernelName() { return kUseAvx512 ? "avx2+fma bvh8, avx-512 packet leaves" : kUseAvx2 ? "avx2+fma bvh8" : "sse bvh4"; }
int kernelWidth() { return kUseAvx2 ? 8 : 4; }

bool TriangleBvh::intersect(const Ray& ray, TriHit& hit, bool cullBack, TraversalCount* count) const {
    if (m_packets.empty()) return false;
    if (count) {   // the cost view: the counting instantiations, so the plain ones stay as they are
        if (!m_nodes8.empty())
            return kern_avx2::traceTriangles8<false, true>(m_nodes8.data(), m_packets.data(), m_prims.data(), m_absMax, ray, &hit, cullBack, count);
        return kUseAvx2
                   ? kern_avx2::traceTriangles<false, true>(m_nodes4.data(), m_packets.data(), m_prims.data(), m_absMax, ray, &hit, cullBack, count)
                   : kern_sse::traceTriangles<false, true>(m_nodes4.data(), m_packets.data(), m_prims.data(), m_absMax, ray, &hit, cullBack, count);
    }
    if (!m_nodes8.empty()) return kern_avx2::traceTriangles8<false>(m_nodes8.data(), m_packets.data(), m_prims.data(), m_absMax, ray, &hit, cullBack);
    return kUseAvx2 ? kern_avx2::traceTriangles<false>(m_nodes4.data(), m_packets.data(), m_prims.data(), m_absMax, ray, &hit, cullBack)
                    : kern_sse::traceTriangles<false>(m_nodes4.data(), m_packets.data(), m_prims.data(), m_absMax, ray, &hit, cullBack);
}

bool TriangleBvh::occluded(const Ray& ray) const {
    if (m_packets.empty()) return false;
    if (!m_nodes8.empty()) return kern_avx2::traceTriangles8<true>(m_nodes8.data(), m_packets.data(), m_prims.data(), m_absMax, ray, nullptr, false);
    return kUseAvx2 ? kern_avx2::traceTriangles<true>(m_nodes4.data(), m_packets.data(), m_prims.data(), m_absMax, ray, nullptr, false)
                    : kern_sse::traceTriangles<true>(m_nodes4.data(), m_packets.data(), m_prims.data(), m_absMax, ray, nullptr, false);
}

uint64_t TriangleBvh::intersectPacket(const Ray* rays, int n, uint64_t active, TriHit* hits, bool cullBack, uint64_t* ties, const RayTransform* move,
                                      const float* tmax) const {
    if (ties) *ties = 0;
    n = std::clamp(n, 0, kMaxPacket);
    if (n < kMaxPacket) active &= (uint64_t(1) << n) - 1;
    if (m_packets.empty() || !active) return 0;
    if (!m_nodes8.empty()) {
        if (ties && kUseAvx512)
            return kern_avx512::tracePacket8<false, true>(m_nodes8.data(), m_packets.data(), m_prims.data(), m_absMax, rays, n, active, hits,
                                                          cullBack, ties, move, tmax);
        if (ties)
            return kern_avx2::tracePacket8<false, true>(m_nodes8.data(), m_packets.data(), m_prims.data(), m_absMax, rays, n, active, hits, cullBack,
                                                        ties, move, tmax);
        if (kUseAvx512)
            return kern_avx512::tracePacket8<false>(m_nodes8.data(), m_packets.data(), m_prims.data(), m_absMax, rays, n, active, hits, cullBack,
                                                    nullptr, move, tmax);
        return kern_avx2::tracePacket8<false>(m_nodes8.data(), m_packets.data(), m_prims.data(), m_absMax, rays, n, active, hits, cullBack, nullptr,
                                              move, tmax);
    }
    uint64_t found = 0;   // BVH4 (SSE, or a tree too big for BVH8): one ray at a time
    for (uint64_t m = active; m; m &= m - 1) {
        const int i = __builtin_ctzll(m);
        if (intersect(move ? move->apply(rays[i], tmax ? tmax[i] : rays[i].tmax) : rays[i], hits[i], cullBack)) found |= uint64_t(1) << i;
    }
    return found;
}

uint64_t TriangleBvh::occludedPacket(const Ray* rays, int n, uint64_t active, const RayTransform* move) const {
    n = std::clamp(n, 0, kMaxPacket);
    if (n < kMaxPacket) active &= (uint64_t(1) << n) - 1;
    if (m_packets.empty() || !active) return 0;
    if (!m_nodes8.empty() && kUseAvx512)
        return kern_avx512::tracePacket8<true>(m_nodes8.data(), m_packets.data(), m_prims.data(), m_absMax, rays, n, active, nullptr, false, nullptr,
                                               move, nullptr);
    if (!m_nodes8.empty())
        return kern_avx2::tracePacket8<true>(m_nodes8.data(), m_packets.data(), m_prims.data(), m_absMax, rays, n, active, nullptr, false, nullptr,
                                             move, nullptr);
    uint64_t found = 0;
    for (uint64_t m = active; m; m &= m - 1) {
        const int i = __builtin_ctzll(m);
        if (occluded(move ? move->apply(rays[i], rays[i].tmax) : rays[i])) found |= uint64_t(1) << i;
    }
    return found;
}

// --- the top level's node test for a packet, 8 or 16 lanes at a time -------------------------

// Bvh4PacketTest::reachChildren4's operations per lane (the same IEEE operations, in the same
// order, with the same NaN rules: max / min return the second operand where either is NaN, and
// <= is false with a NaN), on blocks of W lanes: with every active lane of a block sharing its
// direction signs a child's near and far planes are chosen once, otherwise per lane by the
// sign of the lane's reciprocal (its direction's; BLEND(a, b, r): b where r's sign bit is set,
// else a). A macro, not a function of vectors: GCC warns of the ABI of vector arguments between
// the ISA regions.
#define VIEWER_BVH4_REACH(V, W, SET1, LOAD, SUB, MUL, MAX, MIN, BLEND, LE_MASK, LANE, SIGNS)            \
    for (int blk = 0; blk < kMaxPacket / W; ++blk) {                                                    \
        const int at = W * blk;                                                                         \
        if (!((rays >> at) & ((uint64_t(1) << W) - 1))) continue;                                       \
        const V ox = LOAD(&t.o[0][at]), oy = LOAD(&t.o[1][at]), oz = LOAD(&t.o[2][at]);                 \
        const V rx = LOAD(&t.r[0][at]), ry = LOAD(&t.r[1][at]), rz = LOAD(&t.r[2][at]);                 \
        const V tmin = LOAD(&t.tmin[at]), tmax = LOAD(&t.tmax[at]);                                     \
        const int signs = SIGNS[blk];                                                                   \
        for (int c = 0; c < 4; ++c) {                                                                   \
            if (!((may >> c) & 1) || n.child[c] == Node4::kEmpty) continue;                             \
            V t0x, t1x, t0y, t1y, t0z, t1z;                                                             \
            if (signs >= 0) {                                                                           \
                const int nx = signs & 1, ny = 2 + ((signs >> 1) & 1), nz = 4 + ((signs >> 2) & 1);     \
                t0x = MUL(SUB(SET1(n.b[nx][c]), ox), rx);                                               \
                t1x = MUL(SUB(SET1(n.b[1 - (nx & 1)][c]), ox), rx);                                     \
                t0y = MUL(SUB(SET1(n.b[ny][c]), oy), ry);                                               \
                t1y = MUL(SUB(SET1(n.b[5 - ny][c]), oy), ry);                                           \
                t0z = MUL(SUB(SET1(n.b[nz][c]), oz), rz);                                               \
                t1z = MUL(SUB(SET1(n.b[9 - nz][c]), oz), rz);                                           \
            } else {                                                                                    \
                const V lx = MUL(SUB(SET1(n.b[0][c]), ox), rx), hx = MUL(SUB(SET1(n.b[1][c]), ox), rx); \
                const V ly = MUL(SUB(SET1(n.b[2][c]), oy), ry), hy = MUL(SUB(SET1(n.b[3][c]), oy), ry); \
                const V lz = MUL(SUB(SET1(n.b[4][c]), oz), rz), hz = MUL(SUB(SET1(n.b[5][c]), oz), rz); \
                t0x = BLEND(lx, hx, rx), t1x = BLEND(hx, lx, rx);                                       \
                t0y = BLEND(ly, hy, ry), t1y = BLEND(hy, ly, ry);                                       \
                t0z = BLEND(lz, hz, rz), t1z = BLEND(hz, lz, rz);                                       \
            }                                                                                           \
            const V tn = MAX(MAX(t0x, t0y), MAX(t0z, tmin));                                            \
            const V tf = MUL(MIN(MIN(t1x, t1y), MIN(t1z, tmax)), SET1(Bvh4RayTest::kGrow));             \
            reach[c] |= (uint64_t(LE_MASK(tn, tf)) << at) & rays;                                       \
            if (first >= at && first < at + W) lead[c] = LANE(tn, first - at);                          \
        }                                                                                               \
    }

VIEWER_ISA_REGION_BEGIN("avx2")
namespace {
#define VIEWER_LE8(a, b) _mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OS))
#define VIEWER_LANE8(v, i) _mm256_cvtss_f32(_mm256_permutevar8x32_ps(v, _mm256_set1_epi32(i)))
void reachChildren8(const Bvh4PacketTest& t, const Node4& n, uint64_t rays, int may, uint64_t reach[4], float lead[4], int first) {
    VIEWER_BVH4_REACH(__m256, 8, _mm256_set1_ps, _mm256_load_ps, _mm256_sub_ps, _mm256_mul_ps, _mm256_max_ps, _mm256_min_ps, _mm256_blendv_ps,
                      VIEWER_LE8, VIEWER_LANE8, t.signs8)
}
#undef VIEWER_LE8
#undef VIEWER_LANE8
}   // namespace
VIEWER_ISA_REGION_END

VIEWER_ISA_REGION_BEGIN("avx512f,avx512dq,avx2")
namespace {
#define VIEWER_BLEND16(a, b, r) _mm512_mask_blend_ps(_mm512_movepi32_mask(_mm512_castps_si512(r)), a, b)
#define VIEWER_LE16(a, b) _mm512_cmp_ps_mask(a, b, _CMP_LE_OS)
// (GCC 12's unmasked _mm512_max_ps / _mm512_min_ps warn of an uninitialised operand.)
#define VIEWER_MAX16(a, b) _mm512_maskz_max_ps(0xFFFF, a, b)
#define VIEWER_MIN16(a, b) _mm512_maskz_min_ps(0xFFFF, a, b)
#define VIEWER_LANE16(v, i) _mm512_cvtss_f32(_mm512_maskz_permutexvar_ps(0xFFFF, _mm512_set1_epi32(i), v))
void reachChildren16(const Bvh4PacketTest& t, const Node4& n, uint64_t rays, int may, uint64_t reach[4], float lead[4], int first) {
    VIEWER_BVH4_REACH(__m512, 16, _mm512_set1_ps, _mm512_load_ps, _mm512_sub_ps, _mm512_mul_ps, VIEWER_MAX16, VIEWER_MIN16, VIEWER_BLEND16,
                      VIEWER_LE16, VIEWER_LANE16, t.signs16)
}
#undef VIEWER_BLEND16
#undef VIEWER_LE16
#undef VIEWER_MAX16
#undef VIEWER_MIN16
#undef VIEWER_LANE16
}   // namespace
VIEWER_ISA_REGION_END
#undef VIEWER_BVH4_REACH

void bvh4Reach(const Bvh4PacketTest& test, const Node4& n, uint64_t rays, int may, uint64_t reach[4], float lead[4], int first) {
    if (kUseAvx512)
        reachChildren16(test, n, rays, may, reach, lead, first);
    else if (kUseAvx2)
        reachChildren8(test, n, rays, may, reach, lead, first);
    else
        test.reachChildren4(n, rays, may, reach, lead, first);
}

// --- brute force ------------------------------------------------------------------------------

bool intersectBruteForce(const vec3* pos, const uint32_t* idx, size_t triCount, const Ray& ray, TriHit& hit) {
    return kUseAvx2 ? kern_avx2::bruteForce(pos, idx, triCount, ray, hit) : kern_sse::bruteForce(pos, idx, triCount, ray, hit);
}

}   // namespace rnd::rt
