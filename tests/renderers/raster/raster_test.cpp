// raster_test.cpp - pure tests of the CPU rasterizer ("raster" backend): fill rule, clipping
// across the camera plane in all three projections, perspective-correct interpolation, depth
// test, analytic shading at the centre of a sphere per shading model, fog, AA, culling,
// cancellation, and the batched shading against rnd::shade.
#include "raster/raster_core.h"
#include "raster/raster_shading.h"
#include "renderers/environment.h"
#include "renderers/pbr.h"
#include "renderers/renderer.h"
#include "renderers/shading.h"
#include "renderers/shadow_map.h"
#include "renderers/texture_sampler.h"
#include "scenegraph/frame.h"
#include "scenegraph/transforms.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>

using namespace sg;
using namespace rnd;

namespace {

// ---------------------------------------------------------------------------------------
// helpers
// ---------------------------------------------------------------------------------------

FrameCamera cameraAt(const vec3& eye, const vec3& center, const Projection& p, float aspect, const vec3& up = vec3(0, 1, 0)) {
    return makeFrameCamera(glm::inverse(lookAt(eye, center, up)), p, aspect, glm::length(center - eye));
}

Material unlitMaterial(const vec3& c) {
    Material m;
    m.unlit = true;
    m.baseColor = c;
    return m;
}

std::shared_ptr<Mesh> quadMesh(const vec3& a, const vec3& b, const vec3& c, const vec3& d) {
    auto m = std::make_shared<Mesh>();
    m->positions = {a, b, c, d};
    vec3 n = glm::normalize(glm::cross(b - a, c - a));
    m->normals = {n, n, n, n};
    m->uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m->indices = {0, 1, 2, 0, 2, 3};
    return m;
}

DrawMesh drawOf(std::shared_ptr<Mesh> mesh, const Material& mat, const mat4& world = mat4(1.0f)) {
    DrawMesh d;
    d.mesh = mesh;
    d.material = mat;
    d.world = world;
    d.normal = normalMatrix(world);
    d.mirrored = glm::determinant(mat3(world)) < 0;
    return d;
}

Framebuffer renderRaster(const FrameInput& f, int w, int h, RenderStats* statsOut = nullptr, RenderControl* control = nullptr) {
    auto r = makeRenderer("raster");
    EXPECT_TRUE(r);
    Framebuffer fb;
    RenderStats s = r->render(f, w, h, fb, control);
    if (statsOut)
        *statsOut = s;
    else
        EXPECT_TRUE(s.ok) << s.error;
    return fb;
}

// Pixel (i, j) in window coordinates (y up).
const uint8_t* px(const Framebuffer& fb, int i, int j) { return fb.pixel(i, fb.height - 1 - j); }

}   // namespace

// ---------------------------------------------------------------------------------------
// scan conversion: fill rule, hierarchical vs simple traversal
// ---------------------------------------------------------------------------------------

// A convex polygon split into a fan of triangles around an interior point: every pixel centre
// strictly inside the polygon is covered exactly once, none twice, over many random sub-pixel
// placements.
TEST(RasterFillRuleTest, SharedEdgesCoverEachPixelExactlyOnce) {
    std::mt19937 rng(1234);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    const int W = 48, H = 48;
    int checked = 0;
    for (int iter = 0; iter < 400; ++iter) {
        // Random convex polygon: points on a circle at random angles, random sub-pixel centre.
        int n = 3 + iter % 6;
        float cx = 24 + 4 * U(rng), cy = 24 + 4 * U(rng), r = 6 + 14 * U(rng);
        // Jittered even angles keep the centre inside (every gap < pi).
        std::vector<float> ang(n);
        float phase = U(rng);
        for (int k = 0; k < n; ++k) ang[k] = 2 * kPi * (k + phase + 0.3f * U(rng)) / n;
        std::vector<vec2> poly;
        for (float a : ang) poly.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
        // Snap the test points to the fixed-point grid as the rasterizer does.
        for (auto& p : poly) p = vec2(raster::toFixed(p.x), raster::toFixed(p.y)) / float(raster::kSub);
        vec2 c(raster::toFixed(cx) / float(raster::kSub), raster::toFixed(cy) / float(raster::kSub));
        std::vector<int> count(W * H, 0);
        for (int k = 0; k < n; ++k) {
            // Alternate winding to exercise the CW -> CCW swap.
            vec2 a = poly[k], b = poly[(k + 1) % n];
            float xs[3] = {c.x, a.x, b.x}, ys[3] = {c.y, a.y, b.y};
            if (k % 2) {
                std::swap(xs[1], xs[2]);
                std::swap(ys[1], ys[2]);
            }
            raster::TriSetup t;
            if (!raster::setupTriangle(xs, ys, W, H, t)) continue;
            raster::forEachCoveredPixel(t, 0, 0, W - 1, H - 1, [&](int i, int j) { ++count[j * W + i]; });
        }
        for (int j = 0; j < H; ++j)
            for (int i = 0; i < W; ++i) {
                int cnt = count[j * W + i];
                ASSERT_LE(cnt, 1) << "pixel " << i << "," << j << " covered twice (iteration " << iter << ")";
                // Strictly inside the polygon's outer boundary (margin 1e-3 px): must be covered.
                vec2 p(i + 0.5f, j + 0.5f);
                bool inside = true;
                for (int k = 0; k < n && inside; ++k) {
                    vec2 a = poly[k], b = poly[(k + 1) % n];
                    vec2 e = b - a;
                    float cr = e.x * (p.y - a.y) - e.y * (p.x - a.x);
                    inside = cr > 1e-3f * glm::length(e);
                }
                if (inside) {
                    ++checked;
                    ASSERT_EQ(cnt, 1) << "crack at pixel " << i << "," << j << " (iteration " << iter << ")";
                }
            }
    }
    EXPECT_GT(checked, 10000);
}

TEST(RasterFillRuleTest, HierarchicalTraversalMatchesPerPixelTest) {
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> U(-40.0f, 340.0f);
    for (int iter = 0; iter < 300; ++iter) {
        float xs[3] = {U(rng), U(rng), U(rng)}, ys[3] = {U(rng), U(rng), U(rng)};
        raster::TriSetup t;
        if (!raster::setupTriangle(xs, ys, 300, 200, t)) continue;
        std::vector<uint8_t> a(300 * 200, 0), b(300 * 200, 0);
        raster::forEachCoveredPixel(t, 0, 0, 299, 199, [&](int i, int j) { ++a[j * 300 + i]; });
        raster::forEachCoveredPixelSimple(t, 0, 0, 299, 199, [&](int i, int j) { ++b[j * 300 + i]; });
        ASSERT_EQ(a, b) << "iteration " << iter;
    }
}

