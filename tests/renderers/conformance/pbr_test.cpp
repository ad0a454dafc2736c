// pbr_test.cpp - the pbr reflection model in every backend, held to answers computed here from
// the published formulas (not from renderers/common/pbr.cpp):
//  - glTF 2.0 Appendix B under one directional light (lux), no environment: camera-facing quads
//    for several (base colour, metallic, roughness), and KHR_materials_ior / _specular's F0, F90;
//  - the white furnace: white spheres, metal or not, rough or smooth, in a constant environment
//    reflect its radiance within 3% (multiple scattering kept, Fdez-Aguera 2019);
//  - the environment's pieces: the split-sum table against its integral, a constant map's
//    irradiance and prefiltered levels; KHR_lights_punctual's spot and range windows;
//  - with environment none there is no ambient term: an unlit-by-lights pbr scene is black.
#include "renderers/pbr.h"
#include "render_support.h"
#include "renderers/environment.h"
#include "renderers/renderer.h"
#include "renderers/shading.h"
#include "scenegraph/transforms.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

namespace {

using namespace test_scenes;
using sg::vec3;
namespace fs = std::filesystem;

constexpr float kPi = 3.14159265358979f;
constexpr int W = 32, H = 32;

// glTF 2.0 Appendix B with KHR_materials_specular's F0/F90 (ior 1.5, factors 1: F0 = 0.04, F90 = 1).
vec3 appendixB(const vec3& baseColor, float metallic, float roughness, const vec3& n, const vec3& v, const vec3& l, const vec3& lux, float ior = 1.5f,
               float specular = 1.0f, const vec3& specularColor = vec3(1.0f)) {
    const float r0 = (ior - 1.0f) / (ior + 1.0f);
    const vec3 dielectricF0 = glm::min(vec3(r0 * r0) * specularColor, vec3(1.0f)) * specular;
    const vec3 f0 = dielectricF0 * (1.0f - metallic) + baseColor * metallic;
    const float f90 = specular * (1.0f - metallic) + metallic;
    const vec3 cdiff = baseColor * (1.0f - metallic);
    const float a = roughness * roughness, a2 = a * a;
    const vec3 h = glm::normalize(l + v);
    const float nl = glm::dot(n, l), nv = glm::dot(n, v), nh = glm::dot(n, h), vh = glm::dot(v, h);
    const vec3 F = f0 + (vec3(f90) - f0) * std::pow(1.0f - vh, 5.0f);
    const float q = nh * nh * (a2 - 1.0f) + 1.0f;
    const float D = a2 / (kPi * q * q);
    const float V = 0.5f / (nl * std::sqrt(nv * nv * (1.0f - a2) + a2) + nv * std::sqrt(nl * nl * (1.0f - a2) + a2));
    const vec3 f = (vec3(1.0f) - F) * cdiff / kPi + F * D * V;
    return f * lux * nl;
}

// Every render here also holds that no note says the environment was replaced.
rnd::Framebuffer render(const std::string& backend, const sg::FrameInput& f, const std::string& name) {
    rnd::RenderStats st;
    rnd::Framebuffer fb = testing_support::BackendImages{W, H, "conformance", "pbr"}(backend, f, {name, {}, &st});
    for (const std::string& n : st.config.notes) EXPECT_EQ(n.find("environment"), std::string::npos) << n;
    return fb;
}

::testing::AssertionResult pixelIs(const rnd::Framebuffer& fb, int x, int y, const vec3& linear, int tol) {
    const uint8_t* p = fb.pixel(x, y);
    const int want[3] = {rnd::toByteSRGB(linear.x), rnd::toByteSRGB(linear.y), rnd::toByteSRGB(linear.z)};
    for (int c = 0; c < 3; ++c)
        if (std::abs(int(p[c]) - want[c]) > tol)
            return ::testing::AssertionFailure() << "pixel " << x << "," << y << " is " << int(p[0]) << "," << int(p[1]) << "," << int(p[2])
                                                 << ", expected " << want[0] << "," << want[1] << "," << want[2];
    return ::testing::AssertionSuccess();
}

// A Radiance .hdr of constant radiance 1 (8 x 4, flat RGBE scanlines: 128 128 128 129 = 1.0),
// one file per test (CTest runs the backends' instances as parallel processes: a shared file
// would be rewritten under another's reader).
fs::path constantHdr() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "-" + info->name();
    for (char& c : name)
        if (c == '/') c = '-';
    const fs::path p = testing_support::outputDir("conformance") / (name + "-constant-1.hdr");
    std::ofstream o(p, std::ios::binary);
    o << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n";
    for (int i = 0; i < 32; ++i) o << char(128) << char(128) << char(128) << char(129);
    return p;
}

