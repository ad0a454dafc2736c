// lane_kernel.inl - the bodies of shadeLanes, hitFrames and shadowRays (lane_shading.h) for a
// run of LANE_W lanes starting at lane `off` of a batch: included by lane_shading.cpp twice,
// with SSE2's 4-float vectors (LANE_W 4, run on lanes 0-3 and 4-7) and AVX2's 8-float ones
// (LANE_W 8, every lane at once). Each step below names the scalar expression it repeats; the
// order of the operations is that expression's, which is what makes the bits the same:
//   glm::dot(a, b)    = (a.x b.x + a.y b.y) + a.z b.z     glm::length(a) = sqrt(dot(a, a))
//   v / s             = (v.x / s, v.y / s, v.z / s)       (a division, not a reciprocal)
//   std::max(x, 0)    = x < 0 ? 0 : x  = max(0, x)        (NaN stays NaN, -0 stays -0)
// Neither build fuses a multiply and an add (no FMA in either region, -ffp-contract=off). The
// comparisons keep SSE's predicates (cmpgt: ordered, false with a NaN; cmpnle and cmpneq:
// unordered, true with one).
//
// Expects: LANE_W, and the vector operations below defined for V by the includer.

constexpr int kW = LANE_W;

struct V3 {
    V x, y, z;
};
inline V3 load3(const float (&a)[3][kL], int off) { return {load(a[0] + off), load(a[1] + off), load(a[2] + off)}; }
inline V3 splat(const vec3& v) { return {set1(v.x), set1(v.y), set1(v.z)}; }
inline V3 add(const V3& a, const V3& b) { return {add(a.x, b.x), add(a.y, b.y), add(a.z, b.z)}; }
inline V3 sub(const V3& a, const V3& b) { return {sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z)}; }
inline V3 mul(const V3& a, const V3& b) { return {mul(a.x, b.x), mul(a.y, b.y), mul(a.z, b.z)}; }
inline V3 mul(V s, const V3& a) { return {mul(s, a.x), mul(s, a.y), mul(s, a.z)}; }
inline V3 div(const V3& a, V s) { return {div(a.x, s), div(a.y, s), div(a.z, s)}; }
inline V3 sel(V mask, const V3& a, const V3& b) { return {sel(mask, a.x, b.x), sel(mask, a.y, b.y), sel(mask, a.z, b.z)}; }
inline V dot(const V3& a, const V3& b) { return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z)); }
inline V3 neg(const V3& a) { return {negate(a.x), negate(a.y), negate(a.z)}; }   // glm's -a: the sign bits flipped

// sampleLight(L, p) in lanes: the unit vector toward the light, the distance (infinite for a
// sun) and the radiance arriving (1/r^2, the spot's smoothstep between its cones).
struct LightLanes {
    V3 toL, rad;
    V dist;
    LightLanes(const DrawLight& L, const V3& p) {
        const V zero = setzero(), one = set1(1.0f);
        rad = splat(L.radiance);
        if (L.type == LightType::Directional) {
            toL = splat(-L.direction);
            dist = set1(std::numeric_limits<float>::infinity());
            return;
        }
        const V3 d = sub(splat(L.position), p);
        const V dist2 = dot(d, d);
        dist = vsqrt(dist2);
        toL = sel(cmpgt(dist, zero), div(d, dist), splat(vec3(0, 1, 0)));
        if (L.inverseSquare) rad = div(rad, vmax(set1(1e-8f), dist2));   // radiance / max(dist2, 1e-8)
        if (L.type == LightType::Spot) {
            const V c = dot(neg(toL), splat(L.direction));   // dot(-toLight, direction)
            V t = L.cosInner > L.cosOuter ? div(sub(c, set1(L.cosOuter)), set1(L.cosInner - L.cosOuter)) : vand(cmpge(c, set1(L.cosOuter)), one);
            t = sel(cmplt(t, zero), zero, sel(cmplt(one, t), one, t));   // std::clamp(t, 0, 1)
            const V k = mul(mul(t, t), sub(set1(3.0f), mul(set1(2.0f), t)));
            rad = V3{mul(rad.x, k), mul(rad.y, k), mul(rad.z, k)};
        }
    }
};