TEST(RasterFillRuleTest, TopLeftRuleOnPixelAlignedSquare) {
    // Square from (2,2) to (6,6) in pixel units, pixel centres at +0.5: exactly 4x4 pixels.
    float x0 = 2, x1 = 6, y0 = 2, y1 = 6;
    float ax[3] = {x0, x1, x1}, ay[3] = {y0, y0, y1};
    float bx[3] = {x0, x1, x0}, by[3] = {y0, y1, y1};
    int count = 0;
    for (auto [xs, ys] : {std::pair{ax, ay}, std::pair{bx, by}}) {
        raster::TriSetup t;
        ASSERT_TRUE(raster::setupTriangle(xs, ys, 16, 16, t));
        raster::forEachCoveredPixel(t, 0, 0, 15, 15, [&](int i, int j) {
            EXPECT_TRUE(i >= 2 && i < 6 && j >= 2 && j < 6) << i << "," << j;
            ++count;
        });
    }
    EXPECT_EQ(count, 16);
    // Pixel centres exactly on the edges: the square (1.5,1.5)-(5.5,5.5) includes its left and
    // bottom... with y up, its top-left rule includes the left and top edges: x = 1.5 and y = 5.5.
    float cx[3] = {1.5f, 5.5f, 5.5f}, cy[3] = {1.5f, 1.5f, 5.5f};
    float dx[3] = {1.5f, 5.5f, 1.5f}, dy[3] = {1.5f, 5.5f, 5.5f};
    std::vector<int> cov(16 * 16, 0);
    for (auto [xs, ys] : {std::pair{cx, cy}, std::pair{dx, dy}}) {
        raster::TriSetup t;
        ASSERT_TRUE(raster::setupTriangle(xs, ys, 16, 16, t));
        raster::forEachCoveredPixel(t, 0, 0, 15, 15, [&](int i, int j) { ++cov[j * 16 + i]; });
    }
    int total = 0;
    for (int j = 0; j < 16; ++j)
        for (int i = 0; i < 16; ++i) {
            total += cov[j * 16 + i];
            if (cov[j * 16 + i]) { EXPECT_TRUE(i >= 1 && i <= 4 && j >= 2 && j <= 5) << i << "," << j; }
        }
    EXPECT_EQ(total, 16);
}

// ---------------------------------------------------------------------------------------
// clipping: a floor triangle crossing the camera plane, in all three projections
// ---------------------------------------------------------------------------------------

namespace {
// Coverage expected from the geometry: the pixel's viewing segment between the near and far
// planes (unprojected NDC z = -1 .. 1) hits the floor y = -1 inside the triangle.
bool expectedFloorHit(const FrameInput& f, int i, int j, int W, int H, const vec2 tri[3]) {
    mat4 inv = glm::inverse(f.camera.proj * f.camera.view);
    float x = (i + 0.5f) / W * 2 - 1, y = (j + 0.5f) / H * 2 - 1;
    vec4 a = inv * vec4(x, y, -1, 1), b = inv * vec4(x, y, 1, 1);
    vec3 pa = vec3(a) / a.w, pb = vec3(b) / b.w;
    if ((pa.y + 1) * (pb.y + 1) > 0) return false;
    float t = (pa.y + 1) / (pa.y - pb.y);
    vec3 p = pa + t * (pb - pa);
    vec2 q(p.x, p.z);
    int pos = 0, neg = 0;
    for (int k = 0; k < 3; ++k) {
        vec2 e = tri[(k + 1) % 3] - tri[k];
        float c = e.x * (q.y - tri[k].y) - e.y * (q.x - tri[k].x);
        pos += c > 0;
        neg += c < 0;
    }
    return pos == 0 || neg == 0;
}
}   // namespace

class RasterClipTest : public ::testing::TestWithParam<ProjectionType> {};

TEST_P(RasterClipTest, TriangleCrossingTheCameraPlaneRendersTheVisiblePart) {
    const int W = 160, H = 120;
    // A big floor triangle (y = -1) around and behind the camera at the origin.
    vec2 tri[3] = {{-30, 20}, {30, 20}, {0, -40}};   // (x, z)
    auto mesh = std::make_shared<Mesh>();
    mesh->positions = {{tri[0].x, -1, tri[0].y}, {tri[1].x, -1, tri[1].y}, {tri[2].x, -1, tri[2].y}};
    mesh->indices = {0, 1, 2};
    FrameInput f;
    f.meshes.push_back(drawOf(mesh, unlitMaterial(vec3(1.0f))));
    f.settings.background = vec3(0.0f);
    Projection p;
    p.type = GetParam();
    p.zNear = 0.5f;
    p.zFar = 25.0f;
    p.orthoHalfHeight = 3.0f;
    // Look forward and down; the triangle extends behind the camera (crossing z_eye = 0).
    f.camera = cameraAt(vec3(0, 0, 0), vec3(0, -0.2f, -1), p, float(W) / H);
    Framebuffer fb = renderRaster(f, W, H);
    testing_support::writeImage(fb, "raster", std::string("clip-") + std::string(toString(GetParam())));
    int mismatches = 0, covered = 0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            bool got = px(fb, i, j)[0] > 128;
            bool want = expectedFloorHit(f, i, j, W, H, tri);
            covered += got;
            if (got != want) {
                // Allow only boundary pixels: some neighbour must have the other expectation.
                bool boundary = false;
                for (int dj = -1; dj <= 1; ++dj)
                    for (int di = -1; di <= 1; ++di)
                        if (expectedFloorHit(f, i + di, j + dj, W, H, tri) != want) boundary = true;
                if (!boundary) ++mismatches;
            }
        }
    EXPECT_EQ(mismatches, 0);
    EXPECT_GT(covered, W * H / 10) << "the floor should be visible";
    EXPECT_LT(covered, W * H) << "the far plane / horizon should cut it";
}

INSTANTIATE_TEST_SUITE_P(AllProjections, RasterClipTest,
                         ::testing::Values(ProjectionType::Perspective, ProjectionType::Orthographic, ProjectionType::Oblique),
                         [](const auto& info) { return std::string(toString(info.param)); });

