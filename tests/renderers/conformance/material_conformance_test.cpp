// material_conformance_test.cpp - glTF material rules in every backend, held to the
// specification's answers:
//  - doubleSided / back-face culling: RenderSettings::culling auto culls the back faces of
//    single-sided materials only, on culls every back face, off none; a double-sided surface
//    seen from its back is lit with the flipped normal (as bright as its front);
//  - alphaMode MASK: drawn where alpha = material alpha x texture alpha >= alphaCutoff, cut out
//    elsewhere (what lies behind shows), alpha itself ignored where kept;
//  - alphaMode OPAQUE: alpha ignored;
//  - alphaMode BLEND: "over" in linear light, in depth order whatever the submission order, and
//    blended surfaces do not hide what lies behind them;
//  - shadows (backends that cast them) pass through cut-out texels.
// Quads are unlit so that the expected colour is exact; one lit case checks the flipped normal.
#include "assets/scene_io.h"
#include "render_support.h"
#include "renderers/renderer.h"
#include "renderers/shading.h"
#include "scenegraph/setting_names.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>

namespace {

using namespace test_scenes;
using sg::vec3;

constexpr int W = 32, H = 32;

sg::FrameInput orthoFrame() {
    sg::Projection p;
    p.type = sg::ProjectionType::Orthographic;
    p.orthoHalfHeight = 1.5f;
    sg::FrameInput f = makeFrame(W, H, p, vec3(0, 0, 3), vec3(0.0f));
    f.settings.shadows = false;
    return f;
}

const testing_support::BackendImages render{W, H, "conformance", "material"};

// Expected 8-bit sRGB of a linear colour.
std::array<int, 3> bytes(const vec3& linear) { return {rnd::toByteSRGB(linear.x), rnd::toByteSRGB(linear.y), rnd::toByteSRGB(linear.z)}; }

::testing::AssertionResult pixelIs(const rnd::Framebuffer& fb, int x, int y, const vec3& linear, int tol = 2) {
    const uint8_t* p = fb.pixel(x, y);
    const std::array<int, 3> want = bytes(linear);
    for (int c = 0; c < 3; ++c)
        if (std::abs(int(p[c]) - want[c]) > tol)
            return ::testing::AssertionFailure() << "pixel (" << x << "," << y << ") is " << int(p[0]) << "," << int(p[1]) << "," << int(p[2])
                                                 << ", expected " << want[0] << "," << want[1] << "," << want[2];
    return ::testing::AssertionSuccess();
}

sg::mat4 turnedAway() { return glm::rotate(sg::mat4(1.0f), glm::pi<float>(), vec3(0, 1, 0)); }   // front faces -z

class MaterialConformance : public ::testing::TestWithParam<std::string> {};

// The culling matrix: (material double-sided?, culling mode, seen from the back?) -> drawn?
TEST_P(MaterialConformance, CullingFollowsDoubleSidedUnderAutoAndOverridesWithOnOff) {
    const vec3 red(1, 0, 0), bg(0.0f);
    struct Case {
        bool doubleSided;
        sg::CullMode mode;
        bool back;
        bool mirrored;
        bool drawn;
    };
    const Case cases[] = {
        {false, sg::CullMode::Auto, true, false, false}, {false, sg::CullMode::Auto, false, false, true},
        {true, sg::CullMode::Auto, true, false, true},   {false, sg::CullMode::Off, true, false, true},
        {true, sg::CullMode::On, true, false, false},    {true, sg::CullMode::On, false, false, true},
        {false, sg::CullMode::Auto, false, true, true},  {false, sg::CullMode::Auto, true, true, false},
    };
    int k = 0;
    for (const Case& c : cases) {
        sg::FrameInput f = orthoFrame();
        sg::Material m = unlit(red);
        m.doubleSided = c.doubleSided;
        f.settings.culling = c.mode;
        sg::mat4 world = c.back ? turnedAway() : sg::mat4(1.0f);
        // Mirrored instance (det < 0): its front is still the side its triangles face.
        if (c.mirrored) world = world * glm::scale(sg::mat4(1.0f), vec3(-1, 1, 1));
        addMesh(f, quad(1.0f), m, world);
        const std::string name = "cull" + std::to_string(k++);
        rnd::Framebuffer fb = render(GetParam(), f, name);
        EXPECT_TRUE(pixelIs(fb, W / 2, H / 2, c.drawn ? red : bg))
            << GetParam() << " " << name << ": doubleSided " << c.doubleSided << " culling " << sg::nameOf(c.mode) << (c.back ? " back" : " front")
            << (c.mirrored ? " mirrored" : "");
    }
}

// A double-sided lit quad seen from its back, lit from the camera's side, is as bright as the
// same quad seen from its front: the normal is flipped toward the viewer (glTF 3.9.4).
TEST_P(MaterialConformance, DoubleSidedBackFaceIsLitWithTheFlippedNormal) {
    for (sg::ShadingModel model : {sg::ShadingModel::Flat, sg::ShadingModel::Gouraud, sg::ShadingModel::Phong}) {
        uint8_t got[2][3];
        for (int back = 0; back < 2; ++back) {
            sg::FrameInput f = orthoFrame();
            f.settings.shading = model;
            f.lights.push_back(directional(vec3(0, 0, -1), vec3(1.0f)));
            sg::Material m;
            m.baseColor = vec3(0.6f, 0.5f, 0.4f);
            m.ks = 0.0f;
            m.doubleSided = true;
            addMesh(f, quad(1.0f), m, back ? turnedAway() : sg::mat4(1.0f));
            rnd::Framebuffer fb = render(GetParam(), f, std::string("lit-") + (back ? "back-" : "front-") + std::string(sg::nameOf(model)));
            std::copy_n(fb.pixel(W / 2, H / 2), 3, got[back]);
        }
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[0][c], got[1][c], 1) << GetParam() << " " << sg::nameOf(model) << " channel " << c;
        EXPECT_GT(got[1][0], 100) << GetParam() << " " << sg::nameOf(model) << ": the back face is not lit";
    }
}

