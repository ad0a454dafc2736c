// visibility_test.cpp - the visibility every backend fills on request (Framebuffer::drawable /
// primitive, RenderRequest::aovs' Aov::Visibility) and what is reconstructed from it (renderers/inspect.h):
// known answers at pixels where hand-placed surfaces project, the three backends agreeing,
// anti-aliased images getting the one-sample visibility, blended layers never taking a pixel,
// and the inspector's terms adding up to the pixel's colour.
#include "assets/demo.h"
#include "render_support.h"
#include "renderers/diagnostic.h"
#include "renderers/inspect.h"
#include "renderers/renderer.h"
#include "renderers/shading.h"
#include "test_scenes.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

namespace {

using namespace test_scenes;
using sg::mat4;
using sg::vec3;
using sg::vec4;

constexpr int W = 160, H = 120;

sg::Material lit(const vec3& c) {
    sg::Material m;
    m.baseColor = c;
    m.ka = 0.2f;
    m.kd = 0.7f;
    m.ks = 0.4f;
    m.shininess = 16.0f;
    return m;
}

// Nodes: 1 floor (4 x 4 quad at z = 0), 2 card (two quads in front: drawables 2 and 3), 3 a
// blended veil over the floor's upper left, 4 an implicit sphere (drawable 5).
sg::FrameInput scene() {
    sg::Projection p;
    p.fovyDeg = 50.0f;
    p.zNear = 1.0f;
    p.zFar = 20.0f;
    sg::FrameInput f = makeFrame(W, H, p, vec3(0.0f, 0.0f, 6.0f), vec3(0.0f));
    f.settings.shadows = false;
    f.settings.shading = sg::ShadingModel::Phong;
    f.ambientLight = vec3(0.3f);
    f.lights.push_back(directional(vec3(-0.3f, -0.4f, -1.0f), vec3(0.9f)));
    addMesh(f, quad(2.0f), lit(vec3(0.6f, 0.5f, 0.4f)));
    f.meshes.back().node = 1;
    addMesh(f, quad(0.5f), lit(vec3(0.2f, 0.6f, 0.3f)), glm::translate(mat4(1.0f), vec3(0.8f, 0.3f, 1.0f)));
    f.meshes.back().node = 2;
    addMesh(f, quad(0.3f), lit(vec3(0.2f, 0.3f, 0.7f)), glm::translate(mat4(1.0f), vec3(0.8f, -0.9f, 1.0f)));
    f.meshes.back().node = 2;
    sg::Material veil = unlit(vec3(1.0f));
    veil.alphaMode = sg::AlphaMode::Blend;
    veil.alpha = 0.5f;
    addMesh(f, quad(0.4f), veil, glm::translate(mat4(1.0f), vec3(-1.2f, 1.0f, 2.0f)));
    f.meshes.back().node = 3;
    sg::DrawAnalytic a;
    a.kind = sg::DrawAnalytic::Kind::Implicit;
    a.node = 4;
    a.geometryKey = 4242;
    a.implicit.type = sg::ImplicitType::Sphere;
    a.implicit.radius = 0.6f;
    a.material = lit(vec3(0.8f, 0.2f, 0.2f));
    a.world = glm::translate(mat4(1.0f), vec3(-1.0f, -0.5f, 0.8f));
    a.invWorld = glm::inverse(a.world);
    a.normal = sg::normalMatrix(a.world);
    a.worldBounds = {vec3(-1.6f, -1.1f, 0.2f), vec3(-0.4f, 0.1f, 1.4f)};
    f.analytics.push_back(a);
    return f;
}

// The pixel (top-left origin) whose centre is nearest the projection of world point p.
std::pair<int, int> pixelOf(const sg::FrameInput& f, const vec3& p) {
    vec4 c = f.camera.proj * f.camera.view * vec4(p, 1.0f);
    c /= c.w;
    return {int((c.x * 0.5f + 0.5f) * W), int((0.5f - c.y * 0.5f) * H)};
}

// With the visibility (RenderRequest::aovs).
rnd::Framebuffer renderVisible(const std::string& backend, const sg::FrameInput& f) {
    return testing_support::BackendImages{W, H}(backend, f, {"visibility", {.aovs = {rnd::Aov::Visibility}}});
}

class Visibility : public ::testing::TestWithParam<std::string> {};

TEST_P(Visibility, KnownSurfacesAtKnownPixels) {
    const sg::FrameInput f = scene();
    const rnd::Framebuffer fb = renderVisible(GetParam(), f);
    ASSERT_TRUE(fb.has(rnd::Aov::Visibility));
    auto at = [&](const vec3& p) {
        auto [x, y] = pixelOf(f, p);
        const size_t k = size_t(y) * W + x;
        return std::make_pair(fb.drawable[k], fb.primitive[k]);
    };
    EXPECT_EQ(at(vec3(1.5f, -1.5f, 0.0f)), std::make_pair(1u, 0u));                   // floor, triangle 0 (below its diagonal)
    EXPECT_EQ(at(vec3(-1.5f, 1.5f, 0.0f)), std::make_pair(1u, 1u));                   // floor under the blended veil: still the floor
    EXPECT_EQ(at(vec3(0.9f, 0.2f, 1.0f)), std::make_pair(2u, 0u));                    // card
    EXPECT_EQ(at(vec3(0.7f, -0.8f, 1.0f)), std::make_pair(3u, 1u));                   // the card's second quad
    EXPECT_EQ(at(vec3(-1.0f, -0.5f, 1.4f)), std::make_pair(5u, rnd::kNoPrimitive));   // the sphere: analytic
    EXPECT_EQ(fb.drawable[0], 0u);                                                    // corner: background
    EXPECT_EQ(fb.primitive[0], rnd::kNoPrimitive);
}

TEST_P(Visibility, AntiAliasedImagesGetTheOneSampleVisibility) {
    sg::FrameInput f = scene();
    const rnd::Framebuffer plain = renderVisible(GetParam(), f);
    for (auto [aa, rate] : {std::pair{sg::AAMode::MSAA, 4}, std::pair{sg::AAMode::SSAA, 2}}) {
        f.settings.aa = aa;
        f.settings.aaRate = rate;
        const rnd::Framebuffer fb = renderVisible(GetParam(), f);
        ASSERT_TRUE(fb.has(rnd::Aov::Visibility));
        EXPECT_EQ(fb.drawable, plain.drawable) << GetParam() << " " << f.settings.aaName();
        EXPECT_EQ(fb.primitive, plain.primitive) << GetParam() << " " << f.settings.aaName();
        EXPECT_NE(fb.color, plain.color) << GetParam() << ": the colour image is anti-aliased";
    }
}

TEST_P(Visibility, SurfaceAndTermsAtAPixel) {
    const sg::FrameInput f = scene();
    const rnd::Framebuffer fb = renderVisible(GetParam(), f);
    const sg::InstanceTable ids = sg::instanceTable(f);
    auto [x, y] = pixelOf(f, vec3(1.5f, -1.5f, 0.0f));
    const rnd::SurfaceAt s = rnd::surfaceAt(f, ids, fb, x, y);
    ASSERT_TRUE(s.hit && s.triangle);
    EXPECT_EQ(s.instance, 1u);
    EXPECT_EQ(s.node, 1u);
    EXPECT_NEAR(s.position.z, 0.0f, 1e-5f);
    EXPECT_NEAR(s.position.x, 1.5f, 0.05f);
    EXPECT_NEAR(s.uv.x, 0.875f, 0.02f);
    EXPECT_NEAR(s.uv.y, 0.125f, 0.02f);
    EXPECT_NEAR(s.barycentric.x + s.barycentric.y + s.barycentric.z, 1.0f, 1e-5f);
    EXPECT_NEAR(s.normal.z, 1.0f, 1e-5f);
    EXPECT_NEAR(s.opticalDepth, 6.0f, 1e-3f);
    // The terms add up to the pixel: ambient + sum(diffuse + specular), encoded as the backend did.
    const rnd::PixelTerms t = rnd::pixelTerms(f, s);
    ASSERT_TRUE(t.lit);
    ASSERT_EQ(t.lights.size(), 1u);
    vec3 sum = t.ambient + t.emissive + t.lights[0].diffuse + t.lights[0].specular;
    EXPECT_NEAR(glm::length(sum - t.beforeFog), 0.0f, 1e-6f);
    const uint8_t* px = fb.pixel(x, y);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(int(px[c]), int(rnd::toByteSRGB(t.predicted[c])), 2) << GetParam() << " channel " << c;
    // The sphere's front: normal toward the camera, instance 4.
    auto [sx, sy] = pixelOf(f, vec3(-1.0f, -0.5f, 1.4f));
    const rnd::SurfaceAt sp = rnd::surfaceAt(f, ids, fb, sx, sy);
    ASSERT_TRUE(sp.hit && sp.analytic);
    EXPECT_EQ(sp.instance, 4u);
    EXPECT_GT(sp.normal.z, 0.95f);
    // Two drawables of one node are one instance.
    auto [cx, cy] = pixelOf(f, vec3(0.7f, -0.8f, 1.0f));
    EXPECT_EQ(rnd::surfaceAt(f, ids, fb, cx, cy).instance, 2u);
}

INSTANTIATE_TEST_SUITE_P(EveryBackend, Visibility, ::testing::ValuesIn(rnd::rendererNames()), [](const auto& info) { return info.param; });

// The backends see the same surfaces: the same drawable on >= 99% of pixels (edges may differ
// by a pixel), the same triangle on >= 99% of those.
TEST(VisibilityAgreement, BackendsSeeTheSameSurfaces) {
    const sg::FrameInput f = scene();
    std::vector<rnd::Framebuffer> fbs;
    for (const std::string& b : rnd::rendererNames()) fbs.push_back(renderVisible(b, f));
    for (size_t a = 0; a < fbs.size(); ++a)
        for (size_t b = a + 1; b < fbs.size(); ++b) {
            size_t same = 0, bothMesh = 0, sameTri = 0;
            for (size_t k = 0; k < size_t(W) * H; ++k) {
                if (fbs[a].drawable[k] != fbs[b].drawable[k]) continue;
                ++same;
                if (fbs[a].primitive[k] == rnd::kNoPrimitive) continue;
                ++bothMesh;
                sameTri += fbs[a].primitive[k] == fbs[b].primitive[k];
            }
            const std::string pair = rnd::rendererNames()[a] + " vs " + rnd::rendererNames()[b];
            EXPECT_GE(double(same) / (W * H), 0.99) << pair;
            EXPECT_GE(double(sameTri) / double(bothMesh), 0.99) << pair;
        }
}

}   // namespace

