// tri_kernel.inl - the hot loops of TriangleBvh: BVH4 traversal fused with the 4-triangle
// packet test. Included twice by bvh.cpp: once as plain SSE (namespace kern_sse, RT_FMA 0) and
// once compiled for AVX2+FMA (namespace kern_avx2, RT_FMA 1) behind a run-time CPU check, so
// the default build still runs on any x86-64 while FMA-capable CPUs get fused multiply-adds
// (one instruction per slab plane and per dot-product term).
//
// Requires (in the including scope): Node4, TriPacket4, Ray, TriHit, RayPre.

#if RT_FMA
#define RT_MSUB(a, b, c) _mm_fmsub_ps((a), (b), (c))   // a*b - c
#define RT_MADD(a, b, c) _mm_fmadd_ps((a), (b), (c))   // a*b + c
#else
#define RT_MSUB(a, b, c) _mm_sub_ps(_mm_mul_ps((a), (b)), (c))
#define RT_MADD(a, b, c) _mm_add_ps(_mm_mul_ps((a), (b)), (c))
#endif

// Moller-Trumbore on 4 triangles at once (docs/math.md), with the precomputed normal
// N = e1 x e2, s = o - p0 and R = s x d (scalar triple products):
//   det = -d.N,  b1 = e2.R / det,  b2 = -e1.R / det,  t = s.N / det.
// Division-free: comparisons use the sign-adjusted numerators against |det|; only packets with
// a hit pay for the division. Returns the lane mask of hits in (tmin, tmax) and t, b1, b2.
// cullBack: only triangles whose CCW side faces the ray (det > 0) count. In object space
// this is the front side for mirrored instances too (see TriangleBvh::intersect).
inline int intersectPacket(const TriPacket4& p, const __m128 o[3], const __m128 d[3], __m128 tmin, __m128 tmax, __m128& tOut, __m128& uOut,
                           __m128& vOut, bool cullBack = false) {
    const __m128 nx = _mm_load_ps(p.n[0]), ny = _mm_load_ps(p.n[1]), nz = _mm_load_ps(p.n[2]);
    const __m128 sx = _mm_sub_ps(o[0], _mm_load_ps(p.v0[0]));
    const __m128 sy = _mm_sub_ps(o[1], _mm_load_ps(p.v0[1]));
    const __m128 sz = _mm_sub_ps(o[2], _mm_load_ps(p.v0[2]));
    const __m128 negZero = _mm_set1_ps(-0.0f);
    __m128 det = RT_MADD(d[2], nz, RT_MADD(d[1], ny, _mm_mul_ps(d[0], nx)));
    det = _mm_xor_ps(det, negZero);   // det = -d.N
    const __m128 sign = _mm_and_ps(det, negZero);
    const __m128 absDet = _mm_xor_ps(det, sign);
    const __m128 rx = RT_MSUB(sy, d[2], _mm_mul_ps(sz, d[1]));
    const __m128 ry = RT_MSUB(sz, d[0], _mm_mul_ps(sx, d[2]));
    const __m128 rz = RT_MSUB(sx, d[1], _mm_mul_ps(sy, d[0]));
    __m128 U = RT_MADD(_mm_load_ps(p.e2[2]), rz, RT_MADD(_mm_load_ps(p.e2[1]), ry, _mm_mul_ps(_mm_load_ps(p.e2[0]), rx)));
    __m128 V = RT_MADD(_mm_load_ps(p.e1[2]), rz, RT_MADD(_mm_load_ps(p.e1[1]), ry, _mm_mul_ps(_mm_load_ps(p.e1[0]), rx)));
    __m128 T = RT_MADD(sz, nz, RT_MADD(sy, ny, _mm_mul_ps(sx, nx)));
    U = _mm_xor_ps(U, sign);
    V = _mm_xor_ps(V, _mm_xor_ps(sign, negZero));   // b2 = -e1.R / det
    T = _mm_xor_ps(T, sign);
    const __m128 zero = _mm_setzero_ps();
    __m128 ok = cullBack ? _mm_cmpgt_ps(det, zero) : _mm_cmpneq_ps(det, zero);
    ok = _mm_and_ps(ok, _mm_cmpge_ps(U, zero));
    ok = _mm_and_ps(ok, _mm_cmpge_ps(V, zero));
    ok = _mm_and_ps(ok, _mm_cmple_ps(_mm_add_ps(U, V), absDet));
    ok = _mm_and_ps(ok, _mm_cmpgt_ps(T, _mm_mul_ps(absDet, tmin)));
    ok = _mm_and_ps(ok, _mm_cmplt_ps(T, _mm_mul_ps(absDet, tmax)));
    int mask = _mm_movemask_ps(ok);
    if (mask) {
        const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), absDet);
        tOut = _mm_mul_ps(T, inv);
        uOut = _mm_mul_ps(U, inv);
        vOut = _mm_mul_ps(V, inv);
        // Division rounding may land t on a bound: re-check on the divided values.
        mask &= _mm_movemask_ps(_mm_and_ps(_mm_cmplt_ps(tOut, tmax), _mm_cmpgt_ps(tOut, tmin)));
    }
    return mask;
}

