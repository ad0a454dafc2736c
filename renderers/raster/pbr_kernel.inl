// pbr_kernel.inl - the body of raster::shadeBatch for the pbr reflection model
// (raster_shading.cpp includes it once per instruction set, like shade_kernel.inl): per lane,
// what renderers/pbr.cpp computes for one point (pbrLightTerms for every light,
// pbrEnvironmentTerms for the environment) with the environment's lookups
// (environment.cpp: equirectUv's polynomial atan2 and acos, the bilinear sample of two
// prefiltered levels, the spherical harmonics, the split-sum table) done a vector at a time.
// The ShadeBatch layout for pbr is in raster_shading.h. The order of operations is not the
// scalar code's, so results differ from rnd::shade in the last bits; tests/renderers/raster holds them
// to it.
// NOLINTBEGIN

inline V absV(V x) { return vand(x, castF(set1I(0x7fffffff))); }

// floor(x) as a float and as an integer (x within int range).
inline V floorV(V x, VI& i) {
    i = cvttI(x);
    V fi = cvtF(i);
    const V gt = cmpgt(fi, x);   // negative non-integers: trunc - 1
    i = subI(i, andI(castI(gt), set1I(1)));
    return cvtF(i);
}

// environment.cpp's fastAtan2 per lane.
inline V atan2V(V y, V x) {
    const V ax = absV(x), ay = absV(y);
    const V mx = vmax(ax, ay), mn = vmin(ax, ay);
    const V pos = cmpgt(mx, zeroV());
    const V a = div(mn, sel(pos, mx, set1(1.0f))), s = mul(a, a);
    V r = add(mul(set1(-0.0117212f), s), set1(0.05265332f));
    r = sub(mul(r, s), set1(0.11643287f));
    r = add(mul(r, s), set1(0.19354346f));
    r = sub(mul(r, s), set1(0.33262348f));
    r = add(mul(r, s), set1(0.99997723f));
    r = mul(r, a);
    r = sel(cmpgt(ay, ax), sub(set1(1.57079637f), r), r);
    r = sel(cmplt(x, zeroV()), sub(set1(3.14159274f), r), r);
    r = sel(cmplt(y, zeroV()), sub(zeroV(), r), r);
    return vand(pos, r);
}

// environment.cpp's fastAcos per lane.
inline V acosV(V x) {
    const V a = vmin(absV(x), set1(1.0f));
    V p = set1(-0.0012624911f);
    p = add(mul(p, a), set1(0.0066700901f));
    p = add(mul(p, a), set1(-0.0170881256f));
    p = add(mul(p, a), set1(0.0308918810f));
    p = add(mul(p, a), set1(-0.0501743046f));
    p = add(mul(p, a), set1(0.0889789874f));
    p = add(mul(p, a), set1(-0.2145988016f));
    p = add(mul(p, a), set1(1.5707963050f));
    const V r = mul(vsqrt(sub(set1(1.0f), a)), p);
    return sel(cmplt(x, zeroV()), sub(set1(3.14159274f), r), r);
}

struct RGB {
    V r, g, b;
};