// Whether radiance rad is not (0, 0, 0) (vec3's !=: NaN counts as not equal).
inline V nonZero(const V3& rad) {
    const V zero = setzero();
    return vor(vor(cmpneq(rad.x, zero), cmpneq(rad.y, zero)), cmpneq(rad.z, zero));
}

// Lanes [off, off + kW) of b (padded: every lane holds a hit's inputs); returns the lanes
// shaded as bits from bit off.
unsigned shadeRun(const LaneBatch& b, const FrameInput& f, float rgb[3][kL], int off) {
    const unsigned valid = ((1u << b.count) - 1) >> off & ((1u << kW) - 1);
    const V zero = setzero(), one = set1(1.0f);

    // The coefficients, lane by lane (coefficientsOfMesh).
    alignas(32) float ka[kW], kd[kW], ks[kW], shin[kW], sc[3][kW], em[3][kW];
    unsigned tintedBits = 0, smoothBits = 0;
    for (int l = 0; l < kW; ++l) {
        const SurfaceCoefficients& c = *b.coeff[off + l];
        ka[l] = c.ka, kd[l] = c.kd, ks[l] = c.ks, shin[l] = c.shininess;
        for (int a = 0; a < 3; ++a) sc[a][l] = c.specularColor[a], em[a][l] = c.emissive[a];
        tintedBits |= unsigned(c.specularTinted) << l;
        smoothBits |= unsigned(b.smooth[off + l]) << l;
    }
    const V tinted = maskOf(tintedBits);

    // shadeMeshHit: albedo = (w0 albedoV[0] + w1 albedoV[1] + w2 albedoV[2]) * texColor,
    // n = normalize(w0 Nv[0] + w1 Nv[1] + w2 Nv[2]) where it is longer than 1e-20, else ng; ng without vertex normals.
    const V w0 = load(b.w[0] + off), w1 = load(b.w[1] + off), w2 = load(b.w[2] + off);
    V3 albedo = add(add(mul(w0, load3(b.va[0], off)), mul(w1, load3(b.va[1], off))), mul(w2, load3(b.va[2], off)));
    if (const unsigned textured = (b.textured >> off) & valid) {   // (x * 1 is x bit for bit: the others multiply by 1, or not at all)
        alignas(32) float tex[3][kW];
        for (int a = 0; a < 3; ++a)
            for (int l = 0; l < kW; ++l) tex[a][l] = (textured >> l) & 1 ? b.tex[a][off + l] : 1.0f;
        albedo = mul(albedo, V3{load(tex[0]), load(tex[1]), load(tex[2])});
    }
    const V3 p = load3(b.p, off), ng = load3(b.ng, off);
    V3 n = add(add(mul(w0, load3(b.vn[0], off)), mul(w1, load3(b.vn[1], off))), mul(w2, load3(b.vn[2], off)));
    const V nLen = vsqrt(dot(n, n));
    n = sel(vand(maskOf(smoothBits), cmpgt(nLen, set1(1e-20f))), div(n, nLen), ng);

    // shadeTerms: v = toViewer(eye, p); mul = ka L_ambient; add = emissive.
    V3 v = sub(splat(f.camera.eye), p);
    const V vLen = vsqrt(dot(v, v));
    v = sel(cmpgt(vLen, zero), div(v, vLen), splat(vec3(0, 0, 1)));
    const V3 ambient = splat(f.ambientLight);
    V3 tMul = mul(load(ka), ambient), tAdd = V3{load(em[0]), load(em[1]), load(em[2])};
    const V3 specColor{load(sc[0]), load(sc[1]), load(sc[2])};
    const V kdV = load(kd), ksV = load(ks);
    const bool blinn = f.settings.reflection == ReflectionModel::BlinnPhong;

    unsigned fallback = 0;
    for (size_t i = 0; i < f.lights.size(); ++i) {
        const DrawLight& L = f.lights[i];
        const LightLanes ls(L, p);
        const V3 &toL = ls.toL, &rad = ls.rad;
        const V nl = dot(n, toL);
        // Tracer::lightVisibility: 1 without shadows; with them, the packets' answer where they
        // traced the light, 1 where it does not reach the shading normal (sampleReaches: its terms
        // are zero there), and where it reaches it but was not traced, the lane goes back to trace().
        V visible = one;
        if (f.settings.shadows) {
            unsigned known = 0, lit = 0;
            for (int l = 0; l < kW; ++l) {
                known |= unsigned((b.known[off + l] >> i) & 1) << l;
                lit |= unsigned((b.lit[off + l] >> i) & 1) << l;
            }
            const unsigned reaches = bitsOf(vand(cmpgt(nl, zero), nonZero(rad)));
            fallback |= ~known & reaches;
            visible = vand(maskOf(~(known & ~lit & reaches)), one);   // 0 where traced and blocked
        }
        // lightTerms(coefficients, n, v, sample): zero where n.l <= 0.
        V spec;
        if (!blinn) {
            const V twoNl = mul(set1(2.0f), nl);
            const V3 r = sub(mul(twoNl, n), toL);
            spec = vmax(zero, dot(r, v));
        } else {
            const V3 h = add(toL, v);
            const V hLen = vsqrt(dot(h, h));
            spec = vand(cmpgt(hLen, zero), vmax(zero, dot(n, div(h, hLen))));
        }
        const V front = cmpnle(nl, zero), active = cmpnle(visible, zero);
        alignas(32) float s[kW];
        store(s, spec);
        const unsigned powered = bitsOf(vand(vand(front, active), cmpgt(spec, zero))) & valid;
        for (int l = 0; l < kW; ++l) s[l] = (powered >> l) & 1 ? std::pow(s[l], shin[l]) : 0.0f;
        spec = load(s);
        const V3 ln = mul(nl, rad);   // radiance * nl
        const V ksSpec = mul(ksV, spec);
        V3 liMul = mul(kdV, ln);
        liMul = sel(tinted, add(liMul, mul(ksSpec, ln)), liMul);
        const V3 liAdd = sel(tinted, V3{zero, zero, zero}, mul(mul(ksSpec, ln), specColor));
        const V3 none{zero, zero, zero};
        // shadeTerms: mul += w li.mul, add += w li.add where the light is visible at all.
        tMul = sel(active, add(tMul, mul(visible, sel(front, liMul, none))), tMul);
        tAdd = sel(active, add(tAdd, mul(visible, sel(front, liAdd, none))), tAdd);
    }

    // ShadeTerms::apply: albedo * mul + add.
    const V3 color = add(mul(albedo, tMul), tAdd);
    store(rgb[0] + off, color.x);
    store(rgb[1] + off, color.y);
    store(rgb[2] + off, color.z);
    return (valid & ~fallback) << off;
}

