// math.h - the scene graph's vector/matrix vocabulary (GLM, column-major, right-handed,
// camera looking down -z; conventions in docs/math.md) plus a few small helpers.
#pragma once

#include <glm/ext/vector_uint4_sized.hpp>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace sg {

using glm::ivec2;
using glm::ivec3;
using glm::mat3;
using glm::mat4;
using glm::quat;
using glm::u16vec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;

constexpr float kPi = 3.14159265358979323846f;
inline float radians(float deg) { return deg * (kPi / 180.0f); }
inline float degrees(float rad) { return rad * (180.0f / kPi); }

// Axis-aligned bounding box; empty when min > max.
struct Aabb {
    vec3 min{std::numeric_limits<float>::infinity()};
    vec3 max{-std::numeric_limits<float>::infinity()};

    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    void extend(const vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void extend(const Aabb& b) {
        if (!b.empty()) {
            extend(b.min);
            extend(b.max);
        }
    }
    vec3 center() const { return 0.5f * (min + max); }
    vec3 extent() const { return max - min; }
    // Bounds of this box after an affine transform (all 8 corners).
    Aabb transformed(const mat4& m) const;
    bool operator==(const Aabb&) const = default;
};

// Inline: the ray caster asks per ray and per pixel.
inline bool isFinite(const vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool isFinite(const mat4& m);

// Inverse transpose of the upper 3x3: transforms normals so they stay perpendicular
// to transformed tangents (shear and non-uniform scale included).
mat3 normalMatrix(const mat4& world);

// True when the 3x3 part is invertible enough to be used as a transform.
bool isInvertible(const mat4& m, float eps = 1e-12f);

}   // namespace sg