// sampleLevel (environment.cpp) per lane, every lane in level l: u wraps, v clamps.
inline RGB sampleLevelV(const PbrKernelEnv::Level& l, V u, V v) {
    const V zero = zeroV(), one = set1(1.0f);
    u = sel(vand(cmpge(u, set1(-1.0f)), cmpge(set1(2.0f), u)), u, zero);   // NaN: 0
    v = vmin(vmax(v, zero), one);                                          // NaN: 0
    const V x = sub(mul(u, set1(float(l.width))), set1(0.5f)), y = sub(mul(v, set1(float(l.height))), set1(0.5f));
    VI ix, iy;
    const V tx = sub(x, floorV(x, ix)), ty = sub(y, floorV(y, iy));
    const VI w = set1I(l.width), wm1 = set1I(l.width - 1), hm1 = set1I(l.height - 1), z = set1I(0);
    // u in [-1, 2] puts floor(x) in [-w - 1, 2w - 1]: one wrap each way, then clamped for safety
    ix = addI(ix, andI(cmpgtI(z, ix), w));
    ix = subI(ix, andI(cmpgtI(ix, wm1), w));
    const VI x0 = minI(maxI(ix, z), wm1);
    const VI x1 = andI(addI(x0, set1I(1)), cmpgtI(wm1, x0));   // x0 + 1, or 0 past the last column
    const VI y0 = minI(maxI(iy, z), hm1), y1 = minI(maxI(addI(iy, set1I(1)), z), hm1);
    const VI r0 = mulloI(y0, w), r1 = mulloI(y1, w), three = set1I(3);
    const VI i00 = mulloI(addI(r0, x0), three), i10 = mulloI(addI(r0, x1), three);
    const VI i01 = mulloI(addI(r1, x0), three), i11 = mulloI(addI(r1, x1), three);
    const V sx = sub(one, tx), sy = sub(one, ty);
    RGB c;
    V* out[3] = {&c.r, &c.g, &c.b};
    for (int ch = 0; ch < 3; ++ch) {
        const float* t = l.rgb + ch;
        const V c00 = gatherF(t, i00), c10 = gatherF(t, i10), c01 = gatherF(t, i01), c11 = gatherF(t, i11);
        *out[ch] = add(mul(sy, add(mul(sx, c00), mul(tx, c10))), mul(ty, add(mul(sx, c01), mul(tx, c11))));
    }
    return c;
}

// EnvironmentMap::specular per lane: direction d in the map's frame, roughness per lane.
inline RGB environmentSpecularV(const PbrKernelEnv& e, V dx, V dy, V dz, V rough) {
    const V u = add(set1(0.5f), mul(atan2V(dx, sub(zeroV(), dz)), set1(1.0f / (2.0f * 3.14159265358979323846f))));
    const V v = mul(acosV(vmin(vmax(dy, set1(-1.0f)), set1(1.0f))), set1(1.0f / 3.14159265358979323846f));
    const V lod = mul(vand(cmpgt(rough, zeroV()), vmin(rough, set1(1.0f))), set1(float(PbrKernelEnv::kLevels - 1)));   // NaN: 0
    VI k0;
    const V fk0 = floorV(lod, k0);
    const V f = sub(lod, fk0);
    alignas(32) int32_t ks[kW];
    storeI(ks, k0);
    int lo = ks[0], hi = ks[0];
    for (size_t l = 1; l < kW; ++l) lo = std::min(lo, ks[l]), hi = std::max(hi, ks[l]);
    const bool blend = movemask(cmpgt(f, zeroV())) != 0;
    RGB out{zeroV(), zeroV(), zeroV()};
    // Lanes of one material share a level: mostly one pass; each level's lanes otherwise.
    for (int k = lo; k <= hi; ++k) {
        const V in = castF(cmpeqI(k0, set1I(k)));
        RGB a = sampleLevelV(e.levels[k], u, v);
        if (blend && k + 1 < PbrKernelEnv::kLevels) {
            const RGB b = sampleLevelV(e.levels[k + 1], u, v);
            const V g = sub(set1(1.0f), f);
            a.r = add(mul(g, a.r), mul(f, b.r));
            a.g = add(mul(g, a.g), mul(f, b.g));
            a.b = add(mul(g, a.b), mul(f, b.b));
        }
        out.r = sel(in, a.r, out.r);
        out.g = sel(in, a.g, out.g);
        out.b = sel(in, a.b, out.b);
    }
    const V s = set1(e.intensity);
    return {mul(s, out.r), mul(s, out.g), mul(s, out.b)};
}

