// aov_test.cpp - the synthetic-data export: camera intrinsics K and the computer-vision pose
// (sg::cameraModelOf), depth along the optical axis from every backend's depth buffer
// (sg::opticalDepthMap) and the PFM / sidecar files (assets/aov_io.h), held to answers
// computed by hand: a world point projects through K [R|t] onto the pixel where the quad is
// seen, and each pixel's depth equals the depth of the ray through its centre hitting the
// quad's plane.
#include "assets/aov_io.h"
#include "render_support.h"
#include "renderers/renderer.h"
#include "scenegraph/camera_model.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>

namespace {

using namespace test_scenes;
using sg::vec3;
using sg::vec4;

constexpr int W = 160, H = 120;

// A 4 x 4 quad in the plane z = 0 seen from (1, 0.5, 4) toward (0.1, -0.1, 0): tilted in the image.
sg::FrameInput planeFrame() {
    sg::Projection p;
    p.fovyDeg = 50.0f;
    p.zNear = 0.5f;
    p.zFar = 20.0f;
    sg::FrameInput f = makeFrame(W, H, p, vec3(1.0f, 0.5f, 4.0f), vec3(0.1f, -0.1f, 0.0f));
    f.settings.shadows = false;
    addMesh(f, quad(2.0f), unlit(vec3(0.8f)));
    return f;
}

// Depth (camera z) of the ray through the centre of pixel (i, j) hitting z = 0, by hand from K and the pose.
double planeDepth(const sg::CameraModel& m, int i, int j) {
    const double u = i + 0.5, v = j + 0.5;
    const double fx = m.K[0][0], s = m.K[0][1], cx = m.K[0][2], fy = m.K[1][1], cy = m.K[1][2];
    const double y = (v - cy) / fy, x = (u - cx - s * y) / fx;   // K^-1 [u v 1]
    const glm::dmat4 c2w = glm::inverse(glm::dmat4(m.worldToCamera));
    const glm::dvec3 o(c2w * glm::dvec4(0, 0, 0, 1)), d(c2w * glm::dvec4(x, y, 1, 0));   // d has camera z = 1
    const double t = -o.z / d.z;                                                         // world z = 0
    return t;                                                                            // camera z of o + t d
}

TEST(CameraModel, IntrinsicsAndPoseProjectWorldPointsToTheirPixels) {
    const sg::FrameInput f = planeFrame();
    const sg::CameraModel m = sg::cameraModelOf(f.camera, W, H);
    ASSERT_TRUE(m.pinhole);
    // Symmetric frustum: square pixels, principal point at the centre, no skew.
    const double F = 1.0 / std::tan(glm::radians(25.0));
    EXPECT_NEAR(m.K[1][1], 0.5 * H * F, 1e-3);
    EXPECT_NEAR(m.K[0][0], m.K[1][1], 1e-3);
    EXPECT_NEAR(m.K[0][2], W / 2.0, 1e-4);
    EXPECT_NEAR(m.K[1][2], H / 2.0, 1e-4);
    EXPECT_EQ(m.K[0][1], 0.0);
    // The camera centre maps to the origin; the look-at target lies on the optical axis (z > 0).
    const vec4 eye = m.worldToCamera * vec4(1.0f, 0.5f, 4.0f, 1.0f);
    EXPECT_NEAR(glm::length(vec3(eye)), 0.0f, 1e-5f);
    const vec4 tgt = m.worldToCamera * vec4(0.1f, -0.1f, 0.0f, 1.0f);
    EXPECT_NEAR(tgt.x, 0.0f, 1e-5f);
    EXPECT_NEAR(tgt.y, 0.0f, 1e-5f);
    EXPECT_GT(tgt.z, 0.0f);
    // A point up and to the right in the world (+y world is up) lands above (smaller v) and right of the centre.
    const vec4 up = m.worldToCamera * vec4(0.1f, 0.9f, 0.0f, 1.0f);
    const double v = m.K[1][1] * up.y / up.z + m.K[1][2];
    EXPECT_LT(v, H / 2.0);
}

class AovDepth : public ::testing::TestWithParam<std::string> {};

// Every pixel that sees the quad: depth = the hand-computed plane depth (relative 1e-3); the
// background 0; a world point's projection K [R|t] X lands on a pixel whose depth is X's z.
TEST_P(AovDepth, DepthAlongTheOpticalAxisMatchesTheRayPlaneIntersection) {
    const sg::FrameInput f = planeFrame();
    rnd::Framebuffer fb;
    ASSERT_TRUE(testing_support::renderBackend(GetParam(), f, W, H, fb));
    const std::vector<float> depth = sg::opticalDepthMap(f.camera, W, H, fb.depth);
    const sg::CameraModel m = sg::cameraModelOf(f.camera, W, H);
    int seen = 0, empty = 0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            const float d = depth[size_t(j) * W + i];
            if (d == 0.0f) {
                ++empty;
                continue;
            }
            ++seen;
            const double want = planeDepth(m, i, j);
            ASSERT_NEAR(d, want, 1e-3 * want) << GetParam() << " pixel " << i << "," << j;
        }
    EXPECT_GT(seen, W * H / 4) << GetParam();
    EXPECT_GT(empty, 0) << GetParam();
    const vec4 X = m.worldToCamera * vec4(0.7f, -0.4f, 0.0f, 1.0f);
    const double u = (m.K[0][0] * X.x + m.K[0][1] * X.y) / X.z + m.K[0][2], v = m.K[1][1] * X.y / X.z + m.K[1][2];
    const int i = int(u), j = int(v);
    ASSERT_TRUE(i >= 0 && i < W && j >= 0 && j < H);
    EXPECT_NEAR(depth[size_t(j) * W + i], X.z, 0.02 * X.z) << GetParam() << ": the pixel of X holds X's depth (within a pixel's slope)";
}

