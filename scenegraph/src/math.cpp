// math.cpp - the out-of-line helpers of math.h: Aabb::transformed() (the box around the eight
// transformed corners), isFinite() for vectors and matrices, normalMatrix() (inverse transpose
// of the upper 3x3, identity when degenerate) and isInvertible().
#include "scenegraph/math.h"

namespace sg {

Aabb Aabb::transformed(const mat4& m) const {
    Aabb out;
    if (empty()) return out;
    for (int i = 0; i < 8; ++i) {
        vec3 c((i & 1) ? max.x : min.x, (i & 2) ? max.y : min.y, (i & 4) ? max.z : min.z);
        out.extend(vec3(m * vec4(c, 1.0f)));
    }
    return out;
}

bool isFinite(const mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

mat3 normalMatrix(const mat4& world) {
    mat3 a(world);
    float det = glm::determinant(a);
    if (std::abs(det) < 1e-30f) return mat3(1.0f);   // degenerate: keep normals as they are
    return glm::transpose(glm::inverse(a));
}

bool isInvertible(const mat4& m, float eps) {
    float det = glm::determinant(mat3(m));
    return std::isfinite(det) && std::abs(det) > eps;
}

}   // namespace sg
