// packet_kernel_avx512.inl - the 16-lane steps of the packet traversal on AVX-512: the leaf's
// triangle tests and the rays' own box tests (at leaves and inner nodes). Included by
// packet_kernel.inl in the AVX-512 build of the kernels (namespace kern_avx512, RT_AVX512 1)
// only; the rest of the traversal (the packet's interval node test, the stack) is the AVX2 one.
//
// The AVX2 packet kernel tests each ray that reaches a leaf on its own, 8 triangles (two
// TriPacket4) per 8-lane test. Here, where two or more of a block of 16 rays reach the leaf,
// each triangle is tested against all 16 at once (intersectLeafRays16, as Embree's coherent
// packets do; a lone ray still takes the AVX2 test). Every lane runs exactly the operations of
// intersectPacketPair's lane for that ray and triangle (intersect16), and each ray's hits of a
// pair of packets are taken as closestLane takes them (the tmax from before the pair for the
// tests, lane order, strict less-than), so every hit is bit for bit the AVX2 kernel's and the
// single ray's. (Measured on Zen 5: the same speed from 1 to 8 rays per block as the threshold;
// two rays per 16-lane test of 8 triangles, where few rays reach a leaf, was no faster.)

// Lane-wise max / min of 32-bit integers. (The masked forms with all lanes set: GCC 12's
// unmasked _mm512_max_epi32 and _mm512_min_epi32 warn of an uninitialised operand.)
inline __m512i max16i(__m512i a, __m512i b) { return _mm512_maskz_max_epi32(0xFFFF, a, b); }
inline __m512i min16i(__m512i a, __m512i b) { return _mm512_maskz_min_epi32(0xFFFF, a, b); }

// leafRayMask for the 16 rays of groups 2h and 2h + 1 in one test: the same operations lane by
// lane (bit k: ray 16 h + k).
template <bool Wide = false>
inline unsigned leafRayMask16(const Node8& parent, uint32_t slot, int nx, int ny, int nz, const PacketRays& pr, int h) {
    const int fx = 1 - nx, fy = 5 - ny, fz = 9 - nz;
    const int o = 16 * h;
    const __m512 t0x = _mm512_fmsub_ps(_mm512_set1_ps(parent.b[nx][slot]), _mm512_load_ps(pr.rd[0] + o), _mm512_load_ps(pr.on[0] + o));
    const __m512 t1x = _mm512_fmsub_ps(_mm512_set1_ps(parent.b[fx][slot]), _mm512_load_ps(pr.rd[0] + o), _mm512_load_ps(pr.of[0] + o));
    const __m512 t0y = _mm512_fmsub_ps(_mm512_set1_ps(parent.b[ny][slot]), _mm512_load_ps(pr.rd[1] + o), _mm512_load_ps(pr.on[1] + o));
    const __m512 t1y = _mm512_fmsub_ps(_mm512_set1_ps(parent.b[fy][slot]), _mm512_load_ps(pr.rd[1] + o), _mm512_load_ps(pr.of[1] + o));
    const __m512 t0z = _mm512_fmsub_ps(_mm512_set1_ps(parent.b[nz][slot]), _mm512_load_ps(pr.rd[2] + o), _mm512_load_ps(pr.on[2] + o));
    const __m512 t1z = _mm512_fmsub_ps(_mm512_set1_ps(parent.b[fz][slot]), _mm512_load_ps(pr.rd[2] + o), _mm512_load_ps(pr.of[2] + o));
    const __m512i tn =
        max16i(max16i(_mm512_castps_si512(t0x), _mm512_castps_si512(t0y)), max16i(_mm512_castps_si512(t0z), _mm512_load_si512(pr.tmin + o)));
    __m512i tmax = _mm512_load_si512(pr.tmax + o);
    if constexpr (Wide) tmax = _mm512_add_epi32(tmax, _mm512_set1_epi32(32));
    const __m512i tf = min16i(min16i(_mm512_castps_si512(t1x), _mm512_castps_si512(t1y)), min16i(_mm512_castps_si512(t1z), tmax));
    return unsigned(_mm512_cmple_epi32_mask(tn, tf));
}

// One triangle's fields, broadcast to the 16 lanes.
struct Tri16 {
    __m512 n[3], v0[3], e1[3], e2[3];
};

