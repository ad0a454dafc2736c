// bvh_traverse.inl - the templated BVH4 traversal (included by bvh.h). Ordered front-to-back:
// the 4 child boxes are slab-tested at once with SSE (docs/math.md: overlapping slab intervals
// mean a hit), hit children are sorted by entry distance, the nearest is visited next and the
// others pushed with their entry distance so they can be skipped once a closer hit is known.
#pragma once

#include <emmintrin.h>
#include <xmmintrin.h>
#include <cstddef>
#include <new>

namespace rnd::rt {

inline RayPre::RayPre(const Ray& r, const float* boxAbsMax) {
    // All three axes at once (lane 3 holds tmin / tmax and is ignored): this runs once per ray,
    // which is a few percent of a ray's work on small scenes.
    static_assert(sizeof(Ray) == 32 && offsetof(Ray, dir) == 16, "Ray: org, tmin, dir, tmax packed");
    const __m128 o = _mm_loadu_ps(&r.org.x);
    __m128 d = _mm_loadu_ps(&r.dir.x);
    const __m128 signBit = _mm_set1_ps(-0.0f);
    // A zero component would give 0 * inf = NaN in the slab test: nudge it to +-1e-30 (the slab
    // interval then becomes +-huge, the right answer up to a vanishing angle).
    const __m128 tiny = _mm_cmplt_ps(_mm_andnot_ps(signBit, d), _mm_set1_ps(1e-30f));
    d = _mm_or_ps(_mm_andnot_ps(tiny, d), _mm_and_ps(tiny, _mm_or_ps(_mm_and_ps(d, signBit), _mm_set1_ps(1e-30f))));
    const __m128 rd = _mm_div_ps(_mm_set1_ps(1.0f), d);
    const __m128 ord = _mm_mul_ps(o, rd);
    // E = 2^-20 (|org| + max |b|) |rdir| per axis (see the struct's comment).
    const __m128 absB = boxAbsMax ? _mm_loadu_ps(boxAbsMax) : _mm_setzero_ps();
    const __m128 e = _mm_mul_ps(_mm_mul_ps(_mm_add_ps(_mm_andnot_ps(signBit, o), absB), _mm_andnot_ps(signBit, rd)), _mm_set1_ps(0x1p-20f));
    _mm_store_ps(org, o);
    _mm_store_ps(rdir, rd);
    _mm_store_ps(orgRdir, ord);
    _mm_store_ps(orgRdirNear, _mm_add_ps(ord, e));
    _mm_store_ps(orgRdirFar, _mm_sub_ps(ord, e));
    const int neg = _mm_movemask_ps(d);
    nearX = neg & 1;
    nearY = (neg >> 1) & 1;
    nearZ = (neg >> 2) & 1;
}

// One ray's box test of a Bvh4 node's four children, as Bvh4::traverse and traversePacket do it:
// t = (b - org) * rdir per slab, entry tn = max(near slabs, tmin), exit = min(far slabs, tmax)
// grown by kGrow (rays grazing a box edge are not lost to rounding); a child is reached where
// tn <= exit.
struct Bvh4RayTest {
    __m128 ox, oy, oz, rx, ry, rz, tminV;
    int nx, ny, nz, fx, fy, fz;
    static constexpr float kGrow = 1.0f + 4.0f * std::numeric_limits<float>::epsilon();
    explicit Bvh4RayTest(const Ray& ray) {
        const RayPre pre(ray, nullptr);   // only org and rdir: this test is (b - org) * rdir
        ox = _mm_set1_ps(pre.org[0]), oy = _mm_set1_ps(pre.org[1]), oz = _mm_set1_ps(pre.org[2]);
        rx = _mm_set1_ps(pre.rdir[0]), ry = _mm_set1_ps(pre.rdir[1]), rz = _mm_set1_ps(pre.rdir[2]);
        nx = pre.nearX, ny = 2 + pre.nearY, nz = 4 + pre.nearZ;
        fx = 1 - pre.nearX, fy = 3 - pre.nearY, fz = 5 - pre.nearZ;
        tminV = _mm_set1_ps(ray.tmin);
    }
    // The mask of children reached with the far end at tmax; their entry distances in tn.
    int children(const Node4& n, float tmax, __m128& tn) const {
        const __m128 t0x = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.b[nx]), ox), rx);
        const __m128 t1x = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.b[fx]), ox), rx);
        const __m128 t0y = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.b[ny]), oy), ry);
        const __m128 t1y = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.b[fy]), oy), ry);
        const __m128 t0z = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.b[nz]), oz), rz);
        const __m128 t1z = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.b[fz]), oz), rz);
        tn = _mm_max_ps(_mm_max_ps(t0x, t0y), _mm_max_ps(t0z, tminV));
        __m128 tf = _mm_min_ps(_mm_min_ps(t1x, t1y), _mm_min_ps(t1z, _mm_set1_ps(tmax)));
        tf = _mm_mul_ps(tf, _mm_set1_ps(kGrow));
        return _mm_movemask_ps(_mm_cmple_ps(tn, tf));
    }
};

