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

std::string_view toString(ProjectionType t) {
    switch (t) {
    case ProjectionType::Perspective: return "perspective";
    case ProjectionType::Orthographic: return "orthographic";
    case ProjectionType::Oblique: return "oblique";
    }
    return "?";
}

bool parse(std::string_view s, ProjectionType& out) {
    for (auto t : {ProjectionType::Perspective, ProjectionType::Orthographic, ProjectionType::Oblique})
        if (s == toString(t)) {
            out = t;
            return true;
        }
    return false;
}

}   // namespace sg
