// renderer_contract_test.cpp - the renderer contract: resolveRenderConfig() rules (honoured
// settings, reported substitutions, features not drawn, sizes checked once), Renderer::render()
// checks that are the same for every backend, truthful stats, capabilities that do not change
// when a backend renders, the GLSL enum guard, and the shared shading terms.
#include "gl/gl_renderer.h"
#include "renderers/render_config.h"
#include "renderers/renderer.h"
#include "renderers/shading.h"
#include "scenegraph/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>

using namespace rnd;

namespace {

sg::FrameInput frameWith(const sg::RenderSettings& s) {
    sg::Scene scene;
    sg::ImplicitShape sphere;
    sphere.type = sg::ImplicitType::Sphere;
    scene.addNode("sphere", scene.root(), sg::ImplicitPayload{sphere, -1});
    scene.addDefaultCamera();
    scene.settings = s;
    return sg::flatten(scene, 1.0f, scene.activeCamera);
}

Capabilities rasterLike() {
    Capabilities c;
    c.msaaSamples = {4};
    c.ssaaFactors = {2, 3, 4};
    c.ssaaRendersLarger = true;
    c.maxImageSize = 1000;
    return c;
}

RenderConfig resolve(const sg::RenderSettings& s, const Capabilities& c, int w = 64, int h = 48, std::string* err = nullptr) {
    RenderConfig cfg;
    std::string e;
    bool ok = resolveRenderConfig(frameWith(s), c, w, h, cfg, &e);
    if (err)
        *err = e;
    else
        EXPECT_TRUE(ok) << e;
    return cfg;
}

}   // namespace

TEST(RenderConfigTest, HonouredSettingsHaveNoNotes) {
    sg::RenderSettings s;
    s.setAA("msaa4");
    s.shadows = false;
    RenderConfig c = resolve(s, rasterLike());
    EXPECT_EQ(c.aa, sg::AAMode::MSAA);
    EXPECT_EQ(c.msaaSamples, 4);
    EXPECT_EQ(c.samplesPerPixel, 4);
    EXPECT_EQ(c.aaAsked, "msaa4");
    EXPECT_EQ(c.aaUsed, "msaa4");
    EXPECT_TRUE(c.notes.empty());
    EXPECT_TRUE(c.unsupported.empty());
    EXPECT_EQ(c.tessellation, s.tessellation);
    EXPECT_EQ(c.width, 64);
    EXPECT_EQ(c.height, 48);
}

TEST(RenderConfigTest, SubstitutionsAreReportedNeverSilent) {
    sg::RenderSettings s;
    s.shadows = false;
    s.setAA("msaa8");   // raster-like: only 4 samples
    RenderConfig c = resolve(s, rasterLike());
    EXPECT_EQ(c.msaaSamples, 4);
    EXPECT_EQ(c.aaUsed, "msaa4");
    ASSERT_EQ(c.notes.size(), 1u);
    EXPECT_NE(c.notes[0].find("msaa8 -> msaa4"), std::string::npos) << c.notes[0];
    EXPECT_NE(c.describe().find("asked msaa8"), std::string::npos) << c.describe();

    s.setAA("msaa2");   // below the smallest supported count: the smallest one
    c = resolve(s, rasterLike());
    EXPECT_EQ(c.aaUsed, "msaa4");
    EXPECT_EQ(c.notes.size(), 1u);

    Capabilities none;   // no AA at all
    s.setAA("ssaa3");
    c = resolve(s, none);
    EXPECT_EQ(c.aa, sg::AAMode::None);
    EXPECT_EQ(c.samplesPerPixel, 1);
    ASSERT_EQ(c.notes.size(), 1u);
    EXPECT_NE(c.notes[0].find("ssaa3 -> none"), std::string::npos) << c.notes[0];

    s.setAA("ssaa3");
    c = resolve(s, rasterLike());
    EXPECT_EQ(c.ssaaFactor, 3);
    EXPECT_EQ(c.samplesPerPixel, 9);
    EXPECT_TRUE(c.notes.empty());
}