// hitFrames for lanes [off, off + kW) (padded).
void framesRun(FrameLanes& b, int off) {
    const V zero = setzero();
    const V3 P0 = load3(b.P[0], off), P1 = load3(b.P[1], off), P2 = load3(b.P[2], off);
    const V b1 = load(b.b1 + off), b2 = load(b.b2 + off);
    const V w0 = sub(sub(set1(1.0f), b1), b2);   // 1 - b1 - b2
    const V3 p = add(add(mul(w0, P0), mul(b1, P1)), mul(b2, P2));
    // glm::cross(e1, e2) = (e1.y e2.z - e2.y e1.z, e1.z e2.x - e2.z e1.x, e1.x e2.y - e2.x e1.y)
    const V3 e1 = sub(P1, P0), e2 = sub(P2, P0);
    V3 gn{sub(mul(e1.y, e2.z), mul(e2.y, e1.z)), sub(mul(e1.z, e2.x), mul(e2.z, e1.x)), sub(mul(e1.x, e2.y), mul(e2.x, e1.y))};
    const V gl = vsqrt(dot(gn, gn));
    gn = sel(cmpgt(gl, zero), div(gn, gl), splat(vec3(0, 1, 0)));
    gn = sel(maskOf(b.mirrored >> off), neg(gn), gn);
    const V back = cmpgt(dot(gn, load3(b.dir, off)), zero);
    const V3 ng = sel(back, neg(gn), gn);
    store(b.p[0] + off, p.x), store(b.p[1] + off, p.y), store(b.p[2] + off, p.z);
    store(b.gn[0] + off, gn.x), store(b.gn[1] + off, gn.y), store(b.gn[2] + off, gn.z);
    store(b.ng[0] + off, ng.x), store(b.ng[1] + off, ng.y), store(b.ng[2] + off, ng.z);
    b.back |= (bitsOf(back) << off) & ((1u << b.count) - 1);
}

