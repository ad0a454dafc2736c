// camera_paste_test.cpp - Camera > Paste camera (ViewerState::setViewFromCameraModel): a
// sidecar camera becomes the view with the same pose, and K scaled to the viewport.
#include "scenegraph/camera_model.h"
#include "scenegraph/transforms.h"
#include "ui/viewer_state.h"

#include <gtest/gtest.h>

namespace {

TEST(CameraPaste, SidecarCameraBecomesTheView) {
    ui::ViewerState st;
    st.view.viewportWidth = 400;
    st.view.viewportHeight = 300;
    // A camera made for 200 x 150 (same aspect): eye (3, 2, 6) looking at (0.5, 0, 0), off-centre K.
    sg::Projection p;
    std::string err;
    ASSERT_TRUE(sg::projectionFromIntrinsics(180, 170, 90, 80, 200, 150, 0.2f, 40.0f, p, &err)) << err;
    const sg::mat4 world = glm::inverse(sg::lookAt(sg::vec3(3, 2, 6), sg::vec3(0.5f, 0, 0), sg::vec3(0, 1, 0)));
    const sg::CameraModel m = sg::cameraModelOf(sg::makeFrameCamera(world, p, 200.0f / 150.0f, 5.0f), 200, 150);
    ASSERT_EQ(st.setViewFromCameraModel(m, "perspective", 200, 150), "");
    const sg::vec3 eye = st.view.camera.eye();
    EXPECT_NEAR(eye.x, 3.0f, 1e-4f);
    EXPECT_NEAR(eye.y, 2.0f, 1e-4f);
    EXPECT_NEAR(eye.z, 6.0f, 1e-4f);
    const sg::vec3 fwd = st.view.camera.forward(), want = glm::normalize(sg::vec3(0.5f, 0, 0) - sg::vec3(3, 2, 6));
    EXPECT_NEAR(glm::dot(fwd, want), 1.0f, 1e-5f);
    // K at the viewport's 400 x 300: twice the sidecar's.
    const sg::FrameCamera fc = sg::makeFrameCamera(st.view.camera.world(), st.viewProjection(), 400.0f / 300.0f, st.view.camera.distance);
    const sg::CameraModel k = sg::cameraModelOf(fc, 400, 300);
    ASSERT_TRUE(k.pinhole);
    EXPECT_NEAR(k.K[0][0], 360.0, 0.05);
    EXPECT_NEAR(k.K[1][1], 340.0, 0.05);
    EXPECT_NEAR(k.K[0][2], 180.0, 0.05);
    EXPECT_NEAR(k.K[1][2], 160.0, 0.05);
    // Refusals leave the view alone.
    sg::CameraModel bad = m;
    bad.pinhole = false;
    EXPECT_NE(st.setViewFromCameraModel(bad, "perspective", 200, 150), "");
    EXPECT_NEAR(st.view.camera.eye().x, 3.0f, 1e-4f);
}

}   // namespace