TEST(RenderConfigTest, FeaturesNotDrawnAreListed) {
    sg::RenderSettings s;
    s.shadows = true;
    s.reflections = true;
    s.wireframe = true;
    RenderConfig c = resolve(s, Capabilities{});
    EXPECT_EQ(c.unsupported, (std::vector<std::string>{"shadows", "reflections", "wireframe"}));
    Capabilities all;
    all.shadows = all.reflections = all.wireframe = true;
    EXPECT_TRUE(resolve(s, all).unsupported.empty());
}

TEST(RenderConfigTest, SizesAndSettingsAreCheckedOnce) {
    sg::RenderSettings s;
    std::string err;
    RenderConfig c = resolve(s, rasterLike(), 0, 10, &err);
    EXPECT_EQ(err, "image size 0x10 is out of range 1..1000");
    resolve(s, rasterLike(), 1001, 10, &err);
    EXPECT_EQ(err, "image size 1001x10 is out of range 1..1000");
    s.setAA("ssaa4");   // 300 x 4 = 1200 > 1000 where SSAA renders a larger image
    resolve(s, rasterLike(), 300, 10, &err);
    EXPECT_NE(err.find("1200x40"), std::string::npos) << err;
    Capabilities strata = rasterLike();
    strata.ssaaRendersLarger = false;   // the ray caster's SSAA is rays, not a larger image
    resolve(s, strata, 300, 10, &err);
    EXPECT_EQ(err, "");
    s = {};
    s.fog = sg::FogMode::Linear;
    s.fogStart = 10;
    s.fogEnd = 5;
    resolve(s, rasterLike(), 10, 10, &err);
    EXPECT_EQ(err, "linear fog needs end > start");
}

// Every backend through the one entry point: same checks, errors that name the backend, and
// capabilities that match what the stats say was used.
class BackendContractTest : public ::testing::TestWithParam<std::string> {};

TEST_P(BackendContractTest, RenderChecksSettingsAndSizeTheSameWay) {
    std::string err;
    std::unique_ptr<Renderer> r = makeRenderer(GetParam(), &err);
    ASSERT_TRUE(r) << err;
    const std::string name = GetParam();
    Framebuffer fb;
    sg::RenderSettings bad;
    bad.fog = sg::FogMode::Linear;
    bad.fogStart = 10;
    bad.fogEnd = 5;
    RenderStats s = r->render(frameWith(bad), 32, 32, fb);
    EXPECT_FALSE(s.ok);
    EXPECT_EQ(s.error, name + ": linear fog needs end > start");

    s = r->render(frameWith({}), 0, 10, fb);
    EXPECT_FALSE(s.ok);
    EXPECT_EQ(s.error, name + ": image size 0x10 is out of range 1.." + std::to_string(r->capabilities().maxImageSize));
    int huge = r->capabilities().maxImageSize + 1;
    s = r->render(frameWith({}), huge, 1, fb);
    EXPECT_FALSE(s.ok);
    EXPECT_EQ(s.error.rfind(name + ": image size ", 0), 0u) << s.error;

    RenderControl cancelled;
    cancelled.cancel = true;
    s = r->render(frameWith({}), 16, 16, fb, &cancelled);
    EXPECT_FALSE(s.ok);
    EXPECT_TRUE(s.cancelled);
    EXPECT_EQ(s.error, name + ": cancelled");
}

