// shapes.h - analytic geometry payloads: implicit shapes, CSG operations, parametric surfaces
// and density grids. Here they are data with bounds and evaluation functions; the backends
// intersect them exactly (ray caster) or tessellate them (rasterizers).
// Conventions: every shape lives in its node's local frame; implicit functions are negative
// inside, zero on the surface, positive outside.
#pragma once

#include "scenegraph/math.h"

#include <array>
#include <string_view>
#include <vector>

namespace sg {

enum class ImplicitType { Plane, Sphere, Box, Cylinder, Cone, Torus, Quadric };

struct ImplicitShape {
    ImplicitType type = ImplicitType::Sphere;
    float radius = 1.0f;           // sphere, cylinder, cone (base radius)
    vec3 halfExtents{0.5f};        // box
    float halfHeight = 0.5f;       // cylinder, cone: extent along local y (capped solids)
    float majorRadius = 1.0f;      // torus: ring radius (around local y)
    float minorRadius = 0.25f;     // torus: tube radius
    float planeHalfSize = 10.0f;   // plane y = 0: infinite for rays; rasterizers draw this square
    // General quadric x^T Q x = 0 with x = (x, y, z, 1); inside where x^T Q x < 0.
    mat4 quadric{1.0f, 0, 0, 0, 0, 1.0f, 0, 0, 0, 0, 1.0f, 0, 0, 0, 0, -1.0f};
    Aabb quadricBounds{vec3(-1.0f), vec3(1.0f)};   // quadrics are clipped to this box

    bool operator==(const ImplicitShape&) const = default;

    Aabb localBounds() const;
    // f(p): < 0 inside, 0 on the surface, > 0 outside (not necessarily a distance).
    float value(const vec3& p) const;
    // Outward surface normal direction at p (gradient of f, normalised).
    vec3 normal(const vec3& p) const;
};

// CSG node: combines its children (implicit shapes or nested CSG nodes) left to right:
// union: A | B | C, intersection: A & B & C, difference: A - B - C.
enum class CsgOp { Union, Intersection, Difference };
struct CsgNode {
    CsgOp op = CsgOp::Union;
    bool operator==(const CsgNode&) const = default;
};

// Parametric surface x = f(u,v), y = g(u,v), z = h(u,v) with u, v in [0,1].
enum class ParametricType { Torus, BezierPatch };
struct ParametricSurface {
    ParametricType type = ParametricType::BezierPatch;
    float majorRadius = 1.0f, minorRadius = 0.3f;   // torus
    std::array<vec3, 16> control{};                 // bicubic Bezier, row-major [v][u]

    bool operator==(const ParametricSurface&) const = default;

    vec3 evaluate(float u, float v) const;
    // Partial derivatives dP/du and dP/dv; the normal is dPdu x dPdv.
    void partials(float u, float v, vec3& dPdu, vec3& dPdv) const;
    // evaluate() and partials() in one pass (the same values, bit for bit), for Newton's method.
    vec3 evaluate(float u, float v, vec3& dPdu, vec3& dPdv) const;
    vec3 normal(float u, float v) const;
    Aabb localBounds() const;
    static ParametricSurface defaultPatch();   // a gentle hill over [-1,1]^2
};

// The cubic Bernstein basis at t, b[i] = C(3, i) t^i (1 - t)^(3 - i), and its derivative db[i],
// exactly as ParametricSurface evaluates them (shared, so a faster evaluator gives the same bits).
inline void cubicBernstein(float t, float b[4], float db[4]) {
    float s = 1 - t;
    b[0] = s * s * s;
    b[1] = 3 * t * s * s;
    b[2] = 3 * t * t * s;
    b[3] = t * t * t;
    db[0] = -3 * s * s;
    db[1] = 3 * s * s - 6 * t * s;
    db[2] = 6 * t * s - 3 * t * t;
    db[3] = 3 * t * t;
}

// Scalar density on a regular grid filling `bounds`; the surface is value == isoValue and
// "inside" is value > isoValue. Samples are at the cell corners: dims.x * dims.y * dims.z values,
// x fastest.
struct DensityGrid {
    ivec3 dims{0};
    std::vector<float> values;
    float isoValue = 0.5f;
    Aabb bounds{vec3(-1.0f), vec3(1.0f)};

    bool operator==(const DensityGrid&) const = default;

    float at(int x, int y, int z) const { return values[(size_t(z) * dims.y + y) * dims.x + x]; }
    // Trilinear interpolation at a local position (clamped to the grid).
    float sample(const vec3& p) const;
    vec3 gradient(const vec3& p) const;
    static DensityGrid metaballs(int resolution);   // demo content: three blended blobs
};

std::string_view toString(ImplicitType t);
bool parse(std::string_view s, ImplicitType& out);
std::string_view toString(CsgOp op);
bool parse(std::string_view s, CsgOp& out);
std::string_view toString(ParametricType t);
bool parse(std::string_view s, ParametricType& out);

}   // namespace sg
