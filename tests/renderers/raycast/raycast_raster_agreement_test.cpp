// raycast_raster_agreement_test.cpp - RaycastRasterAgreementTest: the ray caster and the CPU
// rasterizer render the same triangle scenes (shadows and reflections off, no AA) and must
// agree on >= 99% of pixels within 4/255 per channel (silhouette edges may differ by a pixel).
// Covers the three shading models, the three projections, fog, vertex colours, a mirrored
// instance, back faces (two-sided lighting), a magnified bilinear texture and a minified
// mip-mapped one. Also here (it needs the same scene helpers): RaycastTest.
// ReflectedTextureMatchesMirroredCamera, the ray caster against itself through a mirror.
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

using namespace sg;
using namespace rnd;

namespace {

constexpr int kW = 320, kH = 240;

FrameInput baseScene(const Projection& proj) { return test_scenes::triangleAgreementFrame(proj, kW, kH); }

void expectAgree(const FrameInput& f, const std::string& name) {
    auto ray = makeRenderer("raycast");
    auto ras = makeRenderer("raster");
    ASSERT_TRUE(ray && ras);
    Framebuffer a, b;
    RenderStats sa = ray->render(f, kW, kH, a);
    RenderStats sb = ras->render(f, kW, kH, b);
    ASSERT_TRUE(sa.ok) << sa.error;
    ASSERT_TRUE(sb.ok) << sb.error;
    testing_support::ImageTolerance tol = testing_support::agreementTolerance(testing_support::Agreement::AcrossMethods);
    tol.maxMeanAbs = 2.0;   // these scenes: also the mean
    EXPECT_TRUE(testing_support::imagesClose(a, b, tol, "raycast_raster", name)) << name;
    testing_support::writeImage(a, "raycast_raster", name + "-raycast");
}

std::shared_ptr<Texture> checkerTexture() { return test_scenes::minificationChecker(); }

Projection perspective() { return Projection{}; }
Projection ortho() {
    Projection p;
    p.type = ProjectionType::Orthographic;
    p.orthoHalfHeight = 3.0f;
    return p;
}

}   // namespace

TEST(RaycastRasterAgreementTest, PhongPerspective) { expectAgree(baseScene(perspective()), "phong-perspective"); }

TEST(RaycastRasterAgreementTest, FlatPerspective) {
    FrameInput f = baseScene(perspective());
    f.settings.shading = ShadingModel::Flat;
    expectAgree(f, "flat-perspective");
}

TEST(RaycastRasterAgreementTest, GouraudPerspective) {
    FrameInput f = baseScene(perspective());
    f.settings.shading = ShadingModel::Gouraud;
    expectAgree(f, "gouraud-perspective");
}

TEST(RaycastRasterAgreementTest, BlinnPhongOrthographic) {
    FrameInput f = baseScene(ortho());
    f.settings.reflection = ReflectionModel::BlinnPhong;
    expectAgree(f, "blinn-orthographic");
}

TEST(RaycastRasterAgreementTest, PhongOblique) { expectAgree(baseScene(Projection::cabinet()), "phong-oblique"); }

TEST(RaycastRasterAgreementTest, FogAndAttenuation) {
    FrameInput f = baseScene(perspective());
    f.settings.fog = FogMode::Linear;
    f.settings.fogStart = 3.0f;
    f.settings.fogEnd = 12.0f;
    f.lights[0].inverseSquare = true;
    f.lights[0].radiance = vec3(20.0f);
    expectAgree(f, "fog-attenuation");
}

TEST(RaycastRasterAgreementTest, VertexColoursAndTexture) {
    FrameInput f = baseScene(perspective());
    // Vertex colours on the sphere.
    auto sphere = std::make_shared<Mesh>(primitives::uvSphere(0.8f, 48, 24));
    sphere->colors.resize(sphere->positions.size());
    for (size_t i = 0; i < sphere->positions.size(); ++i) sphere->colors[i] = vec4(0.5f + 0.5f * sphere->positions[i] / 0.8f, 1.0f);
    f.meshes[0].mesh = sphere;
    f.meshes[0].material.baseColor = vec3(1.0f);
    // A magnified 4x4 texture on the ground (bilinear, LOD 0 on both).
    auto tex = std::make_shared<Texture>();
    tex->width = tex->height = 4;
    tex->rgba.resize(4 * 4 * 4);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            uint8_t* p = &tex->rgba[size_t(y * 4 + x) * 4];
            p[0] = uint8_t(60 + 60 * x);
            p[1] = uint8_t(60 + 60 * y);
            p[2] = uint8_t((x + y) % 2 ? 220 : 40);
            p[3] = 255;
        }
    tex->filter = FilterMode::Bilinear;
    tex->wrapS = tex->wrapT = WrapMode::ClampToEdge;
    f.meshes[2].texture = tex;
    f.meshes[2].material.baseColor = vec3(1.0f);
    expectAgree(f, "vertex-colours-texture");
}