TEST_P(BackendContractTest, StatsSayWhatWasAskedAndUsed) {
    std::string err;
    std::unique_ptr<Renderer> r = makeRenderer(GetParam(), &err);
    ASSERT_TRUE(r) << err;
    for (const char* aa : {"none", "msaa2", "msaa4", "msaa8", "ssaa2", "ssaa3", "ssaa4"}) {
        sg::RenderSettings s;
        ASSERT_TRUE(s.setAA(aa));
        s.shadows = false;
        Framebuffer fb;
        RenderStats st = r->render(frameWith(s), 40, 30, fb);
        ASSERT_TRUE(st.ok) << aa << ": " << st.error;
        EXPECT_EQ(fb.width, 40);
        EXPECT_EQ(fb.height, 30);
        EXPECT_GT(st.milliseconds, 0.0);
        EXPECT_EQ(st.config.aaAsked, aa);
        // Capabilities (the same before and after a render) tell the truth: a
        // mode is taken as asked exactly when the backend lists it, else a note says why.
        Capabilities caps = r->capabilities();
        const std::vector<int>& list = s.aa == sg::AAMode::MSAA ? caps.msaaSamples : caps.ssaaFactors;
        bool listed = s.aa == sg::AAMode::None || std::find(list.begin(), list.end(), s.aaRate) != list.end();
        EXPECT_EQ(st.config.aaUsed == st.config.aaAsked, listed) << GetParam() << " " << aa << " used " << st.config.aaUsed;
        EXPECT_EQ(st.config.notes.empty(), listed) << GetParam() << " " << aa;
        if (!listed) { EXPECT_NE(st.config.notes[0].find(std::string(aa) + " -> "), std::string::npos) << st.config.notes[0]; }
    }
    // Shadows: asked by default; listed as not drawn exactly by the backends without them.
    Framebuffer fb;
    RenderStats st = r->render(frameWith({}), 16, 16, fb);
    ASSERT_TRUE(st.ok) << st.error;
    bool listed = std::find(st.config.unsupported.begin(), st.config.unsupported.end(), "shadows") != st.config.unsupported.end();
    EXPECT_EQ(listed, !r->capabilities().shadows);
}

// Capabilities are constant for the life of a backend (the UI caches them per backend): the
// same before its first render (GL: before it has a context) and after.
TEST_P(BackendContractTest, CapabilitiesDoNotChangeWhenItRenders) {
    std::string err;
    std::unique_ptr<Renderer> r = makeRenderer(GetParam(), &err);
    ASSERT_TRUE(r) << err;
    const Capabilities before = r->capabilities();
    Framebuffer fb;
    sg::RenderSettings msaa;
    msaa.aa = sg::AAMode::MSAA;
    msaa.aaRate = 4;
    (void)r->render(frameWith(msaa), 32, 32, fb);
    const Capabilities after = r->capabilities();
    EXPECT_EQ(before.affinity, after.affinity);
    EXPECT_EQ(before.msaaSamples, after.msaaSamples);
    EXPECT_EQ(before.ssaaFactors, after.ssaaFactors);
    EXPECT_EQ(before.maxImageSize, after.maxImageSize);
    EXPECT_EQ(before.aovs.names(), after.aovs.names());
    EXPECT_EQ(before.shadows, after.shadows);
    EXPECT_EQ(before.wireframe, after.wireframe);
}

INSTANTIATE_TEST_SUITE_P(EveryBackend, BackendContractTest, ::testing::ValuesIn(rendererNames()), [](const auto& info) { return info.param; });

// Every enum value handed to GLSL is a named constant with the C++ value, and the shaders
// handle every one of them by name (a new enum value without shader code fails here).
TEST(GlslEnumGuardTest, ShadersHandleEveryEnumValueByName) {
    std::string defines = glslEnumDefines();
    std::string src = glslSources();
    // Code only: drop // comments.
    std::string code;
    std::istringstream in(src);
    for (std::string line; std::getline(in, line);) code += line.substr(0, line.find("//")) + "\n";
    // A whole-word occurrence of `name` in the code (no std::regex: GCC 12 warns inside it
    // under -fsanitize=address).
    auto isWordChar = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
    auto hasWord = [&](const std::string& name) {
        for (size_t at = code.find(name); at != std::string::npos; at = code.find(name, at + 1))
            if ((at == 0 || !isWordChar(code[at - 1])) && (at + name.size() >= code.size() || !isWordChar(code[at + name.size()]))) return true;
        return false;
    };
    int count = 0;
    std::istringstream lines(defines);
    for (std::string line; std::getline(lines, line);) {
        std::istringstream words(line);
        std::string directive, name, value;
        if (!(words >> directive >> name >> value) || directive != "#define") continue;
        ++count;
        EXPECT_TRUE(hasWord(name)) << name << " is not handled by the shaders";
    }
    EXPECT_EQ(count, 3 + 3 + 4 + 3 + 3 + 3 + 4);   // shading, reflection, fog, light types, alpha modes, tone mapping, material map bits
    EXPECT_NE(defines.find("#define FOG_EXP2 " + std::to_string(int(sg::FogMode::Exp2))), std::string::npos) << defines;
    EXPECT_NE(defines.find("#define SHADING_GOURAUD " + std::to_string(int(sg::ShadingModel::Gouraud))), std::string::npos) << defines;
    EXPECT_NE(defines.find("#define LIGHT_SPOT " + std::to_string(int(sg::LightType::Spot))), std::string::npos) << defines;
    EXPECT_NE(defines.find("#define TONE_MAPPING_KHR_NEUTRAL " + std::to_string(int(sg::ToneMapping::KhrNeutral))), std::string::npos) << defines;
}

