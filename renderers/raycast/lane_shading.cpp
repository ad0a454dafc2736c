// lane_shading.cpp - shadeLanes (lane_shading.h): Tracer::shadeMeshHit's smooth branch and
// rnd::shadeTerms / sampleLight / lightTerms (renderers/common/shading.cpp) for four hits at once
// in SSE2. Each step below names the scalar expression it repeats; the order of the operations
// is that expression's, which is what makes the bits the same:
//   glm::dot(a, b)    = (a.x b.x + a.y b.y) + a.z b.z     glm::length(a) = sqrt(dot(a, a))
//   v / s             = (v.x / s, v.y / s, v.z / s)       (a division, not a reciprocal)
//   std::max(x, 0)    = x < 0 ? 0 : x  = _mm_max_ps(0, x)  (NaN stays NaN, -0 stays -0)
// The baseline x86-64 target has no FMA, so neither side fuses a multiply and an add.
#include "raycast/lane_shading.h"

#include <emmintrin.h>

#include <cmath>
#include <limits>

namespace rnd::raycast {

using namespace sg;

namespace {

using V = __m128;
constexpr int kL = LaneBatch::kLanes;

V set1(float x) { return _mm_set1_ps(x); }
V add(V a, V b) { return _mm_add_ps(a, b); }
V sub(V a, V b) { return _mm_sub_ps(a, b); }
V mul(V a, V b) { return _mm_mul_ps(a, b); }
V div(V a, V b) { return _mm_div_ps(a, b); }
V sel(V mask, V a, V b) { return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b)); }   // mask ? a : b
V load(const float* p) { return _mm_load_ps(p); }
V maskOf(unsigned bits) {   // lane l all ones where bit l is set
    const __m128i b = _mm_set1_epi32(int(bits)), lane = _mm_setr_epi32(1, 2, 4, 8);
    return _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(b, lane), lane));
}
unsigned bitsOf(V mask) { return unsigned(_mm_movemask_ps(mask)); }

struct V3 {
    V x, y, z;
};
V3 load3(const float (&a)[3][kL]) { return {load(a[0]), load(a[1]), load(a[2])}; }
V3 splat(const vec3& v) { return {set1(v.x), set1(v.y), set1(v.z)}; }
V3 add(const V3& a, const V3& b) { return {add(a.x, b.x), add(a.y, b.y), add(a.z, b.z)}; }
V3 sub(const V3& a, const V3& b) { return {sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z)}; }
V3 mul(const V3& a, const V3& b) { return {mul(a.x, b.x), mul(a.y, b.y), mul(a.z, b.z)}; }
V3 mul(V s, const V3& a) { return {mul(s, a.x), mul(s, a.y), mul(s, a.z)}; }
V3 div(const V3& a, V s) { return {div(a.x, s), div(a.y, s), div(a.z, s)}; }
V3 sel(V mask, const V3& a, const V3& b) { return {sel(mask, a.x, b.x), sel(mask, a.y, b.y), sel(mask, a.z, b.z)}; }
V dot(const V3& a, const V3& b) { return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z)); }

// -a (glm's unary minus: the sign bits flipped).
V3 neg(const V3& a) {
    const V signBit = set1(-0.0f);
    return {_mm_xor_ps(a.x, signBit), _mm_xor_ps(a.y, signBit), _mm_xor_ps(a.z, signBit)};
}