class Pbr : public ::testing::TestWithParam<std::string> {};

// A camera-facing quad (n = +z) seen in perspective, one directional light arriving from l:
// pixel (x, y) is the formula's value with v toward the eye from the quad's point there.
TEST_P(Pbr, CameraFacingQuadsAreAppendixB) {
    struct Case {
        vec3 base;
        float metallic, roughness, ior = 1.5f, specular = 1.0f;
        vec3 specularColor{1.0f};
    };
    const Case cases[] = {
        {vec3(0.9f, 0.6f, 0.2f), 1.0f, 0.3f},
        {vec3(0.9f, 0.6f, 0.2f), 0.0f, 0.3f},
        {vec3(0.5f), 0.5f, 0.6f},
        {vec3(0.2f, 0.5f, 0.8f), 0.0f, 1.0f},
        {vec3(0.95f, 0.9f, 0.85f), 1.0f, 1.0f},
        {vec3(0.7f, 0.3f, 0.3f), 0.25f, 0.1f},
        {vec3(0.3f, 0.6f, 0.3f), 0.0f, 0.45f, 1.8f, 0.5f, vec3(1.0f, 0.5f, 0.25f)},
    };
    const vec3 toLight = glm::normalize(vec3(0.35f, 0.25f, 1.0f));
    const vec3 lux(2.5f);
    for (sg::ShadingModel model : {sg::ShadingModel::Phong}) {   // per pixel (flat: FlatShadingGivesEachTriangleOneColour)
        int i = 0;
        for (const Case& c : cases) {
            sg::Projection p;
            p.type = sg::ProjectionType::Perspective;
            p.fovyDeg = 40.0f;
            const vec3 eye(0, 0, 3);
            sg::FrameInput f = makeFrame(W, H, p, eye, vec3(0.0f));
            f.settings.reflection = sg::ReflectionModel::Pbr;
            f.settings.environment = "none";
            f.settings.shading = model;
            f.settings.shadows = false;
            f.ambientLight = vec3(1.0f);   // not used by pbr
            f.lights.push_back(directional(-toLight, lux));
            sg::Material m;
            m.baseColor = c.base;
            m.metallic = c.metallic;
            m.roughness = c.roughness;
            m.ior = c.ior;
            m.specularFactor = c.specular;
            m.specularColorFactor = c.specularColor;
            addMesh(f, quad(2.0f), m);
            const std::string name = "quad-" + std::to_string(i++) + "-" + std::string(sg::nameOf(model));
            rnd::Framebuffer fb = render(GetParam(), f, name);
            const sg::mat4 inv = glm::inverse(f.camera.viewProj);
            for (int y : {H / 2 - 5, H / 2, H / 2 + 4})
                for (int x : {W / 2 - 5, W / 2, W / 2 + 4}) {
                    // The quad's point at the pixel centre (row 0 at the top).
                    const float nx = (float(x) + 0.5f) / W * 2.0f - 1.0f, ny = 1.0f - (float(y) + 0.5f) / H * 2.0f;
                    const sg::vec4 a = inv * sg::vec4(nx, ny, -1.0f, 1.0f), b = inv * sg::vec4(nx, ny, 1.0f, 1.0f);
                    const vec3 o = vec3(a) / a.w, d = vec3(b) / b.w - o;
                    const vec3 q = o - d * (o.z / d.z);
                    const vec3 want = appendixB(c.base, c.metallic, c.roughness, vec3(0, 0, 1), glm::normalize(eye - q), toLight, lux, c.ior,
                                                c.specular, c.specularColor);
                    EXPECT_TRUE(pixelIs(fb, x, y, want, 1)) << GetParam() << " " << name;
                }
        }
    }
}

