// gl_sample_baseline_test.cpp - GL renders (240x180) of sample models whose correct look is
// known, held against tests/baselines/gl/sample_<name>.png (thresholds of
// gl_baseline_test.cpp). Agreement between the backends is the sweep's job (tests/sweep);
// these hold the picture itself, since all three backends were once wrong together (upside-
// down textures). They render with the pbr model in the default environment. Each baseline was
// looked at by eye:
//  - BoxTextured: the glTF logo reads upright and unmirrored on the faces in view;
//  - SpecGlossVsMetalRough: two textured water bottles (labels, red logo, dark caps), not white
//    silhouettes; under pbr (how glTF files open) the specular-glossiness bottle and the
//    metal-roughness one look alike, as the model's authors made them;
//  - TextureTransformTest: every square shows its arrow/pattern as the model's labels ask
//    (offset, rotation, scale, texCoord override) - the model's own "correct" layout;
//  - ClearCoatTest: the normal-mapped rows show their ribs, the labels their text;
//  - MultiUVTest: the emissive texture on TEXCOORD_1 puts a green glTF logo on each face (its
//    "Multiple UVs not supported" text shows where a viewer reads TEXCOORD_0 instead).
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

constexpr int kWidth = 240, kHeight = 180;

struct Sample {
    const char* name;
    const char* file;   // under testdata/gltf
};

class SampleBaselineGLTest : public ::testing::TestWithParam<Sample> {};

TEST_P(SampleBaselineGLTest, MatchesBaseline) {
    ASSERT_TRUE(testing_support::requireTestdata());
    const Sample& c = GetParam();
    assets::LoadResult r = assets::loadScene(testing_support::testdataDir() / "gltf" / c.file);
    ASSERT_TRUE(r.scene) << r.error;
    r.scene->settings.shadows = false;
    const sg::FrameInput frame = sg::flatten(*r.scene, float(kWidth) / kHeight);
    auto gl = rnd::makeGlRenderer();
    rnd::Framebuffer actual;
    rnd::RenderStats st = gl->render(frame, kWidth, kHeight, actual);
    ASSERT_TRUE(st.ok) << st.error;

    EXPECT_TRUE(testing_support::matchesGlBaseline(actual, std::string("sample_") + c.name));
}

INSTANTIATE_TEST_SUITE_P(Samples, SampleBaselineGLTest,
                         ::testing::Values(Sample{"box_textured", "BoxTextured/glTF/BoxTextured.gltf"},
                                           Sample{"spec_gloss_vs_metal_rough", "SpecGlossVsMetalRough/glTF/SpecGlossVsMetalRough.gltf"},
                                           Sample{"texture_transform_test", "TextureTransformTest/glTF/TextureTransformTest.gltf"},
                                           Sample{"clear_coat_test", "ClearCoatTest/glTF/ClearCoatTest.gltf"},
                                           Sample{"multi_uv_test", "MultiUVTest/glTF/MultiUVTest.gltf"}),
                         [](const ::testing::TestParamInfo<Sample>& i) { return std::string(i.param.name); });

}   // namespace
