// gl_sample_baseline_test.cpp - GL renders (240x180) of sample models whose correct look is
// known, held against tests/baselines/gl/sample_<name>.png (thresholds of
// gl_baseline_test.cpp). Agreement between the backends is the sweep's job (tests/renderers/sweep);
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
//    "Multiple UVs not supported" text shows where a viewer reads TEXCOORD_0 instead);
//  - SheenCloth: the cloth's weave (normal map) and its colour texture (KHR_materials_sheen is
//    not honoured: the cloth without its sheen);
//  - SphereGridInHdr: 5 x 5 gold spheres (metallic 0..1 down, roughness 0..1 across) in a small
//    .hdr sky made by the test (blue above, a sun, brown ground), shown as the background: the
//    smooth metals mirror the sky and the sun, the rough ones blur it, the dielectrics are yellow
//    with white reflections at the rim.
// VIEWER_ACCEPT_BASELINES=1 writes them instead (scripts/accept-baselines.sh). Needs
// ../shared/testdata.
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "gl/gl_renderer.h"
#include "scenegraph/frame.h"
#include "scenegraph/transforms.h"
#include "test_support.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

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
                                           Sample{"multi_uv_test", "MultiUVTest/glTF/MultiUVTest.gltf"},
                                           Sample{"sheen_cloth", "SheenCloth/glTF/SheenCloth.gltf"}),
                         [](const ::testing::TestParamInfo<Sample>& i) { return std::string(i.param.name); });

// A w x h equirectangular Radiance .hdr (flat RGBE scanlines): a blue sky brightening to the
// horizon, a small bright sun, a brown ground.
void writeSkyHdr(const fs::path& p, int w, int h) {
    std::ofstream o(p, std::ios::binary);
    o << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " << h << " +X " << w << "\n";
    const sg::vec3 sun = glm::normalize(sg::vec3(-0.4f, 0.6f, 0.7f));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float u = (float(x) + 0.5f) / float(w), v = (float(y) + 0.5f) / float(h);
            const float phi = (u - 0.5f) * 6.2831853f, theta = v * 3.14159265f;
            const sg::vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
            sg::vec3 c = d.y > 0.0f ? glm::mix(sg::vec3(0.7f, 0.8f, 0.95f), sg::vec3(0.15f, 0.3f, 0.7f), d.y) : sg::vec3(0.25f, 0.17f, 0.1f);
            if (glm::dot(d, sun) > 0.97f) c = sg::vec3(40.0f, 36.0f, 30.0f);
            const float m = std::max({c.x, c.y, c.z});
            int e = 0;
            const float f = std::frexp(m, &e) * 256.0f / m;
            o << char(int(c.x * f)) << char(int(c.y * f)) << char(int(c.z * f)) << char(e + 128);
        }
}

TEST(SampleBaselineGLTest, SphereGridInHdr) {
    const fs::path dir = testing_support::outputDir("gl-baselines");
    const fs::path hdr = dir / "sky.hdr";
    writeSkyHdr(hdr, 64, 32);
    sg::Projection p;
    p.fovyDeg = 34.0f;
    sg::FrameInput f;
    const sg::mat4 cam = glm::inverse(sg::lookAt(sg::vec3(0, 0, 19), sg::vec3(0.0f), sg::vec3(0, 1, 0)));
    f.camera = sg::makeFrameCamera(cam, p, 1.0f, 19.0f);
    f.settings.reflection = sg::ReflectionModel::Pbr;
    f.settings.environment = hdr.string();
    f.settings.environmentBackground = true;
    auto sphere = std::make_shared<const sg::Mesh>(sg::primitives::uvSphere(0.95f, 48, 24));
    for (int row = 0; row < 5; ++row)
        for (int col = 0; col < 5; ++col) {
            sg::DrawMesh d;
            d.mesh = sphere;
            d.material.baseColor = sg::vec3(1.0f, 0.766f, 0.336f);
            d.material.metallic = float(row) / 4.0f;
            d.material.roughness = float(col) / 4.0f;
            d.world = glm::translate(sg::mat4(1.0f), sg::vec3((col - 2) * 2.2f, (2 - row) * 2.2f, 0.0f));
            d.normal = sg::mat3(1.0f);
            f.meshes.push_back(d);
        }
    auto gl = rnd::makeGlRenderer();
    rnd::Framebuffer actual;
    rnd::RenderStats st = gl->render(f, 200, 200, actual);
    ASSERT_TRUE(st.ok) << st.error;
    EXPECT_TRUE(st.config.notes.empty()) << st.config.notes.front();
    EXPECT_TRUE(testing_support::matchesGlBaseline(actual, "sample_sphere_grid_hdr"));
}

}   // namespace
