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

// --- packets of coherent rays (BVH8, AVX2) ----------------------------------------------------
//
// Up to kMaxPacket rays whose directions share their signs (camera rays of a pixel tile, shadow
// rays of neighbouring pixels to one light) traverse the tree together: an inner node tests its
// 8 child boxes once against the whole packet with interval arithmetic (one box test for all
// rays, about twice a single ray's work), and only at a leaf is each ray tested on its own: its
// box test with the ray's current tmax, then the leaf's triangles exactly as traceTriangles8
// tests them (the same packet-pair kernel, the ray broadcast), so every hit is bit for bit the
// single-ray hit. Only the order in which leaves are visited can differ from the single ray's,
// which matters only for exact ties of t between triangles (the first found is kept, as there):
// a ray that meets a triangle at exactly its running tmax is reported (tracePacket8's `ties`).
// Every triangle at the ray's final distance is met: its leaf's box is entered at or before
// that distance (the boxes' rounding margins, see RayPre), so the packet tests it whatever the
// order, and a ray with one triangle at its final distance has the single ray's hit.
//
// Interval test, conservative for every ray of the packet: the slab distance of plane b for ray i
// is (b - o_i) * rdir_i. With the origins in [olo, ohi] and rdir in [rlo, rhi] per axis (one
// sign), for rdir > 0 it is at least min((b - ohi) * rlo, (b - ohi) * rhi) and at most
// max((b - olo) * rlo, (b - olo) * rhi) (mirrored for rdir < 0): a frustum for camera rays (one
// origin), a swept box for rays from several origins. The origin bounds are widened by
// d = 2^-19 (max |o| + max |b|) per axis (oNear / oFar below), so the packet's interval contains
// each ray's own computed interval (RayPre's margin is 2^-20 (|o| + max |b|) |rdir|, the
// rounding of either computation a few 2^-24 (|b| + |o|) |rdir|): the packet enters at least
// every box some ray's own test enters.

// A packet's per-ray data, SoA in groups of 8 rays (one AVX register per group). Rays outside
// the packet get tmax = -1 (a negative integer: their box tests always fail).
struct PacketRays {
    alignas(32) float rd[3][kMaxPacket];   // reciprocal directions (RayPre, nudged zeros)
    alignas(32) float on[3][kMaxPacket];   // orgRdirNear
    alignas(32) float of[3][kMaxPacket];   // orgRdirFar
    alignas(32) float tmin[kMaxPacket];    // max(tmin, 0)
    alignas(32) float tmax[kMaxPacket];    // shrinks as closer hits are found
};

// Ties (tracePacket8): the rays where the hit kept could depend on the visit order
// (closestLaneTies), and the running tmax of the last such pair test (read only for the rays in
// seen).
struct PacketTies {
    uint64_t seen = 0;
    float tie[kMaxPacket];
};

// Packet stack entry: node or leaf reference, the packet's entry distance, and where its box is
// (parent node byte offset and child slot: the leaf's per-ray box test reads it from there).
struct PacketEntry {
    uint32_t ref;
    float t;
    uint32_t parent, slot;
};

// The interval bounds of a slab distance (b - o) * rdir over rdir in [r0, r1] (see above).
inline __m256 packetLower(__m256 b, __m256 r0, __m256 r1, __m256 o) {
    const __m256 x = _mm256_sub_ps(b, o);
    return _mm256_min_ps(_mm256_mul_ps(x, r0), _mm256_mul_ps(x, r1));
}
inline __m256 packetUpper(__m256 b, __m256 r0, __m256 r1, __m256 o) {
    const __m256 x = _mm256_sub_ps(b, o);
    return _mm256_max_ps(_mm256_mul_ps(x, r0), _mm256_mul_ps(x, r1));
}
inline __m256 bcast(const float* p) { return _mm256_broadcast_ss(p); }

