// material.cpp - phongFromMetallicRoughness() (see material.h, docs/math.md).
#include "scenegraph/material.h"

#include <algorithm>

namespace sg {

PhongFromPbr phongFromMetallicRoughness(float metallic, float roughness) {
    const float m = std::clamp(metallic, 0.0f, 1.0f), r = std::clamp(roughness, 0.0f, 1.0f);
    const float a = r * r;
    PhongFromPbr p;
    p.kd = 1.0f - 0.75f * m;
    p.ks = std::clamp(0.04f + 0.96f * m + 0.25f * (1.0f - r) * (1.0f - m), 0.0f, 1.0f);
    p.shininess = a < 1e-3f ? 2048.0f : std::clamp(2.0f / (a * a) - 2.0f, 1.0f, 2048.0f);
    p.tinted = m >= 0.5f;
    return p;
}

}   // namespace sg