#if RT_FMA
// intersectPacket on two packets at once (AVX: lanes 0-3 from a, 4-7 from b). Same
// arithmetic lane by lane, so the same hits. Returns the 8-bit hit mask.
inline __m256 loadPair(const float* x, const float* y) { return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(x)), _mm_load_ps(y), 1); }
// Ties (see closestLaneTies): also *near, the lanes that hit below tmaxW (>= tmax) on the same
// tests. The undivided test then runs with tmaxW (lanes below it are rare beyond those below
// tmax: the common miss costs what it did), and the hit lanes are picked from them after.
template <bool Ties = false>
inline int intersectPacketPair(const TriPacket4& a, const TriPacket4& b, const __m256 o[3], const __m256 d[3], __m256 tmin, __m256 tmax, __m256& tOut,
                               __m256& uOut, __m256& vOut, bool cullBack, __m256 tmaxW = __m256(), int* near = nullptr) {
    const auto ld = loadPair;
    const __m256 nx = ld(a.n[0], b.n[0]), ny = ld(a.n[1], b.n[1]), nz = ld(a.n[2], b.n[2]);
    const __m256 sx = _mm256_sub_ps(o[0], ld(a.v0[0], b.v0[0]));
    const __m256 sy = _mm256_sub_ps(o[1], ld(a.v0[1], b.v0[1]));
    const __m256 sz = _mm256_sub_ps(o[2], ld(a.v0[2], b.v0[2]));
    const __m256 negZero = _mm256_set1_ps(-0.0f);
    __m256 det = _mm256_fmadd_ps(d[2], nz, _mm256_fmadd_ps(d[1], ny, _mm256_mul_ps(d[0], nx)));
    det = _mm256_xor_ps(det, negZero);
    const __m256 sign = _mm256_and_ps(det, negZero);
    const __m256 absDet = _mm256_xor_ps(det, sign);
    const __m256 rx = _mm256_fmsub_ps(sy, d[2], _mm256_mul_ps(sz, d[1]));
    const __m256 ry = _mm256_fmsub_ps(sz, d[0], _mm256_mul_ps(sx, d[2]));
    const __m256 rz = _mm256_fmsub_ps(sx, d[1], _mm256_mul_ps(sy, d[0]));
    __m256 U = _mm256_fmadd_ps(ld(a.e2[2], b.e2[2]), rz, _mm256_fmadd_ps(ld(a.e2[1], b.e2[1]), ry, _mm256_mul_ps(ld(a.e2[0], b.e2[0]), rx)));
    __m256 V = _mm256_fmadd_ps(ld(a.e1[2], b.e1[2]), rz, _mm256_fmadd_ps(ld(a.e1[1], b.e1[1]), ry, _mm256_mul_ps(ld(a.e1[0], b.e1[0]), rx)));
    __m256 T = _mm256_fmadd_ps(sz, nz, _mm256_fmadd_ps(sy, ny, _mm256_mul_ps(sx, nx)));
    U = _mm256_xor_ps(U, sign);
    V = _mm256_xor_ps(V, _mm256_xor_ps(sign, negZero));
    T = _mm256_xor_ps(T, sign);
    const __m256 zero = _mm256_setzero_ps();
    __m256 ok = cullBack ? _mm256_cmp_ps(det, zero, _CMP_GT_OQ) : _mm256_cmp_ps(det, zero, _CMP_NEQ_UQ);
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(U, zero, _CMP_GE_OQ));
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(V, zero, _CMP_GE_OQ));
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(_mm256_add_ps(U, V), absDet, _CMP_LE_OQ));
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(T, _mm256_mul_ps(absDet, tmin), _CMP_GT_OQ));
    if constexpr (Ties) {
        *near = 0;
        const int wide = _mm256_movemask_ps(_mm256_and_ps(ok, _mm256_cmp_ps(T, _mm256_mul_ps(absDet, tmaxW), _CMP_LT_OQ)));
        if (!wide) return 0;
        const __m256 inv = _mm256_div_ps(_mm256_set1_ps(1.0f), absDet);
        tOut = _mm256_mul_ps(T, inv);
        uOut = _mm256_mul_ps(U, inv);
        vOut = _mm256_mul_ps(V, inv);
        const __m256 above = _mm256_cmp_ps(tOut, tmin, _CMP_GT_OQ);
        *near = wide & _mm256_movemask_ps(_mm256_and_ps(_mm256_cmp_ps(tOut, tmaxW, _CMP_LT_OQ), above));
        // The hits: exactly the lanes of the test below with tmax (undivided, then divided).
        return wide & _mm256_movemask_ps(_mm256_and_ps(
                          _mm256_and_ps(_mm256_cmp_ps(T, _mm256_mul_ps(absDet, tmax), _CMP_LT_OQ), _mm256_cmp_ps(tOut, tmax, _CMP_LT_OQ)), above));
    }
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(T, _mm256_mul_ps(absDet, tmax), _CMP_LT_OQ));
    int mask = _mm256_movemask_ps(ok);
    if (mask) {
        const __m256 inv = _mm256_div_ps(_mm256_set1_ps(1.0f), absDet);
        tOut = _mm256_mul_ps(T, inv);
        uOut = _mm256_mul_ps(U, inv);
        vOut = _mm256_mul_ps(V, inv);
        mask &= _mm256_movemask_ps(_mm256_and_ps(_mm256_cmp_ps(tOut, tmax, _CMP_LT_OQ), _mm256_cmp_ps(tOut, tmin, _CMP_GT_OQ)));
    }
    return mask;
}
#endif

