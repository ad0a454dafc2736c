// tile_kernels.inl - the bodies of tile_kernels.h's functions, written once over simd.h's vector
// wrappers (V, VI, kW, set1, add, ...); tile_kernels.cpp includes it for SSE2 and for AVX2. Each
// lane performs the scalar code's IEEE operations in the same order (see tile_kernels.h).
// NOLINTBEGIN

// The rows ja..jb of one vector column of a block (kW pixels from depth/ids + off): e0..e2 are
// the edge values of its lanes on row ja and step by sy0..sy2 from row to row, and j - minY by
// 1.0 (exact: small integers), so the z of a lane is the scalar code's
// (zRef + zdx (i - minX)) + zdy (j - minY), zx holding the first part. colMask: the lanes inside
// the rectangle; `full`: the column lies inside all three edges (only colMask applies).
// Everything by value, so that it stays in registers.
inline void columnRows(int ja, int jb, size_t off, int minY, bool full, VI colMask, V zx, VI e0, VI e1, VI e2, VI sy0, VI sy1, VI sy2, V zdy, VI idv,
                       float* depth, uint32_t* ids) {
    const V zero = zeroV(), one = set1(1.0f);
    const VI minusOne = set1I(-1);
    V dj = set1(float(ja - minY));
    for (int j = ja; j <= jb; ++j, off += kTileSize) {
        const V zy = mul(zdy, dj);
        dj = add(dj, one);
        const VI m = full ? colMask : andI(colMask, cmpgtI(orI(orI(e0, e1), e2), minusOne));   // all three >= 0
        e0 = addI(e0, sy0);
        e1 = addI(e1, sy1);
        e2 = addI(e2, sy2);
        const V mf = castF(m);
        if (movemask(mf) == 0) continue;
        // clamp(z, 0, 1) as std::clamp: min(z, 1) takes 1 for NaN (which fails z < depth as NaN
        // does), max(0, .) keeps -0.
        const V z = vmax(zero, vmin(add(zx, zy), one));
        const V d = loadu(depth + off);
        const V pass = vand(mf, cmplt(z, d));
        storeu(depth + off, sel(pass, z, d));
        storeuI(ids + off, selI(castI(pass), idv, loaduI(ids + off)));
    }
}

// The vector columns of a block whose first pixel is (bx, ja) (blocks are kB = 8 pixels wide:
// one AVX2 vector, two SSE2 ones): each column that has a pixel in [ia, ib] runs columnRows.
// e[k]: edge k's value at the block row's first pixel (32 bits), stepX[k][c]: its change to each
// lane of column c.
template <int kV>
inline void blockRows(int bx, int ia, int ib, int ja, int jb, int tx0, int ty0, const TriCoverage& s, bool full, const int32_t (&e)[3],
                      const VI (&stepX)[3][kV], const VI (&syv)[3], V zRef, V zdx, V zdy, VI idv, float* depth, uint32_t* ids) {
    const VI lane = laneIndex();
    for (int c = 0; c < kV; ++c) {
        const int first = bx + c * int(kW);
        if (first > ib || first + int(kW) - 1 < ia) continue;
        const VI col = addI(set1I(first), lane);
        const VI colMask = andI(cmpgtI(col, set1I(ia - 1)), cmpgtI(set1I(ib + 1), col));
        const V zx = add(zRef, mul(zdx, cvtF(addI(set1I(first - s.minX), lane))));
        columnRows(ja, jb, size_t(ja - ty0) * kTileSize + size_t(first - tx0), s.minY, full, colMask, zx, addI(set1I(e[0]), stepX[0][c]),
                   addI(set1I(e[1]), stepX[1][c]), addI(set1I(e[2]), stepX[2][c]), syv[0], syv[1], syv[2], zdy, idv, depth, ids);
    }
}