// Bvh4RayTest for a packet's rays, lane i holding ray i: each lane makes the operations
// Bvh4RayTest makes for its ray, in the same order, so a child is reached by exactly the rays
// that reach it one by one. A node's child is tested against a group of rays (not a ray against
// the four children): setting the rays up, skipping empty children and making the reach masks
// then cost a fraction as much. The rays are kept lane by lane in arrays, so a test can take
// four (SSE, `reaches`), eight (AVX2) or sixteen (AVX-512) of them at once (bvh4Reach picks the
// widest the CPU has). Where a group's active rays share their direction signs (coherent
// packets, nearly always), a child's near and far bounds are chosen once for the group;
// otherwise per lane.
struct Bvh4PacketTest {
    static constexpr int kGroups = kMaxPacket / 4;
    // Per lane: origin, reciprocal of the (nudged) direction, tmin, tmax. Lanes of inactive rays
    // within a block of 16 that holds an active one repeat an active ray (so every lane a wide
    // test reads is set); a lane's direction is negative on an axis where its reciprocal's sign
    // bit is set (1 / v keeps v's sign, infinities and NaN included).
    alignas(64) float o[3][kMaxPacket];
    alignas(64) float r[3][kMaxPacket];
    alignas(64) float tmin[kMaxPacket];
    alignas(64) float tmax[kMaxPacket];
    // Bit a: negative on axis a, where every active lane of the group agrees; -1 otherwise. Per
    // group of 4, 8 and 16 lanes (read only for groups with an active ray).
    int8_t signs4[kGroups], signs8[kMaxPacket / 8], signs16[kMaxPacket / 16];

