// bvh_binning.h - the BVH builder's primitive references and its binned SAH split, shared by
// the builder (bvh.cpp) and the split itself (bvh_binning.cpp). Private to renderers/raycast.
#pragma once

#include "scenegraph/math.h"

#include <immintrin.h>

#include <cstdint>
#include <cstring>
#include <limits>

namespace rnd::rt::binning {

using sg::vec3;

struct alignas(16) PrimRef {
    __m128 lo, hi;   // lo.w holds the primitive id (bit pattern)
    uint32_t id() const {
        uint32_t i;
        float f = _mm_cvtss_f32(_mm_shuffle_ps(lo, lo, _MM_SHUFFLE(3, 3, 3, 3)));
        std::memcpy(&i, &f, 4);
        return i;
    }
    __m128 center2() const { return _mm_add_ps(lo, hi); }   // 2 x centroid
};

inline PrimRef makeRef(const vec3& mn, const vec3& mx, uint32_t id) {
    float f;
    std::memcpy(&f, &id, 4);
    return {_mm_setr_ps(mn.x, mn.y, mn.z, f), _mm_setr_ps(mx.x, mx.y, mx.z, 0.0f)};
}

struct Box {
    __m128 lo = _mm_set1_ps(std::numeric_limits<float>::infinity());
    __m128 hi = _mm_set1_ps(-std::numeric_limits<float>::infinity());
    void extend(__m128 l, __m128 h) {
        lo = _mm_min_ps(lo, l);
        hi = _mm_max_ps(hi, h);
    }
    void extend(const Box& b) { extend(b.lo, b.hi); }
    float halfArea() const {
        alignas(16) float e[4];
        _mm_store_ps(e, _mm_sub_ps(hi, lo));
        if (e[0] < 0 || e[1] < 0 || e[2] < 0) return 0.0f;
        return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
    }
};

struct Range {
    uint32_t begin = 0, end = 0;
    Box bounds;      // of the primitives
    Box centroids;   // of 2 x centroids
    uint32_t count() const { return end - begin; }
};

// Bounds and centroid bounds of refs[begin, end).
void computeBounds(const PrimRef* refs, Range& r);

inline constexpr int kMaxBins = 32;

// Leaf blocks of leafSize primitives (one packet test each) for n primitives.
inline int blocks(uint32_t n, int leafSize) { return int((n + uint32_t(leafSize) - 1) / uint32_t(leafSize)); }

// Splits r into l and rr (binned SAH with nbins bins, or an object median for tiny ranges or
// when forceMedian); *cost gets the split's SAH cost in the units of a leaf's cost.
void splitRange(PrimRef* refs, const Range& r, Range& l, Range& rr, int nbins, int leafSize, bool forceMedian, float* cost);

}   // namespace rnd::rt::binning
