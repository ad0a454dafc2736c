// packet_kernel.inl - the packet traversal of TriangleBvh (BVH8, AVX2): up to kMaxPacket
// coherent rays walk the tree together. Included by tri_kernel.inl inside its AVX2+FMA part
// (namespace kern_avx2), after the single-ray kernel it builds on (traceTriangles8,
// intersectPacketPair, closestLane / closestLaneTies).

// --- packets of coherent rays (BVH8, AVX2) ----------------------------------------------------
//
// Up to kMaxPacket rays whose directions share their signs (camera rays of a pixel tile, shadow
// rays of neighbouring pixels to one light) traverse the tree together: an inner node tests its
// 8 child boxes once against the whole packet with interval arithmetic (one box test for all
// rays, about twice a single ray's work), and only at a leaf is each ray tested on its own: its
// box test with the ray's current tmax, then the leaf's triangles exactly as traceTriangles8
// tests them (the same packet-pair kernel, the ray broadcast), so every hit is bit for bit the
// single-ray hit. Only the order in which leaves are visited can differ from the single ray's,
// which matters only where hits lie at exactly or nearly the same distance (the first found is
// kept, as there); with ties asked for, such rays are reported (tracePacket8).
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
// (Aligned to 64 bytes for the AVX-512 build's 16-ray loads.)
struct PacketRays {
    alignas(64) float rd[3][kMaxPacket];   // reciprocal directions (RayPre, nudged zeros)
    alignas(64) float on[3][kMaxPacket];   // orgRdirNear
    alignas(64) float of[3][kMaxPacket];   // orgRdirFar
    alignas(64) float tmin[kMaxPacket];    // max(tmin, 0)
    alignas(64) float tmax[kMaxPacket];    // shrinks as closer hits are found
#if RT_AVX512
    alignas(64) float org[3][kMaxPacket], dir[3][kMaxPacket];   // the rays (in the mesh's space), for 16 rays per leaf test
#endif
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

// The smallest (largest) of v's 8 lanes.
inline float laneMin8(__m256 v) {
    __m128 h = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
    h = _mm_min_ps(h, _mm_movehl_ps(h, h));
    return _mm_cvtss_f32(_mm_min_ss(h, _mm_shuffle_ps(h, h, 1)));
}
inline float laneMax8(__m256 v) {
    __m128 h = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
    h = _mm_max_ps(h, _mm_movehl_ps(h, h));
    return _mm_cvtss_f32(_mm_max_ss(h, _mm_shuffle_ps(h, h, 1)));
}

// Max of pr.tmax over the groups in `groups` (bit g: group g has packet rays).
inline float packetTmax(const PacketRays& pr, unsigned groups) {
    __m256 m = _mm256_set1_ps(-std::numeric_limits<float>::infinity());
    for (unsigned gm = groups; gm; gm &= gm - 1) m = _mm256_max_ps(m, _mm256_load_ps(pr.tmax + 8 * __builtin_ctz(gm)));
    return laneMax8(m);
}

// The fixed inputs of one tracePacket8 call, shared by its phases below.
struct PacketScene {
    const Node8* nodes;
    const TriPacket4* packets;
    const uint32_t* prims;
    const float* absMax;
    const Ray* rays;   // the rays in the mesh's space (null where moved is set)
    TriHit* hits;
    bool cullBack;
    PacketTies* ties;   // null unless ties are asked for
    // AVX-512 with a move: the moved rays are read from the packet's lanes (pr's org and dir,
    // which gatherPacket16 stores for every ray of a block it sets up) and the world rays' tmin
    // and tmax (or tmaxIn), the values the rows of moved rays would hold.
    const PacketRays* moved = nullptr;
    const Ray* world = nullptr;
    const float* tmaxIn = nullptr;
    // Ray i in the mesh's space.
    Ray ray(int i) const {
#if RT_AVX512
        if (moved) {
            Ray r;
            r.org = sg::vec3(moved->org[0][i], moved->org[1][i], moved->org[2][i]);
            r.dir = sg::vec3(moved->dir[0][i], moved->dir[1][i], moved->dir[2][i]);
            r.tmin = world[i].tmin;
            r.tmax = tmaxIn ? tmaxIn[i] : world[i].tmax;
            return r;
        }
#endif
        return rays[i];
    }
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

// All ones in lane l where bit l of m is set.
inline __m256 laneMask8(unsigned m) {
    const __m256i bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(m)), bits), bits));
}

