// bvh_binning.cpp - the BVH builder's binned SAH split (binning, SAH sweep, partition, median
// split; Wald 2007 / Embree's binned builder) and the bounds of a range of primitive references.
#include "raycast/bvh_binning.h"

#include <algorithm>

namespace rnd::rt::binning {

// Bounds and centroid bounds of refs[begin, end).
void computeBounds(const PrimRef* refs, Range& r) {
    Box b, c;
    for (uint32_t i = r.begin; i < r.end; ++i) {
        b.extend(refs[i].lo, refs[i].hi);
        __m128 cc = refs[i].center2();
        c.extend(cc, cc);
    }
    // lo.w contains ids: clear it so bounds stay meaningful in xyz (w is ignored anyway).
    r.bounds = b;
    r.centroids = c;
}

// The phases of splitRange (binning, SAH sweep, partition, median split) are always_inline:
// splitRange runs for nearly every node of every build, so it compiles to one function as
// before and the build time does not change by splitting it up.

// Per axis and bin: primitive bounds (lo/hi side by side: one address per update) and counts.
struct Bin {
    __m128 lo, hi;
};
using AxisBins = Bin[3][kMaxBins];
using AxisCounts = uint32_t[3][kMaxBins];

// The best binned SAH split: primitives in bins [0, pos) of `axis` go left. axis < 0: none.
struct SahSplit {
    int axis = -1, pos = 0;
    float cost = std::numeric_limits<float>::infinity();
};

// Binning: on return bins[a][0, nbins) / counts[a][0, nbins) hold, per axis a, the bounds and
// number of the primitives of r whose centroid falls into each bin (scale: bins per unit of 2 x
// centroid, 0 on a flat axis). Only [0, nbins) is written; the rest stays uninitialised.
// Neighbouring primitives usually fall into the same bins, so each update waits for the
// previous one's store: big ranges bin even and odd primitives into two sets (two independent
// dependency chains) merged afterwards.
[[gnu::always_inline]] inline void binPrimitives(const PrimRef* refs, const Range& r, int nbins, const float* scale, AxisBins& bins,
                                                 AxisCounts& counts) {
    Bin bins1[3][kMaxBins];
    uint32_t counts1[3][kMaxBins];
    const bool twoSets = r.count() >= 256;
    const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity()), ninf = _mm_set1_ps(-std::numeric_limits<float>::infinity());
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < nbins; ++b) {
            bins[a][b].lo = inf;
            bins[a][b].hi = ninf;
            counts[a][b] = 0;
            if (twoSets) {
                bins1[a][b].lo = inf;
                bins1[a][b].hi = ninf;
                counts1[a][b] = 0;
            }
        }
    const __m128 sc = _mm_setr_ps(scale[0], scale[1], scale[2], 0.0f);
    const __m128 cm = r.centroids.lo;
    const __m128 zero = _mm_setzero_ps(), maxBin = _mm_set1_ps(float(nbins - 1));
    // Bin index per axis, clamped in float before the conversion (max first: NaN -> 0).
    auto binOf = [&](const PrimRef& p) {
        return _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_sub_ps(p.center2(), cm), sc), zero), maxBin));
    };
    auto add = [](Bin(*set)[kMaxBins], uint32_t(*cnt)[kMaxBins], const PrimRef& p, const int* b) {
        for (int a = 0; a < 3; ++a) {
            Bin& x = set[a][b[a]];
            x.lo = _mm_min_ps(x.lo, p.lo);
            x.hi = _mm_max_ps(x.hi, p.hi);
            ++cnt[a][b[a]];
        }
    };
    uint32_t i = r.begin;
    if (twoSets) {
        for (; i + 1 < r.end; i += 2) {
            alignas(16) int b0[4], b1[4];
            _mm_store_si128(reinterpret_cast<__m128i*>(b0), binOf(refs[i]));
            _mm_store_si128(reinterpret_cast<__m128i*>(b1), binOf(refs[i + 1]));
            add(bins, counts, refs[i], b0);
            add(bins1, counts1, refs[i + 1], b1);
        }
    }
    for (; i < r.end; ++i) {
        alignas(16) int b0[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(b0), binOf(refs[i]));
        add(bins, counts, refs[i], b0);
    }
    if (twoSets)
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < nbins; ++b) {
                bins[a][b].lo = _mm_min_ps(bins[a][b].lo, bins1[a][b].lo);
                bins[a][b].hi = _mm_max_ps(bins[a][b].hi, bins1[a][b].hi);
                counts[a][b] += counts1[a][b];
            }
}