// White spheres (metallic 0 and 1; roughness 0.1 to 1) in a constant environment of radiance
// 0.5 (a radiance-1 file at intensity 0.5, so the answer is not clamped): every pixel of the
// sphere's inner disc is 0.5 within 3%.
TEST_P(Pbr, WhiteFurnaceKeepsTheEnergyAtEveryRoughness) {
    const fs::path hdr = constantHdr();
    for (float metallic : {0.0f, 1.0f})
        for (float roughness : {0.1f, 0.5f, 0.8f, 1.0f}) {
            sg::Projection p;
            p.type = sg::ProjectionType::Orthographic;
            p.orthoHalfHeight = 1.1f;
            sg::FrameInput f = makeFrame(W, H, p, vec3(0, 0, 4), vec3(0.0f));
            f.settings.reflection = sg::ReflectionModel::Pbr;
            f.settings.environment = hdr.string();
            f.settings.environmentIntensity = 0.5f;
            f.settings.shadows = false;
            sg::Material m;
            m.baseColor = vec3(1.0f);
            m.metallic = metallic;
            m.roughness = roughness;
            addMesh(f, sg::primitives::uvSphere(1.0f, 96, 48), m);
            const std::string name = "furnace-m" + std::to_string(int(metallic)) + "-r" + std::to_string(int(roughness * 10));
            rnd::Framebuffer fb = render(GetParam(), f, name);
            float lo = 1.0f, hi = 0.0f;
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x) {
                    const float px = (float(x) + 0.5f) / W * 2.0f - 1.0f, py = (float(y) + 0.5f) / H * 2.0f - 1.0f;
                    if (px * px + py * py > 0.5f) continue;   // the inner disc: n.v >= 0.6 (the sphere's radius is 0.91 here)
                    const float v = rnd::decodeSRGB(float(fb.pixel(x, y)[1]) / 255.0f);
                    lo = std::min(lo, v);
                    hi = std::max(hi, v);
                }
            EXPECT_GE(lo, 0.5f * 0.97f) << GetParam() << " " << name;
            EXPECT_LE(hi, 0.5f * 1.03f) << GetParam() << " " << name;
        }
}

// pbr with environment none and no lights: no ambient term at all (emission still shows).
TEST_P(Pbr, EnvironmentNoneLeavesOnlyTheLightsAndEmission) {
    sg::Projection p;
    p.type = sg::ProjectionType::Orthographic;
    p.orthoHalfHeight = 1.5f;
    sg::FrameInput f = makeFrame(W, H, p, vec3(0, 0, 3), vec3(0.0f));
    f.settings.reflection = sg::ReflectionModel::Pbr;
    f.settings.environment = "none";
    f.settings.background = vec3(0.2f);
    f.ambientLight = vec3(1.0f);
    sg::Material m;
    m.baseColor = vec3(0.8f);
    m.ka = 1.0f;
    addMesh(f, quad(1.0f), m);
    rnd::Framebuffer fb = render(GetParam(), f, "no-ambient");
    EXPECT_TRUE(pixelIs(fb, W / 2, H / 2, vec3(0.0f), 0)) << GetParam();
    f.meshes.back().material.emissive = vec3(0.25f, 0.5f, 0.0f);
    fb = render(GetParam(), f, "emission-only");
    EXPECT_TRUE(pixelIs(fb, W / 2, H / 2, vec3(0.25f, 0.5f, 0.0f), 1)) << GetParam();
}