// The leaf's box (slot of parent) against the rays in group g: mask of rays whose own box test
// (the single-ray test with their current tmax) passes. Wide (closest hit): with each tmax 32
// units in the last place further (widenTmax; beyond the largest float the test just passes
// more boxes), so that every hit near the ray's current one is seen (closestLaneTies).
template <bool Wide = false>
inline unsigned leafRayMask(const Node8& parent, uint32_t slot, int nx, int ny, int nz, const PacketRays& pr, int g) {
    const int fx = 1 - nx, fy = 5 - ny, fz = 9 - nz;   // ny = 2 + s, fy = 3 - s; nz = 4 + s, fz = 5 - s
    const int o = 8 * g;
    const __m256 t0x = _mm256_fmsub_ps(bcast(&parent.b[nx][slot]), _mm256_load_ps(pr.rd[0] + o), _mm256_load_ps(pr.on[0] + o));
    const __m256 t1x = _mm256_fmsub_ps(bcast(&parent.b[fx][slot]), _mm256_load_ps(pr.rd[0] + o), _mm256_load_ps(pr.of[0] + o));
    const __m256 t0y = _mm256_fmsub_ps(bcast(&parent.b[ny][slot]), _mm256_load_ps(pr.rd[1] + o), _mm256_load_ps(pr.on[1] + o));
    const __m256 t1y = _mm256_fmsub_ps(bcast(&parent.b[fy][slot]), _mm256_load_ps(pr.rd[1] + o), _mm256_load_ps(pr.of[1] + o));
    const __m256 t0z = _mm256_fmsub_ps(bcast(&parent.b[nz][slot]), _mm256_load_ps(pr.rd[2] + o), _mm256_load_ps(pr.on[2] + o));
    const __m256 t1z = _mm256_fmsub_ps(bcast(&parent.b[fz][slot]), _mm256_load_ps(pr.rd[2] + o), _mm256_load_ps(pr.of[2] + o));
    const __m256i tn = _mm256_max_epi32(_mm256_max_epi32(_mm256_castps_si256(t0x), _mm256_castps_si256(t0y)),
                                        _mm256_max_epi32(_mm256_castps_si256(t0z), _mm256_load_si256(reinterpret_cast<const __m256i*>(pr.tmin + o))));
    __m256i tmax = _mm256_load_si256(reinterpret_cast<const __m256i*>(pr.tmax + o));
    if constexpr (Wide) tmax = _mm256_add_epi32(tmax, _mm256_set1_epi32(32));   // inactive lanes (-1) stay negative
    const __m256i tf =
        _mm256_min_epi32(_mm256_min_epi32(_mm256_castps_si256(t1x), _mm256_castps_si256(t1y)), _mm256_min_epi32(_mm256_castps_si256(t1z), tmax));
    return unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(tn, tf)))) ^ 0xFFu;
}

// Max of pr.tmax over the groups in `groups` (bit g: group g has packet rays).
inline float packetTmax(const PacketRays& pr, unsigned groups) {
    __m256 m = _mm256_set1_ps(-std::numeric_limits<float>::infinity());
    for (unsigned gm = groups; gm; gm &= gm - 1) m = _mm256_max_ps(m, _mm256_load_ps(pr.tmax + 8 * __builtin_ctz(gm)));
    __m128 h = _mm_max_ps(_mm256_castps256_ps128(m), _mm256_extractf128_ps(m, 1));
    h = _mm_max_ps(h, _mm_movehl_ps(h, h));
    h = _mm_max_ss(h, _mm_shuffle_ps(h, h, 1));
    return _mm_cvtss_f32(h);
}

// The fixed inputs of one tracePacket8 call, shared by its phases below.
struct PacketScene {
    const Node8* nodes;
    const TriPacket4* packets;
    const uint32_t* prims;
    const float* absMax;
    const Ray* rays;
    TriHit* hits;
    bool cullBack;
    PacketTies* ties;   // null unless ties are asked for
};