namespace {
// A point light (inverse square), a directional light and a spot, for the shading tests.
std::vector<sg::DrawLight> threeLights() {
    sg::DrawLight point, dir, spot;
    point.type = sg::LightType::Point;
    point.position = {2, 3, 4};
    point.radiance = {3, 2, 1};
    point.inverseSquare = true;
    dir.type = sg::LightType::Directional;
    dir.direction = glm::normalize(sg::vec3(-1, -2, -1));
    dir.radiance = {0.5f, 0.6f, 0.7f};
    spot.type = sg::LightType::Spot;
    spot.position = {0, 4, 1};
    spot.direction = glm::normalize(sg::vec3(0, -1, -0.2f));
    spot.cosInner = 0.95f;
    spot.cosOuter = 0.8f;
    spot.radiance = {2, 2, 2};
    return {point, dir, spot};
}
}   // namespace

// One shading source: shade() is shadeTerms() applied to the albedo, and the terms do not
// depend on the albedo (what lets Gouraud interpolate them and texture per pixel), for tinted
// and untinted specular, both reflection models, every light type, with and without shadows.
TEST(ShadeTermsTest, ShadeIsTheTermsAppliedToTheAlbedo) {
    sg::FrameInput f;
    f.ambientLight = sg::vec3(0.2f, 0.25f, 0.3f);
    f.lights = threeLights();
    const float visible[3] = {1.0f, 0.0f, 0.5f};
    for (bool tinted : {false, true})
        for (auto model : {sg::ReflectionModel::Phong, sg::ReflectionModel::BlinnPhong})
            for (const float* vis : {static_cast<const float*>(nullptr), visible}) {
                f.settings.reflection = model;
                sg::Material m;
                m.ka = 0.3f;
                m.kd = 0.6f;
                m.ks = 0.5f;
                m.shininess = 12;
                m.specularTinted = tinted;
                m.specularColor = {0.9f, 0.8f, 0.7f};
                m.emissive = {0.01f, 0.02f, 0.03f};
                const sg::vec3 p(0.1f, 0.2f, 0.3f), n = glm::normalize(sg::vec3(0.2f, 1, 0.3f)), eye(1, 2, 6);
                ShadeTerms t = shadeTerms(m, p, n, eye, f, vis);
                for (sg::vec3 albedo : {sg::vec3(0.0f), sg::vec3(1.0f), sg::vec3(0.8f, 0.3f, 0.1f)}) {
                    sg::vec3 c = shade(m, SurfacePoint{p, n, albedo}, eye, f, vis);
                    sg::vec3 want = t.mul * albedo + t.add;
                    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], want[k], 1e-6f) << "tinted " << tinted << " k " << k;
                }
                // The terms by hand for albedo 0 and 1 (untinted specular goes to add only).
                sg::vec3 zero = shade(m, SurfacePoint{p, n, sg::vec3(0.0f)}, eye, f, vis);
                for (int k = 0; k < 3; ++k) EXPECT_NEAR(zero[k], t.add[k], 1e-6f);
                if (tinted) { EXPECT_EQ(t.add, m.emissive); }
            }
}

