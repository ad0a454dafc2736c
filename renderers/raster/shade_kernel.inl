// shade_kernel.inl - the body of raster::shadeBatch (raster_shading.cpp), written once over
// simd.h's vector wrappers (V, VI, kW, set1, add, ...), which raster_shading.cpp brings in for
// SSE2 (4 lanes) and for AVX2 (8 lanes, chosen at run time) before including it. Every lane performs
// the same IEEE operations in the same order in both (no FMA: the AVX2 region enables avx2
// only), so the two give the same bits.
// NOLINTBEGIN
// log2(x) for x > 0 (normal floats): exponent + ln(m)/ln 2 with m in [1, 2) via the atanh
// series ln m = 2 (z + z^3/3 + ... + z^9/9), z = (m - 1)/(m + 1) <= 1/3 (error < 1e-6), the
// series in z^2 by Estrin's scheme (terms side by side: a shorter dependency chain than Horner's).
inline V log2v(V x) {
    VI bits = castI(x);
    VI e = subI(srliI(bits, 23), set1I(127));
    V m = castF(orI(andI(bits, set1I(0x7fffff)), set1I(0x3f800000)));
    V z = div(sub(m, set1(1.0f)), add(m, set1(1.0f)));
    V z2 = mul(z, z), z4 = mul(z2, z2);
    V p = add(add(set1(1.0f), mul(z2, set1(1.0f / 3.0f))),
              mul(z4, add(add(set1(1.0f / 5.0f), mul(z2, set1(1.0f / 7.0f))), mul(z4, set1(1.0f / 9.0f)))));
    V ln = mul(mul(set1(2.0f), z), p);
    return add(cvtF(e), mul(ln, set1(1.4426950408889634f)));
}

// 2^y for y <= 0 (clamped at -126): 2^floor(y) from the exponent bits times 2^f, f in [0, 1),
// by the Taylor series of e^(f ln 2) to degree 7 (error < 2e-6), also by Estrin's scheme.
inline V exp2v(V y) {
    y = vmax(y, set1(-126.0f));
    VI i = cvttI(y);   // toward zero
    V fi = cvtF(i);
    V gt = cmpgt(fi, y);   // negative non-integers: floor = trunc - 1
    i = subI(i, andI(castI(gt), set1I(1)));
    fi = cvtF(i);
    V f = mul(sub(y, fi), set1(0.6931471805599453f));
    // Estrin's scheme: the pairs and powers evaluate side by side (latency ~4 steps, not 8).
    const V f2 = mul(f, f), f4 = mul(f2, f2);
    const V p01 = add(set1(1.0f), f), p23 = add(set1(0.5f), mul(f, set1(1.0f / 6.0f)));
    const V p45 = add(set1(1.0f / 24.0f), mul(f, set1(1.0f / 120.0f))), p67 = add(set1(1.0f / 720.0f), mul(f, set1(1.0f / 5040.0f)));
    const V p = add(add(p01, mul(f2, p23)), mul(f4, add(p45, mul(f2, p67))));
    V scale = castF(slliI(addI(i, set1I(127)), 23));
    return mul(p, scale);
}