// The closest of the hit lanes in `mask` (lane k: triangle ids[k], ids = the packets' ids, 4
// each) if it is closer than tmax: shrinks tmax, fills *hit, returns true.
inline bool closestLane(int mask, const float* ta, const float* ua, const float* va, const uint32_t* ids, float& tmax, TriHit* hit) {
    bool found = false;
    while (mask) {
        const int k = __builtin_ctz(mask);
        mask &= mask - 1;
        if (ta[k] < tmax) {
            tmax = ta[k];
            hit->t = ta[k];
            hit->prim = ids[k];
            hit->b1 = ua[k];
            hit->b2 = va[k];
            found = true;
        }
    }
    return found;
}

// closestLane for a packet's ray, which also sees where the hit kept could depend on the order
// in which leaves are visited (the packet's is not the ray's own). `near`: the lanes that hit
// below widenTmax(tmax) (those below tmax included; intersectPacketPair). Order can matter only
// where another hit lies within widenTmax of the one kept: equal distances, or one a few units
// in the last place away, where the undivided test can take or leave it depending on the
// running tmax. So after the pair, where the running tmax before it or another near lane lies
// within widenTmax of the running tmax, tieT = the running tmax and `bit` is set in `seen`. A
// later closer hit makes it moot: the caller compares tieT with the final tmax. (With the
// packet's boxes tested against widenTmax too, every hit within it is seen; docs/math.md.)
inline bool closestLaneTies(int mask, int near, const float* ta, const float* ua, const float* va, const uint32_t* ids, float& tmax, TriHit* hit,
                            float& tieT, uint64_t& seen, uint64_t bit) {
    const float before = tmax;
    int kept = -1;
    for (int m = mask; m; m &= m - 1) {
        const int k = __builtin_ctz(m);
        if (ta[k] < tmax) {
            tmax = ta[k];
            hit->t = ta[k];
            hit->prim = ids[k];
            hit->b1 = ua[k];
            hit->b2 = va[k];
            kept = k;
        }
    }
    const float w = widenTmax(tmax);
    bool order = kept >= 0 && before <= w;
    for (int m = kept >= 0 ? near & ~(1 << kept) : near; m && !order; m &= m - 1) order = ta[__builtin_ctz(m)] <= w;
    if (order) {
        tieT = tmax;
        seen |= bit;
    }
    return kept >= 0;
}

