// material_maps_test.cpp - glTF material maps in every backend, held to the formulas of
// docs/math.md ("Material textures"; rnd::coefficientsAt / applyMapsToTerms in
// renderers/common/shading.cpp):
//  - emissiveTexture: emissive_eff = emissiveFactor (x) texel (sRGB colour);
//  - occlusionTexture: ka_eff = ka (1 + strength (R - 1)) on the ambient term only (linear data);
//  - metallicRoughnessTexture: per texel (kd, ks, n, tint) = phongFromMetallicRoughness(
//    metallic x B, roughness x G) under Phong shading, the material's own coefficients under
//    Gouraud and flat (lighting at the vertices, once per face), where occlusion and emissive
//    still apply exactly.
// Each case is a 2x1 texture (nearest filter) on an orthographic head-on quad, the left and
// right halves of the image sampling one texel each, so every expected colour is exact.
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "render_support.h"
#include "renderers/renderer.h"
#include "renderers/shading.h"
#include "scenegraph/setting_names.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <map>

namespace {

using namespace test_scenes;
using sg::vec3;

constexpr int W = 32, H = 32;
constexpr int kLeft = W / 2 - 5, kRight = W / 2 + 5;

// A 2x1 texture of two RGB texels, nearest, clamped; srgb false for data textures.
sg::TexturePtr twoTexels(std::array<uint8_t, 3> left, std::array<uint8_t, 3> right, bool srgb) {
    auto t = std::make_shared<sg::Texture>();
    t->width = 2;
    t->height = 1;
    t->rgba = {left[0], left[1], left[2], 255, right[0], right[1], right[2], 255};
    t->filter = sg::FilterMode::Nearest;
    t->wrapS = t->wrapT = sg::WrapMode::ClampToEdge;
    t->srgb = srgb;
    return t;
}

// Head-on orthographic quad, a directional light straight along the view (n.l = 1 and r.v = 1
// everywhere: the specular factor is 1 whatever the exponent), ambient L_a.
sg::FrameInput mapsFrame(const sg::Material& m, const sg::MaterialMaps& maps, sg::ShadingModel model, const vec3& ambient, const vec3& light) {
    sg::Projection p;
    p.type = sg::ProjectionType::Orthographic;
    p.orthoHalfHeight = 1.5f;
    sg::FrameInput f = makeFrame(W, H, p, vec3(0, 0, 3), vec3(0.0f));
    f.settings.shadows = false;
    f.settings.shading = model;
    f.ambientLight = ambient;
    if (light != vec3(0.0f)) f.lights.push_back(directional(vec3(0, 0, -1), light));
    addMesh(f, quad(1.0f), m);
    f.meshes.back().maps = maps;
    return f;
}

const testing_support::BackendImages render{W, H, "conformance", "maps"};

::testing::AssertionResult pixelIs(const rnd::Framebuffer& fb, int x, const vec3& linear, int tol = 2) {
    const uint8_t* p = fb.pixel(x, H / 2);
    const int want[3] = {rnd::toByteSRGB(linear.x), rnd::toByteSRGB(linear.y), rnd::toByteSRGB(linear.z)};
    for (int c = 0; c < 3; ++c)
        if (std::abs(int(p[c]) - want[c]) > tol)
            return ::testing::AssertionFailure() << "pixel x=" << x << " is " << int(p[0]) << "," << int(p[1]) << "," << int(p[2]) << ", expected "
                                                 << want[0] << "," << want[1] << "," << want[2];
    return ::testing::AssertionSuccess();
}

class MaterialMaps : public ::testing::TestWithParam<std::string> {};

const sg::ShadingModel kModels[] = {sg::ShadingModel::Flat, sg::ShadingModel::Gouraud, sg::ShadingModel::Phong};

// Emission only (ka = kd = ks = 0): the factor times the sRGB-decoded texel, lit or unlit.
TEST_P(MaterialMaps, EmissiveTextureMultipliesTheFactor) {
    for (bool unlitMat : {false, true})
        for (sg::ShadingModel model : kModels) {
            sg::Material m;
            m.baseColor = vec3(0.0f);
            m.ka = m.kd = m.ks = 0.0f;
            m.unlit = unlitMat;
            m.emissive = vec3(1.0f, 0.5f, 0.8f);
            sg::MaterialMaps maps;
            maps.emissive = twoTexels({255, 0, 0}, {0, 188, 255}, true);
            const std::string name = std::string("emissive-") + (unlitMat ? "unlit-" : "") + std::string(sg::nameOf(model));
            rnd::Framebuffer fb = render(GetParam(), mapsFrame(m, maps, model, vec3(0.3f), vec3(1.0f)), name);
            EXPECT_TRUE(pixelIs(fb, kLeft, vec3(1.0f, 0.0f, 0.0f))) << GetParam() << " " << name;
            EXPECT_TRUE(pixelIs(fb, kRight, vec3(0.0f, 0.5f * rnd::decodeSRGB(188.0f / 255.0f), 0.8f))) << GetParam() << " " << name;
        }
}

// Ambient only (kd = ks = 0, no light): ka (1 + strength (R - 1)) L_a rho, R read linearly
// (128 -> 0.50196, not sRGB-decoded), at strength 0.5 and 1.
TEST_P(MaterialMaps, OcclusionTextureScalesTheAmbientTermOnly) {
    for (float strength : {1.0f, 0.5f})
        for (sg::ShadingModel model : kModels) {
            sg::Material m;
            m.baseColor = vec3(0.8f, 0.6f, 0.4f);
            m.ka = 1.0f;
            m.kd = m.ks = 0.0f;
            m.occlusionStrength = strength;
            sg::MaterialMaps maps;
            maps.occlusion = twoTexels({128, 0, 0}, {255, 255, 255}, false);
            const vec3 La(0.5f);
            const std::string name = "occlusion-" + std::to_string(int(strength * 10)) + "-" + std::string(sg::nameOf(model));
            rnd::Framebuffer fb = render(GetParam(), mapsFrame(m, maps, model, La, vec3(0.0f)), name);
            const float ao = 1.0f + strength * (128.0f / 255.0f - 1.0f);
            EXPECT_TRUE(pixelIs(fb, kLeft, ao * La * m.baseColor)) << GetParam() << " " << name;
            EXPECT_TRUE(pixelIs(fb, kRight, La * m.baseColor)) << GetParam() << " " << name;
        }
    // A light adds its diffuse term unoccluded: occlusion darkens the ambient term alone.
    sg::Material m;
    m.baseColor = vec3(0.5f);
    m.ka = 1.0f;
    m.kd = 1.0f;
    m.ks = 0.0f;
    sg::MaterialMaps maps;
    maps.occlusion = twoTexels({0, 0, 0}, {255, 255, 255}, false);
    rnd::Framebuffer fb = render(GetParam(), mapsFrame(m, maps, sg::ShadingModel::Phong, vec3(0.4f), vec3(0.6f)), "occlusion-lit");
    EXPECT_TRUE(pixelIs(fb, kLeft, vec3(0.6f * 0.5f))) << GetParam();
    EXPECT_TRUE(pixelIs(fb, kRight, vec3((0.4f + 0.6f) * 0.5f))) << GetParam();
}

// Left texel: dielectric (B = 0), rough (G = 255); right: metal (B = 255), rough. With the
// factors metallic 1, roughness 1: colour = L (kd rho + ks spec), spec = 1, untinted (white)
// for the dielectric, tinted (rho) for the metal. Gouraud keeps the material's coefficients.
TEST_P(MaterialMaps, MetallicRoughnessTextureGivesSurfaceCoefficientsPerTexel) {
    for (sg::ShadingModel model : kModels) {
        sg::Material m;
        m.baseColor = vec3(0.4f, 0.2f, 0.1f);
        m.ka = 0.0f;
        m.kd = 0.5f;
        m.ks = 0.0f;
        m.metallic = 1.0f;
        m.roughness = 1.0f;
        sg::MaterialMaps maps;
        maps.metallicRoughness = twoTexels({0, 255, 0}, {0, 255, 255}, false);
        const vec3 L(0.5f);
        const std::string name = "mr-" + std::string(sg::nameOf(model));
        rnd::Framebuffer fb = render(GetParam(), mapsFrame(m, maps, model, vec3(0.0f), L), name);
        if (model != sg::ShadingModel::Phong) {   // lit once per vertex or face: the material's own coefficients
            EXPECT_TRUE(pixelIs(fb, kLeft, L * 0.5f * m.baseColor)) << GetParam() << " " << name;
            EXPECT_TRUE(pixelIs(fb, kRight, L * 0.5f * m.baseColor)) << GetParam() << " " << name;
            continue;
        }
        const sg::PhongFromPbr d = sg::phongFromMetallicRoughness(0.0f, 1.0f), metal = sg::phongFromMetallicRoughness(1.0f, 1.0f);
        ASSERT_FALSE(d.tinted);
        ASSERT_TRUE(metal.tinted);
        EXPECT_TRUE(pixelIs(fb, kLeft, L * (d.kd * m.baseColor + vec3(d.ks)))) << GetParam() << " " << name;
        EXPECT_TRUE(pixelIs(fb, kRight, L * (metal.kd + metal.ks) * m.baseColor)) << GetParam() << " " << name;
    }
}

// Normal map under Phong shading, a directional light along the view (l = +z), diffuse only:
// colour = L kd rho max(n'.z, 0) with n' = perturbNormal(+z, tangent, texel, scale). Left texel
// (204, 128, 230) tilts the normal toward +x (tangent) by ~37 degrees; right texel (128, 204,
// 230) toward +y, i.e. toward the bitangent w cross(n, t): with w = -1 toward -y. Scale 0 makes
// the map flat. Flat and Gouraud shading keep the geometric/vertex normal.
TEST_P(MaterialMaps, NormalTextureTiltsTheShadingNormal) {
    const vec3 rho(0.8f), L(1.0f);
    auto texel = [](int r, int g, int b) { return vec3(float(r), float(g), float(b)) / 255.0f; };
    for (float w : {1.0f, -1.0f})
        for (float scale : {1.0f, 0.0f})
            for (sg::ShadingModel model : kModels) {
                sg::Material m;
                m.baseColor = rho;
                m.ka = m.ks = 0.0f;
                m.kd = 1.0f;
                m.normalScale = scale;
                sg::MaterialMaps maps;
                maps.normal = twoTexels({204, 128, 230}, {128, 204, 230}, false);
                sg::FrameInput f = mapsFrame(m, maps, model, vec3(0.0f), L);
                sg::Mesh mesh = *f.meshes.back().mesh;
                mesh.tangents.assign(mesh.positions.size(), sg::vec4(1, 0, 0, w));
                mesh.id = sg::newResourceId();   // a different mesh (renderers cache by id)
                f.meshes.back().mesh = std::make_shared<sg::Mesh>(mesh);
                // A light tilted toward +x+y so that tilts toward x and y change the colour.
                f.lights.back().direction = glm::normalize(vec3(-0.5f, -0.5f, -1.0f));
                const vec3 l = -f.lights.back().direction;
                const std::string name =
                    "normal-w" + std::to_string(int(w)) + "-s" + std::to_string(int(scale)) + "-" + std::string(sg::nameOf(model));
                rnd::Framebuffer fb = render(GetParam(), f, name);
                const bool mapped = model == sg::ShadingModel::Phong;
                // The flat normal and the tilted ones are far apart (0.82 vs 0.90, 0.41 .. ): the
                // pixels tell whether the map was applied and which way.
                for (int side = 0; side < 2; ++side) {
                    const vec3 nn =
                        mapped ? rnd::perturbNormal(vec3(0, 0, 1), sg::vec4(1, 0, 0, w), side ? texel(128, 204, 230) : texel(204, 128, 230), scale)
                               : vec3(0, 0, 1);
                    EXPECT_TRUE(pixelIs(fb, side ? kRight : kLeft, L * rho * std::max(glm::dot(nn, l), 0.0f)))
                        << GetParam() << " " << name << " side " << side;
                }
            }
    // The formula itself: +x tilt of atan(0.6 / 0.8039) about y; w = -1 mirrors the y tilt.
    const vec3 a = rnd::perturbNormal(vec3(0, 0, 1), sg::vec4(1, 0, 0, 1), texel(204, 128, 230), 1.0f);
    EXPECT_NEAR(a.x / a.z, (2.0f * 204 / 255 - 1) / (2.0f * 230 / 255 - 1), 1e-5f);
    const vec3 b = rnd::perturbNormal(vec3(0, 0, 1), sg::vec4(1, 0, 0, -1), texel(128, 204, 230), 1.0f);
    EXPECT_LT(b.y, -0.5f);
}

// Generated tangents follow increasing u, the handedness increasing v (glTF's convention).
TEST(MeshTangents, GeneratedFromUvsWithHandedness) {
    sg::Mesh q = quad(1.0f);   // uv (0,0) at (-1,-1), u along +x, v along +y
    q.computeTangents();
    ASSERT_EQ(q.tangents.size(), q.positions.size());
    for (const sg::vec4& t : q.tangents) {
        EXPECT_NEAR(t.x, 1.0f, 1e-6f);
        EXPECT_NEAR(t.w, 1.0f, 0.0f);
    }
    for (auto& uv : q.uv0) uv.y = 1.0f - uv.y;   // v now along -y: left-handed
    q.computeTangents();
    for (const sg::vec4& t : q.tangents) EXPECT_EQ(t.w, -1.0f);
    for (auto& uv : q.uv0) uv.x = 1.0f - uv.x;   // u along -x
    q.computeTangents();
    for (const sg::vec4& t : q.tangents) {
        EXPECT_NEAR(t.x, -1.0f, 1e-6f);
        EXPECT_EQ(t.w, 1.0f);
    }
}

// KHR_materials_pbrSpecularGlossiness texture: specular = ks specularColor (x) RGB (sRGB),
// untinted, exponent n from glossiness x A. With a black base colour the pixel is
// L (x) specular (r.v)^n, r = l = +z, v toward the eye point (0, 0, 3) from the pixel's point
// on the quad. Gouraud keeps the material's own coefficients.
TEST_P(MaterialMaps, SpecularGlossinessTextureGivesTheSpecularColourPerTexel) {
    auto specAt = [](int x, float gloss) {   // (r.v)^n at the centre of pixel (x, H/2)
        const float px = (float(x) + 0.5f) / W * 3.0f - 1.5f, py = 1.5f - (float(H / 2) + 0.5f) / H * 3.0f;
        const vec3 v = glm::normalize(vec3(0, 0, 3) - vec3(px, py, 0));
        return std::pow(v.z, sg::phongFromMetallicRoughness(0.0f, 1.0f - gloss).shininess);
    };
    for (sg::ShadingModel model : kModels) {
        sg::Material m;
        m.baseColor = vec3(0.0f);
        m.ka = 0.0f;
        m.ks = 1.0f;
        m.specularColor = vec3(1.0f, 1.0f, 0.5f);
        m.specularGlossiness = true;
        m.glossiness = 0.5f;
        sg::MaterialMaps maps;
        auto t = std::make_shared<sg::Texture>(*twoTexels({255, 0, 0}, {0, 188, 255}, true));
        t->rgba[3] = 255;   // glossiness 0.5 x 1 and 0.5 x 128/255 (alpha is linear)
        t->rgba[7] = 128;
        maps.metallicRoughness = t;
        const vec3 L(0.8f);
        const std::string name = "specgloss-" + std::string(sg::nameOf(model));
        rnd::Framebuffer fb = render(GetParam(), mapsFrame(m, maps, model, vec3(0.0f), L), name);
        if (model != sg::ShadingModel::Phong) {   // lit at the corners (or one per face) with n = m.shininess: not checked per pixel
            EXPECT_GT(fb.pixel(kLeft, H / 2)[1], 0) << GetParam() << " " << name << ": the texture's red must not reach Gouraud";
            continue;
        }
        EXPECT_TRUE(pixelIs(fb, kLeft, L * vec3(1.0f, 0.0f, 0.0f) * specAt(kLeft, 0.5f))) << GetParam() << " " << name;
        EXPECT_TRUE(pixelIs(fb, kRight, L * vec3(0.0f, rnd::decodeSRGB(188.0f / 255.0f), 0.5f) * specAt(kRight, 0.5f * 128.0f / 255.0f)))
            << GetParam() << " " << name;
    }
}

// Each map samples its own UV set (sg::Material::uv1Maps; glTF texCoord): uv1 mirrors uv0 in
// u, the emissive map reads uv1 and the occlusion map uv0 in the same draw, so the left half
// shows the right texel's emission and its own texel's occlusion. A mesh without uv1 samples
// uv0 for every map.
TEST_P(MaterialMaps, EachMapSamplesItsOwnUvSet) {
    for (bool hasUv1 : {true, false})
        for (sg::ShadingModel model : kModels) {
            sg::Material m;
            m.baseColor = vec3(0.5f);
            m.ka = 1.0f;
            m.kd = m.ks = 0.0f;
            m.emissive = vec3(1.0f);
            m.uv1Maps = sg::Material::EmissiveMap;
            sg::MaterialMaps maps;
            maps.emissive = twoTexels({255, 0, 0}, {0, 0, 255}, true);
            maps.occlusion = twoTexels({0, 0, 0}, {255, 255, 255}, false);
            const vec3 La(0.4f);
            sg::FrameInput f = mapsFrame(m, maps, model, La, vec3(0.0f));
            sg::Mesh mesh = quad(1.0f);
            if (hasUv1)
                for (const sg::vec2& uv : mesh.uv0) mesh.uv1.push_back(sg::vec2(1.0f - uv.x, uv.y));
            f.meshes.back().mesh = std::make_shared<sg::Mesh>(mesh);
            const std::string name = std::string("uv-sets-") + (hasUv1 ? "two-" : "one-") + std::string(sg::nameOf(model));
            rnd::Framebuffer fb = render(GetParam(), f, name);
            const vec3 red(1, 0, 0), blue(0, 0, 1), ambient = La * m.baseColor;
            EXPECT_TRUE(pixelIs(fb, kLeft, hasUv1 ? blue : red)) << GetParam() << " " << name;   // occlusion 0: no ambient
            EXPECT_TRUE(pixelIs(fb, kRight, (hasUv1 ? red : blue) + ambient)) << GetParam() << " " << name;
        }
}

INSTANTIATE_TEST_SUITE_P(EveryBackend, MaterialMaps, ::testing::ValuesIn(rnd::rendererNames()), [](const auto& info) { return info.param; });

// The mapping itself at known points (docs/math.md).
TEST(PhongFromMetallicRoughness, KnownValues) {
    const sg::PhongFromPbr a = sg::phongFromMetallicRoughness(0.0f, 1.0f);
    EXPECT_FLOAT_EQ(a.kd, 1.0f);
    EXPECT_FLOAT_EQ(a.ks, 0.04f);
    EXPECT_FLOAT_EQ(a.shininess, 1.0f);   // 2/1 - 2 = 0, clamped to 1
    const sg::PhongFromPbr b = sg::phongFromMetallicRoughness(1.0f, 0.5f);
    EXPECT_FLOAT_EQ(b.kd, 0.25f);
    EXPECT_FLOAT_EQ(b.ks, 1.0f);
    EXPECT_FLOAT_EQ(b.shininess, 2.0f / (0.25f * 0.25f) - 2.0f);   // a = r^2 = 0.25
    EXPECT_TRUE(b.tinted);
    EXPECT_FLOAT_EQ(sg::phongFromMetallicRoughness(0.0f, 0.0f).shininess, 2048.0f);
    EXPECT_NEAR(sg::phongFromMetallicRoughness(0.0f, 0.0f).ks, 0.29f, 1e-6f);
}

// The import tests' glTF data: a 2x1 PNG (red, green), and the buffer of a unit quad in z = 0:
// 4 positions, then each UV set (4 vec2), then 6 uint16 indices.
using UvSet = std::array<float, 8>;
std::string redGreenPng() {
    const uint8_t rgba[8] = {255, 0, 0, 255, 0, 255, 0, 255};
    std::string png;
    EXPECT_EQ(assets::encodePng(2, 1, rgba, png), "");
    return png;
}
std::string quadBuffer(std::initializer_list<UvSet> uvSets) {
    const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    std::string buf(reinterpret_cast<const char*>(pos), sizeof pos);
    for (const UvSet& uv : uvSets) buf.append(reinterpret_cast<const char*>(uv.data()), sizeof(float) * uv.size());
    buf.append(reinterpret_cast<const char*>(idx), sizeof idx);
    return buf;
}

// glTF import: the maps, their factors and colour spaces reach the material (one glTF texture
// used as colour and as data becomes two textures), and the scene file keeps them.
TEST(MaterialMapsImport, GltfTexturesFactorsAndColourSpaces) {
    namespace fs = std::filesystem;
    fs::path dir = testing_support::outputDir("conformance") / "maps-import";
    fs::create_directories(dir);
    const std::string png = redGreenPng(), buf = quadBuffer({{0, 1, 1, 1, 1, 0, 0, 0}});
    fs::path file = dir / "maps.gltf";
    std::ofstream(file) << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2,"material":0}]}],