// The default environment lights a pbr scene (a glTF never opens in the dark) and, asked for,
// is drawn as the background.
TEST_P(Pbr, DefaultEnvironmentLightsAndCanBeTheBackground) {
    sg::Projection p;
    p.type = sg::ProjectionType::Perspective;
    sg::FrameInput f = makeFrame(W, H, p, vec3(0, 0, 4), vec3(0.0f));
    f.settings.reflection = sg::ReflectionModel::Pbr;
    f.settings.environment = "default";
    f.settings.background = vec3(0.0f);
    sg::Material m;
    m.baseColor = vec3(0.8f);
    m.roughness = 0.5f;
    addMesh(f, sg::primitives::uvSphere(1.0f, 48, 24), m);
    rnd::Framebuffer fb = render(GetParam(), f, "default-env");
    EXPECT_GT(fb.pixel(W / 2, H / 2)[1], 60) << GetParam() << ": the sphere is lit by the environment";
    EXPECT_EQ(fb.pixel(1, 1)[1], 0) << GetParam() << ": the background colour";
    f.settings.environmentBackground = true;
    fb = render(GetParam(), f, "default-env-background");
    EXPECT_GT(fb.pixel(1, 1)[1], 20) << GetParam() << ": the environment behind the sphere";
    // With a tone mapper the backends draw into a linear frame first: the background still shows.
    f.settings.toneMapping = sg::ToneMapping::KhrNeutral;
    fb = render(GetParam(), f, "default-env-background-neutral");
    EXPECT_GT(fb.pixel(1, 1)[1], 20) << GetParam() << ": the environment behind the sphere, tone mapped";
    EXPECT_GT(fb.pixel(W / 2, H / 2)[1], 60) << GetParam();
}

// Flat shading as the seeds define it: the model evaluated once per triangle (at its first
// vertex, with the face normal), so every pixel of a triangle has one colour even where a
// highlight falls on it; Phong and pbr, a shiny sphere under a point light.
TEST_P(Pbr, FlatShadingGivesEachTriangleOneColour) {
    for (sg::ReflectionModel reflection : {sg::ReflectionModel::Phong, sg::ReflectionModel::Pbr}) {
        sg::Projection p;
        sg::FrameInput f = makeFrame(64, 64, p, vec3(0, 0, 3.2f), vec3(0.0f));
        f.settings.reflection = reflection;
        f.settings.shading = sg::ShadingModel::Flat;
        f.settings.environment = "default";
        f.ambientLight = vec3(0.1f);
        f.lights.push_back(point(vec3(1.5f, 1.5f, 3.0f), vec3(1.0f), false));
        sg::Material m;
        m.baseColor = vec3(0.7f, 0.4f, 0.2f);
        m.ks = 0.8f;
        m.shininess = 40.0f;
        m.roughness = 0.3f;
        m.metallic = 0.5f;
        addMesh(f, sg::primitives::uvSphere(1.0f, 12, 6), m);
        rnd::Framebuffer fb;
        ASSERT_TRUE(testing_support::renderBackend(GetParam(), f, 64, 64, fb, {"flat", {.aovs = {rnd::Aov::Visibility}}}));
        testing_support::writeImage(fb, "conformance", "flat-" + GetParam() + "-" + std::string(sg::nameOf(reflection)));
        std::map<uint32_t, std::pair<std::array<int, 3>, std::array<int, 3>>> range;   // primitive -> min, max per channel
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const size_t i = size_t(y) * 64 + size_t(x);
                if (fb.drawable[i] == 0) continue;
                auto it = range.try_emplace(fb.primitive[i], std::array<int, 3>{255, 255, 255}, std::array<int, 3>{0, 0, 0}).first;
                for (int c = 0; c < 3; ++c) {
                    it->second.first[size_t(c)] = std::min(it->second.first[size_t(c)], int(fb.pixel(x, y)[c]));
                    it->second.second[size_t(c)] = std::max(it->second.second[size_t(c)], int(fb.pixel(x, y)[c]));
                }
            }
        EXPECT_GT(range.size(), 20u);
        for (const auto& [prim, mm] : range)
            for (int c = 0; c < 3; ++c)
                EXPECT_LE(mm.second[size_t(c)] - mm.first[size_t(c)], 1) << GetParam() << " " << sg::nameOf(reflection) << " triangle " << prim;
    }
}

INSTANTIATE_TEST_SUITE_P(EveryBackend, Pbr, ::testing::ValuesIn(rnd::rendererNames()), [](const auto& info) { return info.param; });