// shadowRays for lanes [off, off + kW) (padded): their bits into b.reaches, their rays into b.rays.
void shadowRun(ShadowLanes& b, const DrawLight& L, int off) {
    const V zero = setzero();
    const V3 p = load3(b.p, off), ng = load3(b.ng, off);
    const LightLanes ls(L, p);
    const V ngl = dot(ng, ls.toL);
    const unsigned reaches = (bitsOf(vand(cmpgt(ngl, zero), nonZero(ls.rad))) << off) & ((1u << b.count) - 1);   // sampleReaches(ls, ng)
    b.reaches |= reaches;
    if (!reaches) return;
    // Tracer::shadowRay: side = ng.l >= 0 ? 1 : -1; eps = offsetScale(p) =
    // 1e-4 (1 + std::max(|x|, std::max(|y|, |z|))) (std::max(a, b) = b > a ? b : a);
    // org = p + (side eps) ng; tmax = distance (1 - 1e-4) - eps where the distance is finite.
    const V side = sel(cmpge(ngl, zero), set1(1.0f), set1(-1.0f));
    const V eps = mul(set1(1e-4f), add(set1(1.0f), vmax(vmax(vabs(p.z), vabs(p.y)), vabs(p.x))));
    const V3 org = add(p, mul(mul(side, eps), ng));
    const V finite = cmpeq(sub(ls.dist, ls.dist), zero);
    const V tmax = sel(finite, sub(mul(ls.dist, set1(1.0f - 1e-4f)), eps), set1(std::numeric_limits<float>::infinity()));
    alignas(32) float o[4][kW], d[4][kW];   // (org, tmin = 0) and (dir, tmax) per lane, SoA
    store(o[0], org.x), store(o[1], org.y), store(o[2], org.z), store(o[3], zero);
    store(d[0], ls.toL.x), store(d[1], ls.toL.y), store(d[2], ls.toL.z), store(d[3], tmax);
    for (int q = 0; q < kW; q += 4) {   // four rays at a time: SoA to the rays' own layout
        __m128 ov[4], dv[4];
        for (int a = 0; a < 4; ++a) ov[a] = _mm_load_ps(o[a] + q), dv[a] = _mm_load_ps(d[a] + q);
        _MM_TRANSPOSE4_PS(ov[0], ov[1], ov[2], ov[3]);
        _MM_TRANSPOSE4_PS(dv[0], dv[1], dv[2], dv[3]);
        for (int l = 0; l < 4; ++l) {
            _mm_storeu_ps(&b.rays[off + q + l].org.x, ov[l]);
            _mm_storeu_ps(&b.rays[off + q + l].dir.x, dv[l]);
        }
    }
}
