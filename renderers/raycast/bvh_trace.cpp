// bvh_trace.cpp - tracing rays through a TriangleBvh: the SSE (BVH4), AVX2+FMA (BVH8) and
// AVX-512 (its packet leaves) builds of tri_kernel.inl, chosen once at run time, the entry
// points that dispatch to them, and the brute-force reference the tests compare against.
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

namespace {
const bool kUseAvx2 = [] {
    if (rnd::debugSwitches().raycastForceSse) return false;   // force the SSE path
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}();
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

// --- brute force ------------------------------------------------------------------------------

bool intersectBruteForce(const vec3* pos, const uint32_t* idx, size_t triCount, const Ray& ray, TriHit& hit) {
    return kUseAvx2 ? kern_avx2::bruteForce(pos, idx, triCount, ray, hit) : kern_sse::bruteForce(pos, idx, triCount, ray, hit);
}

}   // namespace rnd::rt