// Child ordering keys: the entry distance's bit pattern above the child reference. Distances
// here are >= tmin >= 0, and non-negative floats order like their bits, so keys order by
// distance (a negative tmin would only change the visiting order, never the result).
inline uint64_t sortKey(float t, uint32_t ref) {
    uint32_t b;
    std::memcpy(&b, &t, 4);
    return (uint64_t(b) << 32) | ref;
}
inline float keyDistance(uint64_t key) {
    const uint32_t b = uint32_t(key >> 32);
    float t;
    std::memcpy(&t, &b, 4);
    return t;
}
// Sorts key[0..k) (3 <= k <= 8) by decreasing key: sorting networks (compare-exchanges are a
// compare and two conditional moves), k > 4 padded with zero keys to the 19-exchange network
// for 8.
inline void sortFarFirst(uint64_t* key, int k) {
    auto cx = [key](int a, int b) {
        const uint64_t x = key[a], y = key[b];
        key[a] = x > y ? x : y;
        key[b] = x > y ? y : x;
    };
    if (k == 3) {
        cx(0, 1);
        cx(1, 2);
        cx(0, 1);
        return;
    }
    if (k == 4) {
        cx(0, 1);
        cx(2, 3);
        cx(0, 2);
        cx(1, 3);
        cx(1, 2);
        return;
    }
    for (int i = k; i < 8; ++i) key[i] = 0;
    cx(0, 2);
    cx(1, 3);
    cx(4, 6);
    cx(5, 7);
    cx(0, 4);
    cx(1, 5);
    cx(2, 6);
    cx(3, 7);
    cx(0, 1);
    cx(2, 3);
    cx(4, 5);
    cx(6, 7);
    cx(2, 4);
    cx(3, 5);
    cx(1, 4);
    cx(3, 6);
    cx(1, 2);
    cx(3, 4);
    cx(5, 6);
}

// A traversal stack entry: node or leaf reference and its entry distance.
struct StackEntry {
    uint32_t ref;
    float t;
};

// Front-to-back order for a node with two or more hit children: c0, c1 and those left in
// `mask` (entry distances in dist). Pushes all but the nearest onto the stack, far first, and
// returns the nearest. Selects and sorting networks only: no branch depends on the distances.
inline uint32_t pushFarReturnNear(const uint32_t* child, const float* dist, int c0, int c1, int mask, StackEntry* stack, int& sp) {
    const uint64_t k0 = sortKey(dist[c0], child[c0]), k1 = sortKey(dist[c1], child[c1]);
    if (mask == 0) {
        const uint64_t kFar = k0 > k1 ? k0 : k1, kNear = k0 > k1 ? k1 : k0;
        stack[sp++] = {uint32_t(kFar), keyDistance(kFar)};
        return uint32_t(kNear);
    }
    uint64_t key[8];
    int k = 0;
    key[k++] = k0;
    key[k++] = k1;
    while (mask) {
        const int c = __builtin_ctz(mask);
        mask &= mask - 1;
        key[k++] = sortKey(dist[c], child[c]);
    }
    sortFarFirst(key, k);
    for (int i = 0; i < k - 1; ++i) stack[sp++] = {uint32_t(key[i]), keyDistance(key[i])};
    return uint32_t(key[k - 1]);
}

