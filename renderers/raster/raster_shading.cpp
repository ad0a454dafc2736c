#include "raster/raster_shading.h"

#include "renderers/shading.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rnd::raster {

void ShadeBatch::resize(size_t n) {
    size = n;
    size_t cap = (n + 3) & ~size_t(3);
    for (auto* v : {&px, &py, &pz, &nx, &ny, &nz, &ar, &ag, &ab, &sr, &sg, &sb, &kd, &ks, &shin, &cr, &cg, &cb})
        if (v->size() < cap) v->resize(cap, 0.0f);
    // Padding lanes: harmless values (normal up, zero coefficients).
    for (size_t i = n; i < cap; ++i) {
        px[i] = py[i] = pz[i] = 0;
        nx[i] = nz[i] = 0;
        ny[i] = 1;
        kd[i] = ks[i] = 0;
        shin[i] = 1;
    }
}

#if defined(__SSE2__)
namespace {

using V = __m128;
inline V set1(float x) { return _mm_set1_ps(x); }
inline V add(V a, V b) { return _mm_add_ps(a, b); }
inline V sub(V a, V b) { return _mm_sub_ps(a, b); }
inline V mul(V a, V b) { return _mm_mul_ps(a, b); }
inline V sel(V mask, V a, V b) { return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b)); }

// log2(x) for x > 0 (normal floats): exponent + ln(m)/ln 2 with m in [1, 2) via the atanh
// series ln m = 2 (z + z^3/3 + ... + z^9/9), z = (m - 1)/(m + 1) <= 1/3 (error < 1e-6).
inline V log2v(V x) {
    __m128i bits = _mm_castps_si128(x);
    __m128i e = _mm_sub_epi32(_mm_srli_epi32(bits, 23), _mm_set1_epi32(127));
    V m = _mm_castsi128_ps(_mm_or_si128(_mm_and_si128(bits, _mm_set1_epi32(0x7fffff)), _mm_set1_epi32(0x3f800000)));
    V z = _mm_div_ps(sub(m, set1(1.0f)), add(m, set1(1.0f)));
    V z2 = mul(z, z);
    V p = add(set1(1.0f / 7.0f), mul(z2, set1(1.0f / 9.0f)));
    p = add(set1(1.0f / 5.0f), mul(z2, p));
    p = add(set1(1.0f / 3.0f), mul(z2, p));
    p = add(set1(1.0f), mul(z2, p));
    V ln = mul(mul(set1(2.0f), z), p);
    return add(_mm_cvtepi32_ps(e), mul(ln, set1(1.4426950408889634f)));
}

// 2^y for y <= 0 (clamped at -126): 2^floor(y) from the exponent bits times 2^f, f in [0, 1),
// by the Taylor series of e^(f ln 2) to degree 7 (error < 2e-6).
inline V exp2v(V y) {
    y = _mm_max_ps(y, set1(-126.0f));
    __m128i i = _mm_cvttps_epi32(y);   // toward zero
    V fi = _mm_cvtepi32_ps(i);
    V gt = _mm_cmpgt_ps(fi, y);   // negative non-integers: floor = trunc - 1
    i = _mm_sub_epi32(i, _mm_and_si128(_mm_castps_si128(gt), _mm_set1_epi32(1)));
    fi = _mm_cvtepi32_ps(i);
    V f = mul(sub(y, fi), set1(0.6931471805599453f));
    V p = set1(1.0f / 5040.0f);
    p = add(set1(1.0f / 720.0f), mul(f, p));
    p = add(set1(1.0f / 120.0f), mul(f, p));
    p = add(set1(1.0f / 24.0f), mul(f, p));
    p = add(set1(1.0f / 6.0f), mul(f, p));
    p = add(set1(0.5f), mul(f, p));
    p = add(set1(1.0f), mul(f, p));
    p = add(set1(1.0f), mul(f, p));
    V scale = _mm_castsi128_ps(_mm_slli_epi32(_mm_add_epi32(i, _mm_set1_epi32(127)), 23));
    return mul(p, scale);
}

}   // namespace