// What gatherPacket learns of the rays: those in the packet (pm) and those traced alone
// (single), the packet's direction signs (bit k: axis k negative; -1 before the first ray), the
// bounds of its reciprocal directions (rlo, rhi) and origins (olo, ohi) per axis, and its
// smallest tmin and largest tmax.
struct PacketGather {
    uint64_t pm = 0, single = 0;
    int sign = -1;
    __m128 rlo, rhi, olo, ohi;
    float tminP, tmaxP;
};

// Sorts the active rays into the packet (the first ray's direction signs, finite data, a
// non-empty [tmin, tmax]; their RayPre values into pr) and the rest; every other slot of pr is
// set to never enter a box.
[[gnu::always_inline]] inline PacketGather gatherPacket(const Ray* rays, int n, uint64_t active, const float* absMax, PacketRays& pr) {
    PacketGather g;
    g.rlo = _mm_set1_ps(std::numeric_limits<float>::infinity());
    g.rhi = _mm_set1_ps(-std::numeric_limits<float>::infinity());
    g.olo = g.rlo;
    g.ohi = g.rhi;
    g.tminP = std::numeric_limits<float>::infinity();
    g.tmaxP = -std::numeric_limits<float>::infinity();
    const int groupsN = (n + 7) / 8;
    for (int i = 0; i < 8 * groupsN; ++i) {
        const bool in = (active >> i) & 1;
        bool fits = false;
        if (in) {
            const Ray& r = rays[i];
            const RayPre pre(r, absMax);
            const float tmin = r.tmin > 0.0f ? r.tmin : 0.0f;
            const __m128 rd = _mm_load_ps(pre.rdir), on = _mm_load_ps(pre.orgRdirNear), of = _mm_load_ps(pre.orgRdirFar);
            // Finite: x - x == 0 (lanes 0-2).
            const __m128 z = _mm_add_ps(_mm_add_ps(_mm_sub_ps(rd, rd), _mm_sub_ps(on, on)),
                                        _mm_add_ps(_mm_sub_ps(of, of), _mm_sub_ps(_mm_load_ps(pre.org), _mm_load_ps(pre.org))));
            const int s = pre.nearX | (pre.nearY << 1) | (pre.nearZ << 2);
            if ((_mm_movemask_ps(_mm_cmpeq_ps(z, _mm_setzero_ps())) & 7) == 7 && sg::isFinite(r.dir) && r.tmax > tmin &&
                (g.sign < 0 || s == g.sign)) {
                g.sign = s;
                fits = true;
                g.pm |= uint64_t(1) << i;
                alignas(16) float a[4], b[4], c[4];
                _mm_store_ps(a, rd);
                _mm_store_ps(b, on);
                _mm_store_ps(c, of);
                for (int k = 0; k < 3; ++k) {
                    pr.rd[k][i] = a[k];
                    pr.on[k][i] = b[k];
                    pr.of[k][i] = c[k];
                }
                pr.tmin[i] = tmin;
                pr.tmax[i] = r.tmax;
                g.rlo = _mm_min_ps(g.rlo, rd);
                g.rhi = _mm_max_ps(g.rhi, rd);
                g.olo = _mm_min_ps(g.olo, _mm_load_ps(pre.org));
                g.ohi = _mm_max_ps(g.ohi, _mm_load_ps(pre.org));
                g.tminP = std::min(g.tminP, tmin);
                g.tmaxP = std::max(g.tmaxP, r.tmax);
            } else {
                g.single |= uint64_t(1) << i;
            }
        }
        if (!fits) {   // never enters a box
            for (int k = 0; k < 3; ++k) pr.rd[k][i] = 1.0f, pr.on[k][i] = 0.0f, pr.of[k][i] = 0.0f;
            pr.tmin[i] = 0.0f;
            pr.tmax[i] = -1.0f;
        }
    }
    return g;
}