TEST(RasterClipTest, ClipPolygonKeepsTheInsidePart) {
    // Triangle with one vertex behind the near plane: clipping gives a quad; barycentrics of
    // the new vertices are consistent with their positions.
    vec4 c[3] = {{0, 0, 0, 1}, {1, 0, 0.5f, 1}, {0, 1, -3, 1}};   // third: z < -w
    raster::ClipVertex out[9];
    int n = raster::clipTriangle(c, raster::kClipNear, raster::GuardBand{}, out);
    ASSERT_EQ(n, 4);
    for (int k = 0; k < n; ++k) {
        vec4 rec = out[k].bary.x * c[0] + out[k].bary.y * c[1] + out[k].bary.z * c[2];
        EXPECT_NEAR(glm::length(rec - out[k].clip), 0.0f, 1e-5f);
        EXPECT_GE(out[k].clip.z + out[k].clip.w, -1e-6f);
    }
}

// ---------------------------------------------------------------------------------------
// perspective-correct texture coordinates on a tilted quad vs the analytic answer
// ---------------------------------------------------------------------------------------

TEST(RasterInterpolationTest, PerspectiveCorrectUVOnTiltedQuad) {
    const int W = 128, H = 128, T = 256;
    // Texture whose texel (i, file row r) stores R = i, G = r: unlit + NEAREST returns them.
    auto tex = std::make_shared<Texture>();
    tex->width = T;
    tex->height = T;
    tex->filter = FilterMode::Nearest;
    tex->rgba.resize(size_t(T) * T * 4);
    for (int r = 0; r < T; ++r)
        for (int i = 0; i < T; ++i) {
            uint8_t* p = &tex->rgba[(size_t(r) * T + i) * 4];
            p[0] = uint8_t(i);
            p[1] = uint8_t(r);
            p[2] = 0;
            p[3] = 255;
        }
    // Quad receding in depth: from z = -2 (bottom) to z = -12 (top).
    vec3 a(-1.5f, -1, -2), b(1.5f, -1, -2), c(1.5f, 1.5f, -12), d(-1.5f, 1.5f, -12);
    auto mesh = quadMesh(a, b, c, d);
    FrameInput f;
    DrawMesh dm = drawOf(mesh, unlitMaterial(vec3(1.0f)));
    dm.texture = tex;
    f.meshes.push_back(dm);
    Projection p;
    p.fovyDeg = 60;
    f.camera = cameraAt(vec3(0), vec3(0, 0, -1), p, 1.0f);
    Framebuffer fb = renderRaster(f, W, H);
    mat4 inv = glm::inverse(f.camera.proj * f.camera.view);
    int checked = 0, bad = 0, affineWouldFail = 0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            float x = (i + 0.5f) / W * 2 - 1, y = (j + 0.5f) / H * 2 - 1;
            vec4 o4 = inv * vec4(x, y, -1, 1), e4 = inv * vec4(x, y, 1, 1);
            vec3 o = vec3(o4) / o4.w, dir = vec3(e4) / e4.w - o;
            // Intersect with the quad's plane, express in (u, v) = bilinear frame (a planar
            // parallelogram here: a + u (b - a) + v (d - a)).
            vec3 n = glm::cross(b - a, d - a);
            float t = glm::dot(a - o, n) / glm::dot(dir, n);
            vec3 q = o + t * dir - a;
            vec3 eu = b - a, ev = d - a;
            float uu = glm::dot(q, eu) / glm::dot(eu, eu), vv = glm::dot(q, ev) / glm::dot(ev, ev);
            if (uu < 0.01f || uu > 0.99f || vv < 0.01f || vv > 0.99f) continue;
            const uint8_t* c8 = px(fb, i, j);
            int wantI = int(std::floor(uu * T)), wantR = T - 1 - int(std::floor(vv * T));
            ++checked;
            if (std::abs(c8[0] - wantI) > 1 || std::abs(c8[1] - wantR) > 1) ++bad;
            // Screen-linear v for comparison: how wrong an affine interpolation would be.
            float vAffine = (y * 0.5f + 0.5f);
            if (std::abs(int(std::floor(vAffine * T)) - int(std::floor(vv * T))) > 3) ++affineWouldFail;
        }
    EXPECT_GT(checked, 3000);
    EXPECT_EQ(bad, 0) << "of " << checked;
    EXPECT_GT(affineWouldFail, checked / 4) << "the test scene should be strongly perspective";
}

// ---------------------------------------------------------------------------------------
// depth test
// ---------------------------------------------------------------------------------------

TEST(RasterDepthTest, NearerSurfaceWinsInEitherOrderAndFirstWinsTies) {
    const int W = 64, H = 64;
    auto nearQ = quadMesh({-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3});
    auto farQ = quadMesh({-4, -4, -6}, {4, -4, -6}, {4, 4, -6}, {-4, 4, -6});
    auto sameQ = quadMesh({-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3});
    Projection p;
    for (int order = 0; order < 2; ++order) {
        FrameInput f;
        f.camera = cameraAt(vec3(0), vec3(0, 0, -1), p, 1.0f);
        DrawMesh n = drawOf(nearQ, unlitMaterial(vec3(1, 0, 0))), fr = drawOf(farQ, unlitMaterial(vec3(0, 0, 1)));
        if (order == 0)
            f.meshes = {n, fr};
        else
            f.meshes = {fr, n};
        Framebuffer fb = renderRaster(f, W, H);
        const uint8_t* c = px(fb, 32, 32);
        EXPECT_EQ(c[0], 255);
        EXPECT_EQ(c[2], 0);
        // Depth = window z of the near quad: 0.5 * z_ndc + 0.5.
        vec4 clip = f.camera.proj * vec4(0, 0, -3, 1);
        EXPECT_NEAR(fb.depth[size_t(H - 1 - 32) * W + 32], 0.5f * clip.z / clip.w + 0.5f, 1e-5f);
        const uint8_t* edge = px(fb, 2, 2);   // only the far quad there
        EXPECT_EQ(edge[2], 255);
    }
    // Equal depth: LESS keeps the first one drawn.
    FrameInput f;
    f.camera = cameraAt(vec3(0), vec3(0, 0, -1), p, 1.0f);
    f.meshes = {drawOf(nearQ, unlitMaterial(vec3(0, 1, 0))), drawOf(sameQ, unlitMaterial(vec3(1, 0, 0)))};
    Framebuffer fb = renderRaster(f, W, H);
    EXPECT_EQ(px(fb, 32, 32)[1], 255);
    EXPECT_EQ(px(fb, 32, 32)[0], 0);
}

// ---------------------------------------------------------------------------------------
// shading: analytic intensity at the centre of a sphere, per shading model; fog
// ---------------------------------------------------------------------------------------