// sampleLight(L, p) in lanes: the unit vector toward the light, the distance (infinite for a
// sun) and the radiance arriving (1/r^2, the spot's smoothstep between its cones).
struct LightLanes {
    V3 toL, rad;
    V dist;
    LightLanes(const DrawLight& L, const V3& p) {
        const V zero = _mm_setzero_ps(), one = set1(1.0f);
        rad = splat(L.radiance);
        if (L.type == LightType::Directional) {
            toL = splat(-L.direction);
            dist = set1(std::numeric_limits<float>::infinity());
            return;
        }
        const V3 d = sub(splat(L.position), p);
        const V dist2 = dot(d, d);
        dist = _mm_sqrt_ps(dist2);
        toL = sel(_mm_cmpgt_ps(dist, zero), div(d, dist), splat(vec3(0, 1, 0)));
        if (L.inverseSquare) rad = div(rad, _mm_max_ps(set1(1e-8f), dist2));   // radiance / max(dist2, 1e-8)
        if (L.type == LightType::Spot) {
            const V c = dot(neg(toL), splat(L.direction));   // dot(-toLight, direction)
            V t = L.cosInner > L.cosOuter ? div(sub(c, set1(L.cosOuter)), set1(L.cosInner - L.cosOuter))
                                          : _mm_and_ps(_mm_cmpge_ps(c, set1(L.cosOuter)), one);
            t = sel(_mm_cmplt_ps(t, zero), zero, sel(_mm_cmplt_ps(one, t), one, t));   // std::clamp(t, 0, 1)
            const V k = mul(mul(t, t), sub(set1(3.0f), mul(set1(2.0f), t)));
            rad = V3{mul(rad.x, k), mul(rad.y, k), mul(rad.z, k)};
        }
    }
};

// Whether radiance rad is not (0, 0, 0) (vec3's !=: NaN counts as not equal).
V nonZero(const V3& rad) {
    const V zero = _mm_setzero_ps();
    return _mm_or_ps(_mm_or_ps(_mm_cmpneq_ps(rad.x, zero), _mm_cmpneq_ps(rad.y, zero)), _mm_cmpneq_ps(rad.z, zero));
}

// Lanes count..kL-1 take lane 0's inputs (their results are not used).
void pad(LaneBatch& b) {
    for (int l = b.count; l < kL; ++l) {
        for (int a = 0; a < 3; ++a) {
            b.p[a][l] = b.p[a][0];
            b.ng[a][l] = b.ng[a][0];
            b.w[a][l] = b.w[a][0];
            for (int k = 0; k < 3; ++k) {
                b.vn[k][a][l] = b.vn[k][a][0];
                b.va[k][a][l] = b.va[k][a][0];
            }
        }
        b.smooth[l] = b.smooth[0];
        b.coeff[l] = b.coeff[0];
        b.known[l] = b.known[0];
        b.lit[l] = b.lit[0];
    }
}

}   // namespace

bool laneShadingApplies(const FrameInput& f, bool shadowPackets) {
    const RenderSettings& s = f.settings;
    if (s.shading != ShadingModel::Phong || s.reflection == ReflectionModel::Pbr || f.lights.size() > 64) return false;
    if (!s.shadows || f.lights.empty()) return true;
    if (!shadowPackets) return false;   // shadow rays through cut-outs or blended layers
    for (const DrawLight& L : f.lights)
        if (L.hasSize() && s.shadowRays > 1) return false;   // soft shadows (Tracer::softVisibility)
    return true;
}