// The lighting of fragments [0, n) (n rounded up to kW: ShadeBatch pads to 8).
inline void shadeKernel(ShadeBatch& b, size_t n, const sg::FrameInput& f) {
    const sg::vec3 eye = f.camera.eye;
    const bool blinn = f.settings.reflection == sg::ReflectionModel::BlinnPhong;
    const V zero = zeroV(), one = set1(1.0f);
    const int32_t* mi = b.mat.data();
    for (size_t i = 0; i < n; i += kW) {
        V px = loadu(&b.px[i]), py = loadu(&b.py[i]), pz = loadu(&b.pz[i]);
        V nx = loadu(&b.nx[i]), ny = loadu(&b.ny[i]), nz = loadu(&b.nz[i]);
        // One constant block for all kW fragments (the common case: one material): broadcast
        // it; otherwise copy each lane's block into the arrays and load those (the same values).
        const int32_t m0 = mi[i];
        const bool uniform = m0 >= 0 && allEqualI(mi + i, m0);
        V kd, ks, shin, ar, ag, ab, sr, sgc, sb, cr, cg, cb;
        if (uniform) {
            const ShadeBatch::Constants& c = b.mats[size_t(m0)];
            kd = set1(c.kd), ks = set1(c.ks), shin = set1(c.shin);
            ar = set1(c.ar), ag = set1(c.ag), ab = set1(c.ab);
            sr = set1(c.sr), sgc = set1(c.sg), sb = set1(c.sb);
            cr = set1(c.cr), cg = set1(c.cg), cb = set1(c.cb);
        } else {
            for (size_t l = 0; l < kW; ++l)
                if (mi[i + l] >= 0) b.expand(i + l);
            kd = loadu(&b.kd[i]), ks = loadu(&b.ks[i]), shin = loadu(&b.shin[i]);
            ar = loadu(&b.ar[i]), ag = loadu(&b.ag[i]), ab = loadu(&b.ab[i]);
            sr = loadu(&b.sr[i]), sgc = loadu(&b.sg[i]), sb = loadu(&b.sb[i]);
            cr = loadu(&b.cr[i]), cg = loadu(&b.cg[i]), cb = loadu(&b.cb[i]);
        }
        // diffuse and specular colour factors: kd * albedo, ks * specColor
        V dr = mul(kd, ar), dg = mul(kd, ag), db = mul(kd, ab);
        V qr = mul(ks, sr), qg = mul(ks, sgc), qb = mul(ks, sb);
        // v = normalize(eye - p), (0,0,1) when p is the eye
        V vx = sub(set1(eye.x), px), vy = sub(set1(eye.y), py), vz = sub(set1(eye.z), pz);
        V vl = vsqrt(add(add(mul(vx, vx), mul(vy, vy)), mul(vz, vz)));
        V vpos = cmpgt(vl, zero);
        V ivl = div(one, sel(vpos, vl, one));
        vx = sel(vpos, mul(vx, ivl), zero);
        vy = sel(vpos, mul(vy, ivl), zero);
        vz = sel(vpos, mul(vz, ivl), one);
        V lit = vor(cmpgt(kd, zero), cmpgt(ks, zero));
        if (movemask(lit) == 0) {
            if (uniform) {   // the input colour is the output
                storeu(&b.cr[i], cr);
                storeu(&b.cg[i], cg);
                storeu(&b.cb[i], cb);
            }
            continue;
        }
        for (size_t li = 0; li < f.lights.size(); ++li) {
            const sg::DrawLight& L = f.lights[li];
            V lx, ly, lz, rr = set1(L.radiance.x), rg = set1(L.radiance.y), rb = set1(L.radiance.z);
            if (b.visLights) {   // shadows: the fraction of the light that reaches each fragment
                const V s = loadu(&b.vis[li * b.visStride + i]);
                if (movemask(cmpgt(s, zero)) == 0) continue;
                rr = mul(rr, s);
                rg = mul(rg, s);
                rb = mul(rb, s);
            }
            if (L.type == sg::LightType::Directional) {
                lx = set1(-L.direction.x);
                ly = set1(-L.direction.y);
                lz = set1(-L.direction.z);
            } else {
                V dx = sub(set1(L.position.x), px), dy = sub(set1(L.position.y), py), dz = sub(set1(L.position.z), pz);
                V d2 = add(add(mul(dx, dx), mul(dy, dy)), mul(dz, dz));
                V dist = vsqrt(d2);
                V dpos = cmpgt(dist, zero);
                V id = div(one, sel(dpos, dist, one));
                lx = sel(dpos, mul(dx, id), zero);
                ly = sel(dpos, mul(dy, id), one);
                lz = sel(dpos, mul(dz, id), zero);
                if (L.inverseSquare) {
                    V inv2 = div(one, vmax(d2, set1(1e-8f)));
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
                        t = vand(cmpge(c, set1(L.cosOuter)), one);
                    t = vmin(vmax(t, zero), one);
                    V s = mul(mul(t, t), sub(set1(3.0f), mul(set1(2.0f), t)));
                    rr = mul(rr, s);
                    rg = mul(rg, s);
                    rb = mul(rb, s);
                }
            }
            V nl = add(add(mul(nx, lx), mul(ny, ly)), mul(nz, lz));
            V front = cmpgt(nl, zero);
            if (movemask(vand(front, lit)) == 0) continue;
            V s;
            if (!blinn) {   // r = 2 (n.l) n - l ; s = max(r.v, 0)
                V two = mul(set1(2.0f), nl);
                V rx = sub(mul(two, nx), lx), ry = sub(mul(two, ny), ly), rz = sub(mul(two, nz), lz);
                s = vmax(add(add(mul(rx, vx), mul(ry, vy)), mul(rz, vz)), zero);
            } else {   // h = (l + v)/|l + v| ; s = max(n.h, 0)
                V hx = add(lx, vx), hy = add(ly, vy), hz = add(lz, vz);
                V hl = vsqrt(add(add(mul(hx, hx), mul(hy, hy)), mul(hz, hz)));
                V hpos = cmpgt(hl, zero);
                V nh = div(add(add(mul(nx, hx), mul(ny, hy)), mul(nz, hz)), sel(hpos, hl, one));
                s = vand(hpos, vmax(nh, zero));
            }
            V spos = cmpgt(s, zero);
            V spec = vand(spos, exp2v(mul(shin, log2v(sel(spos, s, one)))));
            V w = vand(front, nl);   // max(n.l, 0) with the n.l <= 0 lanes zeroed
            cr = add(cr, mul(mul(rr, w), add(dr, mul(qr, spec))));
            cg = add(cg, mul(mul(rg, w), add(dg, mul(qg, spec))));
            cb = add(cb, mul(mul(rb, w), add(db, mul(qb, spec))));
        }
        storeu(&b.cr[i], cr);
        storeu(&b.cg[i], cg);
        storeu(&b.cb[i], cb);
    }
}

// NOLINTEND
