// tone_map.cpp - exposure and the tone-mapping operators (see renderers/tone_map.h and
// docs/math.md, "Exposure and tone mapping"). renderers/gl/shaders/tone_map.glsl has the same
// functions under the same names; change both together.
#include "renderers/tone_map.h"

#include <algorithm>
#include <cmath>

namespace rnd {

using sg::vec3;

namespace {

// ACES (Stephen Hill's fit, as the Khronos glTF Sample Viewer's tonemapping.glsl uses it).
// Column-major like GLSL's mat3 constructor, so these lists read exactly as the shader's.
// Input: linear sRGB -> XYZ -> D65 to D60 (Bradford) -> AP1 -> RRT_SAT (the RRT's desaturation).
const sg::mat3 kAcesInputMatrix(0.59719f, 0.07600f, 0.02840f,    // column 0
                                0.35458f, 0.90834f, 0.13383f,    // column 1
                                0.04823f, 0.01566f, 0.83777f);   // column 2
// Output: ODT_SAT (the ODT's desaturation) -> XYZ -> D60 to D65 -> linear sRGB.
const sg::mat3 kAcesOutputMatrix(1.60475f, -0.10208f, -0.00327f,    // column 0
                                 -0.53108f, 1.10813f, -0.07276f,    // column 1
                                 -0.07367f, -0.00605f, 1.07602f);   // column 2
// The Sample Viewer divides the exposed colour by 0.6 before the fit (its "exposure boost",
// taken from Narkowicz's fit, whose input is 0.6 x this fit's for the same mid-grey).
constexpr float kAcesExposureBoost = 1.0f / 0.6f;

// Khronos PBR Neutral's constants (the specification's F_90, K_s and K_d). The offset's
// 0.08 and 6.25 are 2 F_90 and 1 / (4 F_90), written as the reference implementation does.
constexpr float kNeutralF90 = 0.04f;                             // Fresnel at normal incidence, IoR 1.5
constexpr float kNeutralStartCompression = 0.8f - kNeutralF90;   // K_s: where highlights start to compress
constexpr float kNeutralDesaturation = 0.15f;                    // K_d: how fast compressed highlights desaturate

}   // namespace

float exposureScale(float ev) { return std::exp2(ev); }

vec3 acesRrtOdtFit(const vec3& v) {
    const vec3 a = v * (v + 0.0245786f) - 0.000090537f;
    const vec3 b = v * (0.983729f * v + 0.4329510f) + 0.238081f;
    return a / b;
}

vec3 toneMapAces(const vec3& color) {
    vec3 c = kAcesInputMatrix * (color * kAcesExposureBoost);
    c = acesRrtOdtFit(c);
    c = kAcesOutputMatrix * c;
    return glm::clamp(c, 0.0f, 1.0f);
}

vec3 toneMapKhrNeutral(const vec3& color) {
    const float x = std::min(color.r, std::min(color.g, color.b));
    const float offset = x < 0.08f ? x - 6.25f * x * x : kNeutralF90;
    vec3 c = color - offset;
    const float peak = std::max(c.r, std::max(c.g, c.b));
    if (peak < kNeutralStartCompression) return c;
    const float d = 1.0f - kNeutralStartCompression;
    const float newPeak = 1.0f - d * d / (peak + d - kNeutralStartCompression);
    c *= newPeak / peak;
    const float g = 1.0f - 1.0f / (kNeutralDesaturation * (peak - newPeak) + 1.0f);
    return glm::mix(c, vec3(newPeak), g);
}

vec3 toneMap(sg::ToneMapping op, const vec3& color) {
    switch (op) {
    case sg::ToneMapping::None: return color;
    case sg::ToneMapping::Aces: return toneMapAces(color);
    case sg::ToneMapping::KhrNeutral: return toneMapKhrNeutral(color);
    }
    return color;
}

vec3 displayTransform(const vec3& linear, float scale, sg::ToneMapping op) { return toneMap(op, scale * glm::max(linear, vec3(0.0f))); }

}   // namespace rnd