"materials":[{"name":"bottle","pbrMetallicRoughness":{"baseColorTexture":{"index":0},"metallicFactor":0.7,"roughnessFactor":0.4,
  "metallicRoughnessTexture":{"index":0}},"occlusionTexture":{"index":1,"strength":0.3},"emissiveTexture":{"index":1},
  "emissiveFactor":[1,0.5,0.25]}],
"textures":[{"source":0},{"source":0}],
"images":[{"uri":"data:image/png;base64,)"
                        << testing_support::base64Encode(png) << R"("}],
"buffers":[{"byteLength":92,"uri":"data:application/octet-stream;base64,)"
                        << testing_support::base64Encode(buf) << R"("}],
"bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":32},{"buffer":0,"byteOffset":80,"byteLength":12}],
"accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
 {"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"},{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}]})";
    assets::LoadResult r = assets::loadScene(file);
    ASSERT_TRUE(r.scene) << r.error;
    for (const std::string& w : r.warnings) ADD_FAILURE() << "unexpected warning: " << w;
    ASSERT_EQ(r.scene->materials.size(), 1u);
    const sg::Material& m = r.scene->materials[0];
    const auto& tex = r.scene->textures;
    auto srgbOf = [&](int i) { return i >= 0 && size_t(i) < tex.size() ? int(tex[size_t(i)]->srgb) : -1; };
    EXPECT_EQ(srgbOf(m.diffuseTexture), 1);
    EXPECT_EQ(srgbOf(m.metallicRoughnessTexture), 0);   // glTF texture 0 as data: a second texture
    EXPECT_NE(m.diffuseTexture, m.metallicRoughnessTexture);
    EXPECT_EQ(srgbOf(m.occlusionTexture), 0);
    EXPECT_EQ(srgbOf(m.emissiveTexture), 1);
    EXPECT_NEAR(m.metallic, 0.7f, 1e-6f);
    EXPECT_NEAR(m.roughness, 0.4f, 1e-6f);
    EXPECT_NEAR(m.occlusionStrength, 0.3f, 1e-6f);
    EXPECT_EQ(m.emissive, vec3(1.0f, 0.5f, 0.25f));
    const sg::PhongFromPbr ph = sg::phongFromMetallicRoughness(0.7f, 0.4f);
    EXPECT_FLOAT_EQ(m.kd, ph.kd);
    EXPECT_FLOAT_EQ(m.ks, ph.ks);
    EXPECT_FLOAT_EQ(m.shininess, ph.shininess);
    fs::path json = dir / "maps.scene.json";
    ASSERT_EQ(assets::saveSceneJson(*r.scene, json, true), "");
    assets::LoadResult again = assets::loadScene(json);
    ASSERT_TRUE(again.scene) << again.error;
    EXPECT_EQ(again.scene->materials, r.scene->materials);
    ASSERT_EQ(again.scene->textures.size(), tex.size());
    for (size_t i = 0; i < tex.size(); ++i) EXPECT_EQ(again.scene->textures[i]->srgb, tex[i]->srgb) << i;
}

