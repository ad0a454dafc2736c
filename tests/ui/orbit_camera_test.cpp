// orbit_camera_test.cpp - orbit camera math: orbit keeps the distance to the pivot, pan moves
// the pivot in the view plane, zoom scales the distance, fit frames a bounding box,
// setFromWorld round-trips.
#include "ui/orbit_camera.h"

#include <gtest/gtest.h>

using namespace ui;

namespace {
void expectNear(const sg::vec3& a, const sg::vec3& b, float eps = 1e-4f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}
}   // namespace

TEST(OrbitCameraTest, OrbitKeepsDistanceToPivot) {
    OrbitCamera c;
    c.pivot = {1, 2, 3};
    c.distance = 7.5f;
    for (int i = 0; i < 50; ++i) {
        c.orbit(13.0f, -7.0f);
        EXPECT_NEAR(glm::length(c.eye() - c.pivot), 7.5f, 1e-4f);
    }
    // The camera keeps looking at the pivot: -z of the world matrix points to it.
    sg::mat4 w = c.world();
    sg::vec3 toPivot = glm::normalize(c.pivot - sg::vec3(w[3]));
    expectNear(-sg::vec3(w[2]), toPivot);
    // Pitch is clamped short of the poles (no flip).
    c.orbit(0, 100000.0f);
    EXPECT_LT(std::abs(c.pitch), sg::radians(89.5f));
}

TEST(OrbitCameraTest, WorldMatrixIsOrthonormalRightHanded) {
    OrbitCamera c;
    c.yaw = 0.7f;
    c.pitch = -0.3f;
    sg::mat4 w = c.world();
    sg::vec3 x(w[0]), y(w[1]), z(w[2]);
    EXPECT_NEAR(glm::length(x), 1, 1e-5f);
    EXPECT_NEAR(glm::dot(x, y), 0, 1e-5f);
    expectNear(glm::cross(x, y), z);
    EXPECT_GT(y.y, 0.0f);   // no roll: up stays up
}

TEST(OrbitCameraTest, PanMovesPivotInViewPlane) {
    OrbitCamera c;
    c.yaw = 0.4f;
    c.pitch = 0.2f;
    c.distance = 4.0f;
    sg::vec3 eye0 = c.eye(), pivot0 = c.pivot, fwd = c.forward();
    float s = c.panScale(45.0f, 600.0f, false, 1.0f);
    EXPECT_NEAR(s, 2.0f * 4.0f * std::tan(sg::radians(22.5f)) / 600.0f, 1e-6f);
    c.pan(100.0f, -40.0f, s);
    sg::vec3 d = c.pivot - pivot0;
    EXPECT_GT(glm::length(d), 0.0f);
    EXPECT_NEAR(glm::dot(d, fwd), 0.0f, 1e-5f);   // in the view plane
    expectNear(c.eye() - eye0, d);                // eye moves with the pivot
    EXPECT_NEAR(glm::length(d), s * std::sqrt(100.0f * 100.0f + 40.0f * 40.0f), 1e-4f);
    // Dragging right moves the scene right, i.e. the pivot to the camera's left.
    EXPECT_LT(glm::dot(d, c.right()), 0.0f);
}

TEST(OrbitCameraTest, ZoomScalesDistance) {
    OrbitCamera c;
    c.distance = 10.0f;
    sg::vec3 pivot = c.pivot;
    c.zoom(1.0f);
    EXPECT_NEAR(c.distance, 8.5f, 1e-4f);
    c.zoom(-1.0f);
    EXPECT_NEAR(c.distance, 10.0f, 1e-4f);
    expectNear(c.pivot, pivot);
    c.zoom(1e6f);   // never reaches zero or goes through the pivot
    EXPECT_GE(c.distance, OrbitCamera::kMinDistance);
}

TEST(OrbitCameraTest, FitFramesTheBox) {
    sg::Aabb box{{-3, 0, -1}, {5, 2, 4}};
    for (float aspect : {0.5f, 1.0f, 2.0f}) {
        OrbitCamera c;
        c.yaw = 0.6f;
        c.pitch = 0.3f;
        c.fit(box, 45.0f, aspect);
        expectNear(c.pivot, box.center());
        sg::mat4 view = glm::inverse(c.world());
        sg::mat4 proj = glm::perspective(sg::radians(45.0f), aspect, 0.01f, 1000.0f);
        for (int i = 0; i < 8; ++i) {
            sg::vec3 p((i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y, (i & 4) ? box.max.z : box.min.z);
            sg::vec4 clip = proj * view * sg::vec4(p, 1.0f);
            ASSERT_GT(clip.w, 0.0f);
            EXPECT_LE(std::abs(clip.x / clip.w), 1.0f) << "aspect " << aspect << " corner " << i;
            EXPECT_LE(std::abs(clip.y / clip.w), 1.0f) << "aspect " << aspect << " corner " << i;
        }
    }
}

TEST(OrbitCameraTest, SetFromWorldRoundTrips) {
    OrbitCamera a;
    a.pivot = {0.5f, -1, 2};
    a.distance = 3.0f;
    a.yaw = -2.0f;
    a.pitch = 0.5f;
    OrbitCamera b;
    b.setFromWorld(a.world(), 3.0f);
    expectNear(b.pivot, a.pivot);
    expectNear(b.eye(), a.eye());
    EXPECT_NEAR(b.yaw, a.yaw, 1e-4f);
}

TEST(OrbitCameraTest, FlyMovesEyeAndPivotLookTurnsAroundEye) {
    OrbitCamera c;
    c.distance = 5.0f;
    sg::vec3 eye0 = c.eye();
    sg::vec3 fwd = c.forward();
    c.fly({0, 0, 1.0f});
    expectNear(c.eye(), eye0 + fwd);
    sg::vec3 eye1 = c.eye();
    c.look(50.0f, 20.0f);
    expectNear(c.eye(), eye1);
    EXPECT_NEAR(glm::length(c.eye() - c.pivot), 5.0f, 1e-4f);
}