// A 2x1 texture: left texel transparent (alpha 0), right texel opaque, both green.
std::shared_ptr<sg::Texture> halfTransparent() {
    auto t = std::make_shared<sg::Texture>();
    t->width = 2;
    t->height = 1;
    t->rgba = {0, 255, 0, 0, 0, 255, 0, 255};
    t->filter = sg::FilterMode::Nearest;
    t->wrapS = t->wrapT = sg::WrapMode::ClampToEdge;
    return t;
}

// Green textured quad at z = 0 over a blue opaque quad at z = -1.
sg::FrameInput maskFrame(sg::AlphaMode mode, float alpha, float cutoff) {
    sg::FrameInput f = orthoFrame();
    addMesh(f, quad(1.4f), unlit(vec3(0, 0, 1)), glm::translate(sg::mat4(1.0f), vec3(0, 0, -1)));
    sg::Material m = unlit(vec3(1.0f));
    m.alphaMode = mode;
    m.alpha = alpha;
    m.alphaCutoff = cutoff;
    addMesh(f, quad(1.0f), m, sg::mat4(1.0f), halfTransparent());
    return f;
}

TEST_P(MaterialConformance, MaskCutsOutBelowTheCutoffAndOpaqueIgnoresAlpha) {
    const vec3 green(0, 1, 0), blue(0, 0, 1);
    const int left = W / 2 - 5, right = W / 2 + 5;   // inside the left / right texel of the quad
    struct Case {
        sg::AlphaMode mode;
        float alpha, cutoff;
        vec3 left, right;
        const char* name;
    };
    const Case cases[] = {
        {sg::AlphaMode::Mask, 1.0f, 0.5f, blue, green, "mask-texture"},
        {sg::AlphaMode::Mask, 0.4f, 0.5f, blue, blue, "mask-factor-below"},
        {sg::AlphaMode::Mask, 0.6f, 0.5f, blue, green, "mask-factor-above"},
        {sg::AlphaMode::Mask, 0.6f, 0.7f, blue, blue, "mask-cutoff-raised"},
        {sg::AlphaMode::Opaque, 0.1f, 0.5f, green, green, "opaque-ignores-alpha"},
    };
    for (const Case& c : cases) {
        rnd::Framebuffer fb = render(GetParam(), maskFrame(c.mode, c.alpha, c.cutoff), c.name);
        EXPECT_TRUE(pixelIs(fb, left, H / 2, c.left)) << GetParam() << " " << c.name << " (left texel)";
        EXPECT_TRUE(pixelIs(fb, right, H / 2, c.right)) << GetParam() << " " << c.name << " (right texel)";
    }
}

