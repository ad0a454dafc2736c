// orbit_camera.h - the viewer's interactive camera (pure math, no GL, no ImGui).
//
// A turntable camera in the habits of Blender and F3D: it looks at a pivot from `distance`
// away, with yaw around world +y and pitch above/below the horizon (no roll). Orbit, pan,
// dolly-zoom, fly (move eye and pivot together; mouse-look turns around the eye) and fit-to-
// bounds all edit those four numbers; world() turns them into a camera world matrix (camera
// looks down its local -z with +y up, as sg::Camera expects).
#pragma once

#include "scenegraph/math.h"

namespace ui {

class OrbitCamera {
public:
    sg::vec3 pivot{0.0f};
    float distance = 5.0f;
    float yaw = 0.0f;     // radians around world +y; 0 = eye on +z of the pivot
    float pitch = 0.0f;   // radians, + = eye above the pivot; clamped to +-89 degrees
    // Multiplies the projection's orthoHalfHeight (orthographic/oblique zoom).
    float orthoScale = 1.0f;

    static constexpr float kMinDistance = 1e-4f;

    // Camera world matrix (eye -> world).
    sg::mat4 world() const;
    sg::vec3 eye() const;
    sg::vec3 forward() const;   // unit, from eye toward pivot
    sg::vec3 right() const;     // unit, camera +x
    sg::vec3 up() const;        // unit, camera +y

    // Orbit by a mouse delta in pixels (left drag): yaw with dx, pitch with dy.
    void orbit(float dxPixels, float dyPixels, float radiansPerPixel = 0.008f);
    // Pan (middle or shift drag): the point under the cursor follows the cursor. worldPerPixel
    // comes from panScale().
    void pan(float dxPixels, float dyPixels, float worldPerPixel);
    // World units per viewport pixel at the pivot's depth.
    float panScale(float fovyDeg, float viewportHeightPixels, bool orthographic, float orthoHalfHeight) const;
    // Zoom by wheel steps (+ = closer): distance (and orthoScale) scale by factor^steps.
    void zoom(float steps, float factorPerStep = 0.85f);
    // Fly: moves eye and pivot together by a local offset (x right, y up, z forward).
    void fly(const sg::vec3& localOffset);
    // Mouse-look in fly mode: turns around the eye (the pivot moves).
    void look(float dxPixels, float dyPixels, float radiansPerPixel = 0.004f);
    // Frames the bounding sphere of `bounds` for a perspective of fovyDeg and aspect (w/h),
    // keeping the viewing direction. orthoHalfHeight: the projection's, to set orthoScale.
    void fit(const sg::Aabb& bounds, float fovyDeg, float aspect, float orthoHalfHeight = 0.0f);
    // Takes position and direction from a camera world matrix; the pivot is `focus` ahead.
    void setFromWorld(const sg::mat4& cameraWorld, float focus);
};

}   // namespace ui
