// orbit_camera.cpp - turntable camera math (see orbit_camera.h).
#include "ui/orbit_camera.h"

#include <algorithm>
#include <cmath>

namespace ui {

namespace {
constexpr float kMaxPitch = 89.0f * sg::kPi / 180.0f;
// Direction from the pivot to the eye for a yaw/pitch.
sg::vec3 offsetDir(float yaw, float pitch) { return {std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)}; }
}   // namespace

sg::vec3 OrbitCamera::eye() const { return pivot + distance * offsetDir(yaw, pitch); }
sg::vec3 OrbitCamera::forward() const { return -offsetDir(yaw, pitch); }
sg::vec3 OrbitCamera::right() const { return glm::normalize(glm::cross(forward(), sg::vec3(0, 1, 0))); }
sg::vec3 OrbitCamera::up() const { return glm::cross(right(), forward()); }

sg::mat4 OrbitCamera::world() const {
    // Columns: camera axes in world space (x right, y up, z backward) and the eye.
    sg::mat4 m(1.0f);
    m[0] = sg::vec4(right(), 0.0f);
    m[1] = sg::vec4(up(), 0.0f);
    m[2] = sg::vec4(-forward(), 0.0f);
    m[3] = sg::vec4(eye(), 1.0f);
    return m;
}

void OrbitCamera::orbit(float dx, float dy, float rpp) {
    yaw -= dx * rpp;                                               // drag right: scene turns right
    pitch = std::clamp(pitch + dy * rpp, -kMaxPitch, kMaxPitch);   // drag down: look from above
}

void OrbitCamera::pan(float dx, float dy, float wpp) {
    // Screen y grows downward; the scene follows the cursor, so the pivot moves the other way.
    pivot += (-dx * wpp) * right() + (dy * wpp) * up();
}

float OrbitCamera::panScale(float fovyDeg, float viewportHeight, bool ortho, float orthoHalfHeight) const {
    viewportHeight = std::max(viewportHeight, 1.0f);
    if (ortho) return 2.0f * orthoHalfHeight * orthoScale / viewportHeight;
    return 2.0f * distance * std::tan(sg::radians(fovyDeg) * 0.5f) / viewportHeight;
}

void OrbitCamera::zoom(float steps, float factor) {
    float s = std::pow(factor, steps);
    distance = std::max(distance * s, kMinDistance);
    orthoScale = std::max(orthoScale * s, 1e-6f);
}

void OrbitCamera::fly(const sg::vec3& o) {
    sg::vec3 d = o.x * right() + o.y * sg::vec3(0, 1, 0) + o.z * forward();
    pivot += d;
}

void OrbitCamera::look(float dx, float dy, float rpp) {
    sg::vec3 e = eye();
    yaw -= dx * rpp;
    pitch = std::clamp(pitch - dy * rpp, -kMaxPitch, kMaxPitch);
    pivot = e + forward() * distance;   // keep the eye where it is
}

void OrbitCamera::fit(const sg::Aabb& bounds, float fovyDeg, float aspect, float orthoHalfHeight) {
    sg::Aabb b = bounds.empty() ? sg::Aabb{sg::vec3(-1.0f), sg::vec3(1.0f)} : bounds;
    float radius = std::max(0.5f * glm::length(b.extent()), 1e-3f);
    float halfY = sg::radians(std::clamp(fovyDeg, 1.0f, 179.0f)) * 0.5f;
    float halfX = std::atan(std::tan(halfY) * std::max(aspect, 1e-3f));
    float half = std::min(halfX, halfY);
    pivot = b.center();
    distance = radius / std::sin(half) * 1.05f;   // the sphere touches the narrower frustum side
    if (orthoHalfHeight > 0.0f) orthoScale = radius * 1.05f / std::min(1.0f, aspect) / orthoHalfHeight;
}

void OrbitCamera::setFromWorld(const sg::mat4& w, float focus) {
    sg::vec3 e(w[3]);
    sg::vec3 back(w[2]);
    if (glm::length(back) < 1e-12f) back = sg::vec3(0, 0, 1);
    back = glm::normalize(back);
    distance = std::max(focus, kMinDistance);
    pitch = std::clamp(std::asin(std::clamp(back.y, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
    yaw = std::atan2(back.x, back.z);
    pivot = e - back * distance;
    orthoScale = 1.0f;
}

}   // namespace ui