// Triangles in the n lanes from `lane` on (~0u marks an empty lane).
inline uint32_t filledLanes(const uint32_t* lane, int n) {
    uint32_t k = 0;
    for (int i = 0; i < n; ++i) k += lane[i] != ~0u;
    return k;
}

// Front-to-back BVH4 traversal with the packet test inlined (a leaf is 1-7 consecutive
// packets). AnyHit: stop at the first hit and skip the ordering. Returns true on a hit (closest
// hit written to *hit unless AnyHit).
// Count (the cost view): add the nodes visited and the triangle lanes tested to *count; a
// separate instantiation, so the uncounted traversal is unchanged.
template <bool AnyHit, bool Count = false>
inline bool traceTriangles(const Node4* nodes, const TriPacket4* packets, const uint32_t* prims, const float* absMax, const Ray& ray, TriHit* hit,
                           bool cullBack, TraversalCount* count = nullptr) {
    const RayPre pre(ray, absMax);
    const __m128 rx = _mm_set1_ps(pre.rdir[0]), ry = _mm_set1_ps(pre.rdir[1]), rz = _mm_set1_ps(pre.rdir[2]);
    const __m128 orx = _mm_set1_ps(pre.orgRdirNear[0]), ory = _mm_set1_ps(pre.orgRdirNear[1]), orz = _mm_set1_ps(pre.orgRdirNear[2]);
    const int nx = pre.nearX, ny = 2 + pre.nearY, nz = 4 + pre.nearZ;
    const int fx = 1 - pre.nearX, fy = 3 - pre.nearY, fz = 5 - pre.nearZ;
    const __m128 o[3] = {_mm_set1_ps(ray.org.x), _mm_set1_ps(ray.org.y), _mm_set1_ps(ray.org.z)};
    const __m128 d[3] = {_mm_set1_ps(ray.dir.x), _mm_set1_ps(ray.dir.y), _mm_set1_ps(ray.dir.z)};
    const __m128 tminV = _mm_set1_ps(ray.tmin > 0.0f ? ray.tmin : 0.0f);   // see Ray: a negative (or NaN) tmin acts as 0
    // Near (orx...) and far planes: origin terms with the rounding margins folded in (see RayPre).
    const __m128 orxf = _mm_set1_ps(pre.orgRdirFar[0]), oryf = _mm_set1_ps(pre.orgRdirFar[1]), orzf = _mm_set1_ps(pre.orgRdirFar[2]);
    float tmax = ray.tmax;
    __m128 tmaxV = _mm_set1_ps(tmax);
    bool found = false;

    StackEntry stack[256];
    int sp = 0;
    uint32_t cur = 0;
    for (;;) {
        if (!(cur & Node4::kLeafBit)) {
            if constexpr (Count) ++count->nodes;
            const Node4& n = nodes[cur];
            // t = b * rdir - org * rdir (with RayPre's margins); the near/far planes per axis
            // come from the ray's signs.
            const __m128 t0x = RT_MSUB(_mm_load_ps(n.b[nx]), rx, orx), t1x = RT_MSUB(_mm_load_ps(n.b[fx]), rx, orxf);
            const __m128 t0y = RT_MSUB(_mm_load_ps(n.b[ny]), ry, ory), t1y = RT_MSUB(_mm_load_ps(n.b[fy]), ry, oryf);
            const __m128 t0z = RT_MSUB(_mm_load_ps(n.b[nz]), rz, orz), t1z = RT_MSUB(_mm_load_ps(n.b[fz]), rz, orzf);
            const __m128 tn = _mm_max_ps(_mm_max_ps(t0x, t0y), _mm_max_ps(t0z, tminV));
            const __m128 tf = _mm_min_ps(_mm_min_ps(t1x, t1y), _mm_min_ps(t1z, tmaxV));
            int mask = _mm_movemask_ps(_mm_cmple_ps(tn, tf));
            if (mask != 0) {
                alignas(16) float dist[4];
                _mm_store_ps(dist, tn);
                const int c0 = __builtin_ctz(mask);
                mask &= mask - 1;
                if (mask == 0) {
                    cur = n.child[c0];
                    continue;
                }
                if constexpr (AnyHit) {
                    do {
                        int c = __builtin_ctz(mask);
                        mask &= mask - 1;
                        stack[sp++] = {n.child[c], dist[c]};
                    } while (mask);
                    cur = n.child[c0];
                    continue;
                }
                const int c1 = __builtin_ctz(mask);
                mask &= mask - 1;
                cur = pushFarReturnNear(n.child, dist, c0, c1, mask, stack, sp);
                continue;
            }
        } else {
            const TriPacket4* p = packets + ((cur & ~Node4::kLeafBit) >> 3);
            const TriPacket4* end = p + (cur & 7u);
            for (; p != end; ++p) {
                if constexpr (Count) count->prims += filledLanes(prims + 4 * (p - packets), 4);
                __m128 t, u, v;
                int mask = intersectPacket(*p, o, d, tminV, tmaxV, t, u, v, cullBack);
                if (!mask) continue;
                if constexpr (AnyHit) return true;
                alignas(16) float ta[4], ua[4], va[4];
                _mm_store_ps(ta, t);
                _mm_store_ps(ua, u);
                _mm_store_ps(va, v);
                found |= closestLane(mask, ta, ua, va, prims + 4 * (p - packets), tmax, hit);
                tmaxV = _mm_set1_ps(tmax);
            }
        }
        for (;;) {   // pop the next entry that can still hold a closer hit
            if (sp == 0) return found;
            const StackEntry& e = stack[--sp];
            if (AnyHit || e.t <= tmax) {
                cur = e.ref;
                break;
            }
        }
    }
}