// The lighting of fragments [0, n) with glTF's BRDF (n rounded up to kW: ShadeBatch pads to 8).
inline void shadePbrKernel(ShadeBatch& b, size_t n, const sg::FrameInput& f, const PbrKernelEnv& env) {
    const sg::vec3 eye = f.camera.eye;
    const V zero = zeroV(), one = set1(1.0f), invPi = set1(1.0f / 3.14159265358979323846f);
    const int32_t* mi = b.mat.data();
    for (size_t i = 0; i < n; i += kW) {
        // One constant block for all kW fragments (one material): broadcast it; otherwise copy
        // each lane's block into the arrays and load those (the same values).
        const int32_t m0 = mi[i];
        const bool uniform = m0 >= 0 && allEqualI(mi + i, m0);
        V ks, f90, dr, dg, db, f0r, f0g, f0b, occ, cr, cg, cb;
        if (uniform) {
            const ShadeBatch::Constants& c = b.mats[size_t(m0)];
            dr = set1(c.ar), dg = set1(c.ag), db = set1(c.ab);
            f0r = set1(c.sr), f0g = set1(c.sg), f0b = set1(c.sb);
            f90 = set1(c.kd), ks = set1(c.ks), occ = set1(c.shin);
            cr = set1(c.cr), cg = set1(c.cg), cb = set1(c.cb);
        } else {
            for (size_t l = 0; l < kW; ++l)
                if (mi[i + l] >= 0) b.expand(i + l);
            dr = loadu(&b.ar[i]), dg = loadu(&b.ag[i]), db = loadu(&b.ab[i]);   // c_diff
            f0r = loadu(&b.sr[i]), f0g = loadu(&b.sg[i]), f0b = loadu(&b.sb[i]);
            f90 = loadu(&b.kd[i]), ks = loadu(&b.ks[i]), occ = loadu(&b.shin[i]);
            cr = loadu(&b.cr[i]), cg = loadu(&b.cg[i]), cb = loadu(&b.cb[i]);
        }
        const V lit = vor(cmpgt(f90, zero), cmpgt(ks, zero));
        if (movemask(lit) == 0) {   // final colours (unlit, Gouraud, flat) or padding
            if (uniform) {
                storeu(&b.cr[i], cr);
                storeu(&b.cg[i], cg);
                storeu(&b.cb[i], cb);
            }
            continue;
        }
        const V px = loadu(&b.px[i]), py = loadu(&b.py[i]), pz = loadu(&b.pz[i]);
        const V nx = loadu(&b.nx[i]), ny = loadu(&b.ny[i]), nz = loadu(&b.nz[i]);
        const V rough = vmax(ks, set1(1e-3f));   // the padding's 0 kept finite
        const V alpha = mul(rough, rough), a2 = mul(alpha, alpha), oneMinusA2 = sub(one, a2);
        // v = normalize(eye - p), (0,0,1) when p is the eye
        V vx = sub(set1(eye.x), px), vy = sub(set1(eye.y), py), vz = sub(set1(eye.z), pz);
        const V vl = vsqrt(add(add(mul(vx, vx), mul(vy, vy)), mul(vz, vz)));
        const V vpos = cmpgt(vl, zero);
        const V ivl = div(one, sel(vpos, vl, one));
        vx = sel(vpos, mul(vx, ivl), zero);
        vy = sel(vpos, mul(vy, ivl), zero);
        vz = sel(vpos, mul(vz, ivl), one);
        const V ndv = add(add(mul(nx, vx), mul(ny, vy)), mul(nz, vz));
        const V nv = vmax(ndv, zero);
        const V nv2Term = add(mul(mul(nv, nv), oneMinusA2), a2);   // the light-independent half of V
        const V gvRoot = vsqrt(nv2Term);
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
            } else {   // samplePunctualLight
                const V dx = sub(set1(L.position.x), px), dy = sub(set1(L.position.y), py), dz = sub(set1(L.position.z), pz);
                const V d2 = add(add(mul(dx, dx), mul(dy, dy)), mul(dz, dz));
                const V dist = vsqrt(d2);
                const V dpos = cmpgt(dist, zero);
                const V id = div(one, sel(dpos, dist, one));
                lx = sel(dpos, mul(dx, id), zero);
                ly = sel(dpos, mul(dy, id), one);
                lz = sel(dpos, mul(dz, id), zero);
                V atten = one;
                if (L.inverseSquare) atten = div(one, vmax(d2, set1(1e-8f)));
                if (L.range > 0.0f) {   // KHR_lights_punctual's window
                    const V q = mul(d2, set1(1.0f / (L.range * L.range)));
                    const V w = vmin(vmax(sub(one, mul(q, q)), zero), one);
                    atten = mul(atten, mul(w, w));
                }
                if (L.type == sg::LightType::Spot) {
                    const float scale = 1.0f / std::max(L.cosInner - L.cosOuter, 1e-3f);
                    const V c = sub(zero, add(add(mul(lx, set1(L.direction.x)), mul(ly, set1(L.direction.y))), mul(lz, set1(L.direction.z))));
                    const V t = vmin(vmax(mul(sub(c, set1(L.cosOuter)), set1(scale)), zero), one);
                    atten = mul(atten, mul(t, t));
                }
                rr = mul(rr, atten);
                rg = mul(rg, atten);
                rb = mul(rb, atten);
            }
            const V nl = add(add(mul(nx, lx), mul(ny, ly)), mul(nz, lz));
            const V front = vand(cmpgt(nl, zero), lit);
            if (movemask(front) == 0) continue;
            // h = normalize(l + v), n where they cancel
            V hx = add(lx, vx), hy = add(ly, vy), hz = add(lz, vz);
            const V hl = vsqrt(add(add(mul(hx, hx), mul(hy, hy)), mul(hz, hz)));
            const V hpos = cmpgt(hl, zero);
            const V ihl = div(one, sel(hpos, hl, one));
            hx = sel(hpos, mul(hx, ihl), nx);
            hy = sel(hpos, mul(hy, ihl), ny);
            hz = sel(hpos, mul(hz, ihl), nz);
            const V vh = vmax(add(add(mul(vx, hx), mul(vy, hy)), mul(vz, hz)), zero);
            const V nh = vmax(add(add(mul(nx, hx), mul(ny, hy)), mul(nz, hz)), zero);
            const V c = sub(one, vh), c2 = mul(c, c), c5 = mul(mul(c2, c2), c);
            const V Fr = add(f0r, mul(sub(f90, f0r), c5)), Fg = add(f0g, mul(sub(f90, f0g), c5)), Fb = add(f0b, mul(sub(f90, f0b), c5));
            const V q = add(mul(mul(nh, nh), sub(a2, one)), one);
            const V D = div(a2, mul(set1(3.14159265358979323846f), mul(q, q)));
            const V gv = mul(nl, gvRoot);
            const V gl = mul(nv, vsqrt(add(mul(mul(nl, nl), oneMinusA2), a2)));
            const V den = add(gv, gl);
            const V dpos = cmpgt(den, zero);
            const V Vis = vand(dpos, div(set1(0.5f), sel(dpos, den, one)));
            const V spec = mul(D, Vis);
            const V w = vand(front, nl);   // max(n.l, 0), lit lanes only
            // (1 - F) c_diff / pi + F D V, times the light's radiance and n.l
            cr = add(cr, mul(mul(rr, w), add(mul(mul(sub(one, Fr), dr), invPi), mul(Fr, spec))));
            cg = add(cg, mul(mul(rg, w), add(mul(mul(sub(one, Fg), dg), invPi), mul(Fg, spec))));
            cb = add(cb, mul(mul(rb, w), add(mul(mul(sub(one, Fb), db), invPi), mul(Fb, spec))));
        }
        if (env.on) {   // pbrEnvironmentTerms
            const V nvc = vmin(nv, one);
            // split sum: bilinear in the 32 x 32 table (texel centres, clamped edges)
            const float S = float(kSplitSumSize);
            const V x = sub(mul(nvc, set1(S)), set1(0.5f)), y = sub(mul(vmin(vmax(ks, zero), one), set1(S)), set1(0.5f));
            VI ix, iy;
            const V tx = sub(x, floorV(x, ix)), ty = sub(y, floorV(y, iy));
            const VI z = set1I(0), last = set1I(kSplitSumSize - 1), rowLen = set1I(kSplitSumSize);
            const VI x0 = minI(maxI(ix, z), last), x1 = minI(maxI(addI(ix, set1I(1)), z), last);
            const VI y0 = mulloI(minI(maxI(iy, z), last), rowLen), y1 = mulloI(minI(maxI(addI(iy, set1I(1)), z), last), rowLen);
            const VI i00 = slliI(addI(y0, x0), 1), i10 = slliI(addI(y0, x1), 1), i01 = slliI(addI(y1, x0), 1), i11 = slliI(addI(y1, x1), 1);
            const V sx = sub(one, tx), sy = sub(one, ty);
            auto bilerp = [&](const float* t) {
                return add(mul(sy, add(mul(sx, gatherF(t, i00)), mul(tx, gatherF(t, i10)))),
                           mul(ty, add(mul(sx, gatherF(t, i01)), mul(tx, gatherF(t, i11)))));
            };
            const V A = bilerp(env.splitSum), B = bilerp(env.splitSum + 1);
            const V ems = sub(one, add(A, B));
            const V fBr = mul(f90, B);
            // rotated into the map's frame: the normal (diffuse) and the mirrored view (specular)
            const V mnx = add(mul(set1(env.cosRot), nx), mul(set1(env.sinRot), nz));
            const V mnz = add(mul(set1(-env.sinRot), nx), mul(set1(env.cosRot), nz));
            const V two = mul(set1(2.0f), ndv);
            const V rx = sub(mul(two, nx), vx), ry = sub(mul(two, ny), vy), rz = sub(mul(two, nz), vz);
            const V mrx = add(mul(set1(env.cosRot), rx), mul(set1(env.sinRot), rz));
            const V mrz = add(mul(set1(-env.sinRot), rx), mul(set1(env.cosRot), rz));
            const RGB rad = environmentSpecularV(env, mrx, ry, mrz, ks);
            // diffuse: the 9 harmonics at the rotated normal (env.sh has the intensity in it)
            const V y1b = mul(set1(0.488603f), ny), y2b = mul(set1(0.488603f), mnz), y3b = mul(set1(0.488603f), mnx);
            const V y4b = mul(mul(set1(1.092548f), mnx), ny), y5b = mul(mul(set1(1.092548f), ny), mnz);
            const V y6b = mul(set1(0.315392f), sub(mul(set1(3.0f), mul(mnz, mnz)), one));
            const V y7b = mul(mul(set1(1.092548f), mnx), mnz), y8b = mul(set1(0.546274f), sub(mul(mnx, mnx), mul(ny, ny)));
            auto irr = [&](int ch) {
                const float* s = env.sh[ch];
                V e = set1(s[0] * 0.282095f);
                e = add(e, mul(set1(s[1]), y1b));
                e = add(e, mul(set1(s[2]), y2b));
                e = add(e, mul(set1(s[3]), y3b));
                e = add(e, mul(set1(s[4]), y4b));
                e = add(e, mul(set1(s[5]), y5b));
                e = add(e, mul(set1(s[6]), y6b));
                e = add(e, mul(set1(s[7]), y7b));
                e = add(e, mul(set1(s[8]), y8b));
                return vmax(e, zero);
            };
            auto channel = [&](V f0, V cdiff, V radiance, V irradiance, V& out) {
                const V fssEss = add(mul(f0, A), fBr);
                const V fAvg = add(f0, mul(sub(one, f0), set1(1.0f / 21.0f)));
                const V emsF = mul(ems, fAvg);
                const V fmsEms = div(mul(mul(ems, fssEss), fAvg), sub(one, emsF));
                const V diffuse = mul(mul(sub(sub(one, fssEss), fmsEms), cdiff), irradiance);
                const V specular = add(mul(fssEss, radiance), mul(fmsEms, irradiance));
                out = add(out, vand(lit, mul(occ, add(diffuse, specular))));
            };
            channel(f0r, dr, rad.r, irr(0), cr);
            channel(f0g, dg, rad.g, irr(1), cg);
            channel(f0b, db, rad.b, irr(2), cb);
        }
        storeu(&b.cr[i], cr);
        storeu(&b.cg[i], cg);
        storeu(&b.cb[i], cb);
    }
}

// NOLINTEND