// Traces the rays of mask m one by one from the root (traceTriangles8); returns those that hit.
// Ties: adds to *ties the rays whose hit lay among near ones (closestLaneTies): a ray's own order
// inside this mesh, but the caller may have made its tmax another mesh's hit.
template <bool AnyHit, bool Ties = false>
[[gnu::always_inline]] inline uint64_t traceAlone(const PacketScene& sc, uint64_t m, uint64_t* ties) {
    uint64_t found = 0;
    for (; m; m &= m - 1) {
        const int i = __builtin_ctzll(m);
        if constexpr (!Ties) {
            if (traceTriangles8<AnyHit>(sc.nodes, sc.packets, sc.prims, sc.absMax, sc.rays[i], AnyHit ? nullptr : &sc.hits[i], sc.cullBack))
                found |= uint64_t(1) << i;
        } else {
            float tieT = -1.0f;
            const bool hit = traceTriangles8<false, false, true>(sc.nodes, sc.packets, sc.prims, sc.absMax, sc.rays[i], &sc.hits[i], sc.cullBack,
                                                                 nullptr, 0, &tieT);
            if (hit) found |= uint64_t(1) << i;
            if (tieT >= 0.0f && tieT == (hit ? sc.hits[i].t : sc.rays[i].tmax)) *ties |= uint64_t(1) << i;
        }
    }
    return found;
}

// The packet's interval test, per axis (see above): the bounds of the reciprocal directions
// (rl*, rh*) and the widened origin bounds (entry on*, exit of*) broadcast, its smallest tmin,
// and the near planes (nx, ny, nz: rows of Node8::b) with a base pointer per plane.
struct PacketFrustum {
    int nx, ny, nz;
    __m256 rlx, rly, rlz, rhx, rhy, rhz;
    __m256 onx, ony, onz, ofx, ofy, ofz;
    __m256i tmin8i;
    const char *pnx, *pfx, *pny, *pfy, *pnz, *pfz;
};

[[gnu::always_inline]] inline PacketFrustum makePacketFrustum(const PacketGather& g, const float* absMax, const Node8* nodes) {
    PacketFrustum f;
    const int sign = g.sign;
    const int nearX = sign & 1, nearY = (sign >> 1) & 1, nearZ = (sign >> 2) & 1;
    f.nx = nearX;
    f.ny = 2 + nearY;
    f.nz = 4 + nearZ;
    const int fx = 1 - nearX, fy = 3 - nearY, fz = 5 - nearZ;
    alignas(16) float lo[4], hi[4], oL[4], oH[4];
    _mm_store_ps(lo, g.rlo);
    _mm_store_ps(hi, g.rhi);
    _mm_store_ps(oL, g.olo);
    _mm_store_ps(oH, g.ohi);
    float oNear[3], oFar[3];   // widened origin bounds (see above): entry uses oNear, exit oFar
    for (int k = 0; k < 3; ++k) {
        const float d = 0x1p-19f * (std::max(std::abs(oL[k]), std::abs(oH[k])) + absMax[k]);
        const bool neg = (sign >> k) & 1;
        oNear[k] = neg ? oL[k] - d : oH[k] + d;
        oFar[k] = neg ? oH[k] + d : oL[k] - d;
    }
    f.rlx = _mm256_set1_ps(lo[0]), f.rly = _mm256_set1_ps(lo[1]), f.rlz = _mm256_set1_ps(lo[2]);
    f.rhx = _mm256_set1_ps(hi[0]), f.rhy = _mm256_set1_ps(hi[1]), f.rhz = _mm256_set1_ps(hi[2]);
    f.onx = _mm256_set1_ps(oNear[0]), f.ony = _mm256_set1_ps(oNear[1]), f.onz = _mm256_set1_ps(oNear[2]);
    f.ofx = _mm256_set1_ps(oFar[0]), f.ofy = _mm256_set1_ps(oFar[1]), f.ofz = _mm256_set1_ps(oFar[2]);
    f.tmin8i = _mm256_castps_si256(_mm256_set1_ps(g.tminP));

    const char* const nodeBytes = reinterpret_cast<const char*>(nodes);
    f.pnx = planeBase(nodeBytes, f.nx), f.pfx = planeBase(nodeBytes, fx), f.pny = planeBase(nodeBytes, f.ny);
    f.pfy = planeBase(nodeBytes, fy), f.pnz = planeBase(nodeBytes, f.nz), f.pfz = planeBase(nodeBytes, fz);
    return f;
}