// Edge k's change from a block row's first pixel to each lane's pixel, for each vector column c
// (|.| < 2^30 where used). Built in registers (lane * sx from the lane index's bits): eight
// scalar stores read back as one vector stall on store forwarding.
template <int kV>
inline void laneSteps(const int64_t (&sx)[3], VI (&stepX)[3][kV]) {
    const VI lane = laneIndex();
    const VI bit1 = cmpgtI(andI(lane, set1I(1)), set1I(0)), bit2 = cmpgtI(andI(lane, set1I(2)), set1I(0));
    const VI bit4 = cmpgtI(andI(lane, set1I(4)), set1I(0));
    for (int k = 0; k < 3; ++k) {
        const int32_t s1 = int32_t(sx[k]);
        const VI times = addI(addI(andI(bit1, set1I(s1)), andI(bit2, set1I(2 * s1))), andI(bit4, set1I(4 * s1)));
        for (int c = 0; c < kV; ++c) stepX[k][c] = addI(times, set1I(s1 * c * int(kW)));
    }
}

inline void rasterizeOpaqueKernel(const TriCoverage& s, const TriPlanes& pl, uint32_t id, int tx0, int ty0, int x0, int y0, int x1, int y1,
                                  float* depth, uint32_t* ids) {
    constexpr int kB = 8;                           // block size, as forEachCoveredPixel
    constexpr int kV = kB / int(kW);                // vectors per block row
    constexpr int64_t kInside = int64_t(1) << 30;   // an edge that holds over the whole block
    const PackedEdge* e = s.e;
    int64_t sx[3], sy[3];
    for (int k = 0; k < 3; ++k) {
        sx[k] = int64_t(e[k].a) * kSub;
        sy[k] = int64_t(e[k].b) * kSub;
    }
    // A small triangle (most of a detailed mesh's): every edge shorter than 16 pixels in |dx| + |dy|
    // and its part in the tile at most 8 pixels wide: one block at (x0, y0), any number of rows,
    // without the block tests. Its vertices lie within 16 pixels of every pixel of its bbox, so its
    // edge values there stay below (16 * 256)^2: 32 bits. (The bbox alone would not do: a large
    // triangle's bbox clipped to the viewport can be small.) Tested first, so that its path sets
    // up only what it uses.
    constexpr int64_t kShort = 16 * kSub;
    if (x1 - x0 < kB && std::abs(int64_t(e[0].a)) + std::abs(int64_t(e[0].b)) < kShort &&
        std::abs(int64_t(e[1].a)) + std::abs(int64_t(e[1].b)) < kShort && std::abs(int64_t(e[2].a)) + std::abs(int64_t(e[2].b)) < kShort) {
        VI stepX[3][kV];
        laneSteps<kV>(sx, stepX);
        const VI syv[3] = {set1I(int32_t(sy[0])), set1I(int32_t(sy[1])), set1I(int32_t(sy[2]))};
        const int64_t px = int64_t(x0) * kSub + kHalf, py = int64_t(y0) * kSub + kHalf;
        const int32_t ev[3] = {int32_t(e[0].at(px, py)), int32_t(e[1].at(px, py)), int32_t(e[2].at(px, py))};
        blockRows<kV>(x0, x0, x1, y0, y1, tx0, ty0, s, false, ev, stepX, syv, set1(pl.zRef), set1(pl.zdx), set1(pl.zdy), set1I(int32_t(id)), depth,
                      ids);
        return;
    }
    VI stepX[3][kV];
    laneSteps<kV>(sx, stepX);
    const VI idv = set1I(int32_t(id));
    const V zRef = set1(pl.zRef), zdx = set1(pl.zdx), zdy = set1(pl.zdy);
    const VI syv[3] = {set1I(int32_t(sy[0])), set1I(int32_t(sy[1])), set1I(int32_t(sy[2]))};
    int64_t hi[3], lo[3];   // offsets from a block's first pixel to where each edge is largest / smallest
    for (int k = 0; k < 3; ++k) {
        hi[k] = std::max<int64_t>(sx[k], 0) * (kB - 1) + std::max<int64_t>(sy[k], 0) * (kB - 1);
        lo[k] = std::min<int64_t>(sx[k], 0) * (kB - 1) + std::min<int64_t>(sy[k], 0) * (kB - 1);
    }
    const bool small = (x1 - x0) < kB && (y1 - y0) < kB;
    for (int by = small ? y0 : (y0 & ~(kB - 1)); by <= y1; by += kB) {
        for (int bx = small ? x0 : (x0 & ~(kB - 1)); bx <= x1; bx += kB) {
            const int64_t px = int64_t(bx) * kSub + kHalf, py = int64_t(by) * kSub + kHalf;
            int64_t b[3];
            for (int k = 0; k < 3; ++k) b[k] = e[k].at(px, py);
            if (b[0] + hi[0] < 0 || b[1] + hi[1] < 0 || b[2] + hi[2] < 0) continue;   // block outside an edge
            const bool full = b[0] + lo[0] >= 0 && b[1] + lo[1] >= 0 && b[2] + lo[2] >= 0;
            const int ia = std::max(bx, x0), ib = std::min(bx + kB - 1, x1);
            const int ja = std::max(by, y0), jb = std::min(by + kB - 1, y1);
            // Not rejected: b >= -hi > -2^30. An edge that holds over the whole block may be far
            // larger; it is clamped (it stays >= 0 over the block), so every value on the block's
            // rows fits 32 bits.
            int32_t ev[3];
            for (int k = 0; k < 3; ++k) ev[k] = int32_t((b[k] + lo[k] >= 0 ? kInside : b[k]) + sy[k] * (ja - by));
            blockRows<kV>(bx, ia, ib, ja, jb, tx0, ty0, s, full, ev, stepX, syv, zRef, zdx, zdy, idv, depth, ids);
        }
    }
}