#if RT_FMA
// Byte address of bounds plane k (0..5: minx, maxx, miny, ...) of the node at byte offset 0;
// the plane of the node at byte offset ref is then planeBase + ref.
inline const char* planeBase(const char* nodeBytes, int k) { return nodeBytes + offsetof(Node8, b) + size_t(k) * sizeof(Node8::b[0]); }
inline __m256 loadPlane(const char* base, uint32_t ref) { return _mm256_load_ps(reinterpret_cast<const float*>(base + ref)); }

// The same traversal over 8-wide nodes: one AVX compare per node for 8 boxes (BVH8: fewer,
// wider levels); leaf packets tested two at a time (8 lanes). start: the node to begin at (byte
// offset; tracePacket8 continues a ray alone in a subtree).
// Ties (closest hit only): where the hit kept could depend on the visit order (closestLaneTies),
// *tieT = the running tmax (the caller sets it below 0 first).
template <bool AnyHit, bool Count = false, bool Ties = false>
inline bool traceTriangles8(const Node8* nodes, const TriPacket4* packets, const uint32_t* prims, const float* absMax, const Ray& ray, TriHit* hit,
                            bool cullBack, TraversalCount* count = nullptr, uint32_t start = 0, float* tieT = nullptr) {
    const RayPre pre(ray, absMax);
    const __m256 rx = _mm256_set1_ps(pre.rdir[0]), ry = _mm256_set1_ps(pre.rdir[1]), rz = _mm256_set1_ps(pre.rdir[2]);
    const __m256 orx = _mm256_set1_ps(pre.orgRdirNear[0]), ory = _mm256_set1_ps(pre.orgRdirNear[1]), orz = _mm256_set1_ps(pre.orgRdirNear[2]);
    const int nx = pre.nearX, ny = 2 + pre.nearY, nz = 4 + pre.nearZ;
    const int fx = 1 - pre.nearX, fy = 3 - pre.nearY, fz = 5 - pre.nearZ;
    const float tmin = ray.tmin > 0.0f ? ray.tmin : 0.0f;   // see Ray: a negative (or NaN) tmin acts as 0
    const __m256 tmin8 = _mm256_set1_ps(tmin);
    const __m256i tmin8i = _mm256_castps_si256(tmin8);
    const __m256 o8[3] = {_mm256_set1_ps(ray.org.x), _mm256_set1_ps(ray.org.y), _mm256_set1_ps(ray.org.z)};
    const __m256 d8[3] = {_mm256_set1_ps(ray.dir.x), _mm256_set1_ps(ray.dir.y), _mm256_set1_ps(ray.dir.z)};
    // Near and far planes: constants with the rounding margins folded in (see RayPre), which
    // keeps a multiply off each node visit's dependency chain (in-process A/B against scaling
    // tf by 1 + 8 eps: primary rays on 1M triangles 1-3% faster).
    const __m256 orxf = _mm256_set1_ps(pre.orgRdirFar[0]), oryf = _mm256_set1_ps(pre.orgRdirFar[1]), orzf = _mm256_set1_ps(pre.orgRdirFar[2]);
    float tmax = ray.tmax;
    __m256 tmax8 = _mm256_set1_ps(tmax);
    __m256 tmaxW8 = Ties ? _mm256_set1_ps(widenTmax(tmax)) : tmax8;   // (Ties) the near lanes' bound
    bool found = false;
    uint64_t tieSeen = 0;   // (Ties) unused: the caller reads *tieT

    // Inner children are byte offsets into nodes, and each of the six planes this ray reads
    // gets its own base pointer: a plane's address is base + ref, so no arithmetic sits
    // between loading a child reference and loading the child's bounds.
    const char* const nodeBytes = reinterpret_cast<const char*>(nodes);
    const char *pnx = planeBase(nodeBytes, nx), *pfx = planeBase(nodeBytes, fx), *pny = planeBase(nodeBytes, ny);
    const char *pfy = planeBase(nodeBytes, fy), *pnz = planeBase(nodeBytes, nz), *pfz = planeBase(nodeBytes, fz);
    // Opaque to the optimiser: otherwise it folds base + ref back into (nodes + ref) + offset,
    // which puts an add on the chain again.
    asm("" : "+r"(pnx), "+r"(pfx), "+r"(pny), "+r"(pfy), "+r"(pnz), "+r"(pfz));

    StackEntry stack[512];
    int sp = 0;
    uint32_t cur = start;   // the root, or a subtree's node (packets hand single rays over there)
    for (;;) {
        if (!(cur & Node8::kLeafBit)) {
            if constexpr (Count) ++count->nodes;
            const Node8& n = *reinterpret_cast<const Node8*>(nodeBytes + cur);
            const __m256 t0x = _mm256_fmsub_ps(loadPlane(pnx, cur), rx, orx), t1x = _mm256_fmsub_ps(loadPlane(pfx, cur), rx, orxf);
            const __m256 t0y = _mm256_fmsub_ps(loadPlane(pny, cur), ry, ory), t1y = _mm256_fmsub_ps(loadPlane(pfy, cur), ry, oryf);
            const __m256 t0z = _mm256_fmsub_ps(loadPlane(pnz, cur), rz, orz), t1z = _mm256_fmsub_ps(loadPlane(pfz, cur), rz, orzf);
            // Entry/exit distances combined as integers (1-cycle max/min/compare instead of
            // 4-cycle float ones on the node-to-node dependency chain, as Embree does on AVX2).
            // Exact here: tmin >= +0, and non-negative floats order like their bit patterns;
            // a negative exit distance is a negative integer, below any non-negative entry
            // distance, so boxes behind the ray still miss. tn >= tmin >= 0 stays a float.
            const __m256i tn = _mm256_max_epi32(_mm256_max_epi32(_mm256_castps_si256(t0x), _mm256_castps_si256(t0y)),
                                                _mm256_max_epi32(_mm256_castps_si256(t0z), tmin8i));
            const __m256i tf = _mm256_min_epi32(_mm256_min_epi32(_mm256_castps_si256(t1x), _mm256_castps_si256(t1y)),
                                                _mm256_min_epi32(_mm256_castps_si256(t1z), _mm256_castps_si256(Ties ? tmaxW8 : tmax8)));
            // movemask of 8 lanes sets bits 0-7 only: ^ 0xFF is the complement (one op).
            unsigned mask = unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(tn, tf)))) ^ 0xFFu;
            if (mask != 0) {
                alignas(32) float dist[8];
                _mm256_store_si256(reinterpret_cast<__m256i*>(dist), tn);
                const unsigned c0 = unsigned(__builtin_ctz(mask));   // unsigned: no sign extension before the child load
                mask &= mask - 1;
                if (mask == 0) {
                    cur = n.child[c0];
                    continue;
                }
                if constexpr (AnyHit) {
                    do {
                        int c = __builtin_ctz(mask);
                        mask &= mask - 1;
                        stack[sp++] = {n.child[c], dist[c]};
                    } while (mask);
                    cur = n.child[c0];
                    continue;
                }
                const int c1 = __builtin_ctz(mask);
                mask &= mask - 1;
                cur = pushFarReturnNear(n.child, dist, int(c0), c1, int(mask), stack, sp);
                continue;
            }
        } else {
            const TriPacket4* p = packets + ((cur & ~Node8::kLeafBit) >> 3);
            const TriPacket4* end = p + (cur & 7u);
            for (; p < end; p += 2) {   // two packets per AVX test; a last odd one paired with itself
                const bool two = p + 1 < end;
                if constexpr (Count) count->prims += filledLanes(prims + 4 * (p - packets), two ? 8 : 4);
                __m256 t, u, v;
                const int lanes = two ? 0xFF : 0x0F;
                int near = 0;
                const int mask = intersectPacketPair<Ties>(p[0], p[two ? 1 : 0], o8, d8, tmin8, tmax8, t, u, v, cullBack, tmaxW8, &near) & lanes;
                if (!(Ties ? (mask | (near & lanes)) : mask)) continue;
                if constexpr (AnyHit) return true;
                alignas(32) float ta[8], ua[8], va[8];
                _mm256_store_ps(ta, t);
                _mm256_store_ps(ua, u);
                _mm256_store_ps(va, v);
                if constexpr (Ties)
                    found |= closestLaneTies(mask, near & lanes, ta, ua, va, prims + 4 * (p - packets), tmax, hit, *tieT, tieSeen, 1);
                else
                    found |= closestLane(mask, ta, ua, va, prims + 4 * (p - packets), tmax, hit);
                tmax8 = _mm256_set1_ps(tmax);
                if constexpr (Ties) tmaxW8 = _mm256_set1_ps(widenTmax(tmax));
            }
        }
        for (;;) {
            if (sp == 0) return found;
            const StackEntry& e = stack[--sp];
            if (AnyHit || e.t <= (Ties ? widenTmax(tmax) : tmax)) {
                cur = e.ref;
                break;
            }
        }
    }
}