// Bit g: group g of 8 rays has packet rays (pm), for the groupsN groups.
[[gnu::always_inline]] inline unsigned packetGroups(uint64_t pm, int groupsN) {
    unsigned groups = 0;
    for (int g = 0; g < groupsN; ++g)
        if ((pm >> (8 * g)) & 0xFF) groups |= 1u << g;
    return groups;
}

// At inner node cur (not the root), entered from slot curSlot of curParent: the rays that enter
// it (their own box tests, current tmax). Two or more: returns true, the packet goes on. None
// or one: returns false, and the one goes on alone (traceTriangles8 from here: the packet's
// interval test has nothing left to share); its hit updates found and pm (AnyHit: it leaves the
// packet) or its tmax and the packet's (tmaxP, tmax8). Ties: see tracePacket8.
template <bool AnyHit, bool Ties = false>
[[gnu::always_inline]] inline bool packetEnters(const PacketScene& sc, const PacketFrustum& fr, PacketRays& pr, uint32_t cur, uint32_t curParent,
                                                uint32_t curSlot, unsigned groups, uint64_t& pm, uint64_t& found, float& tmaxP, __m256& tmax8) {
    uint64_t am = 0;
    const Node8& parent = *reinterpret_cast<const Node8*>(reinterpret_cast<const char*>(sc.nodes) + curParent);
    for (unsigned gm = groups; gm; gm &= gm - 1) {
        const int g = __builtin_ctz(gm);
        am |= uint64_t(leafRayMask<Ties>(parent, curSlot, fr.nx, fr.ny, fr.nz, pr, g)) << (8 * g);
    }
    am &= pm;
    if (__builtin_popcountll(am) > 1) return true;
    if (am) {
        const int i = __builtin_ctzll(am);
        Ray r = sc.rays[i];
        r.tmax = pr.tmax[i];
        float tieT = -1.0f;
        const bool hit = traceTriangles8<AnyHit, false, Ties>(sc.nodes, sc.packets, sc.prims, sc.absMax, r, AnyHit ? nullptr : &sc.hits[i],
                                                              sc.cullBack, nullptr, cur, &tieT);
        if (Ties && tieT >= 0.0f) {
            sc.ties->tie[i] = tieT;
            sc.ties->seen |= uint64_t(1) << i;
        }
        if (hit) {
            found |= uint64_t(1) << i;
            if constexpr (AnyHit) {
                pm &= ~(uint64_t(1) << i);
            } else {
                pr.tmax[i] = sc.hits[i].t;
                tmaxP = Ties ? widenTmax(packetTmax(pr, groups)) : packetTmax(pr, groups);   // Ties: boxes up to the widened tmax (leafRayMask)
                tmax8 = _mm256_set1_ps(tmaxP);
            }
        }
    }
    return false;
}