unsigned shadeLanes(LaneBatch& b, const FrameInput& f, float rgb[3][kL]) {
    pad(b);
    const unsigned valid = (1u << b.count) - 1;
    const V zero = _mm_setzero_ps(), one = set1(1.0f);

    // The coefficients, lane by lane (coefficientsOfMesh).
    alignas(16) float ka[kL], kd[kL], ks[kL], shin[kL], sc[3][kL], em[3][kL];
    unsigned tintedBits = 0;
    for (int l = 0; l < kL; ++l) {
        const SurfaceCoefficients& c = *b.coeff[l];
        ka[l] = c.ka, kd[l] = c.kd, ks[l] = c.ks, shin[l] = c.shininess;
        for (int a = 0; a < 3; ++a) sc[a][l] = c.specularColor[a], em[a][l] = c.emissive[a];
        tintedBits |= unsigned(c.specularTinted) << l;
    }
    const V tinted = maskOf(tintedBits);

    // shadeMeshHit: albedo = (w0 albedoV[0] + w1 albedoV[1] + w2 albedoV[2]) * texColor,
    // n = normalize(w0 Nv[0] + w1 Nv[1] + w2 Nv[2]) where it is longer than 1e-20, else ng; ng without vertex normals.
    const V w0 = load(b.w[0]), w1 = load(b.w[1]), w2 = load(b.w[2]);
    V3 albedo = add(add(mul(w0, load3(b.va[0])), mul(w1, load3(b.va[1]))), mul(w2, load3(b.va[2])));
    if (const unsigned textured = b.textured & valid) {   // (x * 1 is x bit for bit: the others multiply by 1, or not at all)
        for (int l = 0; l < kL; ++l)
            if (!((textured >> l) & 1))
                for (int a = 0; a < 3; ++a) b.tex[a][l] = 1.0f;
        albedo = mul(albedo, load3(b.tex));
    }
    const V3 p = load3(b.p), ng = load3(b.ng);
    V3 n = add(add(mul(w0, load3(b.vn[0])), mul(w1, load3(b.vn[1]))), mul(w2, load3(b.vn[2])));
    const V nLen = _mm_sqrt_ps(dot(n, n));
    const V smooth = maskOf(unsigned(b.smooth[0]) | unsigned(b.smooth[1]) << 1 | unsigned(b.smooth[2]) << 2 | unsigned(b.smooth[3]) << 3);
    n = sel(_mm_and_ps(smooth, _mm_cmpgt_ps(nLen, set1(1e-20f))), div(n, nLen), ng);

    // shadeTerms: v = toViewer(eye, p); mul = ka L_ambient; add = emissive.
    V3 v = sub(splat(f.camera.eye), p);
    const V vLen = _mm_sqrt_ps(dot(v, v));
    v = sel(_mm_cmpgt_ps(vLen, zero), div(v, vLen), splat(vec3(0, 0, 1)));
    const V3 ambient = splat(f.ambientLight);
    V3 tMul = mul(load(ka), ambient), tAdd = load3(em);
    const V3 specColor = load3(sc);
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
            for (int l = 0; l < kL; ++l) {
                known |= unsigned((b.known[l] >> i) & 1) << l;
                lit |= unsigned((b.lit[l] >> i) & 1) << l;
            }
            const unsigned reaches = bitsOf(_mm_and_ps(_mm_cmpgt_ps(nl, zero), nonZero(rad)));
            fallback |= ~known & reaches;
            visible = _mm_and_ps(maskOf(~(known & ~lit & reaches)), one);   // 0 where traced and blocked
        }
        // lightTerms(coefficients, n, v, sample): zero where n.l <= 0.
        V spec;
        if (!blinn) {
            const V twoNl = mul(set1(2.0f), nl);
            const V3 r = sub(mul(twoNl, n), toL);
            spec = _mm_max_ps(zero, dot(r, v));
        } else {
            const V3 h = add(toL, v);
            const V hLen = _mm_sqrt_ps(dot(h, h));
            spec = _mm_and_ps(_mm_cmpgt_ps(hLen, zero), _mm_max_ps(zero, dot(n, div(h, hLen))));
        }
        const V front = _mm_cmpnle_ps(nl, zero), active = _mm_cmpnle_ps(visible, zero);
        alignas(16) float s[kL];
        _mm_store_ps(s, spec);
        const unsigned powered = bitsOf(_mm_and_ps(_mm_and_ps(front, active), _mm_cmpgt_ps(spec, zero))) & valid;
        for (int l = 0; l < kL; ++l) s[l] = (powered >> l) & 1 ? std::pow(s[l], shin[l]) : 0.0f;
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
    _mm_store_ps(rgb[0], color.x);
    _mm_store_ps(rgb[1], color.y);
    _mm_store_ps(rgb[2], color.z);
    return valid & ~fallback;
}