    Bvh4PacketTest(const Ray* rays, uint64_t active) {
        static_assert(sizeof(Ray) == 32 && offsetof(Ray, dir) == 16, "Ray: org, tmin, dir, tmax packed");
        const __m128 signBit = _mm_set1_ps(-0.0f);
        for (uint64_t blocks = active; blocks;) {   // the blocks of 16 lanes that hold an active ray
            const int b = __builtin_ctzll(blocks) >> 4;
            blocks &= ~(uint64_t(0xFFFF) << (16 * b));
            const unsigned lanes16 = unsigned(active >> (16 * b)) & 0xFFFFu;
            const int from = 16 * b + __builtin_ctz(lanes16);   // an active ray, for groups without one
            int merged[3] = {-2, -2, -2};                       // the two groups of 8, then 16 (-2: none active yet)
            for (int k = 4 * b; k < 4 * b + 4; ++k) {
                const unsigned lanes = unsigned(active >> (4 * k)) & 15u;
                const int firstLane = lanes ? 4 * k + __builtin_ctz(lanes) : from;
                __m128 ov[4], d[4];
                for (int l = 0; l < 4; ++l) {   // inactive lanes repeat an active ray
                    const Ray& ray = rays[((lanes >> l) & 1) ? 4 * k + l : firstLane];
                    ov[l] = _mm_loadu_ps(&ray.org.x);
                    d[l] = _mm_loadu_ps(&ray.dir.x);
                }
                _MM_TRANSPOSE4_PS(ov[0], ov[1], ov[2], ov[3]);   // ox, oy, oz, tmin
                _MM_TRANSPOSE4_PS(d[0], d[1], d[2], d[3]);       // dx, dy, dz, tmax
                for (int a = 0; a < 3; ++a) _mm_store_ps(&o[a][4 * k], ov[a]);
                _mm_store_ps(&tmin[4 * k], ov[3]);
                _mm_store_ps(&tmax[4 * k], d[3]);
                int signs = 0;
                bool mixed = false;
                for (int a = 0; a < 3; ++a) {   // RayPre's nudge of a zero component, then 1 / d
                    __m128 v = d[a];
                    const __m128 tiny = _mm_cmplt_ps(_mm_andnot_ps(signBit, v), _mm_set1_ps(1e-30f));
                    v = _mm_or_ps(_mm_andnot_ps(tiny, v), _mm_and_ps(tiny, _mm_or_ps(_mm_and_ps(v, signBit), _mm_set1_ps(1e-30f))));
                    _mm_store_ps(&r[a][4 * k], _mm_div_ps(_mm_set1_ps(1.0f), v));
                    const unsigned n = unsigned(_mm_movemask_ps(v)) & lanes;
                    if (n == lanes)
                        signs |= 1 << a;
                    else if (n != 0)
                        mixed = true;
                }
                signs4[k] = int8_t(mixed ? -1 : signs);
                if (!lanes) continue;   // (its lanes are copies: no say in the wider groups' signs)
                for (int* m : {&merged[(k >> 1) & 1], &merged[2]}) *m = *m == -2 ? signs4[k] : *m == signs4[k] ? *m : -1;
            }
            signs8[2 * b] = int8_t(merged[0] == -2 ? 0 : merged[0]);
            signs8[2 * b + 1] = int8_t(merged[1] == -2 ? 0 : merged[1]);
            signs16[b] = int8_t(merged[2]);
        }
    }

    // The packet as a whole, for mayReach: per axis the bounds of its rays' origins and
    // reciprocal directions and the direction signs they share, its smallest tmin and largest
    // tmax, each in every lane (made by setWhole on the first node below the root: a packet
    // that meets only the root's leaves never needs them). `whole` is false where the rays do
    // not share their signs or some value is not finite (a NaN can drop out of SSE's min and
    // max, in a ray's own test too, so no bound would hold for it); then every child is tested
    // group by group.
    bool whole = false;
    int wholeSigns = 0;
    __m128 olo[3], ohi[3], rlo[3], rhi[3], tminLo, tmaxHi;

