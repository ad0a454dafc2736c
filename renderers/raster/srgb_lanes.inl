// srgb_lanes.inl - SrgbEncoder's byte for each lane of a vector, written over simd.h's names:
// included inside a kernel file's simd_sse / simd_avx2 namespace (raster/tile_kernels.inl, the
// CPU rasterizer's fragments; raycast/lane_kernel.inl, the ray caster's lanes).

// SrgbEncoder::operator() per lane, branch-free and with one table lookup: values are clamped
// to [2^-13, largest float below 1] first (which encode to 0 and 255 as smaller values, NaN and
// values >= 1 do), then the bucket's packed word gives the byte and where in the bucket it
// steps up (non-negative floats order like their bits).
inline VI encodeSrgb(V x, const SrgbEncoder& t) {
    x = vmin(vmax(x, set1(0x1p-13f)), set1(0x1.fffffep-1f));
    const VI bits = castI(x);
    const VI word = gatherI(reinterpret_cast<const int32_t*>(t.packed), srliI(subI(bits, set1I(0x39000000)), 15));
    const VI step = addI(andI(bits, set1I(~0x7FFF)), andI(word, set1I(0xFFFF)));   // first float of byte + 1
    return subI(srliI(word, 16), cmpgtI(bits, subI(step, set1I(1))));              // + 1 where bits >= step
}