// A minified texture (a checker of 4-texel squares repeated 16 times over the receding ground:
// sharp in front, blending through the mip levels to grey at the back): the ray
// caster's mip level comes from ray differentials, the rasterizer's from analytic screen
// derivatives; both filter trilinearly through the same mip chain, so they agree. Without mip
// mapping the checker aliases into moire and the images differ (checked, so this test can fail).
TEST(RaycastRasterAgreementTest, MinifiedTextureUsesMipLevels) {
    FrameInput f = baseScene(perspective());
    auto ground = std::make_shared<Mesh>(*f.meshes[2].mesh);
    for (vec2& uv : ground->uv0) uv *= 16.0f;
    f.meshes[2].mesh = ground;
    auto tex = checkerTexture();
    f.meshes[2].texture = tex;
    f.meshes[2].material.baseColor = vec3(1.0f);
    expectAgree(f, "minified-texture");

    // Sensitivity: the ray caster at level 0 only (bilinear) against the mip-mapped raster image.
    auto ray = makeRenderer("raycast");
    auto ras = makeRenderer("raster");
    Framebuffer mipmapped, level0;
    ASSERT_TRUE(ras->render(f, kW, kH, mipmapped).ok);
    auto tex0 = std::make_shared<Texture>(*tex);
    tex0->filter = FilterMode::Bilinear;
    f.meshes[2].texture = tex0;
    ASSERT_TRUE(ray->render(f, kW, kH, level0).ok);
    ImageDiff d = compareImages(level0, mipmapped, 4);
    std::printf("[image] level 0 vs mip-mapped: mean %.3f/255, %.3f%% within 4/255\n", d.meanAbs, 100.0 * d.fractionWithin);
    EXPECT_LT(d.fractionWithin, 0.95) << "the scene does not exercise mip selection";
}

TEST(RaycastRasterAgreementTest, BackFaceCulling) {
    // Looking into the open cylinder: without culling its inside (back faces) shows; with
    // culling both backends show the floor through it. The mirrored sphere must not vanish.
    for (bool cull : {false, true}) {
        FrameInput f = baseScene(perspective());
        f.settings.culling = cull ? sg::CullMode::On : sg::CullMode::Off;
        f.camera = makeFrameCamera(glm::inverse(glm::lookAt(vec3(0.4f, 4.0f, 3.0f), vec3(0.2f, 0.3f, 1.2f), vec3(0, 1, 0))), perspective(),
                                   float(kW) / kH, 4.0f);
        expectAgree(f, cull ? "cull-on" : "cull-off");
    }
}

// Mirror-reflected rays choose their mip level from ray differentials too: the neighbouring
// pixels' rays are reflected at the same mirror. A flat mirror (reflectivity 1) at y = 0 under a
// camera looking down shows an unlit, minified checker ceiling; the image must equal the direct
// view of the ceiling from the camera mirrored in y = 0 (mirror removed), flipped left-right.
// Both sample the same mip chain at (nearly) the same levels; at level 0 the reflection aliases
// into moire (checked: the ceiling is minified enough for that to show).
TEST(RaycastTest, ReflectedTextureMatchesMirroredCamera) {
    auto tex = checkerTexture();
    auto ceilingMesh = std::make_shared<Mesh>(primitives::plane(100.0f, 1));
    for (vec2& uv : ceilingMesh->uv0) uv *= 100.0f;   // 2 units per repeat, squares of 1/8
    // The ceiling at y = 2 facing down (rotated half a turn about x).
    DrawMesh ceiling =
        test_scenes::meshInstance(ceilingMesh, glm::rotate(glm::translate(mat4(1.0f), vec3(0, 2, 0)), glm::pi<float>(), vec3(1, 0, 0)), vec3(1.0f));
    ceiling.texture = tex;
    ceiling.material.unlit = true;
    DrawMesh mirror = test_scenes::meshInstance(std::make_shared<Mesh>(primitives::plane(100.0f, 1)), mat4(1.0f), vec3(0.2f));
    mirror.material.reflectivity = 1.0f;

    auto frame = [&](bool withMirror, const vec3& eye, const vec3& target, const vec3& up) {
        FrameInput f;
        f.settings.shadows = false;
        f.settings.reflections = true;
        f.settings.maxBounces = 1;
        f.settings.aa = AAMode::None;
        f.ambientLight = vec3(0.3f);
        f.meshes.push_back(ceiling);
        if (withMirror) f.meshes.push_back(mirror);
        f.camera = makeFrameCamera(glm::inverse(glm::lookAt(eye, target, up)), perspective(), float(kW) / kH, 3.0f);
        return f;
    };
    // Looking down at about 34 degrees: every camera ray meets the mirror.
    const vec3 eye(0.3f, 1.0f, 2.0f), target(0.0f, 0.0f, 0.5f), up(0, 1, 0);
    const vec3 m(1, -1, 1);   // mirroring in y = 0
    auto ray = makeRenderer("raycast");
    Framebuffer reflected, direct;
    ASSERT_TRUE(ray->render(frame(true, eye, target, up), kW, kH, reflected).ok);
    ASSERT_TRUE(ray->render(frame(false, eye * m, target * m, up * m), kW, kH, direct).ok);
    Framebuffer flipped = direct;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int c = 0; c < 4; ++c) flipped.pixel(x, y)[c] = direct.pixel(kW - 1 - x, y)[c];
    testing_support::ImageTolerance tol;
    tol.channelTolerance = 4;
    tol.minFractionWithin = 0.99;
    tol.maxMeanAbs = 1.0;
    EXPECT_TRUE(testing_support::imagesClose(reflected, flipped, tol, "raycast_reflection", "mirror-vs-direct"));

    // Sensitivity: at level 0 (bilinear only) the direct view differs from the mip-mapped one.
    auto tex0 = std::make_shared<Texture>(*tex);
    tex0->filter = FilterMode::Bilinear;
    ceiling.texture = tex0;
    Framebuffer level0;
    // The same renderer: its sampler cache must notice the filter change (the copy keeps the id).
    ASSERT_TRUE(ray->render(frame(false, eye * m, target * m, up * m), kW, kH, level0).ok);
    testing_support::writeImage(reflected, "raycast_reflection", "mirror");
    testing_support::writeImage(level0, "raycast_reflection", "direct-level0");
    ImageDiff d = compareImages(level0, direct, 4);
    std::printf("[image] ceiling at level 0 vs mip-mapped: %.3f%% within 4/255\n", 100.0 * d.fractionWithin);
    EXPECT_LT(d.fractionWithin, 0.9) << "the scene does not exercise mip selection";
}
