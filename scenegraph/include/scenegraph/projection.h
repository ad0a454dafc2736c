// projection.h - camera projection parameters and the matrices they produce.
#pragma once

#include "scenegraph/math.h"

#include <string_view>

namespace sg {

enum class ProjectionType { Perspective, Orthographic, Oblique };

struct Projection {
    ProjectionType type = ProjectionType::Perspective;
    float fovyDeg = 45.0f;   // perspective: total vertical angle of view
    // Perspective: the width / height the author framed for (glTF's aspectRatio; 0 = none). A
    // viewport narrower than that widens the vertical angle so the author's horizontal field
    // stays whole (nothing framed is cut); a wider one keeps fovyDeg and shows more at the sides.
    float aspectRatio = 0.0f;
    float zNear = 0.1f;
    float zFar = 100.0f;
    // Perspective: when true, the general frustum (l, r, b, t at zNear) is used instead of
    // fovy and the viewport aspect.
    bool useFrustum = false;
    float left = -0.1f, right = 0.1f, bottom = -0.1f, top = 0.1f;
    // Orthographic and oblique: half the visible height in view units; width from aspect.
    float orthoHalfHeight = 2.0f;
    // Oblique: receding-axis angle (degrees) and foreshortening factor.
    float obliqueAngleDeg = 45.0f;
    float obliqueFactor = 1.0f;   // 1 = cavalier, 0.5 = cabinet

    bool operator==(const Projection&) const = default;

    // Projection matrix for a viewport of the given aspect (width / height). focusDistance is
    // the distance of the oblique projection's fixed plane in front of the camera.
    mat4 matrix(float aspect, float focusDistance) const;
    // The vertical angle a perspective renders with at that viewport aspect (fovyDeg, widened
    // by aspectRatio as above).
    float effectiveFovyDeg(float aspect) const;

    static Projection cavalier() {
        Projection p;
        p.type = ProjectionType::Oblique;
        p.obliqueFactor = 1.0f;
        p.obliqueAngleDeg = 45.0f;
        return p;
    }
    static Projection cabinet() {
        Projection p;
        p.type = ProjectionType::Oblique;
        p.obliqueFactor = 0.5f;
        p.obliqueAngleDeg = 45.0f;
        return p;
    }
};

// Isometric view (docs/math.md, "Isometric view"): an orthographic projection seen along
// -(1, 1, 1) / sqrt(3) with world +y up - turned 45 degrees about the vertical, then looking
// down arctan(1 / sqrt(2)) = 35.264 degrees - so that the three world axes are foreshortened
// alike (a unit axis is sqrt(2/3) = 0.8165 long on the picture plane) and drawn 120 degrees
// apart. The presets (--projection isometric, View > Axis view > Isometric) set both.
constexpr float kIsometricYawDeg = 45.0f;                  // about +y, from looking down -z
constexpr float kIsometricPitchDeg = 35.26438968275466f;   // down from the horizon: atan(1 / sqrt(2))
// The unit direction an isometric camera looks along: -(1, 1, 1) / sqrt(3).
vec3 isometricViewDirection();
// The world matrix (camera -> world; the camera looks down its -z, +y up) of an isometric camera
// looking at `pivot` from `distance` away, its eye on the (+x, +y, +z) side of the pivot.
mat4 isometricCameraWorld(const vec3& pivot, float distance);

std::string_view toString(ProjectionType t);
bool parse(std::string_view s, ProjectionType& out);

}   // namespace sg