    void setWhole(uint64_t active) {
        const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
        __m128 lo[3] = {inf, inf, inf}, hi[3], rl[3] = {inf, inf, inf}, rh[3], tl = inf, th = _mm_sub_ps(_mm_setzero_ps(), inf);
        for (int a = 0; a < 3; ++a) hi[a] = rh[a] = th;
        // Sums of every origin and reciprocal: NaN where any is NaN or infinite (SSE's min and
        // max may drop a NaN, an add never does); the limits are checked on the bounds below.
        __m128 sum = _mm_setzero_ps(), nanT = _mm_setzero_ps();
        int signs = -1;
        for (int k = 0; k < kGroups; ++k) {
            if (!((active >> (4 * k)) & 15u)) continue;
            if (signs4[k] < 0 || (signs >= 0 && signs4[k] != signs)) return;
            signs = signs4[k];
            for (int a = 0; a < 3; ++a) {
                const __m128 ov = _mm_load_ps(&o[a][4 * k]), rv = _mm_load_ps(&r[a][4 * k]);
                lo[a] = _mm_min_ps(lo[a], ov), hi[a] = _mm_max_ps(hi[a], ov);
                rl[a] = _mm_min_ps(rl[a], rv), rh[a] = _mm_max_ps(rh[a], rv);
                sum = _mm_add_ps(sum, _mm_add_ps(ov, rv));
            }
            const __m128 qmin = _mm_load_ps(&tmin[4 * k]), qmax = _mm_load_ps(&tmax[4 * k]);
            tl = _mm_min_ps(tl, qmin), th = _mm_max_ps(th, qmax);
            nanT = _mm_or_ps(nanT, _mm_cmpunord_ps(qmin, qmax));
        }
        if (signs < 0 || _mm_movemask_ps(_mm_or_ps(nanT, _mm_cmpunord_ps(sum, sum)))) return;
        auto all = [](__m128 v, bool max) {   // the lanes' min or max, in every lane
            const __m128 s = _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1));
            v = max ? _mm_max_ps(v, s) : _mm_min_ps(v, s);
            const __m128 t = _mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 0, 3, 2));
            return max ? _mm_max_ps(v, t) : _mm_min_ps(v, t);
        };
        // Origins within 1e30 and reciprocals of at least 1e-30 (of one sign per axis): no
        // overflow to NaN in the sums above and no 0 x inf in mayReach's products.
        __m128 outside = _mm_setzero_ps();
        for (int a = 0; a < 3; ++a) {
            lo[a] = all(lo[a], false), hi[a] = all(hi[a], true);
            rl[a] = all(rl[a], false), rh[a] = all(rh[a], true);
            const __m128 rMin = (signs >> a) & 1 ? _mm_sub_ps(_mm_setzero_ps(), rh[a]) : rl[a];   // the smallest |r|
            outside = _mm_or_ps(outside, _mm_or_ps(_mm_cmplt_ps(lo[a], _mm_set1_ps(-1e30f)), _mm_cmpgt_ps(hi[a], _mm_set1_ps(1e30f))));
            outside = _mm_or_ps(outside, _mm_cmplt_ps(rMin, _mm_set1_ps(1e-30f)));
        }
        if (_mm_movemask_ps(outside)) return;
        for (int a = 0; a < 3; ++a) olo[a] = lo[a], ohi[a] = hi[a], rlo[a] = rl[a], rhi[a] = rh[a];
        tminLo = all(tl, false), tmaxHi = all(th, true);
        wholeSigns = signs;
        whole = true;
    }

    // The children of n that some ray of the packet may reach (bit c), with interval arithmetic
    // over the packet's bounds (whole must be set): for a ray with origin o in [olo, ohi] and
    // reciprocal r in [rlo, rhi] (one sign), its computed slab distance fl(fl(b - o) r) lies
    // within the bounds of the extreme corners, since rounding is monotonic (a near plane's
    // lowest at the farthest origin, a far plane's highest at the nearest); so a child whose
    // highest exit lies below its lowest entry is reached by no ray's own test.
    int mayReach(const Node4& n) const {
        __m128 tn = tminLo, tf = tmaxHi;
        for (int a = 0; a < 3; ++a) {
            const bool neg = (wholeSigns >> a) & 1;
            const __m128 xn = _mm_sub_ps(_mm_load_ps(n.b[2 * a + (neg ? 1 : 0)]), neg ? olo[a] : ohi[a]);
            const __m128 xf = _mm_sub_ps(_mm_load_ps(n.b[2 * a + (neg ? 0 : 1)]), neg ? ohi[a] : olo[a]);
            tn = _mm_max_ps(tn, _mm_min_ps(_mm_mul_ps(xn, rlo[a]), _mm_mul_ps(xn, rhi[a])));
            tf = _mm_min_ps(tf, _mm_max_ps(_mm_mul_ps(xf, rlo[a]), _mm_mul_ps(xf, rhi[a])));
        }
        tf = _mm_mul_ps(tf, _mm_set1_ps(Bvh4RayTest::kGrow));
        return _mm_movemask_ps(_mm_cmple_ps(tn, tf));
    }

    // The lanes of group k that reach child c of n (bit l: ray 4k + l); the entry distances in tn.
    int reaches(const Node4& n, int c, int k, __m128& tn) const {
        const __m128 ox = _mm_load_ps(&o[0][4 * k]), oy = _mm_load_ps(&o[1][4 * k]), oz = _mm_load_ps(&o[2][4 * k]);
        const __m128 rx = _mm_load_ps(&r[0][4 * k]), ry = _mm_load_ps(&r[1][4 * k]), rz = _mm_load_ps(&r[2][4 * k]);
        __m128 t0x, t1x, t0y, t1y, t0z, t1z;
        const int signs = signs4[k];
        if (signs >= 0) {
            const int nx = signs & 1, ny = 2 + ((signs >> 1) & 1), nz = 4 + ((signs >> 2) & 1);
            t0x = _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(n.b[nx][c]), ox), rx);
            t1x = _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(n.b[1 - (nx & 1)][c]), ox), rx);
            t0y = _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(n.b[ny][c]), oy), ry);
            t1y = _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(n.b[5 - ny][c]), oy), ry);
            t0z = _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(n.b[nz][c]), oz), rz);
            t1z = _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(n.b[9 - nz][c]), oz), rz);
        } else {
            auto slab = [&](int axis, __m128 ov, __m128 rv, __m128& near, __m128& far) {
                const __m128 neg = _mm_castsi128_ps(_mm_srai_epi32(_mm_castps_si128(rv), 31));
                const __m128 lo = _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(n.b[2 * axis][c]), ov), rv);
                const __m128 hi = _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(n.b[2 * axis + 1][c]), ov), rv);
                near = _mm_or_ps(_mm_and_ps(neg, hi), _mm_andnot_ps(neg, lo));
                far = _mm_or_ps(_mm_and_ps(neg, lo), _mm_andnot_ps(neg, hi));
            };
            slab(0, ox, rx, t0x, t1x);
            slab(1, oy, ry, t0y, t1y);
            slab(2, oz, rz, t0z, t1z);
        }
        tn = _mm_max_ps(_mm_max_ps(t0x, t0y), _mm_max_ps(t0z, _mm_load_ps(&tmin[4 * k])));
        __m128 tf = _mm_min_ps(_mm_min_ps(t1x, t1y), _mm_min_ps(t1z, _mm_load_ps(&tmax[4 * k])));
        tf = _mm_mul_ps(tf, _mm_set1_ps(Bvh4RayTest::kGrow));
        return _mm_movemask_ps(_mm_cmple_ps(tn, tf));
    }

    // reach[c]: the rays of `rays` that reach child c of n, for each c in `may` that is not
    // empty (the others keep 0); lead[c]: ray `first`'s entry distance there (set where that ray
    // reaches c). Four lanes per test.
    void reachChildren4(const Node4& n, uint64_t rays, int may, uint64_t reach[4], float lead[4], int first) const {
        for (int c = 0; c < 4; ++c) {
            if (!((may >> c) & 1) || n.child[c] == Node4::kEmpty) continue;   // (empty bounds: never reached)
            for (uint64_t groups = rays; groups;) {
                const int k = __builtin_ctzll(groups) >> 2;
                groups &= ~(uint64_t(15) << (4 * k));
                __m128 tn;
                reach[c] |= uint64_t(reaches(n, c, k, tn)) << (4 * k);
                if (k == first >> 2) {
                    alignas(16) float t[4];
                    _mm_store_ps(t, tn);
                    lead[c] = t[first & 3];
                }
            }
            reach[c] &= rays;
        }
    }
};