// (a0 c0 + a1 c1) + a2 c2, as glm's scalar * vec3 sums (no lambdas: they would not inherit the
// AVX2 target of this region).
inline V dot3(V a0, V a1, V a2, V c0, V c1, V c2) { return add(add(mul(a0, c0), mul(a1, c1)), mul(a2, c2)); }
// Component c of the attribute a[corner][component] at the corner weights bo.
inline V interp(const V (&bo)[3], const V (&a)[3][3], int c) { return dot3(bo[0], bo[1], bo[2], a[0][c], a[1][c], a[2][c]); }

inline void preparePlainKernel(const PlainTri& t, bool fog, const uint16_t* fragPixel, int x0, int y0, size_t k, size_t count, const BatchOut& o,
                               float* fogDist) {
    static_assert(kTileSize == 64, "pixel p of a tile: x = p & 63, y = p >> 6");
    const TriPlanes& pl = *t.pl;
    const VI offX = set1I(x0 - t.minX), offY = set1I(y0 - t.minY), low = set1I(kTileSize - 1);
    V uRef[3], udx[3], udy[3];
    for (int q = 0; q < 3; ++q) {
        uRef[q] = set1(pl.uRef[q]);
        udx[q] = set1(pl.udx[q]);
        udy[q] = set1(pl.udy[q]);
    }
    // Weights of the input corners from the setup vertices' barycentrics b: through the clipped
    // piece's barycentrics, or a permutation.
    V cw[3][3];
    if (t.cb)
        for (int q = 0; q < 3; ++q)
            for (int c = 0; c < 3; ++c) cw[q][c] = set1((*t.cb)[q][c]);
    V pv[3][3], ev[3][3], nv[3][3];   // [corner][component]
    for (int q = 0; q < 3; ++q)
        for (int c = 0; c < 3; ++c) {
            pv[q][c] = set1(t.p[q][c]);
            ev[q][c] = set1(t.pe[q][c]);
            nv[q][c] = set1(t.n[q][c]);
        }
    const VI slot = set1I(t.slot);
    const V zero = zeroV(), one = set1(1.0f);
    for (size_t g = 0; g < count; g += kW) {
        const size_t i = k + g;
        const VI pix = loadU16(fragPixel + i);
        const V di = cvtF(addI(andI(pix, low), offX));
        const V dj = cvtF(addI(srliI(pix, 6), offY));
        V u[3], sum = zero;
        for (int q = 0; q < 3; ++q) {
            u[q] = add(add(uRef[q], mul(udx[q], di)), mul(udy[q], dj));
            sum = add(sum, u[q]);
        }
        const V inv = vand(cmpneq(sum, zero), div(one, sum));
        const V b[3] = {mul(u[0], inv), mul(u[1], inv), mul(u[2], inv)};
        V bo[3];
        if (t.cb) {
            for (int c = 0; c < 3; ++c) bo[c] = dot3(b[0], b[1], b[2], cw[0][c], cw[1][c], cw[2][c]);
        } else if (!t.swapped) {
            bo[0] = b[0];
            bo[1] = b[1];
            bo[2] = b[2];
        } else {
            bo[0] = b[0];
            bo[1] = b[2];
            bo[2] = b[1];
        }
        storeu(o.px + i, interp(bo, pv, 0));
        storeu(o.py + i, interp(bo, pv, 1));
        storeu(o.pz + i, interp(bo, pv, 2));
        V nx, ny, nz;
        if (t.faceNormal) {
            nx = nv[0][0];
            ny = nv[0][1];
            nz = nv[0][2];
        } else {
            nx = interp(bo, nv, 0);
            ny = interp(bo, nv, 1);
            nz = interp(bo, nv, 2);
            const V len = vsqrt(add(add(mul(nx, nx), mul(ny, ny)), mul(nz, nz)));
            const V pos = cmpgt(len, zero);
            nx = sel(pos, div(nx, len), zero);
            ny = sel(pos, div(ny, len), zero);
            nz = sel(pos, div(nz, len), one);
        }
        storeu(o.nx + i, nx);
        storeu(o.ny + i, ny);
        storeu(o.nz + i, nz);
        storeuI(o.mat + i, slot);
        if (!fog) {
            storeu(fogDist + i, zero);
            continue;
        }
        const V ex = interp(bo, ev, 0), ey = interp(bo, ev, 1), ez = interp(bo, ev, 2);
        storeu(fogDist + i, vsqrt(add(add(mul(ex, ex), mul(ey, ey)), mul(ez, ez))));
    }
}

