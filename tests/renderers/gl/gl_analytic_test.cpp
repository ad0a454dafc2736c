// gl_analytic_test.cpp - GL images checked against answers known in closed form: the Phong
// formula at the centre of a lit sphere, fog blends, background and depth values, texture
// orientation, oblique receding angles, orthographic parallelism, anti-aliasing and the GPU
// cache.
#include "gl/gl_renderer.h"
#include "renderers/shading.h"
#include "test_scenes.h"
#include "test_support.h"

#include <cmath>

using namespace sg;
using namespace test_scenes;

namespace {

rnd::Framebuffer render(rnd::Renderer& r, const FrameInput& f, int w, int h) {
    rnd::Framebuffer fb;
    rnd::RenderStats st = r.render(f, w, h, fb);
    EXPECT_TRUE(st.ok) << st.error;
    return fb;
}

rnd::Framebuffer render(const FrameInput& f, int w, int h) {
    auto r = rnd::makeGlRenderer();
    return render(*r, f, w, h);
}

::testing::AssertionResult pixelNear(const rnd::Framebuffer& fb, int x, int y, const vec3& linear, int tol = 1) {
    const uint8_t* p = fb.pixel(x, y);
    for (int c = 0; c < 3; ++c) {
        int want = rnd::toByteSRGB(linear[c]);
        if (std::abs(int(p[c]) - want) > tol)
            return ::testing::AssertionFailure() << "pixel (" << x << "," << y << ") = (" << int(p[0]) << "," << int(p[1]) << "," << int(p[2])
                                                 << "), expected (" << int(rnd::toByteSRGB(linear.r)) << "," << int(rnd::toByteSRGB(linear.g)) << ","
                                                 << int(rnd::toByteSRGB(linear.b)) << ") +-" << tol;
    }
    return ::testing::AssertionSuccess();
}

}   // namespace

// A unit sphere lit head-on, camera on the same axis: at the centre pixel n = l = v = r = h,
// so n.l = 1 and the specular term is 1 for Phong and Blinn-Phong alike:
//   L = ka rho A + kd rho L + ks L  (white highlights).
// The sphere is finely tessellated (512 x 256) so that even flat shading's face normal is
// within ~0.5 degrees of the axis there (error < 0.3/255 for shininess 32).
TEST(GlShadingGLTest, LitSphereCentreMatchesPhongFormula) {
    const int W = 161, H = 121;   // odd: the centre pixel's centre is on the optical axis
    auto sphere = std::make_shared<const Mesh>(primitives::uvSphere(1.0f, 512, 256));
    Material m;
    m.baseColor = vec3(0.5f, 0.3f, 0.2f);
    m.ka = 0.2f;
    m.kd = 0.6f;
    m.ks = 0.3f;
    m.shininess = 32.0f;
    const vec3 ambient(0.3f, 0.25f, 0.2f), L(0.7f);
    const vec3 expected = m.ka * m.baseColor * ambient + m.kd * m.baseColor * L + m.ks * L;
    auto r = rnd::makeGlRenderer();
    const char* lightNames[] = {"directional", "point 1/r^2", "spot"};
    for (int light = 0; light < 3; ++light)
        for (ShadingModel model : {ShadingModel::Flat, ShadingModel::Gouraud, ShadingModel::Phong})
            for (ReflectionModel refl : {ReflectionModel::Phong, ReflectionModel::BlinnPhong}) {
                FrameInput f = makeFrame(W, H, Projection{}, vec3(0, 0, 5), vec3(0));
                f.ambientLight = ambient;
                f.settings.shading = model;
                f.settings.reflection = refl;
                if (light == 0) f.lights.push_back(directional(vec3(0, 0, -1), L));
                if (light == 1) f.lights.push_back(point(vec3(0, 0, 3), 4.0f * L, true));   // d = 2 from (0,0,1)
                if (light == 2) f.lights.push_back(spot(vec3(0, 0, 3), vec3(0, 0, -1), L, 10.0f, 20.0f));
                addMesh(f, sphere, m);
                rnd::Framebuffer fb = render(*r, f, W, H);
                EXPECT_TRUE(pixelNear(fb, W / 2, H / 2, expected))
                    << lightNames[light] << " light, " << toString(model) << " shading, " << toString(refl) << " reflection";
            }
}