namespace {
// Sphere at the origin with a pole facing the camera on +z, a directional light from the
// camera: at the centre n = l = v, so L = ka rho La + L (kd rho + ks) (r.v = n.h = 1).
FrameInput sphereFrame(ShadingModel model, ReflectionModel refl) {
    auto sphere = std::make_shared<Mesh>(primitives::uvSphere(1.0f, 96, 96));
    Material m;
    m.baseColor = vec3(0.6f, 0.3f, 0.2f);
    m.ka = 0.2f;
    m.kd = 0.7f;
    m.ks = 0.25f;
    m.shininess = 20.0f;
    FrameInput f;
    f.meshes.push_back(drawOf(sphere, m, rotationX(kPi / 2)));   // pole +y -> +z
    DrawLight l;
    l.type = LightType::Directional;
    l.direction = vec3(0, 0, -1);
    l.radiance = vec3(0.8f);
    f.lights.push_back(l);
    f.ambientLight = vec3(0.5f);
    f.settings.shading = model;
    f.settings.reflection = refl;
    Projection p;
    p.fovyDeg = 40;
    f.camera = cameraAt(vec3(0, 0, 5), vec3(0), p, 1.0f);
    return f;
}
}   // namespace

TEST(RasterShadingTest, CentreOfSphereMatchesThePhongFormulaPerModel) {
    const vec3 rho(0.6f, 0.3f, 0.2f);
    const vec3 expected = 0.2f * rho * 0.5f + 0.8f * (0.7f * rho + vec3(0.25f));
    for (ShadingModel model : {ShadingModel::Flat, ShadingModel::Gouraud, ShadingModel::Phong})
        for (ReflectionModel refl : {ReflectionModel::Phong, ReflectionModel::BlinnPhong}) {
            FrameInput f = sphereFrame(model, refl);
            Framebuffer fb = renderRaster(f, 65, 65);   // odd size: the centre pixel sees the pole
            const uint8_t* c = px(fb, 32, 32);
            // Flat: the face normal of the pole triangles is tilted by ~1 degree.
            int tol = model == ShadingModel::Flat ? 3 : 1;
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(c[k], toByteSRGB(expected[k]), tol) << toString(model) << "/" << toString(refl) << " channel " << k;
        }
}

TEST(RasterShadingTest, BackFacesAreLitWithTheFlippedNormal) {
    // A quad seen from its back, light from the camera: two-sided lighting gives the front
    // colour; with culling it disappears.
    auto q = quadMesh({-1, -1, -3}, {-1, 1, -3}, {1, 1, -3}, {1, -1, -3});   // clockwise from the camera
    Material m;
    m.baseColor = vec3(0.5f);
    m.ks = 0;
    FrameInput f;
    f.meshes.push_back(drawOf(q, m));
    DrawLight l;
    l.type = LightType::Directional;
    l.direction = vec3(0, 0, -1);
    f.lights.push_back(l);
    f.ambientLight = vec3(0.0f);
    f.settings.background = vec3(0.0f);
    Projection p;
    f.camera = cameraAt(vec3(0), vec3(0, 0, -1), p, 1.0f);
    for (ShadingModel model : {ShadingModel::Flat, ShadingModel::Gouraud, ShadingModel::Phong}) {
        f.settings.shading = model;
        f.settings.culling = sg::CullMode::Off;
        Framebuffer fb = renderRaster(f, 32, 32);
        EXPECT_NEAR(px(fb, 16, 16)[0], toByteSRGB(0.8f * 0.5f), 1) << toString(model);
        f.settings.culling = sg::CullMode::On;
        fb = renderRaster(f, 32, 32);
        EXPECT_EQ(px(fb, 16, 16)[0], 0) << toString(model);
    }
    // Mirrored instances: the window winding flips but the side seen does not (GL:
    // glFrontFace(GL_CW)): the mirrored back face is still culled, a mirrored front face is not.
    f.settings.culling = sg::CullMode::On;
    f.meshes[0] = drawOf(q, m, scaling(vec3(-1, 1, 1)));
    Framebuffer fb = renderRaster(f, 32, 32);
    EXPECT_EQ(px(fb, 16, 16)[0], 0);
    auto front = quadMesh({-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3});
    f.meshes[0] = drawOf(front, m, scaling(vec3(-1, 1, 1)));
    fb = renderRaster(f, 32, 32);
    EXPECT_NEAR(px(fb, 16, 16)[0], toByteSRGB(0.8f * 0.5f), 1);
}

TEST(RasterShadingTest, FogBlendsAtAKnownDistance) {
    auto q = quadMesh({-1, -1, -8}, {1, -1, -8}, {1, 1, -8}, {-1, 1, -8});
    FrameInput f;
    vec3 c(0.9f, 0.2f, 0.1f);
    f.meshes.push_back(drawOf(q, unlitMaterial(c)));
    Projection p;
    f.camera = cameraAt(vec3(0), vec3(0, 0, -1), p, 1.0f);
    for (FogMode mode : {FogMode::Linear, FogMode::Exp, FogMode::Exp2}) {
        f.settings.fog = mode;
        f.settings.fogStart = 2;
        f.settings.fogEnd = 14;
        f.settings.fogDensity = 0.1f;
        f.settings.fogColor = vec3(0.3f, 0.5f, 0.7f);
        Framebuffer fb = renderRaster(f, 33, 33);
        float vis = fogVisibility(f.settings, 8.0f);   // the centre pixel is 8 units away
        vec3 want = vis * c + (1 - vis) * f.settings.fogColor;
        const uint8_t* got = px(fb, 16, 16);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], toByteSRGB(want[k]), 1) << toString(mode);
    }
}

