// lane_kernel.inl - the bodies of shadeLanes, hitFrames, shadowRays and encodeLanes
// (lane_shading.h) for a run of kLaneW lanes starting at lane `off` of a batch: included by
// lane_shading.cpp twice, with SSE2's 4-float vectors (run on lanes 0-3 and 4-7) and AVX2's
// 8-float ones (every lane at once). Each step below names the scalar expression it repeats; the
// order of the operations is that expression's, which is what makes the bits the same:
//   glm::dot(a, b)    = (a.x b.x + a.y b.y) + a.z b.z     glm::length(a) = sqrt(dot(a, a))
//   v / s             = (v.x / s, v.y / s, v.z / s)       (a division, not a reciprocal)
//   std::max(x, 0)    = x < 0 ? 0 : x  = max(0, x)        (NaN stays NaN, -0 stays -0)
// Neither build fuses a multiply and an add (no FMA in either region, -ffp-contract=off). The
// comparisons keep SSE's predicates (cmpgt: ordered, false with a NaN; cmpnle and cmpneq:
// unordered, true with one).
//
// Written over raster/simd.h's names (V, set1, add, ...): included inside a namespace that uses
// one of its sets, with kL (the batch width) defined.

constexpr int kLaneW = int(kW);

inline V vabs(V a) { return vand(a, castF(set1I(0x7fffffff))); }
inline V negate(V a) { return vxor(a, set1(-0.0f)); }                                                    // glm's unary minus: the sign bit flipped
inline V maskOf(unsigned bits) { return castF(cmpeqI(andI(set1I(int(bits)), laneBit()), laneBit())); }   // lane l all ones where bit l is set

struct V3 {
    V x, y, z;
};
inline V3 load3(const float (&a)[3][kL], int off) { return {loadu(a[0] + off), loadu(a[1] + off), loadu(a[2] + off)}; }
inline V3 splat(const vec3& v) { return {set1(v.x), set1(v.y), set1(v.z)}; }
inline V3 add3(const V3& a, const V3& b) { return {add(a.x, b.x), add(a.y, b.y), add(a.z, b.z)}; }
inline V3 sub3(const V3& a, const V3& b) { return {sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z)}; }
inline V3 mul3(const V3& a, const V3& b) { return {mul(a.x, b.x), mul(a.y, b.y), mul(a.z, b.z)}; }
inline V3 scale3(V s, const V3& a) { return {mul(s, a.x), mul(s, a.y), mul(s, a.z)}; }
inline V3 div3(const V3& a, V s) { return {div(a.x, s), div(a.y, s), div(a.z, s)}; }
inline V3 sel3(V mask, const V3& a, const V3& b) { return {sel(mask, a.x, b.x), sel(mask, a.y, b.y), sel(mask, a.z, b.z)}; }
inline V dot(const V3& a, const V3& b) { return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z)); }
inline V3 neg3(const V3& a) { return {negate(a.x), negate(a.y), negate(a.z)}; }

// sampleLight(L, p) in lanes: the unit vector toward the light, the distance (infinite for a
// sun) and the radiance arriving (1/r^2, the spot's smoothstep between its cones).
struct LightLanes {
    V3 toL, rad;
    V dist;
    LightLanes(const DrawLight& L, const V3& p) {
        const V zero = zeroV(), one = set1(1.0f);
        rad = splat(L.radiance);
        if (L.type == LightType::Directional) {
            toL = splat(-L.direction);
            dist = set1(std::numeric_limits<float>::infinity());
            return;
        }
        const V3 d = sub3(splat(L.position), p);
        const V dist2 = dot(d, d);
        dist = vsqrt(dist2);
        toL = sel3(cmpgt(dist, zero), div3(d, dist), splat(vec3(0, 1, 0)));
        if (L.inverseSquare) rad = div3(rad, vmax(set1(1e-8f), dist2));   // radiance / max(dist2, 1e-8)
        if (L.type == LightType::Spot) {
            const V c = dot(neg3(toL), splat(L.direction));   // dot(-toLight, direction)
            V t = L.cosInner > L.cosOuter ? div(sub(c, set1(L.cosOuter)), set1(L.cosInner - L.cosOuter)) : vand(cmpge(c, set1(L.cosOuter)), one);
            t = sel(cmplt(t, zero), zero, sel(cmplt(one, t), one, t));   // std::clamp(t, 0, 1)
            const V k = mul(mul(t, t), sub(set1(3.0f), mul(set1(2.0f), t)));
            rad = V3{mul(rad.x, k), mul(rad.y, k), mul(rad.z, k)};
        }
    }
};

