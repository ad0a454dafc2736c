// light.h - light payload. A light sits at its node's world position and points down its
// node's local -z axis (directional and spot), as in glTF's KHR_lights_punctual.
#pragma once

#include "scenegraph/math.h"

#include <string_view>

namespace sg {

enum class LightType { Point, Directional, Spot };

struct Light {
    LightType type = LightType::Point;
    vec3 color{1.0f};
    float intensity = 1.0f;
    // Inverse-square falloff 1/r^2 (docs/math.md), applied when RenderSettings::attenuation is on.
    bool inverseSquare = false;
    float spotInnerDeg = 20.0f;   // full intensity inside
    float spotOuterDeg = 30.0f;   // zero outside, smooth in between
    // KHR_lights_punctual's range (point and spot): the pbr model fades the light to zero at this
    // distance by (clamp(1 - (d/range)^4, 0, 1))^2 / d^2; 0 = no range (1/d^2 only).
    float range = 0.0f;
    // The light's size, for soft shadows (docs/math.md, "Soft shadows"): point and spot lights are
    // spheres of this radius (world units; 0 = a point), a directional light a disc of this
    // angular radius (degrees; the sun is about 0.27). The ray caster samples the source with
    // several shadow rays, the rasterizers' PCSS filter estimates the penumbra from it; the light
    // itself is still evaluated from its centre.
    float radius = 0.0f;
    float angularRadiusDeg = 0.0f;

    bool operator==(const Light&) const = default;
};

std::string_view toString(LightType t);
bool parse(std::string_view s, LightType& out);

}   // namespace sg