// The inspector's terms add up to the pixel across the whole demo scene (meshes, textures,
// implicit shapes, CSG, three lights, the ray caster's shadows), in every backend: what it
// says made each pixel is what made it.
TEST(VisibilityDemo, TermsAddUpToThePixelsOfTheDemo) {
    sg::Scene scene = assets::makeDemoScene();
    constexpr int DW = 192, DH = 170;
    const sg::FrameInput f = sg::flatten(scene, float(DW) / float(DH));
    const sg::InstanceTable ids = sg::instanceTable(f);
    for (const std::string& b : rnd::rendererNames()) {
        auto r = rnd::makeRenderer(b, nullptr);   // kept: its lightVisibility() answers for this render
        ASSERT_TRUE(r);
        rnd::Framebuffer fb;
        rnd::RenderRequest req;
        req.aovs.add(rnd::Aov::Visibility);
        ASSERT_TRUE(r->render(f, DW, DH, fb, nullptr, req).ok);
        int hit = 0, close = 0;
        for (int y = 1; y < DH - 1; y += 3)
            for (int x = 1; x < DW - 1; x += 3) {
                const rnd::SurfaceAt s = rnd::surfaceAt(f, ids, fb, x, y);
                if (!s.hit) continue;
                // Interior pixels only: at a silhouette the pixel centre and the reconstruction agree, but
                // the neighbours used for the texture footprint may lie on another surface.
                bool interior = true;
                for (int k = 0; k < 4; ++k) {
                    const int i = x + (k == 0) - (k == 1), j = y + (k == 2) - (k == 3);
                    interior = interior && fb.drawable[size_t(j) * DW + i] == s.drawable;
                }
                if (!interior) continue;
                ++hit;
                const rnd::PixelTerms t = rnd::pixelTerms(f, s, r->lightVisibility(f, s.position, s.geometricNormal));
                const uint8_t* px = fb.pixel(x, y);
                int worst = 0;
                for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(px[c]) - int(rnd::toByteSRGB(t.predicted[c]))));
                close += worst <= 3;
            }
        ASSERT_GT(hit, 500) << b;
        EXPECT_GE(double(close) / hit, 0.97) << b << ": " << close << " of " << hit << " pixels within 3/255 of their terms";
    }
}