// Inner node cur: the packet's interval test against its 8 child boxes. The children it enters,
// front to back by the packet's entry distance: the nearest becomes cur (with its parent and
// slot), the others go on the stack. False when it enters none.
[[gnu::always_inline]] inline bool descendPacket(const PacketFrustum& fr, const char* nodeBytes, __m256 tmax8, PacketEntry* stack, int& sp,
                                                 uint32_t& cur, uint32_t& curParent, uint32_t& curSlot) {
    const Node8& nd = *reinterpret_cast<const Node8*>(nodeBytes + cur);
    const __m256 t0x = packetLower(loadPlane(fr.pnx, cur), fr.rlx, fr.rhx, fr.onx), t1x = packetUpper(loadPlane(fr.pfx, cur), fr.rlx, fr.rhx, fr.ofx);
    const __m256 t0y = packetLower(loadPlane(fr.pny, cur), fr.rly, fr.rhy, fr.ony), t1y = packetUpper(loadPlane(fr.pfy, cur), fr.rly, fr.rhy, fr.ofy);
    const __m256 t0z = packetLower(loadPlane(fr.pnz, cur), fr.rlz, fr.rhz, fr.onz), t1z = packetUpper(loadPlane(fr.pfz, cur), fr.rlz, fr.rhz, fr.ofz);
    const __m256i tn =
        _mm256_max_epi32(_mm256_max_epi32(_mm256_castps_si256(t0x), _mm256_castps_si256(t0y)), _mm256_max_epi32(_mm256_castps_si256(t0z), fr.tmin8i));
    const __m256i tf = _mm256_min_epi32(_mm256_min_epi32(_mm256_castps_si256(t1x), _mm256_castps_si256(t1y)),
                                        _mm256_min_epi32(_mm256_castps_si256(t1z), _mm256_castps_si256(tmax8)));
    unsigned mask = unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(tn, tf)))) ^ 0xFFu;
    if (mask == 0) return false;
    alignas(32) float dist[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(dist), tn);
    const unsigned c0 = unsigned(__builtin_ctz(mask));
    mask &= mask - 1;
    if (mask == 0) {
        curParent = cur;
        curSlot = c0;
        cur = nd.child[c0];
        return true;
    }
    // Front to back by the packet's entry distance: keys (distance, slot), far first.
    uint64_t key[8];
    int k = 0;
    key[k++] = sortKey(dist[c0], c0);
    do {
        const int c = __builtin_ctz(mask);
        mask &= mask - 1;
        key[k++] = sortKey(dist[c], uint32_t(c));
    } while (mask);
    if (k == 2) {
        if (key[0] < key[1]) std::swap(key[0], key[1]);
    } else {
        sortFarFirst(key, k);
    }
    for (int i = 0; i < k - 1; ++i) {
        const uint32_t s = uint32_t(key[i]);
        stack[sp++] = {nd.child[s], keyDistance(key[i]), cur, s};
    }
    curParent = cur;
    curSlot = uint32_t(key[k - 1]);
    cur = nd.child[curSlot];
    return true;
}

// Packet ray i against the triangles of a leaf [first, end), exactly as traceTriangles8 tests
// them (the same packet-pair kernel, the ray broadcast). Returns whether it hit (AnyHit) or found
// a closer hit (then pr.tmax[i] and hits[i] hold it). Ties: see tracePacket8.
template <bool AnyHit, bool Ties = false>
[[gnu::always_inline]] inline bool intersectLeafRay(const PacketScene& sc, const TriPacket4* first, const TriPacket4* end, PacketRays& pr, int i) {
    const Ray& r = sc.rays[i];
    const __m256 o8[3] = {_mm256_set1_ps(r.org.x), _mm256_set1_ps(r.org.y), _mm256_set1_ps(r.org.z)};
    const __m256 d8[3] = {_mm256_set1_ps(r.dir.x), _mm256_set1_ps(r.dir.y), _mm256_set1_ps(r.dir.z)};
    const __m256 rtmin = _mm256_set1_ps(pr.tmin[i]);
    __m256 rtmax = _mm256_set1_ps(pr.tmax[i]);
    __m256 rtmaxW = Ties ? _mm256_set1_ps(widenTmax(pr.tmax[i])) : rtmax;   // the near lanes' bound (closestLaneTies)
    bool hit = false;
    for (const TriPacket4* p = first; p < end; p += 2) {
        const bool two = p + 1 < end;
        __m256 t, u, v;
        const int lanes = two ? 0xFF : 0x0F;
        if constexpr (AnyHit) {
            if (intersectPacketPair(p[0], p[two ? 1 : 0], o8, d8, rtmin, rtmax, t, u, v, sc.cullBack) & lanes) return true;
        } else if constexpr (!Ties) {
            const int hm = intersectPacketPair(p[0], p[two ? 1 : 0], o8, d8, rtmin, rtmax, t, u, v, sc.cullBack) & lanes;
            if (!hm) continue;
            alignas(32) float ta[8], ua[8], va[8];
            _mm256_store_ps(ta, t);
            _mm256_store_ps(ua, u);
            _mm256_store_ps(va, v);
            if (closestLane(hm, ta, ua, va, sc.prims + 4 * (p - sc.packets), pr.tmax[i], &sc.hits[i])) hit = true;
            rtmax = _mm256_set1_ps(pr.tmax[i]);
        } else {
            int near = 0;
            const int hm = intersectPacketPair<true>(p[0], p[two ? 1 : 0], o8, d8, rtmin, rtmax, t, u, v, sc.cullBack, rtmaxW, &near) & lanes;
            near &= lanes;
            if (!(hm | near)) continue;
            alignas(32) float ta[8], ua[8], va[8];
            _mm256_store_ps(ta, t);
            _mm256_store_ps(ua, u);
            _mm256_store_ps(va, v);
            if (closestLaneTies(hm, near, ta, ua, va, sc.prims + 4 * (p - sc.packets), pr.tmax[i], &sc.hits[i], sc.ties->tie[i], sc.ties->seen,
                                uint64_t(1) << i)) {
                hit = true;
                rtmax = _mm256_set1_ps(pr.tmax[i]);
                rtmaxW = _mm256_set1_ps(widenTmax(pr.tmax[i]));
            }
        }
    }
    return hit;
}

