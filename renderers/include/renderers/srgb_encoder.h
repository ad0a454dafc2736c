// srgb_encoder.h - the CPU backends' exact linear -> 8-bit sRGB encoder without pow: the byte
// every fragment's or ray-cast pixel's colour channel ends as (the scalar operator(), and the
// tables the rasterizer's vector output kernel in raster/tile_kernels.inl reads).
//
// Floats in [2^-13, 1) fall into buckets by exponent and the top 8 mantissa bits (13 * 256
// buckets, index (bits(x) - bits(2^-13)) >> 15). table[i] is the byte of bucket i's first float
// and x >= next[b], the smallest float whose byte is b + 1, adds one; a bucket is narrower than
// the gap between two thresholds, so one comparison finishes it. Values below 2^-13 (and NaN)
// encode to 0, values >= 1 to 255. The byte is rnd::toByteSRGB's for every float (the ray
// caster's and the GL backend's reference), which tests/renderers/raster checks exhaustively on [2^-14, 1].
#pragma once

#include <cstdint>
#include <cstring>

namespace rnd {

struct SrgbEncoder {
    static constexpr int kMinExp = -13;
    static constexpr int kBuckets = 13 * 256;
    float next[256];           // next[b]: smallest float that encodes to b + 1
    uint8_t table[kBuckets];   // byte at each bucket's start
    // The same per bucket in one 32-bit word, for vector gathers: byte << 16 | the offset, in
    // float bits from the bucket's first float, where the byte becomes byte + 1 (0x8000: not in
    // this bucket). Gives operator()'s byte for every float of the bucket.
    uint32_t packed[kBuckets];

    SrgbEncoder();
    uint8_t operator()(float x) const {
        if (!(x >= 0x1p-13f)) return 0;   // also NaN
        if (x >= 1.0f) return 255;
        uint32_t bits;
        std::memcpy(&bits, &x, 4);
        const uint32_t idx = (bits - 0x39000000u) >> 15;   // 0x39000000 = bits of 2^-13
        const uint8_t b = table[idx];
        return uint8_t(b + (x >= next[b]));
    }
};

// The one encoder (built on first use).
const SrgbEncoder& srgbEncoder();

}   // namespace rnd