// Specular tinted by the base colour and emissive add as the formula says; unlit ignores lights.
TEST(GlShadingGLTest, TintedSpecularEmissiveAndUnlit) {
    const int W = 161, H = 121;
    auto sphere = std::make_shared<const Mesh>(primitives::uvSphere(1.0f, 256, 128));
    Material m;
    m.baseColor = vec3(0.6f, 0.4f, 0.1f);
    m.ka = 0.1f;
    m.kd = 0.5f;
    m.ks = 0.4f;
    m.specularTinted = true;
    m.emissive = vec3(0.05f, 0.0f, 0.1f);
    FrameInput f = makeFrame(W, H, Projection{}, vec3(0, 0, 5), vec3(0));
    f.ambientLight = vec3(0.5f);
    f.lights.push_back(directional(vec3(0, 0, -1), vec3(0.8f)));
    addMesh(f, sphere, m);
    vec3 expected = m.ka * m.baseColor * f.ambientLight + m.emissive + 0.8f * (m.kd * m.baseColor + m.ks * m.baseColor);
    EXPECT_TRUE(pixelNear(render(f, W, H), W / 2, H / 2, expected));
    f.meshes[0].material.unlit = true;
    EXPECT_TRUE(pixelNear(render(f, W, H), W / 2, H / 2, m.baseColor + m.emissive));
}

// Fog on a plane facing the camera at distance d: the centre pixel is f(d) c + (1 - f(d)) C_fog.
TEST(GlFogGLTest, PlaneAtKnownDistanceBlendsAsExpected) {
    const int W = 81, H = 61;
    const float d = 5.0f;
    const vec3 color(0.8f, 0.2f, 0.1f), fogColor(0.2f, 0.4f, 0.6f);
    for (FogMode mode : {FogMode::Linear, FogMode::Exp, FogMode::Exp2}) {
        FrameInput f = makeFrame(W, H, Projection{}, vec3(0, 0, d), vec3(0));
        f.settings.fog = mode;
        f.settings.fogColor = fogColor;
        f.settings.fogStart = 2.0f;
        f.settings.fogEnd = 12.0f;
        f.settings.fogDensity = 0.1f;
        addMesh(f, quad(3.0f), unlit(color));
        float vis = mode == FogMode::Linear ? (12.0f - d) / 10.0f : mode == FogMode::Exp ? std::exp(-0.1f * d) : std::exp(-0.25f);
        EXPECT_NEAR(vis, fogVisibility(f.settings, d), 1e-6f);
        rnd::Framebuffer fb = render(f, W, H);
        EXPECT_TRUE(pixelNear(fb, W / 2, H / 2, vis * color + (1.0f - vis) * fogColor)) << toString(mode);
        // Off-axis pixels are farther away (eye distance, not z): more fog toward the corners.
        if (mode == FogMode::Linear) { EXPECT_GT(fb.pixel(2, 2)[2], fb.pixel(W / 2, H / 2)[2]); }
    }
}

// The background is linear and comes out sRGB-encoded; empty pixels have depth 1; a plane at
// eye depth z has window depth 0.5 z_ndc + 0.5.
TEST(GlFramebufferGLTest, BackgroundAndDepth) {
    const int W = 81, H = 61;
    FrameInput f = makeFrame(W, H, Projection{}, vec3(0, 0, 5), vec3(0));
    f.settings.background = vec3(0.2f, 0.5f, 0.8f);
    addMesh(f, quad(0.5f), unlit(vec3(1.0f)));
    rnd::Framebuffer fb = render(f, W, H);
    EXPECT_TRUE(pixelNear(fb, 0, 0, f.settings.background));
    EXPECT_TRUE(pixelNear(fb, W - 1, H - 1, f.settings.background));
    EXPECT_EQ(fb.depth[0], 1.0f);
    vec4 clip = f.camera.proj * vec4(0, 0, -5, 1);
    float expectedDepth = 0.5f * clip.z / clip.w + 0.5f;
    EXPECT_NEAR(fb.depth[size_t(H / 2) * W + W / 2], expectedDepth, 2e-6f);
    EXPECT_EQ(fb.pixel(W / 2, H / 2)[3], 255);
}