TEST(RasterShadingTest, BatchedShadingMatchesRndShade) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f), P(0.0f, 1.0f);
    FrameInput f;
    f.camera.eye = vec3(0.3f, 2.0f, 6.0f);
    f.ambientLight = vec3(0.4f, 0.5f, 0.6f);
    DrawLight point;
    point.position = vec3(2, 3, 1);
    point.radiance = vec3(3, 2.5f, 2);
    point.inverseSquare = true;
    DrawLight dir;
    dir.type = LightType::Directional;
    dir.direction = glm::normalize(vec3(-0.3f, -1, -0.2f));
    dir.radiance = vec3(0.5f, 0.6f, 0.7f);
    DrawLight spot;
    spot.type = LightType::Spot;
    spot.position = vec3(-1, 4, 0);
    spot.direction = glm::normalize(vec3(0.2f, -1, 0));
    spot.radiance = vec3(2.0f);
    spot.cosInner = std::cos(radians(25));
    spot.cosOuter = std::cos(radians(40));
    f.lights = {point, dir, spot};
    for (ReflectionModel refl : {ReflectionModel::Phong, ReflectionModel::BlinnPhong}) {
        f.settings.reflection = refl;
        const size_t n = 1001;
        raster::ShadeBatch b;
        b.resize(n);
        std::vector<vec3> want(n);
        for (size_t i = 0; i < n; ++i) {
            Material m;
            m.baseColor = vec3(P(rng), P(rng), P(rng));
            m.ka = P(rng);
            m.kd = P(rng);
            m.ks = P(rng);
            m.shininess = 1 + 127 * P(rng);
            m.specularTinted = i % 3 == 0;
            m.emissive = i % 5 == 0 ? vec3(0.1f, 0.0f, 0.2f) : vec3(0.0f);
            m.unlit = i % 17 == 0;
            vec3 pos(2 * U(rng), 2 * U(rng), 2 * U(rng));
            vec3 nrm = glm::normalize(vec3(U(rng), U(rng), U(rng)) + vec3(0, 0.3f, 0));
            vec3 albedo = m.baseColor * vec3(P(rng), P(rng), P(rng));
            b.set(i, m, pos, nrm, albedo, f.ambientLight);
            want[i] = shade(m, SurfacePoint{pos, nrm, albedo}, f.camera.eye, f);
        }
        raster::shadeBatch(b, n, f);
        for (size_t i = 0; i < n; ++i) {
            vec3 got(b.cr[i], b.cg[i], b.cb[i]);
            for (int k = 0; k < 3; ++k) ASSERT_NEAR(got[k], want[i][k], 2e-4f + 2e-4f * std::fabs(want[i][k])) << "fragment " << i;
        }
    }
}

// The pbr kernel (pbr_kernel.inl) against rnd::shade's pbr path: random metal/roughness and
// specular-glossiness points under a point light with a range, a sun and a spot, with and
// without the default environment (its lookups vectorised too), through setPbr and through
// constant blocks. Both instruction sets run in CI (the SSE2 run sets VIEWER_RASTER_SSE).
TEST(RasterShadingTest, BatchedPbrShadingMatchesRndShade) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f), P(0.0f, 1.0f);
    FrameInput f;
    f.settings.reflection = ReflectionModel::Pbr;
    f.camera.eye = vec3(0.3f, 2.0f, 6.0f);
    DrawLight point;
    point.position = vec3(2, 3, 1);
    point.radiance = vec3(30, 25, 20);
    point.inverseSquare = true;
    point.range = 6.0f;
    DrawLight dir;
    dir.type = LightType::Directional;
    dir.direction = glm::normalize(vec3(-0.3f, -1, -0.2f));
    dir.radiance = vec3(2.5f, 2.6f, 2.7f);
    DrawLight spot;
    spot.type = LightType::Spot;
    spot.position = vec3(-1, 4, 0);
    spot.direction = glm::normalize(vec3(0.2f, -1, 0));
    spot.radiance = vec3(20.0f);
    spot.inverseSquare = true;
    spot.cosInner = std::cos(radians(25));
    spot.cosOuter = std::cos(radians(40));
    f.lights = {point, dir, spot};
    for (const char* envName : {"none", "default"}) {
        f.settings.environment = envName;
        f.settings.environmentRotationDeg = 40.0f;
        f.settings.environmentIntensity = 1.3f;
        const EnvironmentLight env = environmentFor(f.settings);
        ASSERT_EQ(bool(env.map), std::string(envName) == "default");
        const size_t n = 1001;
        raster::ShadeBatch b;
        b.resize(n);
        std::vector<vec3> want(n);
        for (size_t i = 0; i < n; ++i) {
            Material m;
            m.baseColor = vec3(P(rng), P(rng), P(rng));
            m.metallic = i % 4 == 0 ? 1.0f : P(rng);
            m.roughness = i % 7 == 0 ? 0.0f : P(rng);   // 0: the clamped 1e-3, a mirror's lobe
            m.ior = 1.2f + P(rng);
            m.emissive = i % 5 == 0 ? vec3(0.1f, 0.0f, 0.2f) : vec3(0.0f);
            m.specularGlossiness = i % 9 == 0;
            m.glossiness = P(rng);
            m.unlit = i % 17 == 0;
            SurfaceCoefficients c = coefficientsOf(m);
            c.occlusion = i % 3 == 0 ? P(rng) : 1.0f;
            const vec3 pos(2 * U(rng), 2 * U(rng), 2 * U(rng));
            const vec3 nrm = glm::normalize(vec3(U(rng), U(rng), U(rng)) + vec3(0, 0.3f, 0));
            const vec3 albedo = m.baseColor * vec3(P(rng), P(rng), P(rng));
            if (c.unlit)
                b.setColor(i, albedo + c.emissive);
            else if (i % 2 == 0)
                b.setPbr(i, pos, nrm, pbrPoint(c, albedo), albedo, c.occlusion, c.emissive);
            else {   // the plain-material path: position and normal per fragment, the rest a constant block
                b.setPbr(i, pos, nrm, pbrPoint(c, albedo), albedo, c.occlusion, c.emissive);
                b.mat[i] = b.addConstants(raster::ShadeBatch::pbrConstants(pbrPoint(c, albedo), albedo, c.occlusion, c.emissive));
                b.ar[i] = b.sr[i] = b.kd[i] = b.ks[i] = b.cr[i] = -7.0f;   // must come from the block
            }
            want[i] = shade(c, SurfacePoint{pos, nrm, albedo}, f.camera.eye, f, nullptr, &env);
        }
        raster::shadeBatch(b, n, f, &env);
        for (size_t i = 0; i < n; ++i) {
            vec3 got(b.cr[i], b.cg[i], b.cb[i]);
            for (int k = 0; k < 3; ++k)
                ASSERT_NEAR(got[k], want[i][k], 1e-4f + 2e-4f * std::fabs(want[i][k])) << "fragment " << i << " environment " << envName;
        }
    }
}

