// shadow_depth_kernel.inl - the shadow depth pass's rows (shadow_map.cpp's rasterizeRows) a
// vector of texels at a time: the same candidate span per row (rowSpan), then every texel of it
// tested and written at once, by the same IEEE operations in the same order as the scalar loop
// (no FMA in either instruction set), so the maps are bit for bit the scalar reference's.
// shadow_map.cpp includes it once per instruction set (raster/simd.h's names); tests/renderers/raster holds
// it to the scalar reference.
// NOLINTBEGIN

// Rasterizes s into rows [r0, r1] of the map (size x size): as rasterizeRows. The scalar loop
// finds the run of inside texels in the span and writes it; here each texel of the span is
// tested (the same edge functions) and written where inside: the same texels, since the inside
// ones form one run. Lanes outside the span (or masked) store back the value they read; the rows
// are this band's alone.
inline void rasterizeRowsV(const TriSetup& s, int size, int r0, int r1, float* map) {
    if (size < int(kW)) {
        rasterizeRows(s, size, r0, r1, map);
        return;
    }
    const V zero = zeroV(), one = set1(1.0f), half = set1(0.5f);
    const VI lane = laneIndex();
    const V ex0 = set1(s.ex[0]), ex1 = set1(s.ex[1]), ex2 = set1(s.ex[2]);
    const V e00 = set1(s.e0[0]), e01 = set1(s.e0[1]), e02 = set1(s.e0[2]);
    const V dwX = set1(s.dwX), iwX = set1(s.iwX);
    // w > 0, or w == 0 on a top or left edge (w >= 0 there)
    auto edgeIn = [&](V w, bool inclusive) { return inclusive ? cmpge(w, zero) : cmpgt(w, zero); };
    const int y0 = std::max(r0, s.y0), y1 = std::min(r1, s.y1);
    for (int y = y0; y <= y1; ++y) {
        const float py = float(y) + 0.5f;
        int xs, xe;
        rowSpan(s, py, xs, xe);
        if (xs > xe) continue;
        float* row = map + size_t(y) * size_t(size);
        const V ey0 = set1(s.ey[0] * py), ey1 = set1(s.ey[1] * py), ey2 = set1(s.ey[2] * py);
        const float iwRowS = s.iwY * py + s.iw0, dwRowS = s.dwY * py + s.dw0;
        const V dwRow = set1(dwRowS), iwRow = set1(iwRowS);
        const V inv = set1(iwRowS != 0.0f ? 1.0f / iwRowS : 0.0f);
        const VI lo = set1I(xs - 1), hi = set1I(xe + 1);
        for (int x = xs; x <= xe; x += int(kW)) {
            const int xv = std::min(x, size - int(kW));   // the last vector of a row ends at the map's edge
            const VI xi = addI(set1I(xv), lane);
            const V px = add(cvtF(xi), half);
            V in = castF(andI(cmpgtI(xi, lo), cmpgtI(hi, xi)));
            in = vand(in, edgeIn(add(add(mul(ex0, px), ey0), e00), s.inclusive[0]));
            in = vand(in, edgeIn(add(add(mul(ex1, px), ey1), e01), s.inclusive[1]));
            in = vand(in, edgeIn(add(add(mul(ex2, px), ey2), e02), s.inclusive[2]));
            if (movemask(in) == 0) continue;
            V z;
            if (s.ortho) {
                z = mul(add(mul(dwX, px), dwRow), inv);
            } else {
                const V iw = add(mul(iwX, px), iwRow), dw = add(mul(dwX, px), dwRow);
                z = sel(cmpneq(iw, zero), div(dw, iw), one);   // (the barycentric normalisation cancels)
            }
            const V ok = vand(in, vand(cmpge(z, zero), cmpge(one, z)));
            const V old = loadu(row + xv);
            storeu(row + xv, sel(ok, vmin(z, old), old));
        }
    }
}

// NOLINTEND