void hitFrames(FrameLanes& b) {
    for (int l = b.count; l < kL; ++l) {   // (unused lanes: lane 0's inputs)
        for (int a = 0; a < 3; ++a) {
            for (int k = 0; k < 3; ++k) b.P[k][a][l] = b.P[k][a][0];
            b.dir[a][l] = b.dir[a][0];
        }
        b.b1[l] = b.b1[0], b.b2[l] = b.b2[0];
    }
    const V zero = _mm_setzero_ps();
    const V3 P0 = load3(b.P[0]), P1 = load3(b.P[1]), P2 = load3(b.P[2]);
    const V b1 = load(b.b1), b2 = load(b.b2);
    const V w0 = sub(sub(set1(1.0f), b1), b2);   // 1 - b1 - b2
    const V3 p = add(add(mul(w0, P0), mul(b1, P1)), mul(b2, P2));
    // glm::cross(e1, e2) = (e1.y e2.z - e2.y e1.z, e1.z e2.x - e2.z e1.x, e1.x e2.y - e2.x e1.y)
    const V3 e1 = sub(P1, P0), e2 = sub(P2, P0);
    V3 gn{sub(mul(e1.y, e2.z), mul(e2.y, e1.z)), sub(mul(e1.z, e2.x), mul(e2.z, e1.x)), sub(mul(e1.x, e2.y), mul(e2.x, e1.y))};
    const V gl = _mm_sqrt_ps(dot(gn, gn));
    gn = sel(_mm_cmpgt_ps(gl, zero), div(gn, gl), splat(vec3(0, 1, 0)));
    gn = sel(maskOf(b.mirrored), neg(gn), gn);
    const V back = _mm_cmpgt_ps(dot(gn, load3(b.dir)), zero);
    const V3 ng = sel(back, neg(gn), gn);
    for (int a = 0; a < 3; ++a) {
        const V* const pv[3] = {&p.x, &p.y, &p.z};
        const V* const gv[3] = {&gn.x, &gn.y, &gn.z};
        const V* const nv[3] = {&ng.x, &ng.y, &ng.z};
        _mm_store_ps(b.p[a], *pv[a]);
        _mm_store_ps(b.gn[a], *gv[a]);
        _mm_store_ps(b.ng[a], *nv[a]);
    }
    b.back = bitsOf(back) & ((1u << b.count) - 1);
}

void shadowRays(ShadowLanes& b, const DrawLight& L) {
    for (int l = b.count; l < kL; ++l)
        for (int a = 0; a < 3; ++a) b.p[a][l] = b.p[a][0], b.ng[a][l] = b.ng[a][0];
    const V zero = _mm_setzero_ps();
    const V3 p = load3(b.p), ng = load3(b.ng);
    const LightLanes ls(L, p);
    const V ngl = dot(ng, ls.toL);
    b.reaches = bitsOf(_mm_and_ps(_mm_cmpgt_ps(ngl, zero), nonZero(ls.rad))) & ((1u << b.count) - 1);   // sampleReaches(ls, ng)
    if (!b.reaches) return;
    // Tracer::shadowRay: side = ng.l >= 0 ? 1 : -1; eps = offsetScale(p) =
    // 1e-4 (1 + std::max(|x|, std::max(|y|, |z|))) (std::max(a, b) = b > a ? b : a);
    // org = p + (side eps) ng; tmax = distance (1 - 1e-4) - eps where the distance is finite.
    const V side = sel(_mm_cmpge_ps(ngl, zero), set1(1.0f), set1(-1.0f));
    const V absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    const V ax = _mm_and_ps(p.x, absMask), ay = _mm_and_ps(p.y, absMask), az = _mm_and_ps(p.z, absMask);
    const V eps = mul(set1(1e-4f), add(set1(1.0f), _mm_max_ps(_mm_max_ps(az, ay), ax)));
    const V3 org = add(p, mul(mul(side, eps), ng));
    const V finite = _mm_cmpeq_ps(sub(ls.dist, ls.dist), zero);
    const V tmax = sel(finite, sub(mul(ls.dist, set1(1.0f - 1e-4f)), eps), set1(std::numeric_limits<float>::infinity()));
    __m128 o[4] = {org.x, org.y, org.z, zero}, d[4] = {ls.toL.x, ls.toL.y, ls.toL.z, tmax};
    _MM_TRANSPOSE4_PS(o[0], o[1], o[2], o[3]);   // (org, tmin = 0) per lane
    _MM_TRANSPOSE4_PS(d[0], d[1], d[2], d[3]);   // (dir, tmax) per lane
    static_assert(sizeof(rt::Ray) == 32 && offsetof(rt::Ray, dir) == 16, "Ray: org, tmin, dir, tmax packed");
    for (int l = 0; l < kL; ++l) {
        _mm_storeu_ps(&b.rays[l].org.x, o[l]);
        _mm_storeu_ps(&b.rays[l].dir.x, d[l]);
    }
}

}   // namespace rnd::raycast