// The vector shadow lookup (shadow_kernel.inl) against rnd::shadowVisibility: a map of random
// triangles over a ground, points on and above the ground with random normals, for a sun and a
// spot with PCF 3 x 3; both instruction sets in CI (raster_shading_sse2 forces SSE2). A tap whose
// comparison is within a float's rounding of the texel's depth may go either way: at most a
// few lanes in a thousand, by one tap.
TEST(RasterShadingTest, VectorShadowLookupMatchesScalar) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f), P(0.0f, 1.0f);
    std::vector<vec3> tris;
    for (int t = 0; t < 300; ++t) {
        const vec3 c(3 * U(rng), 0.5f + 2 * P(rng), 3 * U(rng));
        for (int k = 0; k < 3; ++k) tris.push_back(c + 0.4f * vec3(U(rng), U(rng), U(rng)));
    }
    for (LightType type : {LightType::Directional, LightType::Spot}) {
        FrameInput f;
        f.camera = cameraAt(vec3(0, 6, 8), vec3(0, 0, 0), Projection{}, 1.0f);
        DrawLight L;
        L.type = type;
        L.position = vec3(0.5f, 7, 1);
        L.direction = glm::normalize(vec3(0.2f, -1, -0.1f));
        L.cosInner = std::cos(radians(40));
        L.cosOuter = std::cos(radians(50));
        f.lights = {L};
        f.settings.shadowMapSize = 512;
        const rnd::ShadowPlan plan = rnd::planShadows(f, sg::Aabb{vec3(-4, 0, -4), vec3(4, 3, 4)});
        ASSERT_EQ(plan.views.size(), 1u);
        rnd::ShadowMaps maps;
        maps.size = plan.size;
        maps.depth.resize(size_t(plan.size) * size_t(plan.size));
        rnd::ShadowCaster c;
        c.positions = tris.data();
        c.stride = sizeof(vec3);
        c.triangles = tris.size() / 3;
        c.vertices = tris.size();
        rnd::renderShadowDepth(plan.views[0], plan.size, {c}, maps.map(0));
        const size_t n = 4000;
        raster::ShadeBatch b;
        b.resize(n);
        for (size_t i = 0; i < n; ++i) {
            const vec3 p(3.5f * U(rng), i % 4 == 0 ? 2.5f * P(rng) : 0.0f, 3.5f * U(rng));
            const vec3 nrm = i % 3 == 0 ? glm::normalize(vec3(U(rng), U(rng), U(rng))) : vec3(0, 1, 0);
            b.set(i, coefficientsOf(Material{}), p, nrm, vec3(1.0f), vec3(0.0f));
        }
        std::vector<float> out(n + 8, -1.0f);
        const size_t W = raster::shadowLookupWidth();
        ASSERT_GT(W, 0u);
        for (size_t i = 0; i + W <= n; i += W)
            raster::shadowLookupVector(plan, plan.views[0], maps.map(0), type == LightType::Directional ? L.direction : L.position,
                                       type != LightType::Directional, b, i, out.data());
        size_t differ = 0, shadowed = 0;
        for (size_t i = 0; i < n; ++i) {
            const float want = rnd::shadowVisibility(plan, maps, L, 0, vec3(b.px[i], b.py[i], b.pz[i]), vec3(b.nx[i], b.ny[i], b.nz[i]));
            shadowed += want < 1.0f;
            if (out[i] != want) {
                ++differ;
                EXPECT_NEAR(out[i], want, 1.0f / 9.0f + 1e-6f) << "fragment " << i;
            }
        }
        EXPECT_GT(shadowed, n / 20) << "the test's triangles must shadow part of the ground";
        EXPECT_LE(differ, n / 200) << differ << " lanes differ";
    }
}

// The shadow depth pass's vector kernel (shadow_depth_kernel.inl) against its scalar reference,
// bit for bit: random triangles of every size (below a texel, slivers, larger than the map,
// crossing the near plane of a perspective map) for a sun, a spot and a point light's faces, and
// triangles whose corners and edges lie on texel centres (the top-left rule decides those) in a
// map whose window coordinates are the world's. Both instruction sets in CI (raster_shading_sse2
// forces SSE2).
TEST(RasterShadingTest, VectorShadowDepthMatchesScalar) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f), P(0.0f, 1.0f);
    std::vector<vec3> tris;
    for (int t = 0; t < 3000; ++t) {
        const float scale = t % 5 == 0 ? 0.003f : t % 5 == 1 ? 0.05f : t % 5 == 2 ? 0.4f : t % 5 == 3 ? 2.0f : 9.0f;
        const vec3 c(4 * U(rng), 1.5f + 1.5f * U(rng), 4 * U(rng));
        if (t % 7 == 0) {   // a sliver: two corners close, one far
            const vec3 d = scale * vec3(U(rng), U(rng), U(rng));
            tris.push_back(c);
            tris.push_back(c + d);
            tris.push_back(c + d + 1e-3f * vec3(U(rng), U(rng), U(rng)));
            continue;
        }
        for (int k = 0; k < 3; ++k) tris.push_back(c + scale * vec3(U(rng), U(rng), U(rng)));
    }
    rnd::ShadowCaster c;
    c.positions = tris.data();
    c.stride = sizeof(vec3);
    c.triangles = tris.size() / 3;
    c.vertices = tris.size();
    std::vector<rnd::ShadowView> views;
    for (LightType type : {LightType::Directional, LightType::Spot, LightType::Point}) {
        FrameInput f;
        f.camera = cameraAt(vec3(0, 6, 8), vec3(0, 0, 0), Projection{}, 1.0f);
        DrawLight L;
        L.type = type;
        L.position = vec3(0.5f, type == LightType::Point ? 1.5f : 7.0f, 1);
        L.direction = glm::normalize(vec3(0.2f, -1, -0.1f));
        L.cosInner = std::cos(radians(40));
        L.cosOuter = std::cos(radians(50));
        f.lights = {L};
        f.settings.shadows = true;
        f.settings.shadowMapSize = 203;   // bands and vectors that do not divide it
        const rnd::ShadowPlan plan = rnd::planShadows(f, sg::Aabb{vec3(-4, 0, -4), vec3(4, 3, 4)});
        ASSERT_FALSE(plan.empty());
        views.insert(views.end(), plan.views.begin(), plan.views.end());
    }
    auto compare = [&](const rnd::ShadowView& v, int size, const std::vector<rnd::ShadowCaster>& casters, const char* what) {
        std::vector<float> want(size_t(size) * size_t(size), -1.0f), got(want.size(), -2.0f);
        rnd::renderShadowDepth(v, size, casters, want.data(), rnd::ShadowDepthKernel::Scalar);
        rnd::renderShadowDepth(v, size, casters, got.data(), rnd::ShadowDepthKernel::Auto);
        size_t differ = 0, covered = 0;
        for (size_t i = 0; i < want.size(); ++i) {
            covered += want[i] < 1.0f;
            differ += std::memcmp(&want[i], &got[i], sizeof(float)) != 0;
        }
        EXPECT_EQ(differ, 0u) << what << ": " << differ << " texels differ (" << rnd::shadowDepthKernelName(rnd::ShadowDepthKernel::Auto) << ")";
        EXPECT_GT(covered, want.size() / 50) << what << ": the triangles must cover part of the map";
    };
    for (size_t i = 0; i < views.size(); ++i) compare(views[i], 203, {c}, views[i].perspective ? "perspective view" : "orthographic view");
    // Window coordinates = world x, y exactly (a power-of-two map): corners on texel centres and
    // edges through them, both windings, depths inside and outside [0, 1].
    rnd::ShadowView grid;
    grid.view = sg::mat4(1.0f);
    grid.viewProj = glm::ortho(0.0f, 256.0f, 0.0f, 256.0f, -1.0f, 1.0f);
    std::vector<vec3> snapped;
    std::uniform_int_distribution<int> I(-8, 520), S(1, 24);
    for (int t = 0; t < 4000; ++t) {
        const float x = 0.5f * float(I(rng)), y = 0.5f * float(I(rng));
        const float s = 0.5f * float(S(rng)) * (t % 3 == 0 ? 8.0f : 1.0f);
        const float z0 = 1.2f * U(rng), z1 = 1.2f * U(rng), z2 = 1.2f * U(rng);
        const int shape = t % 4;
        const vec3 a(x, y, z0);
        const vec3 b = shape == 0 ? vec3(x + s, y, z1) : shape == 1 ? vec3(x, y + s, z1) : vec3(x + s, y + 0.5f * float(S(rng)), z1);
        const vec3 d = shape == 2 ? vec3(x - 0.5f * float(S(rng)), y + s, z2) : vec3(x + 0.5f * float(S(rng)), y + s, z2);
        snapped.push_back(a);
        if (t % 2 == 0) {
            snapped.push_back(b);
            snapped.push_back(d);
        } else {
            snapped.push_back(d);
            snapped.push_back(b);
        }
    }
    rnd::ShadowCaster g;
    g.positions = snapped.data();
    g.stride = sizeof(vec3);
    g.triangles = snapped.size() / 3;
    g.vertices = snapped.size();
    compare(grid, 256, {g}, "texel-centre grid");
    compare(grid, 256, {g, c}, "texel-centre grid and random triangles");
}

