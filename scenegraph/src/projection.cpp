// projection.cpp - Projection::matrix(): the projection matrix of a camera's parameters
// (perspective from fovy or an explicit frustum, orthographic, oblique sheared about the focus
// distance), built from the transforms of transforms.h; the isometric view's camera.
#include "scenegraph/projection.h"

#include "scenegraph/transforms.h"

#include <algorithm>
#include <cmath>

namespace sg {

float Projection::effectiveFovyDeg(float aspect) const {
    if (!(aspectRatio > 0.0f) || !(aspect > 0.0f) || aspect >= aspectRatio) return fovyDeg;
    // tan(fovy'/2) aspect = tan(fovy/2) aspectRatio: the same horizontal half-angle.
    const float t = std::tan(radians(fovyDeg) * 0.5f) * aspectRatio / aspect;
    return std::min(degrees(2.0f * std::atan(t)), 179.0f);
}

mat4 Projection::matrix(float aspect, float focusDistance) const {
    if (!(aspect > 0.0f) || !std::isfinite(aspect)) aspect = 1.0f;
    switch (type) {
    case ProjectionType::Perspective:
        if (useFrustum) return frustum(left, right, bottom, top, zNear, zFar);
        return perspective(radians(effectiveFovyDeg(aspect)), aspect, zNear, zFar);
    case ProjectionType::Orthographic: {
        float h = orthoHalfHeight, w = h * aspect;
        return orthographic(-w, w, -h, h, zNear, zFar);
    }
    case ProjectionType::Oblique: {
        float h = orthoHalfHeight, w = h * aspect;
        return oblique(-w, w, -h, h, zNear, zFar, radians(obliqueAngleDeg), obliqueFactor, -focusDistance);
    }
    }
    return mat4(1.0f);
}

vec3 isometricViewDirection() {
    const float yaw = radians(kIsometricYawDeg), pitch = radians(kIsometricPitchDeg);
    // The eye's direction from the pivot: yaw about +y from +z, pitch above the horizon.
    return -vec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
}

mat4 isometricCameraWorld(const vec3& pivot, float distance) {
    const vec3 eye = pivot - distance * isometricViewDirection();
    return glm::inverse(lookAt(eye, pivot, vec3(0.0f, 1.0f, 0.0f)));
}

}   // namespace sg