// Diagnostic views hold the numbers they show: the uv view's red/green is frac(u)/frac(v) at
// a known point, the id view gives one colour per instance (two drawables of one node share
// it), the depth view is brighter where the surface is nearer, the triangle-density view at a
// floor pixel is the colour of 1 / (the floor triangle's projected area), computed by hand.
TEST(DiagnosticViews, KnownAnswersInEveryBackend) {
    const sg::FrameInput f = scene();
    for (const std::string& b : rnd::rendererNames()) {
        SCOPED_TRACE(b);
        const rnd::Framebuffer fb = renderVisible(b, f);
        auto at = [&](const rnd::DiagnosticImage& d, const vec3& p) {
            auto [x, y] = pixelOf(f, p);
            const uint8_t* c = d.image.pixel(x, y);
            return std::array<int, 3>{c[0], c[1], c[2]};
        };
        const rnd::DiagnosticImage uv = rnd::diagnosticImage(rnd::DiagnosticView::Uv, f, fb);
        const auto c = at(uv, vec3(1.5f, -1.5f, 0.0f));
        EXPECT_NEAR(c[0], 0.875 * 255, 4);
        EXPECT_NEAR(c[1], 0.125 * 255, 4);
        EXPECT_EQ(at(uv, vec3(-1.0f, -0.5f, 1.4f)), (std::array<int, 3>{153, 0, 153}));   // the sphere has no uv
        const rnd::DiagnosticImage id = rnd::diagnosticImage(rnd::DiagnosticView::Id, f, fb);
        EXPECT_EQ(at(id, vec3(0.9f, 0.2f, 1.0f)), at(id, vec3(0.7f, -0.8f, 1.0f)));   // one node, two drawables
        EXPECT_NE(at(id, vec3(0.9f, 0.2f, 1.0f)), at(id, vec3(1.5f, -1.5f, 0.0f)));
        EXPECT_EQ(at(id, vec3(3.0f, 2.5f, 0.0f)), (std::array<int, 3>{0, 0, 0}));   // background
        const rnd::DiagnosticImage depth = rnd::diagnosticImage(rnd::DiagnosticView::Depth, f, fb);
        EXPECT_GT(at(depth, vec3(0.9f, 0.2f, 1.0f))[0], at(depth, vec3(1.5f, -1.5f, 0.0f))[0]);   // the card is nearer than the floor
        EXPECT_NE(depth.legend.find("scene units"), std::string::npos);
        const rnd::DiagnosticImage normal = rnd::diagnosticImage(rnd::DiagnosticView::Normal, f, fb);
        EXPECT_EQ(at(normal, vec3(1.5f, -1.5f, 0.0f)), (std::array<int, 3>{128, 128, 255}));   // +z
    }
}