#include "raster/srgb_lanes.inl"

inline void writeFragmentsKernel(const float* cr, const float* cg, const float* cb, const float* fogDist, const uint16_t* fragPixel, size_t n,
                                 const LinearFog& fog, const SrgbEncoder& srgb, uint32_t* color) {
    const V zero = zeroV(), one = set1(1.0f), fogEnd = set1(fog.end), fogRange = set1(fog.range);
    const V fr = set1(fog.color.x), fg = set1(fog.color.y), fb = set1(fog.color.z);
    const VI alpha = set1I(int32_t(0xFF000000u));
    for (size_t k = 0; k < n; k += kW) {
        V r = loadu(cr + k), g = loadu(cg + k), bl = loadu(cb + k);
        if (fog.on) {
            V vis = div(sub(fogEnd, loadu(fogDist + k)), fogRange);
            // std::clamp(vis, 0, 1): vis < 0 ? 0 : (1 < vis ? 1 : vis) (NaN stays NaN)
            const V lt = cmplt(vis, zero), gt = cmplt(one, vis);
            vis = sel(lt, zero, sel(gt, one, vis));
            const V rest = sub(one, vis);
            r = add(mul(vis, r), mul(rest, fr));
            g = add(mul(vis, g), mul(rest, fg));
            bl = add(mul(vis, bl), mul(rest, fb));
        }
        const VI word = orI(orI(encodeSrgb(r, srgb), slliI(encodeSrgb(g, srgb), 8)), orI(slliI(encodeSrgb(bl, srgb), 16), alpha));
        alignas(32) int32_t words[kW];
        storeI(words, word);
        const size_t m = std::min(n - k, kW);
        for (size_t l = 0; l < m; ++l) color[fragPixel[k + l]] = uint32_t(words[l]);
    }
}

// NOLINTEND
