// polygon_render_test.cpp - a U-shaped OBJ face as the CPU backends draw it: every pixel
// well inside the U is lit, every pixel well outside (the notch included) is background, and
// with back-face culling on the face shows from its front only (the triangles kept its winding).
#include "assets/scene_io.h"
#include "renderers/renderer.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace fs = std::filesystem;

namespace {

// The U ([0, 3]^2 without the notch [1, 2] x [1, 3]) in the z = 0 plane, its face starting at
// an inner corner of the notch (where a fan spills into the notch).
std::string uObj(bool clockwise) {
    return "v 2 1 0\nv 1 1 0\nv 1 3 0\nv 0 3 0\nv 0 0 0\nv 3 0 0\nv 3 3 0\nv 2 3 0\n" +
           std::string(clockwise ? "f 8 7 6 5 4 3 2 1\n" : "f 1 2 3 4 5 6 7 8\n");
}

// Signed distance-like margin: > 0 inside the U, < 0 outside (max-norm distance to the
// nearest boundary, good enough to keep samples away from edges).
double insideU(double x, double y) {
    const double square = std::min({x, 3 - x, y, 3 - y});
    const double notch = std::min({x - 1, 2 - x, y - 1, 3 - y});   // > 0 inside the notch
    return std::min(square, -notch);
}

sg::MeshPtr loadU(bool clockwise) {
    const fs::path dir = testing_support::outputDir("geometry");
    fs::create_directories(dir);
    const fs::path p = dir / (clockwise ? "u_cw.obj" : "u.obj");
    std::ofstream(p, std::ios::binary) << uObj(clockwise);
    assets::LoadResult r = assets::loadScene(p);
    EXPECT_TRUE(r.scene) << r.error;
    if (!r.scene || r.scene->meshes.size() != 1) return nullptr;
    return r.scene->meshes[0];
}

}   // namespace

TEST(PolygonRenderTest, UFaceHasItsNotchEmpty) {
    const int W = 64, H = 64;
    const double pixel = 3.2 / H;   // orthographic half height 1.6 around (1.5, 1.5)
    for (bool clockwise : {false, true}) {
        sg::MeshPtr mesh = loadU(clockwise);
        ASSERT_TRUE(mesh);
        for (const char* backend : {"raster", "raycast"})
            for (bool cull : {false, true}) {
                SCOPED_TRACE(std::string(backend) + (clockwise ? " cw" : " ccw") + (cull ? " culling" : ""));
                sg::Projection proj;
                proj.type = sg::ProjectionType::Orthographic;
                proj.orthoHalfHeight = 1.6f;
                sg::FrameInput f = test_scenes::makeFrame(W, H, proj, sg::vec3(1.5f, 1.5f, 5.0f), sg::vec3(1.5f, 1.5f, 0.0f));
                f.settings.culling = cull ? sg::CullMode::On : sg::CullMode::Off;
                test_scenes::addMesh(f, mesh, test_scenes::unlit(sg::vec3(1.0f)));
                auto r = rnd::makeRenderer(backend);
                ASSERT_TRUE(r);
                rnd::Framebuffer fb;
                rnd::RenderStats st = r->render(f, W, H, fb);
                ASSERT_TRUE(st.ok) << st.error;
                const bool visible = !(cull && clockwise);   // a clockwise U faces away from the camera
                int lit = 0, wrong = 0;
                for (int y = 0; y < H; ++y)
                    for (int x = 0; x < W; ++x) {
                        const double wx = 1.5 + (x + 0.5 - W / 2) * pixel, wy = 1.5 - (y + 0.5 - H / 2) * pixel;
                        const double m = insideU(wx, wy);
                        if (std::fabs(m) < 1.5 * pixel) continue;   // edge pixels: either way
                        const bool on = test_scenes::channel(fb, x, y, 0) > 128;
                        lit += on;
                        const bool want = visible && m > 0;
                        if (on != want && wrong++ < 5)
                            ADD_FAILURE() << "pixel " << x << "," << y << " (" << wx << ", " << wy << ") is " << (on ? "lit" : "background")
                                          << (m < 0 && wx > 1 && wx < 2 && wy > 1 ? " in the notch" : "");
                    }
                EXPECT_EQ(wrong, 0);
                if (visible) {
                    EXPECT_GT(lit, 1500);   // 7 of the 10.24 square units in view
                }
                if (HasFailure())
                    testing_support::writeImage(fb, "geometry", std::string("u-") + backend + (clockwise ? "-cw" : "") + (cull ? "-cull" : ""));
            }
    }
}