// Bvh4PacketTest::reachChildren4 with the widest test this CPU has: 16 lanes per test with
// AVX-512, 8 with AVX2, else 4 (bvh_trace.cpp); lane by lane the same operations.
void bvh4Reach(const Bvh4PacketTest& test, const Node4& n, uint64_t rays, int may, uint64_t reach[4], float lead[4], int first);

template <bool AnyHit, bool Count, class LeafFn>
void Bvh4::traverse(const Ray& ray, float& tmax, LeafFn&& leaf, uint32_t* visited) const {
    if (m_nodes.empty()) return;
    const Bvh4RayTest test(ray);

    struct Entry {
        uint32_t ref;
        float t;
    };
    Entry stack[256];
    int sp = 0;
    uint32_t cur = 0;   // root: node 0
    for (;;) {
        if (!(cur & Node4::kLeafBit)) {
            if constexpr (Count) ++*visited;
            const Node4& n = m_nodes[cur];
            __m128 tn;
            int mask = test.children(n, tmax, tn);
            if (mask != 0) {
                alignas(16) float d[4];
                _mm_store_ps(d, tn);
                int c0 = __builtin_ctz(mask);
                mask &= mask - 1;
                if (mask == 0) {
                    cur = n.child[c0];
                    continue;
                }
                if constexpr (AnyHit) {   // no ordering needed: push the rest as they come
                    while (mask) {
                        int c = __builtin_ctz(mask);
                        mask &= mask - 1;
                        stack[sp++] = {n.child[c], d[c]};
                    }
                    cur = n.child[c0];
                    continue;
                }
                int c1 = __builtin_ctz(mask);
                mask &= mask - 1;
                if (mask == 0) {
                    if (d[c0] <= d[c1]) {
                        stack[sp++] = {n.child[c1], d[c1]};
                        cur = n.child[c0];
                    } else {
                        stack[sp++] = {n.child[c0], d[c0]};
                        cur = n.child[c1];
                    }
                    continue;
                }
                // 3 or 4 hits: sort by entry distance (far first on the stack).
                Entry e[4];
                int k = 0;
                e[k++] = {n.child[c0], d[c0]};
                e[k++] = {n.child[c1], d[c1]};
                while (mask) {
                    int c = __builtin_ctz(mask);
                    mask &= mask - 1;
                    e[k++] = {n.child[c], d[c]};
                }
                for (int i = 1; i < k; ++i) {   // insertion sort, descending t
                    Entry x = e[i];
                    int j = i - 1;
                    while (j >= 0 && e[j].t < x.t) {
                        e[j + 1] = e[j];
                        --j;
                    }
                    e[j + 1] = x;
                }
                for (int i = 0; i < k - 1; ++i) stack[sp++] = e[i];
                cur = e[k - 1].ref;
                continue;
            }
        } else {
            uint32_t first = (cur & ~Node4::kLeafBit) >> 3, count = cur & 7u;
            if (leaf(first, count, tmax)) return;
        }
        // Pop the next entry that can still hold a closer hit.
        for (;;) {
            if (sp == 0) return;
            const Entry& e = stack[--sp];
            if (e.t <= tmax) {
                cur = e.ref;
                break;
            }
        }
    }
}