// glTF import of two UV channels: the base colour on TEXCOORD_0, the occlusion texture on
// TEXCOORD_1 with a KHR_texture_transform offset. uv0 and uv1 carry them (v flipped after the
// transform), uv1Maps names the occlusion map, and the scene file keeps it. An emissive texture
// on a third (set, transform) combination samples the base colour's channel, with a warning.
TEST(MaterialMapsImport, TwoUvChannelsWithTheirTransforms) {
    namespace fs = std::filesystem;
    fs::path dir = testing_support::outputDir("conformance") / "maps-uv-sets";
    fs::create_directories(dir);
    const UvSet uvA = {0, 1, 1, 1, 1, 0, 0, 0}, uvB = {0.1f, 0.2f, 0.3f, 0.2f, 0.3f, 0.4f, 0.1f, 0.4f};
    const std::string png = redGreenPng(), buf = quadBuffer({uvA, uvB});
    auto write = [&](const fs::path& file, const std::string& emissive) {
        std::ofstream(file) << R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_texture_transform"],"scene":0,"scenes":[{"nodes":[0]}],
"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1,"TEXCOORD_1":2},"indices":3,"material":0}]}],
"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}},
  "occlusionTexture":{"index":0,"texCoord":1,"extensions":{"KHR_texture_transform":{"offset":[0.5,0.25]}}})"
                            << emissive << R"(}],
"textures":[{"source":0}],
"images":[{"uri":"data:image/png;base64,)"
                            << testing_support::base64Encode(png) << R"("}],
"buffers":[{"byteLength":124,"uri":"data:application/octet-stream;base64,)"
                            << testing_support::base64Encode(buf) << R"("}],
"bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":32},{"buffer":0,"byteOffset":80,"byteLength":32},
 {"buffer":0,"byteOffset":112,"byteLength":12}],
"accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
 {"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"},{"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"},
 {"bufferView":3,"componentType":5123,"count":6,"type":"SCALAR"}]})";
    };
    write(dir / "two.gltf", R"(,"emissiveTexture":{"index":0,"texCoord":1,"extensions":{"KHR_texture_transform":{"offset":[0.5,0.25]}}})");
    assets::LoadResult r = assets::loadScene(dir / "two.gltf");
    ASSERT_TRUE(r.scene) << r.error;
    for (const std::string& w : r.warnings) ADD_FAILURE() << "unexpected warning: " << w;
    ASSERT_EQ(r.scene->materials.size(), 1u);
    EXPECT_EQ(r.scene->materials[0].uv1Maps, sg::Material::OcclusionMap | sg::Material::EmissiveMap);
    ASSERT_EQ(r.scene->meshes.size(), 1u);
    const sg::Mesh& mesh = *r.scene->meshes[0];
    ASSERT_EQ(mesh.uv0.size(), 4u);
    ASSERT_EQ(mesh.uv1.size(), 4u);
    for (size_t i = 0; i < 4; ++i) {
        EXPECT_NEAR(mesh.uv0[i].x, uvA[2 * i], 1e-6f) << i;
        EXPECT_NEAR(mesh.uv0[i].y, 1.0f - uvA[2 * i + 1], 1e-6f) << i;
        EXPECT_NEAR(mesh.uv1[i].x, uvB[2 * i] + 0.5f, 1e-6f) << i;
        EXPECT_NEAR(mesh.uv1[i].y, 1.0f - (uvB[2 * i + 1] + 0.25f), 1e-6f) << i;
    }
    const fs::path json = dir / "two.scene.json";
    ASSERT_EQ(assets::saveSceneJson(*r.scene, json, true), "");
    assets::LoadResult again = assets::loadScene(json);
    ASSERT_TRUE(again.scene) << again.error;
    EXPECT_EQ(again.scene->materials, r.scene->materials);

    write(dir / "three.gltf", R"(,"emissiveTexture":{"index":0,"extensions":{"KHR_texture_transform":{"scale":[2,2]}}})");
    assets::LoadResult three = assets::loadScene(dir / "three.gltf");
    ASSERT_TRUE(three.scene) << three.error;
    EXPECT_EQ(three.scene->materials[0].uv1Maps, sg::Material::OcclusionMap);   // emissive samples channel 0
    ASSERT_EQ(three.warnings.size(), 1u);
    EXPECT_NE(three.warnings[0].find("more than two UV set"), std::string::npos) << three.warnings[0];
}

}   // namespace