// a * b as a value of its own: the empty asm keeps GCC from fusing the product into the sum that
// follows (this region has FMA; code that must give the same bits, compiled without it, has none).
inline __m256 unfusedProduct(__m256 a, __m256 b) {
    __m256 p = _mm256_mul_ps(a, b);
    asm("" : "+x"(p));
    return p;
}

// Rows of 8 floats (lanes l and l + 4 in the halves of v[l]) -> x, y, z, w of the 8 rows.
inline void transposeRows8(const __m256* v, __m256* out) {
    const __m256 t0 = _mm256_unpacklo_ps(v[0], v[1]), t1 = _mm256_unpackhi_ps(v[0], v[1]);
    const __m256 t2 = _mm256_unpacklo_ps(v[2], v[3]), t3 = _mm256_unpackhi_ps(v[2], v[3]);
    out[0] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    out[1] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    out[2] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    out[3] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
}

#if RT_AVX512
// a * b on 16 lanes as a value of its own (see unfusedProduct).
inline __m512 unfusedProduct16(__m512 a, __m512 b) {
    __m512 p = _mm512_mul_ps(a, b);
    asm("" : "+v"(p));
    return p;
}

// Lane-wise min / max. (The masked forms with all lanes set: GCC 12's unmasked ones warn of an
// uninitialised operand.)
inline __m512 min16(__m512 a, __m512 b) { return _mm512_maskz_min_ps(0xFFFF, a, b); }
inline __m512 max16(__m512 a, __m512 b) { return _mm512_maskz_max_ps(0xFFFF, a, b); }

// The smallest lane of each of v[0..15] into out[0..15], the sixteen reductions together: halves,
// then quarters of pairs and fours of vectors are brought into one register and met by one min
// each (45 operations where one at a time takes about 9 each).
template <int Imm>
inline __m512 blocks4(__m512 a, __m512 b) {   // 128-bit blocks (a, a, b, b) as Imm picks them
    return _mm512_maskz_shuffle_f32x4(0xFFFF, a, b, Imm);
}
template <int Imm>
inline __m512 lanes4(__m512 a, __m512 b) {   // in each block: two lanes of a, two of b
    return _mm512_maskz_shuffle_ps(0xFFFF, a, b, Imm);
}
inline void laneMins16(const __m512 v[16], float out[16]) {
    __m512 w[8], x[4], y[2];
    for (int k = 0; k < 8; ++k)
        w[k] = min16(blocks4<0x44>(v[2 * k], v[2 * k + 1]), blocks4<0xEE>(v[2 * k], v[2 * k + 1]));   // v[2k]'s 8 in blocks 0-1
    for (int k = 0; k < 4; ++k)
        x[k] = min16(blocks4<0x88>(w[2 * k], w[2 * k + 1]), blocks4<0xDD>(w[2 * k], w[2 * k + 1]));   // v[4k+j]'s 4 in block j
    for (int k = 0; k < 2; ++k)
        y[k] = min16(lanes4<_MM_SHUFFLE(1, 0, 1, 0)>(x[2 * k], x[2 * k + 1]), lanes4<_MM_SHUFFLE(3, 2, 3, 2)>(x[2 * k], x[2 * k + 1]));
    // Block j: v[j], v[4 + j], v[8 + j], v[12 + j].
    const __m512 z = min16(lanes4<_MM_SHUFFLE(2, 0, 2, 0)>(y[0], y[1]), lanes4<_MM_SHUFFLE(3, 1, 3, 1)>(y[0], y[1]));
    alignas(64) float r[16];
    _mm512_store_ps(r, z);
    for (int j = 0; j < 4; ++j)
        for (int m = 0; m < 4; ++m) out[4 * m + j] = r[4 * j + m];
}