// Leaf cur (its box: slot curSlot of curParent): each packet ray whose own box test passes there
// tests the leaf's triangles on its own. Hits update found; AnyHit: the ray leaves the packet
// (pm, groups); closest hit: the packet's tmax shrinks with the rays'. Ties: see tracePacket8.
template <bool AnyHit, bool Ties = false>
[[gnu::always_inline]] inline void intersectLeafRays(const PacketScene& sc, const PacketFrustum& fr, PacketRays& pr, uint32_t cur, uint32_t curParent,
                                                     uint32_t curSlot, unsigned& groups, uint64_t& pm, uint64_t& found, float& tmaxP, __m256& tmax8) {
    const Node8& parent = *reinterpret_cast<const Node8*>(reinterpret_cast<const char*>(sc.nodes) + curParent);
    const TriPacket4* first = sc.packets + ((cur & ~Node8::kLeafBit) >> 3);
    const TriPacket4* end = first + (cur & 7u);
    bool shrunk = false;
    for (unsigned gm = groups; gm; gm &= gm - 1) {
        const int g = __builtin_ctz(gm);
        unsigned rm = leafRayMask<Ties>(parent, curSlot, fr.nx, fr.ny, fr.nz, pr, g) & unsigned(pm >> (8 * g)) & 0xFFu;
        while (rm) {
            const int i = 8 * g + __builtin_ctz(rm);
            rm &= rm - 1;
            if (intersectLeafRay<AnyHit, Ties>(sc, first, end, pr, i)) {
                found |= uint64_t(1) << i;
                if constexpr (AnyHit)
                    pm &= ~(uint64_t(1) << i);
                else
                    shrunk = true;
            }
        }
        if constexpr (AnyHit)
            if (!((pm >> (8 * g)) & 0xFF)) groups &= ~(1u << g);
    }
    if constexpr (!AnyHit) {
        if (shrunk) {
            tmaxP = Ties ? widenTmax(packetTmax(pr, groups)) : packetTmax(pr, groups);
            tmax8 = _mm256_set1_ps(tmaxP);
        }
    }
}

// The next stack entry that can still hold a closer hit (any entry, for AnyHit) becomes cur, with
// its parent and slot; false when none is left.
template <bool AnyHit>
[[gnu::always_inline]] inline bool popPacketEntry(const PacketEntry* stack, int& sp, float tmaxP, uint32_t& cur, uint32_t& curParent,
                                                  uint32_t& curSlot) {
    for (;;) {
        if (sp == 0) return false;
        const PacketEntry& e = stack[--sp];
        if (AnyHit || e.t <= tmaxP) {
            cur = e.ref;
            curParent = e.parent;
            curSlot = e.slot;
            return true;
        }
    }
}

