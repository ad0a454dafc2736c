// agreement_matrix_test.cpp - BackendAgreementMatrix: the three backends render the same
// reference scenes at the same size and settings (shadows, reflections and AA off) and every
// pair is compared: mean absolute difference per channel (0..255 units) and the fraction of
// pixels whose channels all lie within 4/255. The matrix is printed; the thresholds are the
// ones README.md promises: GL vs raster mean below 1/255; ray caster vs raster >= 99% of pixels
// within 4/255 (shadows off). GL vs ray caster is not promised directly; it is held to the
// same 99% within 4/255 as ray caster vs raster (GL and raster agree to < 1/255 on average).
// Images of every backend go to build/<preset>/test-output/agreement-matrix/.
#include "assets/demo.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>

using namespace sg;

namespace {

constexpr int kW = 320, kH = 240;

struct MatrixScene {
    std::string name;
    FrameInput frame;
};

void offlineSettings(FrameInput& f) {
    f.settings.shadows = false;
    f.settings.reflections = false;
    f.settings.aa = AAMode::None;
}

std::vector<MatrixScene> scenes() {
    std::vector<MatrixScene> s;
    FrameInput demo = flatten(assets::makeDemoScene(), float(kW) / kH);
    offlineSettings(demo);
    s.push_back({"demo", demo});
    // The same demo without its analytic shapes (implicits, CSG, parametric patch, density
    // grid), which the ray caster intersects exactly where the rasterizers draw tessellations
    // (a difference the README names as genuine): the row shows how much of the demo's
    // difference they account for.
    FrameInput meshesOnly = demo;
    meshesOnly.analytics.clear();
    s.push_back({"demo_meshes_only", meshesOnly});
    FrameInput sphere = test_scenes::litSphereFrame(kW, kH, ShadingModel::Phong, ReflectionModel::Phong, test_scenes::SphereLight::Directional, 256);
    offlineSettings(sphere);
    s.push_back({"lit_sphere", sphere});
    FrameInput quad = test_scenes::texturedQuadFrame(kW, kH, true);
    offlineSettings(quad);
    s.push_back({"textured_quad", quad});
    FrameInput tri = test_scenes::triangleAgreementFrame(Projection{}, kW, kH);
    offlineSettings(tri);
    s.push_back({"triangle_scene", tri});
    return s;
}

}   // namespace

TEST(BackendAgreementMatrix, ReferenceScenes) {
    const std::vector<std::string> names = rnd::rendererNames();
    for (const char* needed : {"gl", "raster", "raycast"})
        ASSERT_NE(std::find(names.begin(), names.end(), needed), names.end()) << "backend " << needed << " is not built";
    std::map<std::string, std::unique_ptr<rnd::Renderer>> renderers;
    for (const std::string& n : {std::string("gl"), std::string("raster"), std::string("raycast")}) {
        std::string err;
        renderers[n] = rnd::makeRenderer(n, &err);
        ASSERT_TRUE(renderers[n]) << err;
    }
    struct Pair {
        const char *a, *b;
    };
    const Pair pairs[] = {{"gl", "raster"}, {"raster", "raycast"}, {"gl", "raycast"}};
    std::printf("\n%-18s | %-26s | %-26s | %-26s\n", "scene (320x240)", "gl ~ raster", "raster ~ raycast", "gl ~ raycast");
    std::printf("%-18s | %-26s | %-26s | %-26s\n", "", "mean/255  within 4/255", "mean/255  within 4/255", "mean/255  within 4/255");
    for (const MatrixScene& s : scenes()) {
        std::map<std::string, rnd::Framebuffer> img;
        for (auto& [n, r] : renderers) {
            rnd::RenderStats st = r->render(s.frame, kW, kH, img[n]);
            ASSERT_TRUE(st.ok) << s.name << ": " << n << " could not render: " << st.error;
            testing_support::writeImage(img[n], "agreement-matrix", s.name + "-" + n);
        }
        std::printf("%-18s", s.name.c_str());
        rnd::ImageDiff d[3];
        for (int i = 0; i < 3; ++i) {
            d[i] = rnd::compareImages(img[pairs[i].a], img[pairs[i].b], 4);
            std::printf(" | %7.3f   %8.3f%%      ", d[i].meanAbs, 100.0 * d[i].fractionWithin);
        }
        std::printf("\n");
        // README: GL vs raster mean below 1/255; ray caster vs raster >= 99% within 4/255 with
        // shadows off. GL vs ray caster: the same 99% (see the top of the file).
        const testing_support::ImageTolerance glRaster{1.0, 0.0, 4}, withRaycast{255.0, 0.99, 4};
        const testing_support::ImageTolerance* tol[3] = {&glRaster, &withRaycast, &withRaycast};
        for (int i = 0; i < 3; ++i) {
            const bool ok = d[i].meanAbs < tol[i]->maxMeanAbs && d[i].fractionWithin >= tol[i]->minFractionWithin;
            if (ok) continue;
            ADD_FAILURE() << s.name << ": " << pairs[i].a << " ~ " << pairs[i].b << ": " << d[i].describe() << " (allowed: mean < "
                          << tol[i]->maxMeanAbs << ", within 4/255 >= " << tol[i]->minFractionWithin * 100 << "%)";
            // Writes <scene>-<a>-vs-<b>-{actual,expected,diff}.png (a as actual, b as expected).
            (void)testing_support::imagesClose(img[pairs[i].a], img[pairs[i].b], {0.0, 1.0, 0}, "agreement-matrix",
                                               s.name + "-" + pairs[i].a + "-vs-" + pairs[i].b);
        }
    }
}