// gatherPacket (below) sixteen rays at a time on AVX-512: lane by lane the same operations as
// its groups of eight (the rays loaded and transposed eight at a time, then everything else in
// 16 lanes), so pr and the bounds get the same values. An inactive lane repeats the block's
// first active ray (the eight-ray groups repeat their own first; those lanes are never read as
// rays). The moved rays are not written back as rows: tracePacket8 reads them from pr.org and
// pr.dir (PacketScene::ray), which hold every ray of a block set up here.
inline PacketGather gatherPacket16(const Ray* rays, int n, uint64_t active, const float* absMax, PacketRays& pr, const RayTransform* move,
                                   const float* tmaxIn) {
    PacketGather g;
    const __m512 inf = _mm512_set1_ps(std::numeric_limits<float>::infinity()), ninf = _mm512_set1_ps(-std::numeric_limits<float>::infinity());
    const __m512 signBit = _mm512_set1_ps(-0.0f), zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
    __m512 rlo[3] = {inf, inf, inf}, rhi[3] = {ninf, ninf, ninf}, olo[3] = {inf, inf, inf}, ohi[3] = {ninf, ninf, ninf};
    __m512 tminLo = inf, tmaxHi = ninf;
    const int blocksN = (n + 15) / 16;
    for (int b = 0; b < blocksN; ++b) {
        const unsigned lanes = unsigned(active >> (16 * b)) & 0xFFFFu;
        const int o16 = 16 * b;
        if (!lanes) {   // never enters a box
            for (int a = 0; a < 3; ++a) {
                _mm512_store_ps(pr.rd[a] + o16, one);
                _mm512_store_ps(pr.on[a] + o16, zero);
                _mm512_store_ps(pr.of[a] + o16, zero);
                _mm512_store_ps(pr.org[a] + o16, zero);
                _mm512_store_ps(pr.dir[a] + o16, zero);
            }
            _mm512_store_ps(pr.tmin + o16, zero);
            _mm512_store_ps(pr.tmax + o16, _mm512_set1_ps(-1.0f));
            continue;
        }
        const int firstLane = __builtin_ctz(lanes);
        auto ray = [&](int l) -> const Ray& { return rays[o16 + (((lanes >> l) & 1) ? l : firstLane)]; };
        __m512 org[4], dir[4];   // x, y, z and tmin / tmax of the 16 rays
        for (int h = 0; h < 2; ++h) {
            __m256 ov[4], dv[4], o8[4], d8[4];
            for (int l = 0; l < 4; ++l) {
                const Ray &lo = ray(8 * h + l), &hi = ray(8 * h + l + 4);
                ov[l] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(&lo.org.x)), _mm_loadu_ps(&hi.org.x), 1);
                dv[l] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(&lo.dir.x)), _mm_loadu_ps(&hi.dir.x), 1);
            }
            transposeRows8(ov, o8);
            transposeRows8(dv, d8);
            for (int a = 0; a < 4; ++a) {
                org[a] = h == 0 ? _mm512_castps256_ps512(o8[a]) : _mm512_insertf32x8(org[a], o8[a], 1);
                dir[a] = h == 0 ? _mm512_castps256_ps512(d8[a]) : _mm512_insertf32x8(dir[a], d8[a], 1);
            }
        }
        if (move) {
            __m512 mo[3], md[3];
            for (int r = 0; r < 3; ++r) {
                const float(*c)[4] = move->col;
                const float(*d)[4] = move->lin;
                mo[r] =
                    _mm512_add_ps(_mm512_add_ps(unfusedProduct16(_mm512_set1_ps(c[0][r]), org[0]), unfusedProduct16(_mm512_set1_ps(c[1][r]), org[1])),
                                  _mm512_add_ps(unfusedProduct16(_mm512_set1_ps(c[2][r]), org[2]), _mm512_set1_ps(c[3][r])));
                md[r] =
                    _mm512_add_ps(_mm512_add_ps(unfusedProduct16(_mm512_set1_ps(d[0][r]), dir[0]), unfusedProduct16(_mm512_set1_ps(d[1][r]), dir[1])),
                                  unfusedProduct16(_mm512_set1_ps(d[2][r]), dir[2]));
            }
            for (int r = 0; r < 3; ++r) org[r] = mo[r], dir[r] = md[r];
            if (tmaxIn) {
                alignas(64) float t[16];
                for (int l = 0; l < 16; ++l) t[l] = tmaxIn[o16 + (((lanes >> l) & 1) ? l : firstLane)];
                dir[3] = _mm512_load_ps(t);
            }
        }
        for (int a = 0; a < 3; ++a) {
            _mm512_store_ps(pr.org[a] + o16, org[a]);
            _mm512_store_ps(pr.dir[a] + o16, dir[a]);
        }
        __m512 rd[3], on[3], of[3];
        __mmask16 bad = 0;   // lanes with a value that is not finite (x - x is NaN there)
        unsigned neg[3];
        for (int a = 0; a < 3; ++a) {
            __m512 d = dir[a];
            bad |= _mm512_cmp_ps_mask(_mm512_sub_ps(d, d), zero, _CMP_NEQ_UQ);
            const __mmask16 tiny = _mm512_cmp_ps_mask(_mm512_andnot_ps(signBit, d), _mm512_set1_ps(1e-30f), _CMP_LT_OS);
            d = _mm512_mask_mov_ps(d, tiny, _mm512_or_ps(_mm512_and_ps(d, signBit), _mm512_set1_ps(1e-30f)));
            rd[a] = _mm512_div_ps(one, d);
            const __m512 ord = unfusedProduct16(org[a], rd[a]);
            const __m512 absB = _mm512_set1_ps(absMax ? absMax[a] : 0.0f);
            const __m512 e = unfusedProduct16(_mm512_mul_ps(_mm512_add_ps(_mm512_andnot_ps(signBit, org[a]), absB), _mm512_andnot_ps(signBit, rd[a])),
                                              _mm512_set1_ps(0x1p-20f));
            on[a] = _mm512_add_ps(ord, e);
            of[a] = _mm512_sub_ps(ord, e);
            const __m512 z = _mm512_add_ps(_mm512_add_ps(_mm512_sub_ps(rd[a], rd[a]), _mm512_sub_ps(on[a], on[a])),
                                           _mm512_add_ps(_mm512_sub_ps(of[a], of[a]), _mm512_sub_ps(org[a], org[a])));
            bad |= _mm512_cmp_ps_mask(z, zero, _CMP_NEQ_UQ);
            neg[a] = unsigned(_mm512_movepi32_mask(_mm512_castps_si512(d)));
        }
        const __m512 tmin = max16(org[3], zero);   // r.tmin > 0 ? r.tmin : 0
        const __m512 tmax = dir[3];
        const unsigned nonEmpty = unsigned(_mm512_cmp_ps_mask(tmax, tmin, _CMP_GT_OQ));
        const unsigned ok = lanes & ~unsigned(bad) & nonEmpty;
        if (g.sign < 0 && ok) {   // the first ray that fits sets the packet's signs
            const int l = __builtin_ctz(ok);
            g.sign = int((neg[0] >> l) & 1) | int(((neg[1] >> l) & 1) << 1) | int(((neg[2] >> l) & 1) << 2);
        }
        unsigned same = 0xFFFFu;
        for (int a = 0; a < 3; ++a) same &= (g.sign >> a) & 1 ? neg[a] : ~neg[a];
        const unsigned fits = ok & same & 0xFFFFu;
        g.pm |= uint64_t(fits) << o16;
        g.single |= uint64_t(lanes & ~fits) << o16;
        const __mmask16 fit = __mmask16(fits);
        for (int a = 0; a < 3; ++a) {
            _mm512_store_ps(pr.rd[a] + o16, _mm512_mask_blend_ps(fit, one, rd[a]));
            _mm512_store_ps(pr.on[a] + o16, _mm512_mask_blend_ps(fit, zero, on[a]));
            _mm512_store_ps(pr.of[a] + o16, _mm512_mask_blend_ps(fit, zero, of[a]));
            rlo[a] = min16(rlo[a], _mm512_mask_blend_ps(fit, inf, rd[a]));
            rhi[a] = max16(rhi[a], _mm512_mask_blend_ps(fit, ninf, rd[a]));
            olo[a] = min16(olo[a], _mm512_mask_blend_ps(fit, inf, org[a]));
            ohi[a] = max16(ohi[a], _mm512_mask_blend_ps(fit, ninf, org[a]));
        }
        _mm512_store_ps(pr.tmin + o16, _mm512_mask_blend_ps(fit, zero, tmin));
        _mm512_store_ps(pr.tmax + o16, _mm512_mask_blend_ps(fit, _mm512_set1_ps(-1.0f), tmax));
        tminLo = min16(tminLo, _mm512_mask_blend_ps(fit, inf, tmin));
        tmaxHi = max16(tmaxHi, _mm512_mask_blend_ps(fit, ninf, tmax));
    }
    // The bounds: the largest as minus the smallest of the negated lanes (none is NaN; a zero's
    // sign is free, as in any order of the eight-lane reductions).
    auto minus = [&](__m512 a) { return _mm512_xor_ps(a, signBit); };
    const __m512 v[16] = {rlo[0],        rlo[1],        rlo[2],        olo[0],        olo[1],        olo[2],        tminLo,        inf,
                          minus(rhi[0]), minus(rhi[1]), minus(rhi[2]), minus(ohi[0]), minus(ohi[1]), minus(ohi[2]), minus(tmaxHi), inf};
    float m[16];
    laneMins16(v, m);
    g.rlo = _mm_setr_ps(m[0], m[1], m[2], 0.0f);
    g.olo = _mm_setr_ps(m[3], m[4], m[5], 0.0f);
    g.tminP = m[6];
    g.rhi = _mm_setr_ps(-m[8], -m[9], -m[10], 0.0f);
    g.ohi = _mm_setr_ps(-m[11], -m[12], -m[13], 0.0f);
    g.tmaxP = -m[14];
    return g;
}
#endif