// intersectPacketPair's test on 16 lanes (a ray each): the same arithmetic lane
// by lane. Returns the 16-bit hit mask. Ties: also *near, as intersectPacketPair<true> gives it.
template <bool Ties = false>
[[gnu::always_inline]] inline unsigned intersect16(const Tri16& q, const __m512 o[3], const __m512 d[3], __m512 tmin, __m512 tmax, __m512& tOut,
                                                   __m512& uOut, __m512& vOut, bool cullBack, __m512 tmaxW = __m512(), unsigned* near = nullptr) {
    const __m512 sx = _mm512_sub_ps(o[0], q.v0[0]);
    const __m512 sy = _mm512_sub_ps(o[1], q.v0[1]);
    const __m512 sz = _mm512_sub_ps(o[2], q.v0[2]);
    const __m512 negZero = _mm512_set1_ps(-0.0f);
    __m512 det = _mm512_fmadd_ps(d[2], q.n[2], _mm512_fmadd_ps(d[1], q.n[1], _mm512_mul_ps(d[0], q.n[0])));
    det = _mm512_xor_ps(det, negZero);
    const __m512 sign = _mm512_and_ps(det, negZero);
    const __m512 absDet = _mm512_xor_ps(det, sign);
    const __m512 rx = _mm512_fmsub_ps(sy, d[2], _mm512_mul_ps(sz, d[1]));
    const __m512 ry = _mm512_fmsub_ps(sz, d[0], _mm512_mul_ps(sx, d[2]));
    const __m512 rz = _mm512_fmsub_ps(sx, d[1], _mm512_mul_ps(sy, d[0]));
    __m512 U = _mm512_fmadd_ps(q.e2[2], rz, _mm512_fmadd_ps(q.e2[1], ry, _mm512_mul_ps(q.e2[0], rx)));
    __m512 V = _mm512_fmadd_ps(q.e1[2], rz, _mm512_fmadd_ps(q.e1[1], ry, _mm512_mul_ps(q.e1[0], rx)));
    __m512 T = _mm512_fmadd_ps(sz, q.n[2], _mm512_fmadd_ps(sy, q.n[1], _mm512_mul_ps(sx, q.n[0])));
    U = _mm512_xor_ps(U, sign);
    V = _mm512_xor_ps(V, _mm512_xor_ps(sign, negZero));
    T = _mm512_xor_ps(T, sign);
    const __m512 zero = _mm512_setzero_ps();
    __mmask16 ok = cullBack ? _mm512_cmp_ps_mask(det, zero, _CMP_GT_OQ) : _mm512_cmp_ps_mask(det, zero, _CMP_NEQ_UQ);
    ok = _mm512_mask_cmp_ps_mask(ok, U, zero, _CMP_GE_OQ);
    ok = _mm512_mask_cmp_ps_mask(ok, V, zero, _CMP_GE_OQ);
    ok = _mm512_mask_cmp_ps_mask(ok, _mm512_add_ps(U, V), absDet, _CMP_LE_OQ);
    ok = _mm512_mask_cmp_ps_mask(ok, T, _mm512_mul_ps(absDet, tmin), _CMP_GT_OQ);
    if constexpr (Ties) {
        *near = 0;
        const __mmask16 wide = _mm512_mask_cmp_ps_mask(ok, T, _mm512_mul_ps(absDet, tmaxW), _CMP_LT_OQ);
        if (!wide) return 0;
        const __m512 inv = _mm512_div_ps(_mm512_set1_ps(1.0f), absDet);
        tOut = _mm512_mul_ps(T, inv);
        uOut = _mm512_mul_ps(U, inv);
        vOut = _mm512_mul_ps(V, inv);
        const __mmask16 above = _mm512_mask_cmp_ps_mask(wide, tOut, tmin, _CMP_GT_OQ);
        *near = _mm512_mask_cmp_ps_mask(above, tOut, tmaxW, _CMP_LT_OQ);
        return _mm512_mask_cmp_ps_mask(_mm512_mask_cmp_ps_mask(above, T, _mm512_mul_ps(absDet, tmax), _CMP_LT_OQ), tOut, tmax, _CMP_LT_OQ);
    }
    ok = _mm512_mask_cmp_ps_mask(ok, T, _mm512_mul_ps(absDet, tmax), _CMP_LT_OQ);
    if (ok) {
        const __m512 inv = _mm512_div_ps(_mm512_set1_ps(1.0f), absDet);
        tOut = _mm512_mul_ps(T, inv);
        uOut = _mm512_mul_ps(U, inv);
        vOut = _mm512_mul_ps(V, inv);
        ok = _mm512_mask_cmp_ps_mask(ok, tOut, tmax, _CMP_LT_OQ);
        ok = _mm512_mask_cmp_ps_mask(ok, tOut, tmin, _CMP_GT_OQ);
    }
    return ok;
}

// widenTmax on 16 lanes.
inline __m512 widenTmax16(__m512 t) {
    const __m512i b = _mm512_castps_si512(t), inf = _mm512_set1_epi32(0x7F800000);
    return _mm512_castsi512_ps(_mm512_mask_min_epu32(b, _mm512_cmplt_epu32_mask(b, inf), _mm512_add_epi32(b, _mm512_set1_epi32(32)), inf));
}

