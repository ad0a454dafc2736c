// posed_agreement_test.cpp - PosedAgreement: skinned and morphed sample models posed at a
// time of their animation (what `viewer render SCENE --time T` does: assets::applyAnimation,
// then flatten) render the same in the three backends, since the deformation is computed
// once on the CPU and shared: GL vs raster mean <= 1/255 and >= 99.5% of pixels within 3/255;
// raster vs ray caster >= 99% within 4/255 (shadows, reflections and AA off). Each case also
// checks that the pose moved pixels (the image differs from the file's rest pose). Images go
// to build/<preset>/test-output/posed-agreement/. Needs ../shared/testdata.
#include "assets/scene_io.h"
#include "render_support.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <map>

namespace {

constexpr int kW = 320, kH = 240;

struct PosedCase {
    const char* name;
    const char* file;   // under testdata/gltf
    float time;
};

// Loads the file and flattens it as posed at `time` of clip 0 (time < 0: the rest pose).
sg::FrameInput posedFrame(const PosedCase& c, float time) {
    assets::LoadResult r = assets::loadScene(testing_support::testdataDir() / "gltf" / c.file);
    EXPECT_TRUE(r.scene) << r.error;
    if (!r.scene) return {};
    EXPECT_FALSE(r.animations.empty());
    if (time >= 0 && !r.animations.empty()) assets::applyAnimation(*r.scene, r.animations[0], time);
    sg::FrameInput f = sg::flatten(*r.scene, float(kW) / kH);
    f.settings.shadows = false;
    f.settings.reflections = false;
    f.settings.aa = sg::AAMode::None;
    return f;
}

class PosedAgreement : public ::testing::TestWithParam<PosedCase> {};

TEST_P(PosedAgreement, ThreeBackendsAgree) {
    ASSERT_TRUE(testing_support::requireTestdata());
    const PosedCase& c = GetParam();
    sg::FrameInput frame = posedFrame(c, c.time);
    ASSERT_FALSE(frame.meshes.empty());
    std::map<std::string, rnd::Framebuffer> img;
    for (const char* b : {"gl", "raster", "raycast"}) {
        ASSERT_TRUE(testing_support::renderBackend(b, frame, kW, kH, img[b], {c.name}));
        testing_support::writeImage(img[b], "posed-agreement", std::string(c.name) + "-" + b);
    }
    const testing_support::ImageTolerance glRaster = testing_support::agreementTolerance(testing_support::Agreement::SameMethod);
    const testing_support::ImageTolerance rasterRay = testing_support::agreementTolerance(testing_support::Agreement::AcrossMethods);
    EXPECT_TRUE(testing_support::imagesClose(img["gl"], img["raster"], glRaster, "posed-agreement", std::string(c.name) + "-gl-vs-raster"));
    EXPECT_TRUE(
        testing_support::imagesClose(img["raycast"], img["raster"], rasterRay, "posed-agreement", std::string(c.name) + "-raycast-vs-raster"));

    // The pose shows: the raster image differs from the rest pose's in a good share of pixels.
    rnd::Framebuffer rest;
    ASSERT_TRUE(testing_support::renderBackend("raster", posedFrame(c, -1.0f), kW, kH, rest, {"rest pose"}));
    rnd::ImageDiff d = rnd::compareImages(img["raster"], rest, 8);
    EXPECT_LT(d.fractionWithin, 0.99) << c.name << ": the posed image looks like the rest pose (" << d.describe() << ")";
}

INSTANTIATE_TEST_SUITE_P(Samples, PosedAgreement,
                         ::testing::Values(PosedCase{"cesium_man_t1", "CesiumMan/glTF/CesiumMan.gltf", 1.0f},
                                           PosedCase{"morph_cube_t1_5", "AnimatedMorphCube/glTF/AnimatedMorphCube.gltf", 1.5f}),
                         [](const ::testing::TestParamInfo<PosedCase>& i) { return std::string(i.param.name); });

}   // namespace
