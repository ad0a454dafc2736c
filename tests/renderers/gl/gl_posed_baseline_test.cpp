// gl_posed_baseline_test.cpp - GL renders (160x120) of sample models posed at a time of their
// animation (CesiumMan mid-walk: skinning; AnimatedMorphCube: morph weights), the way
// `viewer render SCENE --time T` makes them (assets::applyAnimation, flatten), held against
// tests/baselines/gl/posed_<name>.png with the thresholds of gl_baseline_test.cpp. The
// baselines were looked at by eye (legs apart mid-stride; the cube flattened toward a slab).
// VIEWER_ACCEPT_BASELINES=1 writes them instead (scripts/accept-baselines.sh). Needs
// ../shared/testdata.
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "gl/gl_renderer.h"
#include "scenegraph/frame.h"
#include "test_support.h"

#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace {

constexpr int kWidth = 160, kHeight = 120;

struct PosedScene {
    const char* name;
    const char* file;   // under testdata/gltf
    float time;
};

class PosedBaselineGLTest : public ::testing::TestWithParam<PosedScene> {};

TEST_P(PosedBaselineGLTest, MatchesBaseline) {
    ASSERT_TRUE(testing_support::requireTestdata());
    const PosedScene& c = GetParam();
    assets::LoadResult r = assets::loadScene(testing_support::testdataDir() / "gltf" / c.file);
    ASSERT_TRUE(r.scene) << r.error;
    ASSERT_FALSE(r.animations.empty());
    assets::applyAnimation(*r.scene, r.animations[0], c.time);
    sg::FrameInput frame = sg::flatten(*r.scene, float(kWidth) / kHeight);
    auto gl = rnd::makeGlRenderer();
    rnd::Framebuffer actual;
    rnd::RenderStats st = gl->render(frame, kWidth, kHeight, actual);
    ASSERT_TRUE(st.ok) << st.error;

    EXPECT_TRUE(testing_support::matchesGlBaseline(actual, std::string("posed_") + c.name));
}

INSTANTIATE_TEST_SUITE_P(Samples, PosedBaselineGLTest,
                         ::testing::Values(PosedScene{"cesium_man_t1", "CesiumMan/glTF/CesiumMan.gltf", 1.0f},
                                           PosedScene{"morph_cube_t1_5", "AnimatedMorphCube/glTF/AnimatedMorphCube.gltf", 1.5f}),
                         [](const ::testing::TestParamInfo<PosedScene>& i) { return std::string(i.param.name); });

}   // namespace