// Blend: red (alpha 0.5) at z = 0.5 and green (alpha 0.5) at z = 0 over blue at z = -1, in both
// submission orders: back to front, blue -> (0, .5, .5) -> (.5, .25, .25), whatever the order.
TEST_P(MaterialConformance, BlendCompositesOverInDepthOrder) {
    for (int order = 0; order < 2; ++order) {
        sg::FrameInput f = orthoFrame();
        sg::Material red = unlit(vec3(1, 0, 0)), green = unlit(vec3(0, 1, 0));
        red.alphaMode = green.alphaMode = sg::AlphaMode::Blend;
        red.alpha = green.alpha = 0.5f;
        auto addRed = [&] { addMesh(f, quad(0.6f), red, glm::translate(sg::mat4(1.0f), vec3(0.3f, 0, 0.5f))); };
        auto addGreen = [&] { addMesh(f, quad(0.6f), green, glm::translate(sg::mat4(1.0f), vec3(-0.3f, 0, 0))); };
        if (order == 0) {
            addRed();
            addGreen();
        } else {
            addGreen();
            addRed();
        }
        // The opaque quad last: blended surfaces in front of it must not have hidden it.
        addMesh(f, quad(1.2f), unlit(vec3(0, 0, 1)), glm::translate(sg::mat4(1.0f), vec3(0, 0, -1)));
        rnd::Framebuffer fb = render(GetParam(), f, "blend-order" + std::to_string(order));
        const int cx = W / 2, cy = H / 2;   // both quads overlap here
        EXPECT_TRUE(pixelIs(fb, cx, cy, vec3(0.5f, 0.25f, 0.25f))) << GetParam() << " order " << order << " (both layers)";
        EXPECT_TRUE(pixelIs(fb, cx - 8, cy, vec3(0.0f, 0.5f, 0.5f))) << GetParam() << " order " << order << " (green only)";
        EXPECT_TRUE(pixelIs(fb, cx + 8, cy, vec3(0.5f, 0.0f, 0.5f))) << GetParam() << " order " << order << " (red only)";
        EXPECT_TRUE(pixelIs(fb, 1, 1, vec3(0.0f))) << GetParam() << " background";
    }
}

INSTANTIATE_TEST_SUITE_P(EveryBackend, MaterialConformance, ::testing::ValuesIn(rnd::rendererNames()), [](const auto& info) { return info.param; });

