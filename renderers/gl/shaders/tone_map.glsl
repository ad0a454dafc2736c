// tone_map.glsl - the display transform's operators (renderers/tone_map.h), mirroring
// renderers/common/tone_map.cpp function for function: the same names, the same constants in
// the same order (docs/math.md, "Exposure and tone mapping"). Change both together.
//   TONE_MAPPING   TONE_MAPPING_NONE, TONE_MAPPING_ACES or TONE_MAPPING_KHR_NEUTRAL
//                  (sg::ToneMapping values)

// ACES: Stephen Hill's fit, as the Khronos glTF Sample Viewer applies it. Column-major.
// Input: linear sRGB -> XYZ -> D65 to D60 -> AP1 -> RRT_SAT.
const mat3 kAcesInputMatrix = mat3(0.59719, 0.07600, 0.02840,    // column 0
                                   0.35458, 0.90834, 0.13383,    // column 1
                                   0.04823, 0.01566, 0.83777);   // column 2
// Output: ODT_SAT -> XYZ -> D60 to D65 -> linear sRGB.
const mat3 kAcesOutputMatrix = mat3(1.60475, -0.10208, -0.00327,    // column 0
                                    -0.53108, 1.10813, -0.07276,    // column 1
                                    -0.07367, -0.00605, 1.07602);   // column 2
const float kAcesExposureBoost = 1.0 / 0.6;

// Khronos PBR Neutral: F_90, K_s, K_d of its specification.
const float kNeutralF90 = 0.04;
const float kNeutralStartCompression = 0.8 - kNeutralF90;
const float kNeutralDesaturation = 0.15;

vec3 acesRrtOdtFit(vec3 v) {
    vec3 a = v * (v + 0.0245786) - 0.000090537;
    vec3 b = v * (0.983729 * v + 0.4329510) + 0.238081;
    return a / b;
}

vec3 toneMapAces(vec3 color) {
    vec3 c = kAcesInputMatrix * (color * kAcesExposureBoost);
    c = acesRrtOdtFit(c);
    c = kAcesOutputMatrix * c;
    return clamp(c, 0.0, 1.0);
}

vec3 toneMapKhrNeutral(vec3 color) {
    float x = min(color.r, min(color.g, color.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : kNeutralF90;
    vec3 c = color - offset;
    float peak = max(c.r, max(c.g, c.b));
    if (peak < kNeutralStartCompression) return c;
    float d = 1.0 - kNeutralStartCompression;
    float newPeak = 1.0 - d * d / (peak + d - kNeutralStartCompression);
    c *= newPeak / peak;
    float g = 1.0 - 1.0 / (kNeutralDesaturation * (peak - newPeak) + 1.0);
    return mix(c, vec3(newPeak), g);
}

// The frame's operator (rnd::toneMap with the operator compiled in).
vec3 toneMap(vec3 color) {
#if TONE_MAPPING == TONE_MAPPING_ACES
    return toneMapAces(color);
#elif TONE_MAPPING == TONE_MAPPING_KHR_NEUTRAL
    return toneMapKhrNeutral(color);
#elif TONE_MAPPING == TONE_MAPPING_NONE
    return color;
#else
#error "TONE_MAPPING: a sg::ToneMapping value this shader does not handle"
#endif
}

// T(scale max(linear, 0)); scale = rnd::exposureScale(exposure) = 2^exposure.
vec3 displayTransform(vec3 linear, float scale) { return toneMap(scale * max(linear, vec3(0.0))); }