#include "raycast/packet_kernel.inl"
#endif

// Brute force over all triangles with the same packet test (tests).
inline bool bruteForce(const sg::vec3* pos, const uint32_t* idx, size_t triCount, const Ray& ray, TriHit& hit) {
    const __m128 o[3] = {_mm_set1_ps(ray.org.x), _mm_set1_ps(ray.org.y), _mm_set1_ps(ray.org.z)};
    const __m128 d[3] = {_mm_set1_ps(ray.dir.x), _mm_set1_ps(ray.dir.y), _mm_set1_ps(ray.dir.z)};
    bool found = false;
    float tmax = ray.tmax;
    for (size_t t = 0; t < triCount; ++t) {
        TriPacket4 p{};
        setLane(p, 0, pos[idx[3 * t]], pos[idx[3 * t + 1]], pos[idx[3 * t + 2]]);
        __m128 tv, u, v;
        if (intersectPacket(p, o, d, _mm_set1_ps(ray.tmin), _mm_set1_ps(tmax), tv, u, v) & 1) {
            tmax = _mm_cvtss_f32(tv);
            hit.t = tmax;
            hit.prim = uint32_t(t);
            hit.b1 = _mm_cvtss_f32(u);
            hit.b2 = _mm_cvtss_f32(v);
            found = true;
        }
    }
    return found;
}

#undef RT_MSUB
#undef RT_MADD
