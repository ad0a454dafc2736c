// camera_model.cpp - cameraModelOf(), opticalDepth() (see camera_model.h).
//
// K from the projection matrix P (glm's P[col][row]) and the viewport: with eye coordinates
// (x, y, z), z < 0 in front, clip w = -z for a pinhole (P's last row 0 0 -1 0), window
// x_w = (x_ndc + 1) w/2 and y_w = (y_ndc + 1) h/2 (origin bottom-left). In camera axes
// X = x, Y = -y, Z = -z and image coordinates u = x_w, v = h - y_w:
//   u = (w/2) P00 X/Z - (w/2) P01 Y/Z + (w/2)(1 - P02)
//   v = (h/2) P11 Y/Z - (h/2) P10 X/Z + (h/2)(1 + P12)
// so fx = (w/2) P00, s = -(w/2) P01, cx = (w/2)(1 - P02), fy = (h/2) P11, cy = (h/2)(1 + P12)
// (our perspective matrices have P10 = 0: K is upper triangular).
#include "scenegraph/camera_model.h"

#include <cmath>

namespace sg {

CameraModel cameraModelOf(const FrameCamera& cam, int width, int height) {
    CameraModel m;
    const mat4& P = cam.proj;
    m.projection = P;
    m.zNear = cam.projection.zNear;
    m.zFar = cam.projection.zFar;
    const mat4 flip = glm::scale(mat4(1.0f), vec3(1.0f, -1.0f, -1.0f));   // eye (y up, z back) -> camera (y down, z forward)
    m.worldToCamera = flip * cam.view;
    m.cameraToWorld = cam.viewInverse * flip;
    m.pinhole = P[0][3] == 0.0f && P[1][3] == 0.0f && P[2][3] == -1.0f && P[3][3] == 0.0f && P[3][0] == 0.0f && P[3][1] == 0.0f && P[0][1] == 0.0f;
    if (!m.pinhole) return m;
    const double hw = 0.5 * width, hh = 0.5 * height;
    m.K[0][0] = hw * P[0][0];
    m.K[0][1] = P[1][0] == 0.0f ? 0.0 : -hw * P[1][0];   // no -0 in the JSON
    m.K[0][2] = hw * (1.0 - P[2][0]);
    m.K[1][1] = hh * P[1][1];
    m.K[1][2] = hh * (1.0 + P[2][1]);
    return m;
}

namespace {
// Window position of pixel (i, j)'s centre (y up), to NDC, back to the eye through inv(P).
float depthAt(const glm::dmat4& inv, int width, int height, int i, int j, float zWindow) {
    if (!(zWindow < 1.0f)) return 0.0f;
    const double xw = i + 0.5, yw = (height - 1 - j) + 0.5;
    const glm::dvec4 e = inv * glm::dvec4(2.0 * xw / width - 1.0, 2.0 * yw / height - 1.0, 2.0 * double(zWindow) - 1.0, 1.0);
    if (!(std::fabs(e.w) > 0.0)) return 0.0f;
    return float(-e.z / e.w);
}
}   // namespace

float opticalDepth(const FrameCamera& cam, int width, int height, int i, int j, float zWindow) {
    return depthAt(glm::inverse(glm::dmat4(cam.proj)), width, height, i, j, zWindow);
}

std::vector<float> opticalDepthMap(const FrameCamera& cam, int width, int height, const std::vector<float>& zWindow) {
    std::vector<float> out(zWindow.size(), 0.0f);
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj));
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) {
            const size_t k = size_t(j) * size_t(width) + size_t(i);
            if (k < zWindow.size()) out[k] = depthAt(inv, width, height, i, j, zWindow[k]);
        }
    return out;
}

bool projectionFromIntrinsics(double fx, double fy, double cx, double cy, int width, int height, float zNear, float zFar, Projection& out,
                              std::string* error) {
    auto fail = [&](const std::string& msg) {
        if (error) *error = msg;
        return false;
    };
    if (!(fx > 0) || !(fy > 0) || !std::isfinite(fx) || !std::isfinite(fy) || !std::isfinite(cx) || !std::isfinite(cy))
        return fail("focal lengths must be positive and finite, the principal point finite");
    if (width < 1 || height < 1) return fail("image size must be positive");
    if (!(zNear > 0) || !(zFar > zNear) || !std::isfinite(zFar)) return fail("needs 0 < near < far");
    Projection p;
    p.type = ProjectionType::Perspective;
    p.useFrustum = true;
    p.zNear = zNear;
    p.zFar = zFar;
    const double n = zNear;
    p.left = float(-n * cx / fx);
    p.right = float(n * (width - cx) / fx);
    p.top = float(n * cy / fy);
    p.bottom = float(n * (cy - height) / fy);
    p.fovyDeg = float(glm::degrees(2.0 * std::atan(0.5 * height / fy)));   // for the UI; the frustum is what renders
    out = p;
    return true;
}

FrameCamera frameCameraFromModel(const CameraModel& m, ProjectionType type, float aspect, float focusDistance) {
    const mat4 flip = glm::scale(mat4(1.0f), vec3(1.0f, -1.0f, -1.0f));   // its own inverse
    FrameCamera c;
    c.projection.type = type;
    c.projection.zNear = m.zNear;
    c.projection.zFar = m.zFar;
    c.aspect = aspect;
    c.focusDistance = focusDistance;
    c.view = flip * m.worldToCamera;
    c.viewInverse = m.cameraToWorld * flip;   // exact, so the same eye and rays as the original
    c.proj = m.projection;
    c.viewProj = c.proj * c.view;
    c.eye = vec3(c.viewInverse[3]);
    return c;
}

}   // namespace sg
