// shadow_kernel.inl - rnd::shadowVisibility (renderers/common/shadow_map.cpp) for a vector of
// fragments at once, every lane reading the same map (a directional or spot light, or a point
// light's face when all lanes pick it): the same steps per lane (normal offset, depth bias,
// receiver-plane bias per tap, k x k taps, texels outside the map lit). raster_shadows.cpp
// includes it once per instruction set, like shade_kernel.inl; tests/renderers/raster holds it to the
// scalar function.
// NOLINTBEGIN

// Fragments [i, i + kW) of the batch: the fraction of the light reaching each, into out[i...].
// toLight: the light's direction (directional) or position (otherwise, `positional`).
inline void shadowLookupV(const ShadowPlan& plan, const ShadowView& v, const float* map, const sg::vec3& lightVec, bool positional,
                          const ShadeBatch& b, size_t i, float* out) {
    const V zero = zeroV(), one = set1(1.0f);
    const V px = loadu(&b.px[i]), py = loadu(&b.py[i]), pz = loadu(&b.pz[i]);
    V nx = loadu(&b.nx[i]), ny = loadu(&b.ny[i]), nz = loadu(&b.nz[i]);
    // The side the light is on.
    V lx, ly, lz;
    if (positional) {
        lx = sub(set1(lightVec.x), px);
        ly = sub(set1(lightVec.y), py);
        lz = sub(set1(lightVec.z), pz);
    } else {
        lx = set1(-lightVec.x);
        ly = set1(-lightVec.y);
        lz = set1(-lightVec.z);
    }
    const V away = cmplt(add(add(mul(nx, lx), mul(ny, ly)), mul(nz, lz)), zero);
    nx = sel(away, sub(zero, nx), nx);
    ny = sel(away, sub(zero, ny), ny);
    nz = sel(away, sub(zero, nz), nz);
    const sg::mat4& vw = v.view;
    auto depthOf = [&](V x, V y, V z) {   // -(view * p).z
        return sub(zero, add(add(add(mul(set1(vw[0][2]), x), mul(set1(vw[1][2]), y)), mul(set1(vw[2][2]), z)), set1(vw[3][2])));
    };
    const V t = v.perspective ? mul(set1(v.texelAtUnit), depthOf(px, py, pz)) : set1(v.texelAtUnit);
    const V off = mul(set1(plan.normalBias), t);
    const V qx = add(px, mul(off, nx)), qy = add(py, mul(off, ny)), qz = add(pz, mul(off, nz));
    const sg::mat4& m = v.viewProj;
    auto row = [&](int r) { return add(add(add(mul(set1(m[0][r]), qx), mul(set1(m[1][r]), qy)), mul(set1(m[2][r]), qz)), set1(m[3][r])); };
    const V cx = row(0), cy = row(1), cw = row(3);
    const V front = cmpgt(cw, zero);   // behind the light's eye: lit
    const V icw = div(one, sel(front, cw, one));
    const V u = add(mul(mul(cx, icw), set1(0.5f)), set1(0.5f)), w = add(mul(mul(cy, icw), set1(0.5f)), set1(0.5f));
    const V zb = sub(depthOf(qx, qy, qz), mul(set1(plan.depthBias), t));
    const float range = v.farZ - v.nearZ;
    if (!(range > 0.0f)) {   // no depth range (planShadows never makes one): lit
        storeu(out + i, one);
        return;
    }
    const V dRecv = mul(sub(zb, set1(v.nearZ)), set1(1.0f / range));
    // receiver-plane slope per texel
    const V mx = add(add(mul(set1(vw[0][0]), nx), mul(set1(vw[1][0]), ny)), mul(set1(vw[2][0]), nz));
    const V my = add(add(mul(set1(vw[0][1]), nx), mul(set1(vw[1][1]), ny)), mul(set1(vw[2][1]), nz));
    const V mz = add(add(mul(set1(vw[0][2]), nx), mul(set1(vw[1][2]), ny)), mul(set1(vw[2][2]), nz));
    V cosRay = mz;
    if (v.perspective) {   // against the ray to the light, not the map's axis
        const V ll = vsqrt(add(add(mul(lx, lx), mul(ly, ly)), mul(lz, lz)));
        cosRay = div(add(add(mul(nx, lx), mul(ny, ly)), mul(nz, lz)), sel(cmpgt(ll, zero), ll, one));
    }
    const V mzc = vmax(cosRay, mul(set1(0.25f), vsqrt(add(mul(mx, mx), mul(my, my)))));
    const V mpos = cmpgt(mzc, zero);
    const V scale = div(mul(t, set1(1.0f / range)), sel(mpos, mzc, one));
    const V slopeX = vand(mpos, mul(mx, scale)), slopeY = vand(mpos, mul(my, scale));
    const int N = plan.size, k = plan.pcf;
    const V fN = set1(float(N));
    const V su = mul(u, fN), sv = mul(w, fN);
    VI i0, j0;
    floorV(add(su, set1(-0.5f * float(k) + 0.5f)), i0);
    floorV(add(sv, set1(-0.5f * float(k) + 0.5f)), j0);
    // Lanes far outside (or NaN) would overflow the index: clamp the start, taps outside stay lit.
    const VI lim = set1I(N + 1), neg = set1I(-k - 1);
    i0 = minI(maxI(i0, neg), lim);
    j0 = minI(maxI(j0, neg), lim);
    V lit = zero;
    const V allOnes = castF(set1I(-1));
    const VI zI = set1I(0), nm1 = set1I(N - 1), NI = set1I(N);
    for (int dj = 0; dj < k; ++dj) {
        const VI j = addI(j0, set1I(dj));
        const V jin = castF(andI(cmpgtI(j, set1I(-1)), cmpgtI(NI, j)));
        const V cy0 = sub(add(cvtF(j), set1(0.5f)), sv);
        const VI rowBase = mulloI(minI(maxI(j, zI), nm1), NI);
        for (int di = 0; di < k; ++di) {
            const VI ii = addI(i0, set1I(di));
            const V in = vand(jin, castF(andI(cmpgtI(ii, set1I(-1)), cmpgtI(NI, ii))));
            const V d = gatherF(map, addI(rowBase, minI(maxI(ii, zI), nm1)));
            const V dTap = add(add(dRecv, mul(slopeX, sub(add(cvtF(ii), set1(0.5f)), su))), mul(slopeY, cy0));
            // lit: outside the map, or the receiver no deeper than the texel
            lit = add(lit, vand(sel(in, cmpge(d, dTap), allOnes), one));
        }
    }
    const V frac = mul(lit, set1(1.0f / float(k * k)));
    storeu(out + i, sel(front, frac, one));
}

// NOLINTEND
