// gl_variants_test.cpp - the GL backend's shader switches (mesh.frag's list: base colour
// texture, each material map, specular-glossiness, vertex colours, unlit, alpha mode; fog mode,
// shading and reflection model; the visibility, wireframe and overdraw passes) compile in every
// combination that can differ, and draw what the CPU rasterizer draws. A frame holds a grid of
// quads, one per combination of the material switches, so each draw takes its own program.
//
// Which combinations: every one of the material switches under Phong shading (mesh.frag's
// switches nest only inside UNLIT and the shading branches: Phong's holds the normal map), the
// switches Gouraud and flat shading branch on (occlusion and emissive maps, unlit) with and
// without the others, and each fog mode and reflection model (code of their own, which reads no
// material switch) under each shading model. About 400 programs: ~1 minute on llvmpipe when
// Mesa's shader disk cache does not hold them yet (the first run after a shader edit), ~2 s
// when it does.
#include "gl/gl_renderer.h"
#include "renderers/renderer.h"
#include "scenegraph/setting_names.h"
#include "test_scenes.h"
#include "test_support.h"

#include <array>
#include <string>

using namespace sg;
using namespace test_scenes;

namespace {

constexpr int kCell = 8;   // pixels per grid cell; the quad covers the middle 80%

// A 2x2 texture of one colour, nearest and clamped (every sample exact in every backend).
TexturePtr solid(std::array<uint8_t, 4> rgba, bool srgb) {
    auto t = std::make_shared<Texture>();
    t->width = t->height = 2;
    t->rgba.resize(16);
    for (size_t i = 0; i < t->rgba.size(); ++i) t->rgba[i] = rgba[i % 4];
    t->filter = FilterMode::Nearest;
    t->wrapS = t->wrapT = WrapMode::ClampToEdge;
    t->srgb = srgb;
    return t;
}

struct Combination {
    bool texture, emissive, occlusion, normal, colors, unlit;
    int metalRough;   // 0 none, 1 metallic-roughness, 2 specular-glossiness
    AlphaMode alpha;
    std::string name() const {
        return std::string(texture ? "T" : "-") + (emissive ? "E" : "-") + (occlusion ? "O" : "-") + "-MS"[metalRough] + (normal ? "N" : "-") +
               (colors ? "C" : "-") + (unlit ? "U" : "-") + std::string(nameOf(alpha));
    }
};

// Every combination of the material switches: 2^6 x 3 x 3 = 576.
std::vector<Combination> allCombinations() {
    std::vector<Combination> out;
    for (int bits = 0; bits < 64; ++bits)
        for (int mr = 0; mr < 3; ++mr)
            for (AlphaMode a : {AlphaMode::Opaque, AlphaMode::Mask, AlphaMode::Blend})
                out.push_back({bool(bits & 1), bool(bits & 2), bool(bits & 4), bool(bits & 8), bool(bits & 16), bool(bits & 32), mr, a});
    return out;
}

// The switches the shading branches read (occlusion, emissive and normal maps, unlit), each
// combination with the other switches off and then on (texture, metallic-roughness, vertex
// colours, mask): 32.
std::vector<Combination> shadingCombinations() {
    std::vector<Combination> out;
    for (int bits = 0; bits < 32; ++bits) {
        const bool rest = bits & 16;
        out.push_back(
            {rest, bool(bits & 1), bool(bits & 2), bool(bits & 4), rest, bool(bits & 8), rest ? 1 : 0, rest ? AlphaMode::Mask : AlphaMode::Opaque});
    }
    return out;
}

// The grid of quads (columns x rows cells of one world unit, orthographic, head-on), lit by a
// directional light from the upper left and ambient light.
FrameInput variantsFrame(const std::vector<Combination>& combos, int cols, int rows) {
    Projection p;
    p.type = ProjectionType::Orthographic;
    p.orthoHalfHeight = 0.5f * float(rows);
    FrameInput f = makeFrame(cols * kCell, rows * kCell, p, vec3(0, 0, 5), vec3(0.0f));
    f.settings.shadows = false;
    f.settings.fogStart = 2.0f;
    f.settings.fogEnd = 12.0f;
    f.settings.fogDensity = 0.08f;
    f.settings.fogColor = vec3(0.2f, 0.3f, 0.4f);
    f.ambientLight = vec3(0.3f);
    f.lights.push_back(directional(vec3(0.4f, -0.3f, -1.0f), vec3(0.9f)));

    Mesh plain = quad(0.4f), coloured = quad(0.4f);   // two meshes (a copy would share the cache key, Mesh::id)
    plain.tangents.assign(4, vec4(1, 0, 0, 1));
    coloured.tangents = plain.tangents;
    coloured.colors.assign(4, vec4(0.9f, 0.8f, 0.7f, 0.9f));
    auto plainMesh = std::make_shared<const Mesh>(plain), colouredMesh = std::make_shared<const Mesh>(coloured);
    const TexturePtr base = solid({200, 180, 160, 230}, true), emissive = solid({255, 128, 64, 255}, true);
    const TexturePtr occlusion = solid({128, 128, 128, 255}, false), metalRough = solid({90, 160, 200, 200}, false);
    const TexturePtr normal = solid({160, 140, 230, 255}, false);
    for (size_t i = 0; i < combos.size(); ++i) {
        const Combination& c = combos[i];
        Material m;
        m.baseColor = vec3(0.7f, 0.5f, 0.3f);
        m.ks = 0.4f;
        m.shininess = 16.0f;
        m.emissive = vec3(0.1f, 0.05f, 0.0f);
        m.metallic = 0.6f;
        m.roughness = 0.5f;
        m.specularGlossiness = c.metalRough == 2;
        m.glossiness = 0.7f;
        m.alpha = 0.8f;   // kept by the mask's cutoff 0.5; blended over the background
        m.alphaMode = c.alpha;
        m.unlit = c.unlit;
        const float x = float(int(i) % cols) - 0.5f * float(cols - 1), y = 0.5f * float(rows - 1) - float(int(i) / cols);
        addMesh(f, c.colors ? colouredMesh : plainMesh, m, glm::translate(mat4(1.0f), vec3(x, y, 0.0f)), c.texture ? base : nullptr);
        MaterialMaps& maps = f.meshes.back().maps;
        if (c.emissive) maps.emissive = emissive;
        if (c.occlusion) maps.occlusion = occlusion;
        if (c.metalRough) maps.metallicRoughness = metalRough;
        if (c.normal) maps.normal = normal;
    }
    return f;
}

rnd::Framebuffer render(rnd::Renderer& r, const FrameInput& f, int cols, int rows, const rnd::RenderRequest& request = {}) {
    rnd::Framebuffer fb;
    const rnd::RenderStats st = r.render(f, cols * kCell, rows * kCell, fb, nullptr, request);
    EXPECT_TRUE(st.ok) << r.name() << ": " << st.error;
    return fb;
}

// The GL image of `combos` under setup (shading, reflection, fog) against the rasterizer's at every
// cell's centre (within 3/255, and not the background).
void expectMatchesRasterizer(const std::vector<Combination>& combos, ShadingModel shading, ReflectionModel reflection, FogMode fog) {
    const int cols = 24, rows = int(combos.size() + cols - 1) / cols;
    FrameInput f = variantsFrame(combos, cols, rows);
    f.settings.shading = shading;
    f.settings.reflection = reflection;
    f.settings.fog = fog;
    const std::string setup = std::string(nameOf(shading)) + "/" + std::string(nameOf(reflection)) + "/fog " + std::string(nameOf(fog));
    std::string err;
    auto gl = rnd::makeGlRenderer();
    auto raster = rnd::makeRenderer("raster", &err);
    ASSERT_TRUE(raster) << err;
    const rnd::Framebuffer a = render(*gl, f, cols, rows), b = render(*raster, f, cols, rows);
    ASSERT_EQ(a.color.size(), b.color.size()) << setup;
    int failed = 0;
    for (size_t i = 0; i < combos.size(); ++i) {
        const int x = int(i) % cols * kCell + kCell / 2, y = int(i) / cols * kCell + kCell / 2;
        const uint8_t *p = a.pixel(x, y), *q = b.pixel(x, y);
        const bool close = std::abs(p[0] - q[0]) <= 3 && std::abs(p[1] - q[1]) <= 3 && std::abs(p[2] - q[2]) <= 3;
        const bool drawn = p[0] || p[1] || p[2];
        EXPECT_TRUE(close && drawn) << setup << " " << combos[i].name() << ": gl " << int(p[0]) << "," << int(p[1]) << "," << int(p[2]) << " raster "
                                    << int(q[0]) << "," << int(q[1]) << "," << int(q[2]);
        failed += !(close && drawn);
    }
    if (failed) {
        testing_support::writeImage(a, "gl-variants", "variants-gl");
        testing_support::writeImage(b, "gl-variants", "variants-raster");
    }
}

}   // namespace