// A renderer keeps its shadow maps when a frame's plan and casters are the last frame's; every
// frame of a sequence (the same frame again, a caster moved, a mesh edited in place, the camera
// moved, a blended caster, shadows off and on) matches a new renderer's image exactly.
TEST(RasterShadowTest, KeptMapsMatchNewlyDrawnOnes) {
    Material m;
    m.baseColor = vec3(0.7f);
    m.ka = 0.2f;
    m.kd = 0.8f;
    m.ks = 0.0f;
    m.doubleSided = true;
    auto ground = quadMesh({-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4});
    auto box = std::make_shared<Mesh>(primitives::box(vec3(0.6f, 0.3f, 0.5f)));
    FrameInput f0;
    f0.meshes.push_back(drawOf(ground, m));
    f0.meshes.push_back(drawOf(box, m, glm::translate(mat4(1.0f), vec3(-0.5f, 1.2f, 0.0f))));
    DrawLight sun;
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(vec3(0.3f, -1.0f, -0.2f));
    sun.radiance = vec3(1.0f);
    f0.lights = {sun};
    f0.ambientLight = vec3(0.5f);
    f0.settings.shadows = true;
    f0.settings.shadowMapSize = 512;
    Projection p;
    f0.camera = cameraAt(vec3(0, 6, 7), vec3(0, 0, 0), p, 1.0f);
    FrameInput moved = f0;
    moved.meshes[1] = drawOf(box, m, glm::translate(mat4(1.0f), vec3(0.7f, 1.2f, 0.3f)));
    FrameInput camera = f0;
    camera.camera = cameraAt(vec3(1, 5, 7), vec3(0, 0, 0), p, 1.0f);
    FrameInput blended = f0;
    blended.meshes[1].material.alphaMode = AlphaMode::Blend;
    blended.meshes[1].material.alpha = 0.5f;
    FrameInput off = f0;
    off.settings.shadows = false;
    auto edited = std::make_shared<Mesh>(*box);
    FrameInput editedFrame = f0;
    editedFrame.meshes[1] = drawOf(edited, m, f0.meshes[1].world);
    auto r = makeRenderer("raster");
    ASSERT_TRUE(r);
    auto check = [&](const FrameInput& f, const char* what) -> Framebuffer {
        Framebuffer kept;
        RenderStats st = r->render(f, 96, 96, kept);
        EXPECT_TRUE(st.ok) << st.error;
        const Framebuffer fresh = renderRaster(f, 96, 96);
        EXPECT_TRUE(kept.color == fresh.color) << what;
        return kept;
    };
    const Framebuffer a = check(f0, "first frame");
    check(f0, "the same frame again");
    const Framebuffer b = check(moved, "a caster moved");
    EXPECT_FALSE(a.color == b.color) << "the moved caster's shadow must move";
    check(moved, "the moved caster again");
    check(editedFrame, "the same mesh in another object");
    for (vec3& q : edited->positions) q.y *= 2.0f;   // edited in place: the same mesh object
    check(editedFrame, "the mesh edited in place");
    check(camera, "the camera moved");
    check(blended, "the caster blended (casts nothing)");
    check(off, "shadows off");
    check(f0, "shadows on again");
}

// ---------------------------------------------------------------------------------------
// anti-aliasing, progress, cancellation, lines
// ---------------------------------------------------------------------------------------

TEST(RasterAATest, MsaaAndSsaaSmoothEdgesAndKeepInteriors) {
    auto mesh = std::make_shared<Mesh>();
    mesh->positions = {{-0.9f, -0.7f, -3}, {0.8f, -0.9f, -3}, {0.1f, 0.95f, -3}};
    mesh->indices = {0, 1, 2};
    FrameInput f;
    f.meshes.push_back(drawOf(mesh, unlitMaterial(vec3(1.0f))));
    f.settings.background = vec3(0.0f);
    Projection p;
    f.camera = cameraAt(vec3(0), vec3(0, 0, -1), p, 1.0f);
    auto countPartial = [](const Framebuffer& fb) {
        int n = 0;
        for (size_t i = 0; i < fb.color.size(); i += 4) n += fb.color[i] > 0 && fb.color[i] < 255;
        return n;
    };
    Framebuffer none = renderRaster(f, 64, 64);
    EXPECT_EQ(countPartial(none), 0);
    for (auto [mode, rate] : {std::pair{AAMode::MSAA, 4}, std::pair{AAMode::SSAA, 2}, std::pair{AAMode::SSAA, 4}}) {
        f.settings.aa = mode;
        f.settings.aaRate = rate;
        Framebuffer fb = renderRaster(f, 64, 64);
        ASSERT_EQ(fb.width, 64);
        EXPECT_GT(countPartial(fb), 40);
        EXPECT_EQ(px(fb, 32, 32)[0], 255);
        EXPECT_EQ(px(fb, 1, 62)[0], 0);
        auto d = compareImages(fb, none, 255);
        EXPECT_LT(d.meanAbs, 10.0) << d.describe();
    }
}