void shadeBatch(ShadeBatch& b, size_t n, const sg::FrameInput& f) {
    const sg::vec3 eye = f.camera.eye;
    const bool blinn = f.settings.reflection == sg::ReflectionModel::BlinnPhong;
    const V zero = _mm_setzero_ps(), one = set1(1.0f);
    for (size_t i = 0; i < n; i += 4) {
        V px = _mm_loadu_ps(&b.px[i]), py = _mm_loadu_ps(&b.py[i]), pz = _mm_loadu_ps(&b.pz[i]);
        V nx = _mm_loadu_ps(&b.nx[i]), ny = _mm_loadu_ps(&b.ny[i]), nz = _mm_loadu_ps(&b.nz[i]);
        V kd = _mm_loadu_ps(&b.kd[i]), ks = _mm_loadu_ps(&b.ks[i]), shin = _mm_loadu_ps(&b.shin[i]);
        V ar = _mm_loadu_ps(&b.ar[i]), ag = _mm_loadu_ps(&b.ag[i]), ab = _mm_loadu_ps(&b.ab[i]);
        V sr = _mm_loadu_ps(&b.sr[i]), sgc = _mm_loadu_ps(&b.sg[i]), sb = _mm_loadu_ps(&b.sb[i]);
        // diffuse and specular colour factors: kd * albedo, ks * specColor
        V dr = mul(kd, ar), dg = mul(kd, ag), db = mul(kd, ab);
        V qr = mul(ks, sr), qg = mul(ks, sgc), qb = mul(ks, sb);
        // v = normalize(eye - p), (0,0,1) when p is the eye
        V vx = sub(set1(eye.x), px), vy = sub(set1(eye.y), py), vz = sub(set1(eye.z), pz);
        V vl = _mm_sqrt_ps(add(add(mul(vx, vx), mul(vy, vy)), mul(vz, vz)));
        V vpos = _mm_cmpgt_ps(vl, zero);
        V ivl = _mm_div_ps(one, sel(vpos, vl, one));
        vx = sel(vpos, mul(vx, ivl), zero);
        vy = sel(vpos, mul(vy, ivl), zero);
        vz = sel(vpos, mul(vz, ivl), one);
        V cr = _mm_loadu_ps(&b.cr[i]), cg = _mm_loadu_ps(&b.cg[i]), cb = _mm_loadu_ps(&b.cb[i]);
        V lit = _mm_or_ps(_mm_cmpgt_ps(kd, zero), _mm_cmpgt_ps(ks, zero));
        if (_mm_movemask_ps(lit) == 0) continue;
        for (const sg::DrawLight& L : f.lights) {
            V lx, ly, lz, rr = set1(L.radiance.x), rg = set1(L.radiance.y), rb = set1(L.radiance.z);
            if (L.type == sg::LightType::Directional) {
                lx = set1(-L.direction.x);
                ly = set1(-L.direction.y);
                lz = set1(-L.direction.z);
            } else {
                V dx = sub(set1(L.position.x), px), dy = sub(set1(L.position.y), py), dz = sub(set1(L.position.z), pz);
                V d2 = add(add(mul(dx, dx), mul(dy, dy)), mul(dz, dz));
                V dist = _mm_sqrt_ps(d2);
                V dpos = _mm_cmpgt_ps(dist, zero);
                V id = _mm_div_ps(one, sel(dpos, dist, one));
                lx = sel(dpos, mul(dx, id), zero);
                ly = sel(dpos, mul(dy, id), one);
                lz = sel(dpos, mul(dz, id), zero);
                if (L.inverseSquare) {
                    V inv2 = _mm_div_ps(one, _mm_max_ps(d2, set1(1e-8f)));
                    rr = mul(rr, inv2);
                    rg = mul(rg, inv2);
                    rb = mul(rb, inv2);
                }
                if (L.type == sg::LightType::Spot) {
                    V c = sub(zero, add(add(mul(lx, set1(L.direction.x)), mul(ly, set1(L.direction.y))), mul(lz, set1(L.direction.z))));
                    V t;
                    if (L.cosInner > L.cosOuter)
                        t = mul(sub(c, set1(L.cosOuter)), set1(1.0f / (L.cosInner - L.cosOuter)));
                    else
                        t = _mm_and_ps(_mm_cmpge_ps(c, set1(L.cosOuter)), one);
                    t = _mm_min_ps(_mm_max_ps(t, zero), one);
                    V s = mul(mul(t, t), sub(set1(3.0f), mul(set1(2.0f), t)));
                    rr = mul(rr, s);
                    rg = mul(rg, s);
                    rb = mul(rb, s);
                }
            }
            V nl = add(add(mul(nx, lx), mul(ny, ly)), mul(nz, lz));
            V front = _mm_cmpgt_ps(nl, zero);
            if (_mm_movemask_ps(_mm_and_ps(front, lit)) == 0) continue;
            V s;
            if (!blinn) {   // r = 2 (n.l) n - l ; s = max(r.v, 0)
                V two = mul(set1(2.0f), nl);
                V rx = sub(mul(two, nx), lx), ry = sub(mul(two, ny), ly), rz = sub(mul(two, nz), lz);
                s = _mm_max_ps(add(add(mul(rx, vx), mul(ry, vy)), mul(rz, vz)), zero);
            } else {   // h = (l + v)/|l + v| ; s = max(n.h, 0)
                V hx = add(lx, vx), hy = add(ly, vy), hz = add(lz, vz);
                V hl = _mm_sqrt_ps(add(add(mul(hx, hx), mul(hy, hy)), mul(hz, hz)));
                V hpos = _mm_cmpgt_ps(hl, zero);
                V nh = _mm_div_ps(add(add(mul(nx, hx), mul(ny, hy)), mul(nz, hz)), sel(hpos, hl, one));
                s = _mm_and_ps(hpos, _mm_max_ps(nh, zero));
            }
            V spos = _mm_cmpgt_ps(s, zero);
            V spec = _mm_and_ps(spos, exp2v(mul(shin, log2v(sel(spos, s, one)))));
            V w = _mm_and_ps(front, nl);   // max(n.l, 0) with the n.l <= 0 lanes zeroed
            cr = add(cr, mul(mul(rr, w), add(dr, mul(qr, spec))));
            cg = add(cg, mul(mul(rg, w), add(dg, mul(qg, spec))));
            cb = add(cb, mul(mul(rb, w), add(db, mul(qb, spec))));
        }
        _mm_storeu_ps(&b.cr[i], cr);
        _mm_storeu_ps(&b.cg[i], cg);
        _mm_storeu_ps(&b.cb[i], cb);
    }
}

#else

void shadeBatch(ShadeBatch& b, size_t n, const sg::FrameInput& f) {
    for (size_t i = 0; i < n; ++i) {
        if (b.kd[i] == 0 && b.ks[i] == 0) continue;
        sg::Material m;
        m.kd = b.kd[i];
        m.ks = b.ks[i];
        m.shininess = b.shin[i];
        m.specularColor = {b.sr[i], b.sg[i], b.sb[i]};
        SurfacePoint s{{b.px[i], b.py[i], b.pz[i]}, {b.nx[i], b.ny[i], b.nz[i]}, {b.ar[i], b.ag[i], b.ab[i]}};
        sg::vec3 v = f.camera.eye - s.position;
        float len = glm::length(v);
        v = len > 0 ? v / len : sg::vec3(0, 0, 1);
        sg::vec3 c(b.cr[i], b.cg[i], b.cb[i]);
        for (const auto& L : f.lights) c += lightTerms(m, s.normal, v, sampleLight(L, s.position), f.settings.reflection).apply(s.albedo);
        b.cr[i] = c.x;
        b.cg[i] = c.y;
        b.cb[i] = c.z;
    }
}

#endif

}   // namespace rnd::raster