// Traces rays[i] for the bits i of `active` (n <= kMaxPacket); hits[i] gets exactly what
// traceTriangles8 writes for that ray. Rays that do not fit the packet (other direction signs
// than the first, non-finite data, an empty [tmin, tmax]) are traced one by one. Returns the
// mask of rays that hit. The phases above are force-inlined: this is one loop, as it was written.
// Only the order in which leaves are visited can differ from a ray's own, which matters where
// hits lie at exactly (or within a few units in the last place of) the same distance: there the
// packet keeps the first it finds. Ties (closest hit): *ties gets the rays where that could be
// so (closestLaneTies; the packet then also tests boxes up to widenTmax), for the caller to
// trace alone; their hits[i] are left as the packet found them.
template <bool AnyHit, bool Ties = false>
inline uint64_t tracePacket8(const Node8* nodes, const TriPacket4* packets, const uint32_t* prims, const float* absMax, const Ray* rays, int n,
                             uint64_t active, TriHit* hits, bool cullBack, uint64_t* ties = nullptr) {
    static_assert(!(AnyHit && Ties), "ties are for closest hits");
    if constexpr (Ties) *ties = 0;
    if (n < kMaxPacket) active &= (uint64_t(1) << n) - 1;
    std::conditional_t<Ties, PacketTies, char> tieState;   // (a char, unused, without ties)
    PacketTies* tiesP = nullptr;
    if constexpr (Ties) tiesP = &tieState;
    const PacketScene sc{nodes, packets, prims, absMax, rays, hits, cullBack, tiesP};
    PacketRays pr;
    const PacketGather pg = gatherPacket(rays, n, active, absMax, pr);
    uint64_t tiesAlone = 0;
    uint64_t found = traceAlone<AnyHit, Ties>(sc, pg.single, &tiesAlone);
    if (__builtin_popcountll(pg.pm) <= 1) {   // nothing to share
        found |= traceAlone<AnyHit, Ties>(sc, pg.pm, &tiesAlone);
        if constexpr (Ties) *ties = tiesAlone;
        return found;
    }
    uint64_t pm = pg.pm;
    unsigned groups = packetGroups(pm, (n + 7) / 8);
    const PacketFrustum fr = makePacketFrustum(pg, absMax, nodes);
    float tmaxP = Ties ? widenTmax(pg.tmaxP) : pg.tmaxP;   // Ties: see leafRayMask
    __m256 tmax8 = _mm256_set1_ps(tmaxP);

    const char* const nodeBytes = reinterpret_cast<const char*>(nodes);
    PacketEntry stack[512];
    int sp = 0;
    uint32_t cur = 0, curParent = 0, curSlot = 0;
    for (;;) {
        const bool inner = !(cur & Node8::kLeafBit);
        if (inner && cur != 0 && !packetEnters<AnyHit, Ties>(sc, fr, pr, cur, curParent, curSlot, groups, pm, found, tmaxP, tmax8)) {
            if constexpr (AnyHit)
                if (!pm) return found;
        } else if (inner) {
            if (descendPacket(fr, nodeBytes, tmax8, stack, sp, cur, curParent, curSlot)) continue;
        } else {
            intersectLeafRays<AnyHit, Ties>(sc, fr, pr, cur, curParent, curSlot, groups, pm, found, tmaxP, tmax8);
            if constexpr (AnyHit)
                if (!pm) return found;
        }
        if (!popPacketEntry<AnyHit>(stack, sp, tmaxP, cur, curParent, curSlot)) break;
    }
    if constexpr (Ties) {
        *ties = tiesAlone;
        for (uint64_t m = tieState.seen; m; m &= m - 1) {   // a tie at a distance the ray's hit then went below does not count
            const int i = __builtin_ctzll(m);
            if (tieState.tie[i] == pr.tmax[i]) *ties |= uint64_t(1) << i;
        }
    }
    return found;
}
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