// The rays of block h (rays 16 h + k for the bits k of `rays`) against the triangles of a leaf
// [first, end), each triangle broadcast against all 16 lanes. Per pair of packets, as the single
// ray tests them: each triangle with the ray's tmax from before the pair, and the hits taken in
// lane order with a strict less-than on the running tmax (closestLane's rule), so every hit is
// bit for bit the single ray's. Returns the rays that hit (AnyHit) or found a closer hit (their
// pr.tmax and hits then hold it). Empty lanes (all zero, never a hit) are skipped.
// Ties: closestLaneTies' rule per ray and pair, on all lanes at once: with a hit kept in the
// pair, order matters where the tmax before it, or another near lane, lies within
// widenTmax(new tmax) (the kept lane is near too, so: two near lanes within it); without one,
// where any near lane does.
template <bool AnyHit, bool Ties = false>
[[gnu::always_inline]] inline unsigned intersectLeafRays16(const PacketScene& sc, const TriPacket4* first, const TriPacket4* end, PacketRays& pr,
                                                           int h, unsigned rays) {
    const int o = 16 * h;
    const __m512 org[3] = {_mm512_load_ps(pr.org[0] + o), _mm512_load_ps(pr.org[1] + o), _mm512_load_ps(pr.org[2] + o)};
    const __m512 dir[3] = {_mm512_load_ps(pr.dir[0] + o), _mm512_load_ps(pr.dir[1] + o), _mm512_load_ps(pr.dir[2] + o)};
    const __m512 tmin = _mm512_load_ps(pr.tmin + o);
    __m512 tmax = _mm512_load_ps(pr.tmax + o);
    __m512 tmaxW = Ties ? widenTmax16(tmax) : tmax;
    __m512 bestU = _mm512_setzero_ps(), bestV = _mm512_setzero_ps();
    __m512i bestPrim = _mm512_setzero_si512();
    unsigned changed = 0;
    for (const TriPacket4* p = first; p < end; p += 2) {
        const int count = p + 1 < end ? 8 : 4;
        const uint32_t* ids = sc.prims + 4 * (p - sc.packets);
        __m512 run = tmax;   // the running tmax; the tests use tmax, the one from before the pair
        unsigned kept = 0;   // (Ties) rays with a hit kept in this pair
        __m512 nearT[8];     // (Ties) the pair's near lanes: distances and masks
        unsigned nearM[8];
        int nears = 0;
        for (int k = 0; k < count; ++k) {
            if (ids[k] == ~0u) continue;
            const TriPacket4& q = p[k >> 2];
            const int l = k & 3;
            Tri16 tri;
            for (int a = 0; a < 3; ++a) {
                tri.n[a] = _mm512_set1_ps(q.n[a][l]);
                tri.v0[a] = _mm512_set1_ps(q.v0[a][l]);
                tri.e1[a] = _mm512_set1_ps(q.e1[a][l]);
                tri.e2[a] = _mm512_set1_ps(q.e2[a][l]);
            }
            __m512 t, u, v;
            unsigned near = 0;
            const unsigned hm = intersect16<Ties>(tri, org, dir, tmin, tmax, t, u, v, sc.cullBack, tmaxW, &near) & rays;
            if constexpr (Ties) {
                near &= rays;
                if (near) {
                    nearT[nears] = t;
                    nearM[nears++] = near;
                }
            }
            if (!hm) continue;
            if constexpr (AnyHit) {
                changed |= hm;
                rays &= ~hm;
                if (!rays) return changed;
            } else {
                const __mmask16 closer = _mm512_mask_cmp_ps_mask(__mmask16(hm), t, run, _CMP_LT_OQ);
                run = _mm512_mask_mov_ps(run, closer, t);
                bestU = _mm512_mask_mov_ps(bestU, closer, u);
                bestV = _mm512_mask_mov_ps(bestV, closer, v);
                bestPrim = _mm512_mask_set1_epi32(bestPrim, closer, int(ids[k]));
                changed |= closer;
                kept |= closer;
            }
        }
        if constexpr (Ties) {
            if (nears) {
                const __m512 w = widenTmax16(run);
                unsigned one = 0, two = 0;   // near lanes within w: at least one, at least two
                for (int c = 0; c < nears; ++c) {
                    const unsigned m = _mm512_mask_cmp_ps_mask(__mmask16(nearM[c]), nearT[c], w, _CMP_LE_OQ);
                    two |= one & m;
                    one |= m;
                }
                const unsigned order = (kept & (unsigned(_mm512_cmp_ps_mask(tmax, w, _CMP_LE_OQ)) | two)) | (~kept & one);
                if (order) {
                    _mm512_mask_storeu_ps(sc.ties->tie + o, __mmask16(order), run);
                    sc.ties->seen |= uint64_t(order) << o;
                }
            }
            tmaxW = widenTmax16(run);
        }
        tmax = run;
    }
    if constexpr (!AnyHit) {
        if (changed) {
            alignas(64) float ta[16], ua[16], va[16];
            alignas(64) uint32_t pa[16];
            _mm512_store_ps(ta, tmax);
            _mm512_store_ps(ua, bestU);
            _mm512_store_ps(va, bestV);
            _mm512_store_si512(pa, bestPrim);
            _mm512_mask_store_ps(pr.tmax + o, __mmask16(changed), tmax);
            for (unsigned m = changed; m; m &= m - 1) {
                const int k = __builtin_ctz(m);
                TriHit& hit = sc.hits[o + k];
                hit.t = ta[k];
                hit.prim = pa[k];
                hit.b1 = ua[k];
                hit.b2 = va[k];
            }
        }
    }
    return changed;
}