// lightReaches() is what lets the ray caster skip a shadow ray: wherever it says no, the
// light's terms are exactly zero for every material and reflection model (so the visibility
// cannot matter), and it says yes on a fair share of random points, for every light type.
TEST(ShadeTermsTest, ALightThatDoesNotReachAddsExactlyNothing) {
    SurfaceCoefficients m;
    m.ka = 0.3f;
    m.kd = 0.6f;
    m.ks = 0.5f;
    m.shininess = 12;
    m.specularColor = {0.9f, 0.8f, 0.7f};
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-3.0f, 3.0f);
    for (const sg::DrawLight& light : threeLights()) {
        int reached = 0, notReached = 0;
        for (int i = 0; i < 4000; ++i) {
            const sg::vec3 p(u(rng), u(rng) * 0.3f, u(rng)), n = glm::normalize(sg::vec3(u(rng), u(rng), u(rng)));
            const sg::vec3 toEye = glm::normalize(sg::vec3(u(rng), u(rng), u(rng)));
            if (lightReaches(light, p, n)) {
                ++reached;
                continue;
            }
            ++notReached;
            for (bool tinted : {false, true})
                for (auto model : {sg::ReflectionModel::Phong, sg::ReflectionModel::BlinnPhong}) {
                    m.specularTinted = tinted;
                    const ShadeTerms t = lightTerms(m, n, toEye, sampleLight(light, p), model);
                    ASSERT_EQ(t.mul, sg::vec3(0.0f)) << "light type " << int(light.type) << " at " << i;
                    ASSERT_EQ(t.add, sg::vec3(0.0f)) << "light type " << int(light.type) << " at " << i;
                }
        }
        EXPECT_GT(reached, 200) << int(light.type);
        EXPECT_GT(notReached, 200) << int(light.type);
    }
}

// toByteSRGB's table gives the formula's byte round(255 encodeSRGB(x)) for every float in
// [0, 1] (all of them near the 255 byte thresholds, every 61st elsewhere), and clamps
// outside (negative, above 1, infinities, NaN to 0).
TEST(ShadeTermsTest, SrgbBytesFromTheTableAreTheFormulas) {
    auto formula = [](float x) { return int(uint8_t(encodeSRGB(x) * 255.0f + 0.5f)); };
    auto fromBits = [](uint32_t b) {
        float x;
        std::memcpy(&x, &b, 4);
        return x;
    };
    uint32_t one;
    const float oneF = 1.0f;
    std::memcpy(&one, &oneF, 4);
    size_t checked = 0;
    for (uint32_t b = 0; b <= one; b += 61) {
        const float x = fromBits(b);
        ASSERT_EQ(int(toByteSRGB(x)), formula(x)) << x;
        ++checked;
    }
    for (int byte = 1; byte < 256; ++byte) {   // each threshold: bisect, then every float around it
        uint32_t lo = 0, hi = one;
        while (hi - lo > 1) {
            const uint32_t mid = lo + (hi - lo) / 2;
            (formula(fromBits(mid)) >= byte ? hi : lo) = mid;
        }
        for (uint32_t b = hi - 2000; b <= hi + 2000 && b <= one; ++b) {
            ASSERT_EQ(int(toByteSRGB(fromBits(b))), formula(fromBits(b))) << fromBits(b);
            ++checked;
        }
    }
    EXPECT_GT(checked, size_t(16'000'000));
    EXPECT_EQ(toByteSRGB(-0.5f), 0);
    EXPECT_EQ(toByteSRGB(1.5f), 255);
    EXPECT_EQ(toByteSRGB(std::numeric_limits<float>::infinity()), 255);
    EXPECT_EQ(toByteSRGB(-std::numeric_limits<float>::infinity()), 0);
    EXPECT_EQ(toByteSRGB(std::numeric_limits<float>::quiet_NaN()), 0);
}
