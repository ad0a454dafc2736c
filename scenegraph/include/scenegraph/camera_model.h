// camera_model.h - the frame's camera as computer vision writes it (docs/math.md, "Camera
// intrinsics K"): pixel coordinates from the image's top-left corner (pixel (i, j) covers
// [i, i+1] x [j, j+1], its centre at (i + 0.5, j + 0.5)), camera axes x right, y down, z forward,
// so that for a perspective camera  [u, v, 1]^T ~ K [R | t] X  (X a world point).
#pragma once

#include "scenegraph/frame.h"

#include <string>
#include <vector>

namespace sg {

struct CameraModel {
    // Pinhole intrinsics [[fx, s, cx], [0, fy, cy], [0, 0, 1]] (row-major as written in JSON);
    // valid only when `pinhole` (perspective projections; orthographic and oblique have none).
    double K[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    bool pinhole = false;
    mat4 worldToCamera{1.0f};   // world -> camera, computer-vision axes (x right, y down, z forward)
    mat4 cameraToWorld{1.0f};   // its inverse, kept exactly (the camera's pose in the world)
    mat4 projection{1.0f};      // eye -> clip (OpenGL conventions), for every projection type
    float zNear = 0.1f, zFar = 100.0f;
};

// The model of `cam` for a width x height image.
CameraModel cameraModelOf(const FrameCamera& cam, int width, int height);

// The other way round: the perspective projection whose K is [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]
// for a width x height image, as a general frustum at zNear (docs/math.md, "Camera from K"):
//   l = -n cx / fx,  r = n (w - cx) / fx,  t = n cy / fy,  b = n (cy - h) / fy.
// Returns false (and *error) for non-positive or non-finite focal lengths or planes.
bool projectionFromIntrinsics(double fx, double fy, double cx, double cy, int width, int height, float zNear, float zFar, Projection& out,
                              std::string* error);

// The frame camera that renders exactly as `m` did: view from worldToCamera, the projection
// matrix itself (perspective, orthographic or oblique), `type` the projection's kind.
// `focusDistance` is kept for interaction only (the oblique plane is already in the matrix).
FrameCamera frameCameraFromModel(const CameraModel& m, ProjectionType type, float aspect, float focusDistance);

// Depth along the optical axis (the camera-space z above, scene units) of the surface seen at
// pixel (i, j) (j from the top row) whose window depth is zWindow (0 near .. 1 far, as the
// backends' depth buffers hold it); 0 for zWindow >= 1 (nothing drawn there).
float opticalDepth(const FrameCamera& cam, int width, int height, int i, int j, float zWindow);
// The same for a whole depth buffer (rows top-down, width x height), into a map of the same layout.
std::vector<float> opticalDepthMap(const FrameCamera& cam, int width, int height, const std::vector<float>& zWindow);

}   // namespace sg