// Texture rows are top-down with row 0 at v = 1; uv (0,0) is the bottom-left of the quad.
// Vertex colours multiply the base colour.
TEST(GlTextureGLTest, OrientationAndVertexColours) {
    const int W = 81, H = 81;
    auto t = std::make_shared<Texture>();
    t->width = t->height = 2;
    t->filter = FilterMode::Nearest;
    // top-left red, top-right green, bottom-left blue, bottom-right white
    t->rgba = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
    Projection ortho;
    ortho.type = ProjectionType::Orthographic;
    ortho.orthoHalfHeight = 1.0f;
    FrameInput f = makeFrame(W, H, ortho, vec3(0, 0, 5), vec3(0));
    addMesh(f, quad(1.0f), unlit(vec3(1.0f)), mat4(1.0f), t);
    rnd::Framebuffer fb = render(f, W, H);
    EXPECT_TRUE(pixelNear(fb, 20, 20, vec3(1, 0, 0), 0));
    EXPECT_TRUE(pixelNear(fb, 60, 20, vec3(0, 1, 0), 0));
    EXPECT_TRUE(pixelNear(fb, 20, 60, vec3(0, 0, 1), 0));
    EXPECT_TRUE(pixelNear(fb, 60, 60, vec3(1, 1, 1), 0));

    Mesh q = quad(1.0f);
    q.colors.assign(4, vec4(0.5f, 1.0f, 0.25f, 1.0f));
    FrameInput g = makeFrame(W, H, ortho, vec3(0, 0, 5), vec3(0));
    addMesh(g, q, unlit(vec3(0.8f, 0.5f, 1.0f)));
    EXPECT_TRUE(pixelNear(render(g, W, H), W / 2, H / 2, vec3(0.4f, 0.5f, 0.25f)));
}

namespace {

// Silhouette height of column x in pixels (unlit white on black, anti-aliased: sub-pixel).
double columnCoverage(const rnd::Framebuffer& fb, int x) {
    double sum = 0;
    for (int y = 0; y < fb.height; ++y) sum += fb.pixel(x, y)[0] / 255.0;
    return sum;
}

}   // namespace

// Oblique projection of a unit cube facing the camera: the back face is shifted by
// factor * depth along (cos a, sin a), so the silhouette's top edge left of the front face's
// corner rises at angle a: the column coverage there grows with slope tan(a).
TEST(GlProjectionGLTest, ObliqueRecedingEdgesAtSetAngle) {
    const int W = 321, H = 241;
    for (auto [angle, factor] : {std::pair{45.0f, 1.0f}, std::pair{30.0f, 1.0f}, std::pair{60.0f, 0.5f}}) {
        Projection p = Projection::cavalier();
        p.obliqueAngleDeg = angle;
        p.obliqueFactor = factor;
        p.orthoHalfHeight = 1.5f;
        FrameInput f = makeFrame(W, H, p, vec3(0, 0, 5), vec3(0));
        f.settings.aa = AAMode::SSAA;
        f.settings.aaRate = 4;
        addMesh(f, primitives::box(vec3(0.5f)), unlit(vec3(1.0f)));
        rnd::Framebuffer fb = render(f, W, H);
        testing_support::writeImage(fb, "gl", "oblique-" + std::to_string(int(angle)));
        const float a = glm::radians(angle);
        const double scale = H / (2.0 * p.orthoHalfHeight);   // pixels per unit
        auto toPx = [&](double x) { return (x + p.orthoHalfHeight * double(W) / H) * scale; };
        // Front face (z = +0.5, half a unit in front of the reference plane) moves by -0.5 factor
        // (cos a, sin a); the back face by +0.5 factor (cos a, sin a).
        double x0 = -0.5 - 0.5 * factor * std::cos(a), dx = factor * std::cos(a);
        int c1 = int(toPx(x0 + 0.25 * dx)), c2 = int(toPx(x0 + 0.75 * dx));
        double h1 = columnCoverage(fb, c1), h2 = columnCoverage(fb, c2);
        double measured = glm::degrees(std::atan2(h2 - h1, double(c2 - c1)));
        EXPECT_NEAR(measured, angle, 1.5) << "columns " << c1 << ", " << c2 << ": heights " << h1 << ", " << h2;
        EXPECT_NEAR(h2 - h1, (c2 - c1) * std::tan(a), 1.5) << "angle " << angle;
        // The front face is a full unit square: coverage in its middle is one unit of pixels
        // plus the receding top face.
        double mid = columnCoverage(fb, int(toPx(0.0)));
        EXPECT_NEAR(mid, scale * (1.0 + factor * std::sin(a)), 1.5);
    }
}