// The ray caster with reflections on traces real reflections for smooth pbr surfaces (instead
// of the environment's prefiltered one): a mirror-smooth metal sphere shows the red panel
// beside it; with reflections off, or rough, it does not.
TEST(PbrRaycast, SmoothSurfacesReflectTheScene) {
    auto render = [](bool reflections, float roughness) {
        sg::Projection p;
        sg::FrameInput f = makeFrame(64, 64, p, vec3(0, 0, 4), vec3(0.0f));
        f.settings.reflection = sg::ReflectionModel::Pbr;
        f.settings.environment = "default";
        f.settings.reflections = reflections;
        sg::Material metal;
        metal.baseColor = vec3(0.95f);
        metal.metallic = 1.0f;
        metal.roughness = roughness;
        addMesh(f, sg::primitives::uvSphere(1.0f, 64, 32), metal);
        // A red panel to the right, facing the sphere (seen in it, off screen itself).
        addMesh(f, quad(3.0f), unlit(vec3(1.0f, 0.0f, 0.0f)),
                glm::translate(sg::mat4(1.0f), vec3(3.0f, 0, 0)) * glm::rotate(sg::mat4(1.0f), -1.5707963f, vec3(0, 1, 0)));
        rnd::Framebuffer fb;
        EXPECT_TRUE(testing_support::renderBackend("raycast", f, 64, 64, fb, {"reflections"}));
        testing_support::writeImage(fb, "conformance",
                                    std::string("pbr-reflect-") + (reflections ? "on" : "off") + "-r" + std::to_string(int(roughness * 10)));
        // The sphere's right rim: its mirror direction points at the panel.
        const uint8_t* px = fb.pixel(32 + 13, 32);
        return int(px[0]) - int(px[1]);
    };
    EXPECT_GT(render(true, 0.0f), 80) << "the panel, red, in the mirror";
    EXPECT_LT(render(false, 0.0f), 30) << "no reflections: the environment";
    EXPECT_LT(render(true, 0.6f), 30) << "rough: the prefiltered environment";
}

TEST(PbrEnvironment, SplitSumTableHoldsItsIntegral) {
    for (float nv : {0.05f, 0.3f, 0.7f, 1.0f})
        for (float r : {0.05f, 0.25f, 0.5f, 0.9f}) {
            const sg::vec2 exact = rnd::splitSumIntegral(nv, r, 4096), table = rnd::splitSum(nv, r);
            EXPECT_NEAR(table.x, exact.x, 0.02f) << nv << " " << r;
            EXPECT_NEAR(table.y, exact.y, 0.02f) << nv << " " << r;
            EXPECT_LE(exact.x + exact.y, 1.0001f);
        }
    // A mirror reflects everything: A + B -> 1; a rough surface loses energy to single scattering.
    const sg::vec2 smooth = rnd::splitSumIntegral(0.8f, 0.02f, 4096), rough = rnd::splitSumIntegral(0.8f, 1.0f, 4096);
    EXPECT_NEAR(smooth.x + smooth.y, 1.0f, 0.01f);
    EXPECT_LT(rough.x + rough.y, 0.8f);
}

TEST(PbrEnvironment, ConstantMapHasConstantIrradianceAndLevels) {
    std::vector<float> img(64 * 32 * 3, 0.75f);
    rnd::EnvironmentMap map("constant", 64, 32, img.data());
    for (const vec3& n : {vec3(0, 1, 0), vec3(0, -1, 0), glm::normalize(vec3(1, 2, -3)), vec3(0, 0, 1)}) {
        EXPECT_NEAR(map.diffuse(n).x, 0.75f, 0.0075f);
        for (float r : {0.0f, 0.3f, 0.7f, 1.0f}) EXPECT_NEAR(map.specular(n, r).y, 0.75f, 0.0075f) << r;
    }
    // The equirectangular convention: -z is the image centre, +y the top row.
    EXPECT_NEAR(rnd::equirectUv(vec3(0, 0, -1)).x, 0.5f, 1e-6f);
    EXPECT_NEAR(rnd::equirectUv(vec3(0, 1, 0)).y, 0.0f, 1e-6f);
    EXPECT_NEAR(rnd::equirectUv(vec3(1, 0, 0)).x, 0.75f, 1e-6f);
    // Its fast atan2/acos hold the exact formula within 1e-5 rad everywhere.
    for (int i = 0; i < 2000; ++i) {
        const float a = float(i) * 0.731f, b = float(i) * 0.193f;
        const vec3 d = glm::normalize(vec3(std::cos(a) * std::sin(b * 3.1f), std::cos(b * 3.1f), std::sin(a) * std::sin(b * 3.1f)));
        const sg::vec2 uv = rnd::equirectUv(d);
        EXPECT_NEAR(uv.y, std::acos(d.y) / kPi, 1e-5f / kPi + 1e-6f) << d.y;
        if (std::abs(d.x) + std::abs(d.z) < 1e-4f) continue;   // a pole: any u
        float u = 0.5f + std::atan2(d.x, -d.z) / (2.0f * kPi);
        if (std::abs(uv.x - u) > 0.5f) u += uv.x > u ? 1.0f : -1.0f;   // the seam
        EXPECT_NEAR(uv.x, u, 1e-5f / (2.0f * kPi) + 1e-6f) << d.x << " " << d.y << " " << d.z;
    }
}