template <class LeafFn>
void Bvh4::traversePacket(const Ray* rays, uint64_t active, LeafFn&& leaf, const uint64_t* live) const {
    if (m_nodes.empty() || !active) return;
    Bvh4PacketTest test(rays, active);
    bool wholeSet = false;
    struct Entry {
        uint32_t ref;
        uint64_t rays;
    };
    Entry stack[256];
    int sp = 0;
    uint32_t cur = 0;   // root: node 0
    uint64_t curRays = active;
    for (;;) {
        if (live) curRays &= *live;
        if (!curRays) {   // every ray of this entry is done
        } else if (!(cur & Node4::kLeafBit)) {
            const Node4& n = m_nodes[cur];
            uint64_t reach[4] = {0, 0, 0, 0};
            alignas(16) float lead[4];   // entry distances for the packet's first ray here
            const int first = __builtin_ctzll(curRays);
            // Below the root (whose children most packets reach), children that no ray can reach
            // are found for the whole packet at once first.
            int may = 15;
            if (cur != 0) {
                if (!wholeSet) test.setWhole(active);
                wholeSet = true;
                if (test.whole) may = test.mayReach(n);
            }
            bvh4Reach(test, n, curRays, may, reach, lead, first);
            // Children reached, nearest (for the first ray) visited first.
            Entry e[4];
            float key[4];
            int k = 0;
            for (int c = 0; c < 4; ++c)
                if (reach[c]) {
                    key[k] = (reach[c] >> first) & 1 ? lead[c] : std::numeric_limits<float>::infinity();
                    e[k++] = {n.child[c], reach[c]};
                }
            for (int i = 1; i < k; ++i)   // insertion sort, descending key (far first on the stack)
                for (int j = i; j > 0 && key[j - 1] < key[j]; --j) {
                    std::swap(key[j - 1], key[j]);
                    std::swap(e[j - 1], e[j]);
                }
            if (k > 0) {
                for (int i = 0; i < k - 1; ++i) stack[sp++] = e[i];
                cur = e[k - 1].ref;
                curRays = e[k - 1].rays;
                continue;
            }
        } else {
            const uint32_t first = (cur & ~Node4::kLeafBit) >> 3, count = cur & 7u;
            if (leaf(first, count, curRays)) return;
        }
        if (sp == 0) return;
        --sp;
        cur = stack[sp].ref;
        curRays = stack[sp].rays;
    }
}

}   // namespace rnd::rt