// Sorts the active rays into the packet (the first ray's direction signs, finite data, a
// non-empty [tmin, tmax]; their RayPre values into pr) and the rest; every other slot of pr is
// set to never enter a box. Eight rays at a time: RayPre's operations (the nudge of a tiny
// direction component, 1 / d, o * rdir and the margin 2^-20 (|o| + max |b|) |rdir|) in the same
// order on each lane, so pr holds bit for bit what RayPre gives each ray (where the compiler
// fuses the margin's product with 2^-20 into a sum, that product is exact, so the bits agree). The packet's bounds
// are the same values whatever the order they are taken in, up to the sign of a zero origin
// coordinate, which makePacketFrustum's widening (d > 0 for any mesh with a box) removes.
// move (with tmaxIn: the rays' tmax, null: their own): the rays are world rays, moved into the
// mesh's space first, as RayTransform::applyTo moves them (per lane (c0 x + c1 y) + (c2 z + c3)
// and (c0 x + c1 y) + c2 z, no product fused into a sum), and written to moved[i] for the leaves.
// (The AVX-512 build's tracePacket8 takes gatherPacket16 instead.)
[[gnu::always_inline]] inline PacketGather gatherPacket(const Ray* rays, int n, uint64_t active, const float* absMax, PacketRays& pr,
                                                        const RayTransform* move = nullptr, const float* tmaxIn = nullptr, Ray* moved = nullptr) {
    static_assert(sizeof(Ray) == 32 && offsetof(Ray, tmin) == 12 && offsetof(Ray, dir) == 16 && offsetof(Ray, tmax) == 28,
                  "Ray: org, tmin, dir, tmax packed");
    PacketGather g;
    const __m256 inf = _mm256_set1_ps(std::numeric_limits<float>::infinity()), ninf = _mm256_set1_ps(-std::numeric_limits<float>::infinity());
    const __m256 signBit = _mm256_set1_ps(-0.0f), zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    __m256 rlo[3] = {inf, inf, inf}, rhi[3] = {ninf, ninf, ninf}, olo[3] = {inf, inf, inf}, ohi[3] = {ninf, ninf, ninf};
    __m256 tminLo = inf, tmaxHi = ninf;
    const int groupsN = (n + 7) / 8;
    for (int k = 0; k < groupsN; ++k) {
        const unsigned lanes = unsigned(active >> (8 * k)) & 0xFFu;
        const int o8 = 8 * k;
        if (!lanes) {   // never enters a box
            for (int a = 0; a < 3; ++a) {
                _mm256_store_ps(pr.rd[a] + o8, one);
                _mm256_store_ps(pr.on[a] + o8, zero);
                _mm256_store_ps(pr.of[a] + o8, zero);
            }
            _mm256_store_ps(pr.tmin + o8, zero);
            _mm256_store_ps(pr.tmax + o8, _mm256_set1_ps(-1.0f));
#if RT_AVX512
            for (int a = 0; a < 3; ++a) {
                _mm256_store_ps(pr.org[a] + o8, zero);
                _mm256_store_ps(pr.dir[a] + o8, zero);
            }
#endif
            continue;
        }
        // The group's rays as (org, tmin) and (dir, tmax) rows, lanes l and l + 4 in one register
        // (an inactive lane repeats an active ray: only active slots of `rays` are read).
        const int firstLane = __builtin_ctz(lanes);
        auto ray = [&](int l) -> const Ray& { return rays[o8 + (((lanes >> l) & 1) ? l : firstLane)]; };
        __m256 ov[4], dv[4];
        for (int l = 0; l < 4; ++l) {
            const Ray &lo = ray(l), &hi = ray(l + 4);
            ov[l] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(&lo.org.x)), _mm_loadu_ps(&hi.org.x), 1);
            dv[l] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(&lo.dir.x)), _mm_loadu_ps(&hi.dir.x), 1);
        }
        __m256 org[4], dir[4];   // x, y, z and tmin / tmax
        transposeRows8(ov, org);
        transposeRows8(dv, dir);
        if (move) {
            __m256 mo[3], md[3];
            for (int r = 0; r < 3; ++r) {
                const float(*c)[4] = move->col;
                const float(*d)[4] = move->lin;
                mo[r] = _mm256_add_ps(_mm256_add_ps(unfusedProduct(_mm256_set1_ps(c[0][r]), org[0]), unfusedProduct(_mm256_set1_ps(c[1][r]), org[1])),
                                      _mm256_add_ps(unfusedProduct(_mm256_set1_ps(c[2][r]), org[2]), _mm256_set1_ps(c[3][r])));
                md[r] = _mm256_add_ps(_mm256_add_ps(unfusedProduct(_mm256_set1_ps(d[0][r]), dir[0]), unfusedProduct(_mm256_set1_ps(d[1][r]), dir[1])),
                                      unfusedProduct(_mm256_set1_ps(d[2][r]), dir[2]));
            }
            for (int r = 0; r < 3; ++r) org[r] = mo[r], dir[r] = md[r];
            if (tmaxIn) {
                alignas(32) float t[8];
                for (int l = 0; l < 8; ++l) t[l] = tmaxIn[o8 + (((lanes >> l) & 1) ? l : firstLane)];
                dir[3] = _mm256_load_ps(t);
            }
            __m256 ro[4], rw[4];   // back to rows: lane l's ray in the low half of ro[l], lane l + 4's in the high half
            transposeRows8(org, ro);
            transposeRows8(dir, rw);
            for (int l = 0; l < 4; ++l) {
                _mm_storeu_ps(&moved[o8 + l].org.x, _mm256_castps256_ps128(ro[l]));
                _mm_storeu_ps(&moved[o8 + l].dir.x, _mm256_castps256_ps128(rw[l]));
                _mm_storeu_ps(&moved[o8 + l + 4].org.x, _mm256_extractf128_ps(ro[l], 1));
                _mm_storeu_ps(&moved[o8 + l + 4].dir.x, _mm256_extractf128_ps(rw[l], 1));
            }
        }