// Orthographic projection keeps parallel edges parallel: a long rod seen from the side has
// the same height in pixels at both ends, while perspective makes the near end taller.
TEST(GlProjectionGLTest, OrthographicKeepsParallelEdgesParallel) {
    const int W = 241, H = 121;
    mat4 rod = glm::rotate(mat4(1.0f), glm::radians(60.0f), vec3(0, 1, 0));
    auto heights = [&](ProjectionType type) {
        Projection p;
        p.type = type;
        p.orthoHalfHeight = 1.5f;
        FrameInput f = makeFrame(W, H, p, vec3(0, 0, 6), vec3(0));
        f.settings.aa = AAMode::SSAA;
        f.settings.aaRate = 4;
        addMesh(f, primitives::box(vec3(0.3f, 0.3f, 2.5f)), unlit(vec3(1.0f)), rod);
        rnd::Framebuffer fb = render(f, W, H);
        // Left end of the rod is the far end (rotation by +60 degrees about y).
        return std::pair{columnCoverage(fb, W / 2 - 40), columnCoverage(fb, W / 2 + 40)};
    };
    auto [orthoFar, orthoNear] = heights(ProjectionType::Orthographic);
    EXPECT_GT(orthoFar, 10.0);
    EXPECT_NEAR(orthoFar, orthoNear, 0.5);
    auto [perspFar, perspNear] = heights(ProjectionType::Perspective);
    EXPECT_GT(perspNear - perspFar, 2.0) << "perspective should foreshorten the far end";
}

namespace {

// Pixels whose red channel is strictly between black and white: anti-aliased edge pixels.
int intermediatePixels(const rnd::Framebuffer& fb) {
    int n = 0;
    for (int y = 0; y < fb.height; ++y)
        for (int x = 0; x < fb.width; ++x) n += fb.pixel(x, y)[0] > 8 && fb.pixel(x, y)[0] < 247;
    return n;
}

}   // namespace

// A white square rotated by 20 degrees on black: without AA every pixel is black or white;
// MSAA and SSAA produce graded edge pixels.
TEST(GlAntiAliasingGLTest, MsaaAndSsaaSoftenEdges) {
    const int W = 161, H = 121;
    auto frame = [&](AAMode mode, int rate) {
        FrameInput f = makeFrame(W, H, Projection{}, vec3(0, 0, 5), vec3(0));
        f.settings.aa = mode;
        f.settings.aaRate = rate;
        addMesh(f, quad(1.0f), unlit(vec3(1.0f)), glm::rotate(mat4(1.0f), glm::radians(20.0f), vec3(0, 0, 1)));
        return f;
    };
    auto r = rnd::makeGlRenderer();
    int none = intermediatePixels(render(*r, frame(AAMode::None, 1), W, H));
    int msaa4 = intermediatePixels(render(*r, frame(AAMode::MSAA, 4), W, H));
    int msaa8 = intermediatePixels(render(*r, frame(AAMode::MSAA, 8), W, H));   // or fewer, with a note, on a driver without 8
    int ssaa2 = intermediatePixels(render(*r, frame(AAMode::SSAA, 2), W, H));
    int ssaa4 = intermediatePixels(render(*r, frame(AAMode::SSAA, 4), W, H));
    std::printf("[aa] intermediate edge pixels: none %d, msaa4 %d, msaa8 %d, ssaa2 %d, ssaa4 %d\n", none, msaa4, msaa8, ssaa2, ssaa4);
    EXPECT_EQ(none, 0);
    EXPECT_GT(msaa4, 100);
    EXPECT_GT(msaa8, 100);
    EXPECT_GT(ssaa2, 100);
    EXPECT_GT(ssaa4, 100);
    EXPECT_GT(rnd::glCacheCounters(*r).platform.size(), 0u);
}

