// soft_shadows.cpp - softShadowRay(): the ray caster's shadow rays to a light with a size
// (shadow_map.h; docs/math.md, "Soft shadows").
#include "renderers/sampling.h"
#include "renderers/shadow_map.h"

#include <cmath>
#include <limits>

namespace rnd {

using sg::vec2;
using sg::vec3;

vec2 concentricDisc(float a, float b) {
    const float x = 2.0f * a - 1.0f, y = 2.0f * b - 1.0f;
    if (x == 0.0f && y == 0.0f) return vec2(0.0f);
    constexpr float kQuarterPi = 0.78539816339744831f;
    float r, phi;
    if (std::abs(x) > std::abs(y)) {
        r = x;
        phi = kQuarterPi * (y / x);
    } else {
        r = y;
        phi = 2.0f * kQuarterPi - kQuarterPi * (x / y);
    }
    return {r * std::cos(phi), r * std::sin(phi)};
}

ShadowRayTarget softShadowRay(const sg::DrawLight& L, const vec3& p, int k, int n, const vec2& rotation) {
    float a = (float(k) + 0.5f) / float(n) + rotation.x, b = radicalInverse(uint32_t(k)) + rotation.y;
    a -= std::floor(a);
    b -= std::floor(b);
    const vec2 d = concentricDisc(a, b);
    // The disc's axis: toward the light's centre from p (directional: against its direction).
    const bool directional = L.type == sg::LightType::Directional;
    vec3 axis = directional ? -L.direction : L.position - p;
    const float centre = glm::length(axis);
    if (!(centre > 0.0f)) return {vec3(0.0f, 0.0f, 1.0f), 0.0f};
    axis /= centre;
    // An orthonormal frame around the axis (Duff et al. 2017).
    const float s = std::copysign(1.0f, axis.z), e = -1.0f / (s + axis.z);
    const vec3 t(1.0f + s * axis.x * axis.x * e, s * axis.x * axis.y * e, -s * axis.x);
    const vec3 bt(axis.x * axis.y * e, s + axis.y * axis.y * e, -axis.y);
    ShadowRayTarget r;
    if (directional) {
        r.dir = glm::normalize(axis + L.tanAngularRadius * (d.x * t + d.y * bt));
        r.distance = std::numeric_limits<float>::infinity();
    } else {
        const vec3 to = axis * centre + L.radius * (d.x * t + d.y * bt);
        r.distance = glm::length(to);
        r.dir = r.distance > 0.0f ? to / r.distance : axis;
    }
    return r;
}

}   // namespace rnd