#if RT_AVX512
        for (int a = 0; a < 3; ++a) {
            _mm256_store_ps(pr.org[a] + o8, org[a]);
            _mm256_store_ps(pr.dir[a] + o8, dir[a]);
        }
#endif
        __m256 rd[3], on[3], of[3];
        __m256 bad = zero;   // lanes with a value that is not finite (x - x is NaN there)
        unsigned neg[3];
        for (int a = 0; a < 3; ++a) {
            __m256 d = dir[a];
            bad = _mm256_or_ps(bad, _mm256_cmp_ps(_mm256_sub_ps(d, d), zero, _CMP_NEQ_UQ));   // sg::isFinite(r.dir)
            const __m256 tiny = _mm256_cmp_ps(_mm256_andnot_ps(signBit, d), _mm256_set1_ps(1e-30f), _CMP_LT_OS);
            d = _mm256_or_ps(_mm256_andnot_ps(tiny, d), _mm256_and_ps(tiny, _mm256_or_ps(_mm256_and_ps(d, signBit), _mm256_set1_ps(1e-30f))));
            rd[a] = _mm256_div_ps(one, d);
            const __m256 ord = _mm256_mul_ps(org[a], rd[a]);
            const __m256 absB = _mm256_set1_ps(absMax ? absMax[a] : 0.0f);
            const __m256 e = _mm256_mul_ps(_mm256_mul_ps(_mm256_add_ps(_mm256_andnot_ps(signBit, org[a]), absB), _mm256_andnot_ps(signBit, rd[a])),
                                           _mm256_set1_ps(0x1p-20f));
            on[a] = _mm256_add_ps(ord, e);
            of[a] = _mm256_sub_ps(ord, e);
            const __m256 z = _mm256_add_ps(_mm256_add_ps(_mm256_sub_ps(rd[a], rd[a]), _mm256_sub_ps(on[a], on[a])),
                                           _mm256_add_ps(_mm256_sub_ps(of[a], of[a]), _mm256_sub_ps(org[a], org[a])));
            bad = _mm256_or_ps(bad, _mm256_cmp_ps(z, zero, _CMP_NEQ_UQ));
            neg[a] = unsigned(_mm256_movemask_ps(d));
        }
        const __m256 tmin = _mm256_max_ps(org[3], zero);   // r.tmin > 0 ? r.tmin : 0
        const __m256 tmax = dir[3];
        const unsigned nonEmpty = unsigned(_mm256_movemask_ps(_mm256_cmp_ps(tmax, tmin, _CMP_GT_OQ)));
        const unsigned ok = lanes & ~unsigned(_mm256_movemask_ps(bad)) & nonEmpty;
        if (g.sign < 0 && ok) {   // the first ray that fits sets the packet's signs
            const int l = __builtin_ctz(ok);
            g.sign = int((neg[0] >> l) & 1) | int(((neg[1] >> l) & 1) << 1) | int(((neg[2] >> l) & 1) << 2);
        }
        unsigned same = 0xFFu;
        for (int a = 0; a < 3; ++a) same &= (g.sign >> a) & 1 ? neg[a] : ~neg[a];
        const unsigned fits = ok & same;
        g.pm |= uint64_t(fits) << o8;
        g.single |= uint64_t(lanes & ~fits) << o8;
        const __m256 fitV = laneMask8(fits);
        for (int a = 0; a < 3; ++a) {
            _mm256_store_ps(pr.rd[a] + o8, _mm256_blendv_ps(one, rd[a], fitV));
            _mm256_store_ps(pr.on[a] + o8, _mm256_blendv_ps(zero, on[a], fitV));
            _mm256_store_ps(pr.of[a] + o8, _mm256_blendv_ps(zero, of[a], fitV));
            rlo[a] = _mm256_min_ps(rlo[a], _mm256_blendv_ps(inf, rd[a], fitV));
            rhi[a] = _mm256_max_ps(rhi[a], _mm256_blendv_ps(ninf, rd[a], fitV));
            olo[a] = _mm256_min_ps(olo[a], _mm256_blendv_ps(inf, org[a], fitV));
            ohi[a] = _mm256_max_ps(ohi[a], _mm256_blendv_ps(ninf, org[a], fitV));
        }
        _mm256_store_ps(pr.tmin + o8, _mm256_blendv_ps(zero, tmin, fitV));
        _mm256_store_ps(pr.tmax + o8, _mm256_blendv_ps(_mm256_set1_ps(-1.0f), tmax, fitV));
        tminLo = _mm256_min_ps(tminLo, _mm256_blendv_ps(inf, tmin, fitV));
        tmaxHi = _mm256_max_ps(tmaxHi, _mm256_blendv_ps(ninf, tmax, fitV));
    }
    g.rlo = _mm_setr_ps(laneMin8(rlo[0]), laneMin8(rlo[1]), laneMin8(rlo[2]), 0.0f);
    g.rhi = _mm_setr_ps(laneMax8(rhi[0]), laneMax8(rhi[1]), laneMax8(rhi[2]), 0.0f);
    g.olo = _mm_setr_ps(laneMin8(olo[0]), laneMin8(olo[1]), laneMin8(olo[2]), 0.0f);
    g.ohi = _mm_setr_ps(laneMax8(ohi[0]), laneMax8(ohi[1]), laneMax8(ohi[2]), 0.0f);
    g.tminP = laneMin8(tminLo);
    g.tmaxP = laneMax8(tmaxHi);
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
            if (traceTriangles8<AnyHit>(sc.nodes, sc.packets, sc.prims, sc.absMax, sc.ray(i), AnyHit ? nullptr : &sc.hits[i], sc.cullBack))
                found |= uint64_t(1) << i;
        } else {
            float tieT = -1.0f;
            const Ray r = sc.ray(i);
            const bool hit =
                traceTriangles8<false, false, true>(sc.nodes, sc.packets, sc.prims, sc.absMax, r, &sc.hits[i], sc.cullBack, nullptr, 0, &tieT);
            if (hit) found |= uint64_t(1) << i;
            if (tieT >= 0.0f && tieT == (hit ? sc.hits[i].t : r.tmax)) *ties |= uint64_t(1) << i;
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

#if RT_AVX512
#include "raycast/packet_kernel_avx512.inl"
#endif

// The box of slot `slot` of parent (a node's or a leaf's) against the rays of the groups in
// `groups`: bit i for ray i whose own box test passes (leafRayMask; 16 rays per test on AVX-512).
template <bool Wide>
[[gnu::always_inline]] inline uint64_t raysEntering(const Node8& parent, uint32_t slot, const PacketFrustum& fr, const PacketRays& pr,
                                                    unsigned groups) {
    uint64_t m = 0;
#if RT_AVX512
    for (int h = 0; h < kMaxPacket / 16; ++h)
        if ((groups >> (2 * h)) & 3u) m |= uint64_t(leafRayMask16<Wide>(parent, slot, fr.nx, fr.ny, fr.nz, pr, h)) << (16 * h);
#else
    for (unsigned gm = groups; gm; gm &= gm - 1) {
        const int g = __builtin_ctz(gm);
        m |= uint64_t(leafRayMask<Wide>(parent, slot, fr.nx, fr.ny, fr.nz, pr, g)) << (8 * g);
    }
#endif
    return m;
}

// At inner node cur (not the root), entered from slot curSlot of curParent: the rays that enter
// it (their own box tests, current tmax). Two or more: returns true, the packet goes on. None
// or one: returns false, and the one goes on alone (traceTriangles8 from here: the packet's
// interval test has nothing left to share); its hit updates found and pm (AnyHit: it leaves the
// packet) or its tmax and the packet's (tmaxP, tmax8). Ties: see tracePacket8.
template <bool AnyHit, bool Ties = false>
[[gnu::always_inline]] inline bool packetEnters(const PacketScene& sc, const PacketFrustum& fr, PacketRays& pr, uint32_t cur, uint32_t curParent,
                                                uint32_t curSlot, unsigned groups, uint64_t& pm, uint64_t& found, float& tmaxP, __m256& tmax8) {
    const Node8& parent = *reinterpret_cast<const Node8*>(reinterpret_cast<const char*>(sc.nodes) + curParent);
    uint64_t am = raysEntering<Ties>(parent, curSlot, fr, pr, groups) & pm;
    if (__builtin_popcountll(am) > 1) return true;
    if (am) {
        const int i = __builtin_ctzll(am);
        Ray r = sc.ray(i);
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
    const Ray r = sc.ray(i);
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
// tests the leaf's triangles on its own (with AVX-512, two or more of a block of 16 test each
// triangle together). Hits update found; AnyHit: the ray leaves the packet (pm, groups); closest
// hit: the packet's tmax shrinks with the rays'. Ties: see tracePacket8.
template <bool AnyHit, bool Ties = false>
[[gnu::always_inline]] inline void intersectLeafRays(const PacketScene& sc, const PacketFrustum& fr, PacketRays& pr, uint32_t cur, uint32_t curParent,
                                                     uint32_t curSlot, unsigned& groups, uint64_t& pm, uint64_t& found, float& tmaxP, __m256& tmax8) {
    const Node8& parent = *reinterpret_cast<const Node8*>(reinterpret_cast<const char*>(sc.nodes) + curParent);
    const TriPacket4* first = sc.packets + ((cur & ~Node8::kLeafBit) >> 3);
    const TriPacket4* end = first + (cur & 7u);
    // The rays whose own box test passes (it reads only the ray's own tmax: all of them first).
    uint64_t lm = raysEntering<Ties>(parent, curSlot, fr, pr, groups) & pm;
    uint64_t hit = 0;
#if RT_AVX512
    for (int h = 0; h < kMaxPacket / 16; ++h) {   // two or more of a block of 16 (packet_kernel_avx512.inl)
        const unsigned b = unsigned(lm >> (16 * h)) & 0xFFFFu;
        if (!(b & (b - 1))) continue;   // none or one
        hit |= uint64_t(intersectLeafRays16<AnyHit, Ties>(sc, first, end, pr, h, b)) << (16 * h);
        lm &= ~(uint64_t(b) << (16 * h));
    }
#endif
    for (; lm; lm &= lm - 1) {
        const int i = __builtin_ctzll(lm);
        if (intersectLeafRay<AnyHit, Ties>(sc, first, end, pr, i)) hit |= uint64_t(1) << i;
    }
    found |= hit;
    if constexpr (AnyHit) {
        pm &= ~hit;
        for (unsigned gm = groups; gm; gm &= gm - 1)
            if (!((pm >> (8 * __builtin_ctz(gm))) & 0xFF)) groups &= ~(1u << __builtin_ctz(gm));
    } else if (hit) {
        tmaxP = Ties ? widenTmax(packetTmax(pr, groups)) : packetTmax(pr, groups);
        tmax8 = _mm256_set1_ps(tmaxP);
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
                             uint64_t active, TriHit* hits, bool cullBack, uint64_t* ties = nullptr, const RayTransform* move = nullptr,
                             const float* tmaxIn = nullptr) {
    static_assert(!(AnyHit && Ties), "ties are for closest hits");
    if constexpr (Ties) *ties = 0;
    if (n < kMaxPacket) active &= (uint64_t(1) << n) - 1;
    std::conditional_t<Ties, PacketTies, char> tieState;   // (a char, unused, without ties)
    PacketTies* tiesP = nullptr;
    if constexpr (Ties) tiesP = &tieState;
    PacketRays pr;
#if RT_AVX512
    // With move: the rays in the mesh's space are read from pr (PacketScene::ray).
    const PacketGather pg = gatherPacket16(rays, n, active, absMax, pr, move, tmaxIn);
    PacketScene sc{nodes, packets, prims, absMax, move ? nullptr : rays, hits, cullBack, tiesP};
    if (move) {
        sc.moved = &pr;
        sc.world = rays;
        sc.tmaxIn = tmaxIn;
    }
#else
    PacketScratch<Ray> moved;   // with move: the rays in the mesh's space (gatherPacket writes the active groups)
    const PacketGather pg = gatherPacket(rays, n, active, absMax, pr, move, tmaxIn, moved.data());
    const PacketScene sc{nodes, packets, prims, absMax, move ? moved.data() : rays, hits, cullBack, tiesP};
#endif
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