TEST(GlShaderVariantsGLTest, EveryMaterialCombinationUnderPhongMatchesTheRasterizer) {
    expectMatchesRasterizer(allCombinations(), ShadingModel::Phong, ReflectionModel::Phong, FogMode::Linear);
}

TEST(GlShaderVariantsGLTest, ShadingBranchesFogModesAndReflectionModelsMatchTheRasterizer) {
    for (ShadingModel shading : {ShadingModel::Flat, ShadingModel::Gouraud, ShadingModel::Phong}) {
        expectMatchesRasterizer(shadingCombinations(), shading, ReflectionModel::BlinnPhong, FogMode::Exp);
        const std::vector<Combination> ends = {shadingCombinations().front(), shadingCombinations().back()};
        for (ReflectionModel reflection : {ReflectionModel::Phong, ReflectionModel::BlinnPhong})
            for (FogMode fog : {FogMode::Off, FogMode::Linear, FogMode::Exp, FogMode::Exp2}) expectMatchesRasterizer(ends, shading, reflection, fog);
    }
}

// The passes' own switches: the visibility output (every cell shows its draw, blended ones
// excepted: they write neither depth nor visibility), the wireframe overlay and the overdraw
// view (at least one fragment per covered pixel).
TEST(GlShaderVariantsGLTest, VisibilityWireframeAndOverdrawPasses) {
    std::vector<Combination> combos = shadingCombinations();
    for (AlphaMode a : {AlphaMode::Opaque, AlphaMode::Blend}) combos.push_back({true, true, true, true, true, false, 2, a});
    const int cols = 24, rows = int(combos.size() + cols - 1) / cols;
    FrameInput f = variantsFrame(combos, cols, rows);
    f.settings.wireframe = true;
    auto gl = rnd::makeGlRenderer();
    rnd::RenderRequest request;
    request.aovs.add(rnd::Aov::Visibility);
    request.aovs.add(rnd::Aov::Overdraw);
    const rnd::Framebuffer fb = render(*gl, f, cols, rows, request);
    ASSERT_TRUE(fb.has(rnd::Aov::Visibility));
    ASSERT_TRUE(fb.has(rnd::Aov::Overdraw));
    for (size_t i = 0; i < combos.size(); ++i) {
        const int x = int(i) % cols * kCell + kCell / 2, y = int(i) / cols * kCell + kCell / 2;
        const size_t at = size_t(y) * fb.width + x;
        EXPECT_EQ(fb.drawable[at], combos[i].alpha == AlphaMode::Blend ? 0u : uint32_t(i + 1)) << combos[i].name();
        EXPECT_GE(fb.overdraw[at], 1u) << combos[i].name();
    }
}