// GPU objects are cached per mesh id + version: an unchanged frame uploads nothing; editing
// one mesh re-uploads only that mesh; a texture shared by two meshes is uploaded once.
TEST(GlCacheGLTest, UploadsOnlyWhatChanged) {
    const int W = 64, H = 48;
    FrameInput f = makeFrame(W, H, Projection{}, vec3(0, 0, 6), vec3(0));
    f.lights.push_back(directional(vec3(0, 0, -1), vec3(1.0f)));
    auto tex = checker(16, 4, vec3(1.0f), vec3(0.0f));
    auto a = std::make_shared<Mesh>(primitives::box(vec3(0.4f)));
    auto b = std::make_shared<Mesh>(primitives::uvSphere(0.4f, 16, 8));
    auto c = std::make_shared<Mesh>(primitives::torus(0.4f, 0.1f, 16, 8));
    addMesh(f, a, Material{}, glm::translate(mat4(1.0f), vec3(-1, 0, 0)), tex);
    addMesh(f, b, Material{}, mat4(1.0f), tex);
    addMesh(f, c, Material{}, glm::translate(mat4(1.0f), vec3(1, 0, 0)));
    addMesh(f, c, Material{}, glm::translate(mat4(1.0f), vec3(1, 1, 0)));   // second instance
    auto r = rnd::makeGlRenderer();
    rnd::Framebuffer first = render(*r, f, W, H);
    rnd::GlCacheCounters c1 = rnd::glCacheCounters(*r);
    EXPECT_EQ(c1.meshUploads, 3u);
    EXPECT_EQ(c1.textureUploads, 1u);
    rnd::Framebuffer second = render(*r, f, W, H);
    rnd::GlCacheCounters c2 = rnd::glCacheCounters(*r);
    EXPECT_EQ(c2.meshUploads, 3u) << "an unchanged frame must upload nothing";
    EXPECT_EQ(c2.textureUploads, 1u);
    EXPECT_EQ(rnd::compareImages(first, second, 0).maxAbs, 0);

    b->positions[0] += vec3(0.01f);   // edit one mesh
    b->touch();
    render(*r, f, W, H);
    rnd::GlCacheCounters c3 = rnd::glCacheCounters(*r);
    EXPECT_EQ(c3.meshUploads, 4u) << "only the edited mesh is re-uploaded";
    EXPECT_EQ(c3.textureUploads, 1u);
    EXPECT_EQ(c3.meshesCached, 3u);
}

// Meshes that fail validation (indices out of range) are skipped, not drawn out of bounds.
TEST(GlCacheGLTest, InvalidMeshIsSkipped) {
    Mesh bad = primitives::box(vec3(0.5f));
    bad.indices.push_back(100000);
    bad.indices.push_back(0);
    bad.indices.push_back(1);
    FrameInput f = makeFrame(32, 32, Projection{}, vec3(0, 0, 5), vec3(0));
    addMesh(f, bad, unlit(vec3(1.0f)));
    auto r = rnd::makeGlRenderer();
    rnd::Framebuffer fb;
    rnd::RenderStats st = r->render(f, 32, 32, fb);
    EXPECT_TRUE(st.ok) << st.error;
    EXPECT_EQ(fb.pixel(16, 16)[0], 0);
}