// SAH sweep over the filled bins: the cheapest split with primitives on both sides, over the
// axes of non-zero centroid extent (the first of equal costs wins: axis order, then bin order).
[[gnu::always_inline]] inline SahSplit bestSahSplit(const AxisBins& bins, const AxisCounts& counts, int nbins, const float* ext, int leafSize) {
    SahSplit best;
    auto halfArea = [](__m128 lo, __m128 hi) {
        __m128 e = _mm_max_ps(_mm_sub_ps(hi, lo), _mm_setzero_ps());
        __m128 e2 = _mm_shuffle_ps(e, e, _MM_SHUFFLE(3, 0, 2, 1));   // (y, z, x)
        __m128 m = _mm_mul_ps(e, e2);                                // (xy, yz, zx, w*w)
        // xy + yz + zx in registers: ((xy + yz) + zx), the same order as before.
        __m128 s01 = _mm_add_ss(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 1, 1, 1)));
        return _mm_cvtss_f32(_mm_add_ss(s01, _mm_movehl_ps(m, m)));
    };
    // Leaf blocks: a shift for the usual power-of-two leaf sizes (an integer division per
    // candidate split otherwise costs more than the rest of the sweep).
    const int leafShift = leafSize == 4 ? 2 : leafSize == 2 ? 1 : leafSize == 1 ? 0 : -1;
    auto blocksOf = [&](uint32_t c) { return leafShift >= 0 ? float((c + uint32_t(leafSize) - 1) >> leafShift) : float(blocks(c, leafSize)); };
    for (int a = 0; a < 3; ++a) {
        if (!(ext[a] > 0)) continue;
        float rightArea[kMaxBins];
        uint32_t rightCount[kMaxBins];
        __m128 lo = _mm_set1_ps(std::numeric_limits<float>::infinity()), hi = _mm_set1_ps(-std::numeric_limits<float>::infinity());
        uint32_t cnt = 0;
        for (int i = nbins - 1; i > 0; --i) {
            lo = _mm_min_ps(lo, bins[a][i].lo);
            hi = _mm_max_ps(hi, bins[a][i].hi);
            cnt += counts[a][i];
            rightArea[i] = halfArea(lo, hi);
            rightCount[i] = cnt;
        }
        lo = _mm_set1_ps(std::numeric_limits<float>::infinity());
        hi = _mm_set1_ps(-std::numeric_limits<float>::infinity());
        cnt = 0;
        for (int i = 1; i < nbins; ++i) {
            lo = _mm_min_ps(lo, bins[a][i - 1].lo);
            hi = _mm_max_ps(hi, bins[a][i - 1].hi);
            cnt += counts[a][i - 1];
            if (cnt == 0 || rightCount[i] == 0) continue;
            float cost = halfArea(lo, hi) * blocksOf(cnt) + rightArea[i] * blocksOf(rightCount[i]);
            if (cost < best.cost) {
                best.cost = cost;
                best.axis = a;
                best.pos = i;
            }
        }
    }
    return best;
}

// Partition of refs[r.begin, r.end) at split s (cm: the centroid minimum on s.axis, scale: its
// bin scale): returns mid such that [r.begin, mid) are the primitives binned below s.pos and
// [mid, r.end) the others, and gathers the two sides' centroid bounds into lc / rc (their
// primitive bounds come from the bins), so no further pass over the primitives is needed.
// Bin index < pos, i.e. trunc(clamp((c - cm) * s, 0, nbins - 1)) < pos, is (c - cm) * s < pos
// for the finite centroids here (the same float operations as the binning, so both agree
// exactly); one SIMD compare, lane a. Two-pointer (Hoare) partition.
[[gnu::always_inline]] inline uint32_t partitionAtBin(PrimRef* refs, const Range& r, const SahSplit& s, float cm, float scale, Box& lc, Box& rc) {
    const __m128 cmv = _mm_set1_ps(cm), sv = _mm_set1_ps(scale), posv = _mm_set1_ps(float(s.pos));
    const int laneBit = 1 << s.axis;
    auto goesLeft = [&](const PrimRef& p) {
        return (_mm_movemask_ps(_mm_cmplt_ps(_mm_mul_ps(_mm_sub_ps(p.center2(), cmv), sv), posv)) & laneBit) != 0;
    };
    PrimRef* lo = refs + r.begin;
    PrimRef* hi = refs + r.end;
    for (;;) {
        while (lo < hi && goesLeft(*lo)) {
            __m128 c = lo->center2();
            lc.extend(c, c);
            ++lo;
        }
        while (lo < hi && !goesLeft(*(hi - 1))) {
            --hi;
            __m128 c = hi->center2();
            rc.extend(c, c);
        }
        if (lo >= hi) break;
        --hi;
        std::swap(*lo, *hi);
        __m128 c0 = lo->center2(), c1 = hi->center2();
        lc.extend(c0, c0);
        rc.extend(c1, c1);
        ++lo;
    }
    return uint32_t(lo - refs);
}