INSTANTIATE_TEST_SUITE_P(EveryBackend, AovDepth, ::testing::ValuesIn(rnd::rendererNames()), [](const auto& info) { return info.param; });

// The three depth maps agree: median relative difference <= 1e-3 where both see geometry.
TEST(AovDepthAgreement, BackendsAgreeOnDepth) {
    const sg::FrameInput f = planeFrame();
    std::vector<std::vector<float>> maps;
    for (const std::string& b : rnd::rendererNames()) {
        rnd::Framebuffer fb;
        ASSERT_TRUE(testing_support::renderBackend(b, f, W, H, fb));
        maps.push_back(sg::opticalDepthMap(f.camera, W, H, fb.depth));
    }
    for (size_t a = 0; a < maps.size(); ++a)
        for (size_t b = a + 1; b < maps.size(); ++b) {
            std::vector<double> rel;
            for (size_t k = 0; k < maps[a].size(); ++k)
                if (maps[a][k] > 0 && maps[b][k] > 0) rel.push_back(std::fabs(maps[a][k] - maps[b][k]) / maps[a][k]);
            ASSERT_FALSE(rel.empty());
            std::nth_element(rel.begin(), rel.begin() + long(rel.size() / 2), rel.end());
            EXPECT_LE(rel[rel.size() / 2], 1e-3) << rnd::rendererNames()[a] << " vs " << rnd::rendererNames()[b];
        }
}

TEST(AovFiles, PfmRoundTripsAndTheSidecarHoldsTheCamera) {
    namespace fs = std::filesystem;
    const fs::path dir = testing_support::outputDir("aov");
    fs::create_directories(dir);
    std::vector<float> v(6);
    for (size_t k = 0; k < v.size(); ++k) v[k] = 0.5f * float(k);   // top row 0 0.5 1, bottom 1.5 2 2.5
    ASSERT_EQ(assets::writePfm(dir / "t.pfm", 3, 2, v, true), "");
    std::string bytes;
    {
        std::ifstream in(dir / "t.pfm", std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    ASSERT_EQ(bytes.rfind("Pf\n3 2\n-1.0\n", 0), 0u);
    float first;
    std::memcpy(&first, bytes.data() + 12, 4);
    EXPECT_EQ(first, 1.5f);   // PFM stores the bottom row first
    int w = 0, h = 0;
    std::vector<float> back;
    ASSERT_EQ(assets::readPfm(dir / "t.pfm", w, h, back), "");
    EXPECT_EQ(w, 3);
    EXPECT_EQ(h, 2);
    EXPECT_EQ(back, v);
    EXPECT_NE(assets::writePfm(dir / "t.pfm", 3, 2, v, false), "");   // never replaced without overwrite

    assets::AovSidecar s;
    s.width = W;
    s.height = H;
    s.backend = "raster";
    s.projection = "perspective";
    s.camera = sg::cameraModelOf(planeFrame().camera, W, H);
    ASSERT_EQ(assets::writeAovSidecar(dir / "t.json", s, true), "");
    std::ifstream in(dir / "t.json");
    std::string text((std::istreambuf_iterator<char>(in)), {});
    for (const char* key : {"\"K\"", "\"world_to_camera\"", "\"projection\": \"perspective\"", "\"near\"", "\"far\"", "\"width\": 160"})
        EXPECT_NE(text.find(key), std::string::npos) << key << " in " << text;
}

}   // namespace

// K -> projection -> K: projectionFromIntrinsics is the inverse of cameraModelOf, off-centre
// principal points included, and rejects what has no frustum.
TEST(CameraModel, ProjectionFromIntrinsicsGivesBackItsK) {
    const sg::FrameInput f = planeFrame();
    for (auto [fx, fy, cx, cy] : {std::array<double, 4>{200, 200, 80, 60}, {150.5, 171.25, 20.0, 100.0}, {400, 380, 159.0, 1.0}}) {
        sg::Projection p;
        std::string err;
        ASSERT_TRUE(sg::projectionFromIntrinsics(fx, fy, cx, cy, W, H, 0.5f, 20.0f, p, &err)) << err;
        const sg::FrameCamera cam = sg::makeFrameCamera(f.camera.viewInverse, p, float(W) / H, 5.0f);
        const sg::CameraModel m = sg::cameraModelOf(cam, W, H);
        ASSERT_TRUE(m.pinhole);
        EXPECT_NEAR(m.K[0][0], fx, 1e-3 * fx);
        EXPECT_NEAR(m.K[1][1], fy, 1e-3 * fy);
        EXPECT_NEAR(m.K[0][2], cx, 1e-3);
        EXPECT_NEAR(m.K[1][2], cy, 1e-3);
        EXPECT_EQ(m.K[0][1], 0.0);
    }
    sg::Projection p;
    std::string err;
    EXPECT_FALSE(sg::projectionFromIntrinsics(0, 100, 10, 10, W, H, 0.5f, 20.0f, p, &err));
    EXPECT_FALSE(sg::projectionFromIntrinsics(100, 100, 10, 10, W, H, 2.0f, 1.0f, p, &err));
    EXPECT_FALSE(err.empty());
}
