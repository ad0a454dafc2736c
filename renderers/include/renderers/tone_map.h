// tone_map.h - the display transform, the last step of every backend before the sRGB encoding
// (docs/math.md, "Exposure and tone mapping"): a pixel's linear colour L - after fog, blending
// and the anti-aliasing resolve (the mean of its samples' linear colours) - is shown as
//   encodeSRGB(T(2^EV max(L, 0)))
// with EV = RenderSettings::exposure and T the operator of RenderSettings::toneMapping:
//   none         T(c) = c (the sRGB encoding clips at 1)
//   aces         Stephen Hill's fit of the ACES reference rendering transform (RRT) and sRGB
//                output transform (ODT), between the sRGB -> AP1 (RRT_SAT) and AP1 (ODT_SAT)
//                -> sRGB matrices, as the Khronos glTF Sample Viewer applies it: its input is
//                divided by 0.6 first (the Sample Viewer's "exposure boost", which puts the
//                fit's mid-grey where Narkowicz's fit has it), output clamped to [0, 1]
//   khr-neutral  the Khronos PBR Neutral tone mapper, as its specification writes it
// When the transform is the identity (exposure 0, no operator) the backends encode L exactly
// as before, through their fast paths. This is the one scalar implementation; the GL backend's
// renderers/gl/shaders/tone_map.glsl mirrors it function for function, with the same names.
#pragma once

#include "scenegraph/math.h"
#include "scenegraph/settings.h"

namespace rnd {

// 2^ev: the factor RenderSettings::exposure multiplies the linear colour by.
float exposureScale(float ev);

// The rational fit of the RRT + ODT in AP1, per channel:
//   (v (v + 0.0245786) - 0.000090537) / (v (0.983729 v + 0.4329510) + 0.238081).
sg::vec3 acesRrtOdtFit(const sg::vec3& v);
// ACES filmic: clamp(kAcesOutputMatrix acesRrtOdtFit(kAcesInputMatrix (c / 0.6)), 0, 1).
sg::vec3 toneMapAces(const sg::vec3& color);
// Khronos PBR Neutral (KhronosGroup/ToneMapping, PBR_Neutral): an offset f of the darkest
// channel x (x - x^2 / 0.16 below 0.08, else 0.04), then above the peak p = max(c - f) of
// 0.76 a compression of the peak to p_n = 1 - 0.24^2 / (p - 0.52) and a desaturation toward
// p_n by 1 - 1 / (0.15 (p - p_n) + 1). Output in [0, 1] for non-negative input.
sg::vec3 toneMapKhrNeutral(const sg::vec3& color);
// The operator `op` (none: the colour as it is).
sg::vec3 toneMap(sg::ToneMapping op, const sg::vec3& color);
// T(scale max(linear, 0)): what the display shows of `linear`, before the sRGB encoding.
sg::vec3 displayTransform(const sg::vec3& linear, float scale, sg::ToneMapping op);

// A frame's display transform, from its settings.
struct DisplayTransform {
    explicit DisplayTransform(const sg::RenderSettings& s)
        : identity(s.displayTransformIsIdentity()), scale(exposureScale(s.exposure)), op(s.toneMapping) {}
    bool identity = true;   // exposure 0 and no operator: encode the linear colour as it is
    float scale = 1.0f;     // exposureScale(exposure)
    sg::ToneMapping op = sg::ToneMapping::None;
    // The identity returns `linear` itself (bit for bit).
    sg::vec3 operator()(const sg::vec3& linear) const { return identity ? linear : displayTransform(linear, scale, op); }
};

}   // namespace rnd