// Object median: reorders refs[r.begin, r.end) so that the lower half by centroid along the
// widest centroid axis comes first (order kept when all centroids coincide); returns the middle.
[[gnu::always_inline]] inline uint32_t medianSplit(PrimRef* refs, const Range& r, const float* ext) {
    int a = ext[0] >= ext[1] ? (ext[0] >= ext[2] ? 0 : 2) : (ext[1] >= ext[2] ? 1 : 2);
    const uint32_t mid = r.begin + r.count() / 2;
    if (ext[a] > 0)
        std::nth_element(refs + r.begin, refs + mid, refs + r.end, [a](const PrimRef& x, const PrimRef& y) {
            alignas(16) float cx[4], cy[4];
            _mm_store_ps(cx, x.center2());
            _mm_store_ps(cy, y.center2());
            return cx[a] < cy[a];
        });
    return mid;
}

// Splits r into l and rr (binned SAH, or an object median for tiny ranges); *cost gets the
// split's SAH cost sum(halfArea(child) * blocks(child)), in the units of a leaf's cost
// halfArea * blocks (blocks of leafSize primitives: one packet test each).
void splitRange(PrimRef* refs, const Range& r, Range& l, Range& rr, int nbins, int leafSize, bool forceMedian, float* cost) {
    const uint32_t n = r.count();
    alignas(16) float cmin[4], cmax[4];
    _mm_store_ps(cmin, r.centroids.lo);
    _mm_store_ps(cmax, r.centroids.hi);
    float ext[3] = {cmax[0] - cmin[0], cmax[1] - cmin[1], cmax[2] - cmin[2]};

    // Few primitives need few bins: the per-split fixed cost (clearing and sweeping the bins)
    // otherwise dominates the many small splits near the leaves.
    if (int(n) < nbins) nbins = std::max(4, int(n));
    // Big ranges get twice the bins (up to 32): the few top-level splits decide most of the
    // tree's quality (1M triangles: shadow rays ~5% faster, build ~4% slower).
    if (n >= 1024) nbins = std::min(2 * nbins, kMaxBins);
    // Tiny ranges (a few leaves' worth): an object-median split on the widest centroid axis
    // costs a fraction of a binned SAH evaluation and loses little quality this close to the
    // leaves; the many splits down here otherwise dominate the build time.
    if (n <= uint32_t(2 * leafSize)) forceMedian = true;

    SahSplit best;
    float scale[3];
    AxisBins bins;
    AxisCounts counts;
    if (!forceMedian) {
        for (int a = 0; a < 3; ++a) scale[a] = ext[a] > 0 ? float(nbins) * 0.99999f / ext[a] : 0.0f;
        binPrimitives(refs, r, nbins, scale, bins, counts);
        best = bestSahSplit(bins, counts, nbins, ext, leafSize);
    }

    uint32_t mid;
    if (best.axis >= 0) {
        const int a = best.axis;
        Box lc, rc;
        mid = partitionAtBin(refs, r, best, cmin[a], scale[a], lc, rc);
        if (mid != r.begin && mid != r.end) {
            // Both sides non-empty: bounds from the bins, centroid bounds from the partition.
            l = Range();
            rr = Range();
            l.begin = r.begin;
            l.end = mid;
            rr.begin = mid;
            rr.end = r.end;
            for (int i = 0; i < best.pos; ++i) l.bounds.extend(bins[a][i].lo, bins[a][i].hi);
            for (int i = best.pos; i < nbins; ++i) rr.bounds.extend(bins[a][i].lo, bins[a][i].hi);
            l.centroids = lc;
            rr.centroids = rc;
            *cost = best.cost;
            return;
        }
        mid = r.begin + n / 2;   // numerical corner case: fall through to bounds by a pass
    } else {
        // All centroids coincide (or median forced): split by order along the widest axis.
        mid = medianSplit(refs, r, ext);
    }
    l.begin = r.begin;
    l.end = mid;
    rr.begin = mid;
    rr.end = r.end;
    computeBounds(refs, l);
    computeBounds(refs, rr);
    *cost = l.bounds.halfArea() * float(blocks(l.count(), leafSize)) + rr.bounds.halfArea() * float(blocks(rr.count(), leafSize));
}

}   // namespace rnd::rt::binning
