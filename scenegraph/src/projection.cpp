// projection.cpp - Projection::matrix(): the projection matrix of a camera's parameters
// (perspective from fovy or an explicit frustum, orthographic, oblique sheared about the focus
// distance), built from the transforms of transforms.h.
#include "scenegraph/projection.h"

#include "scenegraph/transforms.h"

namespace sg {

mat4 Projection::matrix(float aspect, float focusDistance) const {
    if (!(aspect > 0.0f) || !std::isfinite(aspect)) aspect = 1.0f;
    switch (type) {
    case ProjectionType::Perspective:
        if (useFrustum) return frustum(left, right, bottom, top, zNear, zFar);
        return perspective(radians(fovyDeg), aspect, zNear, zFar);
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

}   // namespace sg