TEST(PbrEnvironment, BadFilesAreRefusedWithTheReason) {
    const fs::path dir = testing_support::outputDir("conformance");
    const fs::path junk = dir / "junk.hdr";
    std::ofstream(junk) << "not an image";
    int w = 0, h = 0;
    std::vector<float> rgb;
    std::string e = rnd::loadRadianceHdr(junk.string(), w, h, rgb);
    EXPECT_NE(e.find("junk.hdr: "), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos);
    e = rnd::loadRadianceHdr((dir / "missing.hdr").string(), w, h, rgb);
    EXPECT_NE(e.find("missing.hdr: no such file"), std::string::npos) << e;
    const fs::path huge = dir / "huge.hdr";
    std::ofstream(huge, std::ios::binary) << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n";
    e = rnd::loadRadianceHdr(huge.string(), w, h, rgb);
    EXPECT_NE(e.find("huge.hdr: "), std::string::npos) << e;
    // The renderers light without it and say why.
    sg::RenderSettings s;
    s.reflection = sg::ReflectionModel::Pbr;
    s.environment = junk.string();
    std::string why;
    EXPECT_FALSE(rnd::environmentFor(s, &why).map);
    EXPECT_NE(why.find("junk.hdr"), std::string::npos);
}

TEST(PbrLights, PunctualWindowsAsKhrLightsPunctual) {
    sg::DrawLight spot;
    spot.type = sg::LightType::Spot;
    spot.position = vec3(0, 0, 2);
    spot.direction = vec3(0, 0, -1);
    spot.radiance = vec3(8.0f);
    spot.inverseSquare = true;
    spot.cosInner = std::cos(0.2f);
    spot.cosOuter = std::cos(0.4f);
    // On the axis: candela / d^2.
    EXPECT_NEAR(rnd::samplePunctualLight(spot, vec3(0)).radiance.x, 2.0f, 1e-5f);
    // Between the cones: ((cos - cos_outer) / (cos_inner - cos_outer))^2.
    const float angle = 0.3f;
    const vec3 p = vec3(2.0f * std::tan(angle), 0, 0);
    const float d2 = glm::dot(p - spot.position, p - spot.position);
    const float t = (std::cos(angle) - spot.cosOuter) / (spot.cosInner - spot.cosOuter);
    EXPECT_NEAR(rnd::samplePunctualLight(spot, p).radiance.x, 8.0f / d2 * t * t, 1e-4f);
    // Range: (clamp(1 - (d/range)^4, 0, 1))^2 / d^2, zero at and past the range.
    sg::DrawLight point;
    point.position = vec3(0, 0, 2);
    point.radiance = vec3(4.0f);
    point.inverseSquare = true;
    point.range = 4.0f;
    const float q = 4.0f / 16.0f, w = 1.0f - q * q;
    EXPECT_NEAR(rnd::samplePunctualLight(point, vec3(0)).radiance.x, 4.0f / 4.0f * w * w, 1e-5f);
    EXPECT_EQ(rnd::samplePunctualLight(point, vec3(0, 0, -2.5f)).radiance.x, 0.0f);
}

}   // namespace
