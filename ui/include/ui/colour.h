// colour.h - colours as the user sees them. The scene stores colours linear (what the renderers
// light with); the framebuffers, the viewport and colour pickers elsewhere show sRGB-encoded
// values. The colour editors convert both ways, so a background stored as linear 0.08 shows as
// sRGB 80 / 255, the value a colour picker reads off the viewport.
#pragma once

#include "scenegraph/math.h"

#include <algorithm>
#include <cmath>

namespace ui {

// The sRGB transfer function (IEC 61966-2-1) per channel; negative values clamp to 0, values
// above 1 (HDR light colours) follow the same curve.
inline float srgbFromLinear(float linear) {
    float x = std::max(linear, 0.0f);
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}
inline float linearFromSrgb(float encoded) {
    float x = std::max(encoded, 0.0f);
    return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f);
}
inline sg::vec3 srgbFromLinear(const sg::vec3& c) { return {srgbFromLinear(c.x), srgbFromLinear(c.y), srgbFromLinear(c.z)}; }
inline sg::vec3 linearFromSrgb(const sg::vec3& c) { return {linearFromSrgb(c.x), linearFromSrgb(c.y), linearFromSrgb(c.z)}; }

}   // namespace ui