// Backends that cast shadows: a blocker between a light and a floor. Cut out entirely it casts
// no shadow, opaque it casts a full one; blended (alpha 0.25) it lets 75% of the light through
// a shadow ray, and all of it past a shadow map (rnd::castsShadow: a depth map holds no partial
// answer).
TEST(MaterialShadows, ShadowRaysPassCutOutsAndAreDimmedByBlendedSurfaces) {
    int tested = 0;
    for (const std::string& backend : rnd::rendererNames()) {
        std::string err;
        auto r = rnd::makeRenderer(backend, &err);
        ASSERT_TRUE(r) << err;
        if (!r->capabilities().shadows) continue;
        ++tested;
        const char* names[4] = {"none", "opaque", "cut-out", "blend"};
        const bool maps = r->capabilities().shadowMaps;
        const float expected[4] = {1.0f, 0.0f, 1.0f, maps ? 1.0f : 0.75f};   // fraction of the light reaching the floor
        for (int k = 0; k < 4; ++k) {
            sg::FrameInput f = orthoFrame();
            f.settings.shadows = true;
            // The light travels toward -x and -z: the blocker at x = +0.5 shades the floor at x = -0.5.
            f.lights.push_back(directional(glm::normalize(vec3(-1, 0, -1)), vec3(1.0f)));
            sg::Material floor;
            floor.baseColor = vec3(1.0f);
            floor.ka = 0.0f;
            floor.kd = 1.0f;
            floor.ks = 0.0f;
            addMesh(f, quad(1.4f), floor, glm::translate(sg::mat4(1.0f), vec3(0, 0, -1)));
            if (k > 0) {
                sg::Material blocker = unlit(vec3(0.0f));
                blocker.alphaMode = k == 1 ? sg::AlphaMode::Opaque : k == 2 ? sg::AlphaMode::Mask : sg::AlphaMode::Blend;
                blocker.alpha = k == 2 ? 0.0f : 0.25f;
                addMesh(f, quad(0.3f), blocker, glm::translate(sg::mat4(1.0f), vec3(0.5f, 0.0f, 0.0f)));
            }
            rnd::Framebuffer fb;
            rnd::RenderStats st = r->render(f, W, H, fb);
            ASSERT_TRUE(st.ok) << st.error;
            testing_support::writeImage(fb, "conformance", std::string("material-") + backend + "-shadow-" + names[k]);
            const int x = int(float(W) / 2 + (-0.5f / 1.5f) * float(H) / 2);   // floor at world x = -0.5
            EXPECT_TRUE(pixelIs(fb, x, H / 2, vec3(expected[k] * std::sqrt(0.5f)))) << backend << " blocker " << names[k];
        }
    }
    EXPECT_GT(tested, 0) << "no backend casts shadows";
}

// glTF import: alphaMode, alphaCutoff, baseColorFactor alpha and doubleSided reach the material.
TEST(MaterialImport, GltfAlphaModeCutoffAndDoubleSided) {
    namespace fs = std::filesystem;
    fs::path dir = testing_support::outputDir("conformance") / "material-import";
    fs::create_directories(dir);
    // One triangle, three primitives sharing it with three materials.
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::string b64 = testing_support::base64Encode(std::string_view(reinterpret_cast<const char*>(pos), sizeof pos));
    fs::path file = dir / "alpha.gltf";
    std::ofstream(file) << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0},{"attributes":{"POSITION":0},"material":1},{"attributes":{"POSITION":0},"material":2}]}],
"materials":[{"name":"plain"},
 {"name":"cut","alphaMode":"MASK","alphaCutoff":0.3,"pbrMetallicRoughness":{"baseColorFactor":[1,1,1,0.8]}},
 {"name":"glass","alphaMode":"BLEND","doubleSided":true,"pbrMetallicRoughness":{"baseColorFactor":[1,1,1,0.4]}}],
"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,)"
                        << b64 << R"("}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})";
    assets::LoadResult r = assets::loadScene(file);
    ASSERT_TRUE(r.scene) << r.error;
    std::map<std::string, sg::Material> byName;
    for (const sg::Material& m : r.scene->materials) byName[m.name] = m;
    ASSERT_TRUE(byName.count("plain") && byName.count("cut") && byName.count("glass"));
    EXPECT_EQ(byName["plain"].alphaMode, sg::AlphaMode::Opaque);
    EXPECT_FALSE(byName["plain"].doubleSided);   // glTF's default
    EXPECT_EQ(byName["cut"].alphaMode, sg::AlphaMode::Mask);
    EXPECT_NEAR(byName["cut"].alphaCutoff, 0.3f, 1e-6f);
    EXPECT_NEAR(byName["cut"].alpha, 0.8f, 1e-6f);
    EXPECT_EQ(byName["glass"].alphaMode, sg::AlphaMode::Blend);
    EXPECT_NEAR(byName["glass"].alpha, 0.4f, 1e-6f);
    EXPECT_TRUE(byName["glass"].doubleSided);
    // The scene file keeps them.
    fs::path json = dir / "alpha.scene.json";
    ASSERT_EQ(assets::saveSceneJson(*r.scene, json, true), "");
    assets::LoadResult again = assets::loadScene(json);
    ASSERT_TRUE(again.scene) << again.error;
    EXPECT_EQ(again.scene->materials, r.scene->materials);
}

}   // namespace