TEST(RasterRendererTest, ReportsProgressAndHonoursCancel) {
    auto q = quadMesh({-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3});
    FrameInput f;
    f.meshes.push_back(drawOf(q, unlitMaterial(vec3(1.0f))));
    Projection p;
    f.camera = cameraAt(vec3(0), vec3(0, 0, -1), p, 1.0f);
    RenderControl ctl;
    std::atomic<int> tiles{0};
    ctl.onTileDone = [&] { ++tiles; };
    RenderStats s;
    renderRaster(f, 200, 130, &s, &ctl);
    EXPECT_TRUE(s.ok);
    EXPECT_EQ(tiles.load(), 4 * 3);
    EXPECT_FLOAT_EQ(ctl.progress.load(), 1.0f);
    RenderControl cancel;
    cancel.cancel = true;
    renderRaster(f, 200, 130, &s, &cancel);
    EXPECT_FALSE(s.ok);
    EXPECT_TRUE(s.cancelled);
    EXPECT_TRUE(makeRenderer("raster")->capabilities().progressive);
}

TEST(RasterRendererTest, LinesPointsAndWireframe) {
    auto lines = std::make_shared<Mesh>();
    lines->mode = PrimitiveMode::Lines;
    lines->positions = {{-1, 0, -3}, {1, 0, -3}, {0, -1, -3}, {0, 1, -3}};
    lines->indices = {0, 1, 2, 3};
    auto points = std::make_shared<Mesh>();
    points->mode = PrimitiveMode::Points;
    points->positions = {{0.5f, 0.5f, -3}};
    points->indices = {0};
    FrameInput f;
    f.meshes.push_back(drawOf(lines, unlitMaterial(vec3(1, 0, 0))));
    f.meshes.push_back(drawOf(points, unlitMaterial(vec3(0, 1, 0))));
    f.settings.background = vec3(0.0f);
    Projection p;
    p.fovyDeg = 90;
    f.camera = cameraAt(vec3(0), vec3(0, 0, -1), p, 1.0f);
    Framebuffer fb = renderRaster(f, 61, 61);
    int red = 0, green = 0;
    for (size_t i = 0; i < fb.color.size(); i += 4) {
        red += fb.color[i] == 255 && fb.color[i + 1] == 0;
        green += fb.color[i + 1] == 255;
    }
    EXPECT_GE(red, 2 * 19);   // two segments ~20 px long (1/3 of the view), 1 px wide
    EXPECT_LE(red, 2 * 22);
    EXPECT_EQ(green, 4);   // points are 2x2 pixels, like GL with point size 2
    // Wireframe overlay over a quad draws the edge colour along the outline.
    auto q = quadMesh({-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3});
    FrameInput g;
    g.meshes.push_back(drawOf(q, unlitMaterial(vec3(1.0f))));
    g.settings.wireframe = true;
    g.settings.wireframeColor = vec3(0.0f);
    g.settings.background = vec3(0.0f, 0.0f, 1.0f);
    g.camera = f.camera;
    Framebuffer wf = renderRaster(g, 61, 61);
    int dark = 0;
    for (size_t i = 0; i < wf.color.size(); i += 4) dark += wf.color[i] == 0 && wf.color[i + 2] == 0;
    EXPECT_GT(dark, 4 * 15);   // outline + diagonal
}

TEST(RasterRendererTest, BadGeometryIsSkippedNotCrashed) {
    auto mesh = std::make_shared<Mesh>();
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    mesh->positions = {{0, 0, -3}, {1, 0, -3}, {nan, 1, -3}, {inf, 0, -3}, {1e30f, -1e30f, -3}, {0, 1, -3}, {0.5f, 0.5f, 1e-30f}};
    mesh->indices = {0, 1, 2, 0, 3, 1, 0, 4, 5, 0, 1, 5, 0, 1, 6, 0, 1, 99};   // last: index out of range
    FrameInput f;
    f.meshes.push_back(drawOf(mesh, unlitMaterial(vec3(1.0f))));
    f.settings.background = vec3(0.0f);
    f.settings.wireframe = true;
    Projection p;
    f.camera = cameraAt(vec3(0), vec3(0, 0, -1), p, 1.0f);
    RenderStats s;
    Framebuffer fb = renderRaster(f, 64, 64, &s);
    EXPECT_TRUE(s.ok) << s.error;
    EXPECT_EQ(px(fb, 40, 36)[0], 255);   // the valid triangle (0, 1, 5) is drawn
    // Degenerate sizes are reported, not crashed on.
    Framebuffer empty;
    EXPECT_FALSE(makeRenderer("raster")->render(f, 0, 10, empty).ok);
}

// Mip levels of a non-power-of-two texture are built like GL's linear-blit glGenerateMipmap:
// level texel x samples the level above bilinearly at (x + 0.5) * w_prev / w - 0.5. A 3x1
// texture red | green | blue has a 1x1 level 1 that is exactly green (the centre texel), not the
// red-green average a 2x2 box would give; even sizes keep the box average.
TEST(TextureSamplerTest, NpotMipLevelsAreBuiltLikeGlsBlit) {
    sg::Texture t;
    t.width = 3;
    t.height = 1;
    t.rgba = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255};
    t.filter = sg::FilterMode::Trilinear;
    rnd::SampledTexture s(t);
    ASSERT_EQ(s.levels(), 2);
    const sg::vec3 l1 = s.sampleLevel(sg::vec2(0.5f, 0.5f), 1, false);
    EXPECT_NEAR(l1.r, 0.0f, 1e-6f);
    EXPECT_NEAR(l1.g, 1.0f, 1e-6f);
    EXPECT_NEAR(l1.b, 0.0f, 1e-6f);
    // 2x1 red | green: the box average, (0.5, 0.5, 0) in linear light (re-quantised to sRGB bytes).
    t.width = 2;
    t.rgba = {255, 0, 0, 255, 0, 255, 0, 255};
    rnd::SampledTexture e(t);
    const sg::vec3 half = e.sampleLevel(sg::vec2(0.5f, 0.5f), 1, false);
    const uint8_t b[3] = {rnd::toByteSRGB(0.5f), rnd::toByteSRGB(0.5f), 0};
    const sg::vec3 want = rnd::srgbBytesToLinear(b);
    EXPECT_NEAR(half.r, want.r, 1e-6f);
    EXPECT_NEAR(half.g, want.g, 1e-6f);
    EXPECT_NEAR(half.b, 0.0f, 1e-6f);
}