TEST(DiagnosticViews, TriangleDensityIsOneOverTheProjectedArea) {
    const sg::FrameInput f = scene();
    const rnd::Framebuffer fb = renderVisible("raster", f);
    // The card's triangle 0: (0.3,-0.2,1), (1.3,-0.2,1), (1.3,0.8,1) projected by hand.
    float area = 0;
    {
        vec3 w[3];
        const vec3 P[3] = {{0.3f, -0.2f, 1}, {1.3f, -0.2f, 1}, {1.3f, 0.8f, 1}};
        for (int k = 0; k < 3; ++k) {
            vec4 c = f.camera.proj * f.camera.view * vec4(P[k], 1.0f);
            w[k] = vec3((c.x / c.w * 0.5f + 0.5f) * W, (c.y / c.w * 0.5f + 0.5f) * H, 0);
        }
        area = 0.5f * std::fabs((w[1].x - w[0].x) * (w[2].y - w[0].y) - (w[1].y - w[0].y) * (w[2].x - w[0].x));
    }
    ASSERT_GT(area, 170.0f);
    ASSERT_LT(area, 1000.0f);
    // The same density through the view's own colour scale: render a one-triangle-per-`area` legend point.
    const rnd::DiagnosticImage tri = rnd::diagnosticImage(rnd::DiagnosticView::Triangles, f, fb);
    auto [x, y] = pixelOf(f, vec3(0.9f, 0.2f, 1.0f));
    const uint8_t* c = tri.image.pixel(x, y);
    // density = 1/area is between 1e-3 and 6e-3 here (blue .. cyan): blue dominant, no red.
    const double t = (std::log10(1.0 / area) + 3.0) / 3.0;
    ASSERT_GT(t, 0.0);
    ASSERT_LT(t, 0.25);
    EXPECT_GT(c[2], 200);
    EXPECT_LT(c[0], 40);
    EXPECT_NEAR(c[1], (0.2 + (0.8 - 0.2) * (t * 4.0)) * 255, 3);   // green runs 0.2 -> 0.8 from blue to cyan
    // Analytic shapes have no triangles of their own: grey.
    auto [sx, sy] = pixelOf(f, vec3(-1.0f, -0.5f, 1.4f));
    EXPECT_EQ(tri.image.pixel(sx, sy)[0], 89);
}
