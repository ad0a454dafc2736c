// sampling.h - the small sampling helpers several parts of the renderers share: an integer hash
// (C++ and shaders/shadow.glsl alike), Hammersley's radical inverse, Shirley and Chiu's
// concentric map of the square onto the disc.
#pragma once

#include "scenegraph/math.h"

#include <cstdint>

namespace rnd {

// A 32-bit integer hash (Wellons' "lowbias32"); shadow.glsl's pcssHash is the same, bit for bit.
inline uint32_t hash32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

// The top 24 bits of h as a float in [0, 1) (exact in float, the same in GLSL).
inline float unitFloat(uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }

// Van der Corput's radical inverse in base 2 of i, in [0, 1) (Hammersley points: ((i + 0.5)/n, it)).
float radicalInverse(uint32_t i);

// The unit disc point of Shirley and Chiu's concentric map for (a, b) in [0, 1)^2.
sg::vec2 concentricDisc(float a, float b);

}   // namespace rnd