// Whether radiance rad is not (0, 0, 0) (vec3's !=: NaN counts as not equal).
inline V nonZero(const V3& rad) {
    const V zero = zeroV();
    return vor(vor(cmpneq(rad.x, zero), cmpneq(rad.y, zero)), cmpneq(rad.z, zero));
}

// Lanes [off, off + kLaneW) of b (padded: every lane holds a hit's inputs); returns the lanes
// shaded as bits from bit off.
unsigned shadeRun(const LaneBatch& b, const FrameInput& f, float rgb[3][kL], int off) {
    const unsigned valid = ((1u << b.count) - 1) >> off & ((1u << kLaneW) - 1);
    const V zero = zeroV(), one = set1(1.0f);

    // The coefficients, lane by lane (coefficientsOfMesh).
    alignas(32) float ka[kLaneW], kd[kLaneW], ks[kLaneW], shin[kLaneW], sc[3][kLaneW], em[3][kLaneW];
    unsigned tintedBits = 0, smoothBits = 0;
    for (int l = 0; l < kLaneW; ++l) {
        const SurfaceCoefficients& c = *b.coeff[off + l];
        ka[l] = c.ka, kd[l] = c.kd, ks[l] = c.ks, shin[l] = c.shininess;
        for (int a = 0; a < 3; ++a) sc[a][l] = c.specularColor[a], em[a][l] = c.emissive[a];
        tintedBits |= unsigned(c.specularTinted) << l;
        smoothBits |= unsigned(b.smooth[off + l]) << l;
    }
    const V tinted = maskOf(tintedBits);

    // shadeMeshHit: albedo = (w0 albedoV[0] + w1 albedoV[1] + w2 albedoV[2]) * texColor,
    // n = normalize(w0 Nv[0] + w1 Nv[1] + w2 Nv[2]) where it is longer than 1e-20, else ng; ng without vertex normals.
    const V w0 = loadu(b.w[0] + off), w1 = loadu(b.w[1] + off), w2 = loadu(b.w[2] + off);
    V3 albedo = add3(add3(scale3(w0, load3(b.va[0], off)), scale3(w1, load3(b.va[1], off))), scale3(w2, load3(b.va[2], off)));
    if (const unsigned textured = (b.textured >> off) & valid) {   // (x * 1 is x bit for bit: the others multiply by 1, or not at all)
        alignas(32) float tex[3][kLaneW];
        for (int a = 0; a < 3; ++a)
            for (int l = 0; l < kLaneW; ++l) tex[a][l] = (textured >> l) & 1 ? b.tex[a][off + l] : 1.0f;
        albedo = mul3(albedo, V3{loadu(tex[0]), loadu(tex[1]), loadu(tex[2])});
    }
    const V3 p = load3(b.p, off), ng = load3(b.ng, off);
    V3 n = add3(add3(scale3(w0, load3(b.vn[0], off)), scale3(w1, load3(b.vn[1], off))), scale3(w2, load3(b.vn[2], off)));
    const V nLen = vsqrt(dot(n, n));
    n = sel3(vand(maskOf(smoothBits), cmpgt(nLen, set1(1e-20f))), div3(n, nLen), ng);

    // shadeTerms: v = toViewer(eye, p); mul = ka L_ambient; add = emissive.
    V3 v = sub3(splat(f.camera.eye), p);
    const V vLen = vsqrt(dot(v, v));
    v = sel3(cmpgt(vLen, zero), div3(v, vLen), splat(vec3(0, 0, 1)));
    const V3 ambient = splat(f.ambientLight);
    V3 tMul = scale3(loadu(ka), ambient), tAdd = V3{loadu(em[0]), loadu(em[1]), loadu(em[2])};
    const V3 specColor{loadu(sc[0]), loadu(sc[1]), loadu(sc[2])};
    const V kdV = loadu(kd), ksV = loadu(ks);
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
            for (int l = 0; l < kLaneW; ++l) {
                known |= unsigned((b.known[off + l] >> i) & 1) << l;
                lit |= unsigned((b.lit[off + l] >> i) & 1) << l;
            }
            const unsigned reaches = unsigned(movemask(vand(cmpgt(nl, zero), nonZero(rad))));
            fallback |= ~known & reaches;
            visible = vand(maskOf(~(known & ~lit & reaches)), one);   // 0 where traced and blocked
        }
        // lightTerms(coefficients, n, v, sample): zero where n.l <= 0.
        V spec;
        if (!blinn) {
            const V twoNl = mul(set1(2.0f), nl);
            const V3 r = sub3(scale3(twoNl, n), toL);
            spec = vmax(zero, dot(r, v));
        } else {
            const V3 h = add3(toL, v);
            const V hLen = vsqrt(dot(h, h));
            spec = vand(cmpgt(hLen, zero), vmax(zero, dot(n, div3(h, hLen))));
        }
        const V front = cmpnle(nl, zero), active = cmpnle(visible, zero);
        alignas(32) float s[kLaneW];
        storeu(s, spec);
        const unsigned powered = unsigned(movemask(vand(vand(front, active), cmpgt(spec, zero)))) & valid;
        for (int l = 0; l < kLaneW; ++l) s[l] = (powered >> l) & 1 ? std::pow(s[l], shin[l]) : 0.0f;
        spec = loadu(s);
        const V3 ln = scale3(nl, rad);   // radiance * nl
        const V ksSpec = mul(ksV, spec);
        V3 liMul = scale3(kdV, ln);
        liMul = sel3(tinted, add3(liMul, scale3(ksSpec, ln)), liMul);
        const V3 liAdd = sel3(tinted, V3{zero, zero, zero}, mul3(scale3(ksSpec, ln), specColor));
        const V3 none{zero, zero, zero};
        // shadeTerms: mul += w li.mul, add += w li.add where the light is visible at all.
        tMul = sel3(active, add3(tMul, scale3(visible, sel3(front, liMul, none))), tMul);
        tAdd = sel3(active, add3(tAdd, scale3(visible, sel3(front, liAdd, none))), tAdd);
    }

    // ShadeTerms::apply: albedo * mul + add.
    const V3 color = add3(mul3(albedo, tMul), tAdd);
    storeu(rgb[0] + off, color.x);
    storeu(rgb[1] + off, color.y);
    storeu(rgb[2] + off, color.z);
    return (valid & ~fallback) << off;
}