// Every pixel of a plane lit by a point (1/r^2), a spot (partly inside its cone falloff) and a
// directional light, with fog, equals rnd::shade() + rnd::applyFog() evaluated on the CPU at
// the same surface point: the shaders mirror renderers/common/shading.cpp. (Phong shading;
// flat shading's one colour per triangle is FlatShadingGivesEachTriangleOneColour's. Shadows
// off: rnd::shade has none, and the point light's maps see the far plane at grazing angles,
// where the filter's edge taps may dim a pixel by a few levels.)
TEST(GlShadingGLTest, PlaneMatchesSharedShadingFunctionEverywhere) {
    const int W = 96, H = 72;
    for (bool generic : {false, true})
        for (ShadingModel model : {ShadingModel::Phong})
            for (ReflectionModel refl : {ReflectionModel::Phong, ReflectionModel::BlinnPhong}) {
                FrameInput f = makeFrame(W, H, Projection{}, vec3(0.6f, 0.4f, 4.0f), vec3(0.0f));
                f.ambientLight = vec3(0.2f, 0.22f, 0.25f);
                f.settings.shading = model;
                f.settings.reflection = refl;
                f.settings.fog = FogMode::Exp;
                f.settings.fogDensity = 0.04f;
                f.settings.fogColor = vec3(0.3f, 0.3f, 0.35f);
                f.settings.shadows = false;
                f.lights.push_back(point(vec3(1.0f, 1.0f, 1.5f), vec3(2.5f, 2.2f, 2.0f), true));
                f.lights.push_back(spot(vec3(-1.0f, 0.5f, 2.0f), vec3(0.2f, -0.25f, -1.0f), vec3(1.2f, 1.0f, 0.6f), 10.0f, 25.0f));
                f.lights.push_back(directional(vec3(0.2f, -0.3f, -1.0f), vec3(0.15f, 0.2f, 0.3f)));
                // More than 8 lights switch to the generic program (a loop reading the types).
                for (int i = 0; generic && i < 3; ++i) {
                    f.lights.push_back(point(vec3(-1.0f + i, 1.0f, 2.0f), vec3(0.3f), i % 2 == 0));
                    f.lights.push_back(spot(vec3(1.0f, -1.0f + i, 2.0f), vec3(-0.1f * i, 0.2f, -1.0f), vec3(0.4f), 15.0f, 30.0f));
                }
                Material m;
                m.baseColor = vec3(0.7f, 0.6f, 0.5f);
                m.ka = 0.3f;
                m.kd = 0.6f;
                m.ks = 0.4f;
                m.shininess = 20.0f;
                addMesh(f, quad(6.0f), m);
                rnd::Framebuffer fb = render(f, W, H);

                mat4 inv = glm::inverse(f.camera.viewProj);
                double sum = 0;
                int worst = 0, count = 0;
                for (int row = 0; row < H; ++row)
                    for (int x = 0; x < W; ++x) {
                        // Pixel centre -> NDC -> ray through the near and far planes -> z = 0 plane.
                        float nx = 2.0f * (x + 0.5f) / W - 1.0f, ny = 2.0f * (H - 1 - row + 0.5f) / H - 1.0f;
                        vec4 a = inv * vec4(nx, ny, -1.0f, 1.0f), b = inv * vec4(nx, ny, 1.0f, 1.0f);
                        vec3 p0 = vec3(a) / a.w, p1 = vec3(b) / b.w;
                        float t = p0.z / (p0.z - p1.z);
                        vec3 p = p0 + t * (p1 - p0);
                        rnd::SurfacePoint sp{p, vec3(0, 0, 1), m.baseColor};
                        vec3 c = rnd::shade(m, sp, f.camera.eye, f);
                        c = rnd::applyFog(f.settings, c, glm::length(vec3(f.camera.view * vec4(p, 1.0f))));
                        for (int ch = 0; ch < 3; ++ch) {
                            int d = std::abs(int(fb.pixel(x, row)[ch]) - int(rnd::toByteSRGB(c[ch])));
                            worst = std::max(worst, d);
                            sum += d;
                            ++count;
                        }
                    }
                double mean = sum / count;
                std::printf("[plane] %s/%s%s: mean %.3f max %d\n", std::string(toString(model)).c_str(), std::string(toString(refl)).c_str(),
                            generic ? " (9 lights, generic program)" : "", mean, worst);
                EXPECT_LE(mean, 0.5) << toString(model) << " " << toString(refl);
                EXPECT_LE(worst, 3) << toString(model) << " " << toString(refl);
            }
}

// Up to 32 lights are shaded (one program per light setup); more are ignored, not an error.
TEST(GlShadingGLTest, ManyLightsOfEachKind) {
    const int W = 81, H = 61;
    auto sphere = std::make_shared<const Mesh>(primitives::uvSphere(1.0f, 64, 32));
    FrameInput f = makeFrame(W, H, Projection{}, vec3(0, 0, 5), vec3(0));
    Material m;
    m.ka = 0.0f;
    m.ks = 0.0f;
    addMesh(f, sphere, m);
    // 30 dim directional lights head-on add up exactly like one bright one.
    for (int i = 0; i < 30; ++i) f.lights.push_back(directional(vec3(0, 0, -1), vec3(0.02f)));
    rnd::Framebuffer many = render(f, W, H);
    EXPECT_TRUE(pixelNear(many, W / 2, H / 2, m.kd * m.baseColor * 0.6f));
    for (int i = 0; i < 10; ++i) f.lights.push_back(point(vec3(0, 0, 3), vec3(1.0f), true));   // 40 > 32
    for (int i = 0; i < 5; ++i) f.lights.push_back(spot(vec3(0, 0, 3), vec3(0, 0, -1), vec3(1.0f), 5.0f, 10.0f));
    auto r = rnd::makeGlRenderer();
    rnd::Framebuffer fb;
    rnd::RenderStats st = r->render(f, W, H, fb);
    EXPECT_TRUE(st.ok) << st.error;
    // The first 32 count: 30 directional (0.6) + 2 points at distance 2 (2 x 1/4).
    EXPECT_TRUE(pixelNear(fb, W / 2, H / 2, m.kd * m.baseColor * (0.6f + 0.5f)));
}