// hitFrames for lanes [off, off + kLaneW) (padded).
void framesRun(FrameLanes& b, int off) {
    const V zero = zeroV();
    const V3 P0 = load3(b.P[0], off), P1 = load3(b.P[1], off), P2 = load3(b.P[2], off);
    const V b1 = loadu(b.b1 + off), b2 = loadu(b.b2 + off);
    const V w0 = sub(sub(set1(1.0f), b1), b2);   // 1 - b1 - b2
    const V3 p = add3(add3(scale3(w0, P0), scale3(b1, P1)), scale3(b2, P2));
    // glm::cross(e1, e2) = (e1.y e2.z - e2.y e1.z, e1.z e2.x - e2.z e1.x, e1.x e2.y - e2.x e1.y)
    const V3 e1 = sub3(P1, P0), e2 = sub3(P2, P0);
    V3 gn{sub(mul(e1.y, e2.z), mul(e2.y, e1.z)), sub(mul(e1.z, e2.x), mul(e2.z, e1.x)), sub(mul(e1.x, e2.y), mul(e2.x, e1.y))};
    const V gl = vsqrt(dot(gn, gn));
    gn = sel3(cmpgt(gl, zero), div3(gn, gl), splat(vec3(0, 1, 0)));
    gn = sel3(maskOf(b.mirrored >> off), neg3(gn), gn);
    const V back = cmpgt(dot(gn, load3(b.dir, off)), zero);
    const V3 ng = sel3(back, neg3(gn), gn);
    storeu(b.p[0] + off, p.x), storeu(b.p[1] + off, p.y), storeu(b.p[2] + off, p.z);
    storeu(b.gn[0] + off, gn.x), storeu(b.gn[1] + off, gn.y), storeu(b.gn[2] + off, gn.z);
    storeu(b.ng[0] + off, ng.x), storeu(b.ng[1] + off, ng.y), storeu(b.ng[2] + off, ng.z);
    b.back |= (unsigned(movemask(back)) << off) & ((1u << b.count) - 1);
}

// shadowRays for lanes [off, off + kLaneW) (padded): their bits into b.reaches, their rays into b.rays.
void shadowRun(ShadowLanes& b, const DrawLight& L, int off) {
    const V zero = zeroV();
    const V3 p = load3(b.p, off), ng = load3(b.ng, off);
    const LightLanes ls(L, p);
    const V ngl = dot(ng, ls.toL);
    const unsigned reaches = (unsigned(movemask(vand(cmpgt(ngl, zero), nonZero(ls.rad)))) << off) & ((1u << b.count) - 1);   // sampleReaches(ls, ng)
    b.reaches |= reaches;
    if (!reaches) return;
    // Tracer::shadowRay: side = ng.l >= 0 ? 1 : -1; eps = offsetScale(p) =
    // 1e-4 (1 + std::max(|x|, std::max(|y|, |z|))) (std::max(a, b) = b > a ? b : a);
    // org = p + (side eps) ng; tmax = distance (1 - 1e-4) - eps where the distance is finite.
    const V side = sel(cmpge(ngl, zero), set1(1.0f), set1(-1.0f));
    const V eps = mul(set1(1e-4f), add(set1(1.0f), vmax(vmax(vabs(p.z), vabs(p.y)), vabs(p.x))));
    const V3 org = add3(p, scale3(mul(side, eps), ng));
    const V finite = cmpeq(sub(ls.dist, ls.dist), zero);
    const V tmax = sel(finite, sub(mul(ls.dist, set1(1.0f - 1e-4f)), eps), set1(std::numeric_limits<float>::infinity()));
    alignas(32) float o[4][kLaneW], d[4][kLaneW];   // (org, tmin = 0) and (dir, tmax) per lane, SoA
    storeu(o[0], org.x), storeu(o[1], org.y), storeu(o[2], org.z), storeu(o[3], zero);
    storeu(d[0], ls.toL.x), storeu(d[1], ls.toL.y), storeu(d[2], ls.toL.z), storeu(d[3], tmax);
    for (int q = 0; q < kLaneW; q += 4) {   // four rays at a time: SoA to the rays' own layout
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

#include "raster/srgb_lanes.inl"

// encodeLanes for lanes [off, off + kLaneW): each channel's byte (encodeSrgb), alpha 255, and
// magenta (bytes 255, 0, 255, 255) where a channel is not finite (x - x is NaN exactly there).
void encodeRun(const float rgb[3][kL], uint32_t out[kL], int off) {
    const SrgbEncoder& t = srgbEncoder();
    const V r = loadu(rgb[0] + off), g = loadu(rgb[1] + off), b = loadu(rgb[2] + off);
    const V finite = cmpeq(add(add(sub(r, r), sub(g, g)), sub(b, b)), zeroV());
    const VI word = orI(orI(encodeSrgb(r, t), slliI(encodeSrgb(g, t), 8)), orI(slliI(encodeSrgb(b, t), 16), set1I(int(0xFF000000u))));
    storeuI(out + off, selI(castI(finite), word, set1I(int(0xFFFF00FFu))));
}
