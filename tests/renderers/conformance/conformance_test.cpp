// conformance_test.cpp - BackendConformance: every backend in rnd::rendererNames() x every
// reference scene, each image held to an answer computed from the formulas
// (conformance_formulas.h), never to another backend:
//   sphere_*      a lit unit sphere, one light without attenuation, for each shading model
//                 (flat, Gouraud, Phong) x reflection model (Phong, Blinn-Phong) x light
//                 (directional, point). Phong shading: a 256 x 128 sphere, each interior pixel
//                 (n.v > 0.3, away from the silhouette) equals the formula at the exact sphere
//                 hit of its camera ray, within 3/255. Flat and Gouraud differ from that by
//                 construction, so they are checked for what they must be on a coarse 24 x 12
//                 sphere whose triangles are 15-25 px wide: flat = the formula once per
//                 triangle, at its first vertex with its face normal (the seeds: evaluated
//                 at one vertex, every fragment takes that colour); Gouraud = the
//                 formula at the three vertices (vertex normal, vertex position, per-vertex
//                 view vector), interpolated with the hit's barycentrics (perspective-correct);
//                 both within 2/255 at pixels >= 1 px from every triangle edge.
//   fog_*         an unlit plane receding to 40 units: colour = f(d) C + (1 - f(d)) C_fog with
//                 d the eye-space distance of the pixel's hit point, linear / exp / exp2, 2/255.
//   texture_*     a 4x4 nearest-filtered texture of distinct colours on a quad, head-on
//                 (orthographic) and tilted under perspective: 9 points per texel, mapped
//                 through the uv mapping to world and projected, show that texel (1/255).
//   projection_*  an unlit box under perspective, orthographic, cavalier and cabinet: the 8
//                 corners projected with the projection formulas written out below (and
//                 checked against the frame's matrices); pixels more than 1 px inside the
//                 corners' hull are lit, more than 1 px outside are background, and the
//                 footprint's bounding box and centroid are within 1 px of the prediction.
//   aa_*          an unlit white square turned 20 degrees on black: AA off gives binary pixels,
//                 lit exactly where the pixel centre is inside; with MSAA 4 / SSAA 2x2 / SSAA
//                 4x4 every pixel's linear value is the covered area of its square (clipped
//                 exactly), within a bound for its sample count (below).
//   tonemap_*     exposure and tone mapping (renderers/tone_map.h): an unlit quad of linear
//                 colour (2.4, 0.6, 0.05) - above 1 in red - over the left half of an
//                 orthographic view, the background (0.9, 0.6, 0.3) on the right: every pixel
//                 away from the edge is encodeSRGB(T(2^EV c)) of its colour (surface and
//                 background alike) within 1/255, for each operator at a few exposures, and
//                 with MSAA / SSAA (a constant colour resolves to itself).
//   aa_*_ev2      the aa_* edge at +2 EV (no operator): the display transform comes after the
//                 resolve, so a pixel whose square the quad covers by c shows min(4 c, 1) -
//                 white from c = 1/4 on - where mapping each sample before averaging would show
//                 c: the pixels 30-70% covered must be white, the others within the aa_* bound
//                 mapped through the transform.
// A failure prints the pixels (position, expected, actual) and writes -actual/-expected/-diff
// PNGs to build/<preset>/test-output/conformance/. When the GL backend cannot get a context
// its instances fail with the reason (RenderStats::error); nothing is skipped silently.
#include "conformance_formulas.h"
#include "render_support.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>

using namespace sg;
using namespace conformance;
using testing_support::PixelCheck;

namespace {

const char* kSuite = "conformance";

// Renders with a fresh backend; fails the test with the backend's reason when it cannot.
using testing_support::renderBackend;

rnd::Framebuffer blankImage(int w, int h, const vec3& background) {
    rnd::Framebuffer fb;
    fb.resize(w, h);
    const auto b = toBytes(background);
    const uint8_t rgba[4] = {b[0], b[1], b[2], 255};
    fb.clear(rgba);
    return fb;
}

void setPixel(rnd::Framebuffer& fb, int x, int row, const std::array<uint8_t, 3>& c) {
    for (int ch = 0; ch < 3; ++ch) fb.pixel(x, row)[ch] = c[size_t(ch)];
}

PixelCheck check(int x, int row, const std::array<uint8_t, 3>& c, int tol) {
    PixelCheck p;
    p.x = x;
    p.y = row;
    for (int ch = 0; ch < 3; ++ch) p.expected[ch] = c[size_t(ch)];
    p.tolerance = tol;
    return p;
}

std::string caseName(const std::string& backend, const std::string& scene) { return backend + "-" + scene; }

// ---------------------------------------------------------------------------------------
// Lit sphere.

void checkLitSphere(const std::string& backend, ShadingModel shading, ReflectionModel refl, test_scenes::SphereLight light,
                    const std::string& scene) {
    const int W = 161, H = 161;
    const bool phong = shading == ShadingModel::Phong;
    const FrameInput f = test_scenes::litSphereFrame(W, H, shading, refl, light, phong ? 256 : 24);
    rnd::Framebuffer actual;
    ASSERT_TRUE(renderBackend(backend, f, W, H, actual));

    const DrawMesh& dm = f.meshes[0];
    const Material& m = dm.material;
    const vec3 eye = f.camera.eye;
    const Mesh& mesh = *dm.mesh;
    // World-space triangles of the tessellated sphere (world = identity, kept general).
    std::vector<vec3> P(mesh.positions.size()), N(mesh.positions.size());
    for (size_t i = 0; i < P.size(); ++i) {
        P[i] = vec3(dm.world * vec4(mesh.positions[i], 1.0f));
        N[i] = glm::normalize(dm.normal * mesh.normals[i]);
    }
    std::vector<vec3> vertexColour(P.size());
    for (size_t i = 0; i < P.size(); ++i) vertexColour[i] = phongRadiance(m, m.baseColor, P[i], N[i], eye, f);

    rnd::Framebuffer expected = blankImage(W, H, f.settings.background);
    std::vector<PixelCheck> checks;
    const int tol = phong ? 3 : 2;
    double maxModelGap = 0;   // how far the checked model is from per-pixel Phong on the true sphere
    for (int row = 0; row < H; ++row)
        for (int x = 0; x < W; ++x) {
            const Ray ray = pixelRay(f.camera, W, H, x, row);
            const float ts = hitSphere(ray, vec3(0.0f), 1.0f);
            vec3 exact(0.0f);
            float nv = -1.0f;
            if (ts > 0.0f) {
                const vec3 p = ray.org + ts * ray.dir, n = glm::normalize(p);
                exact = phongRadiance(m, m.baseColor, p, n, eye, f);
                nv = glm::dot(n, glm::normalize(eye - p));
            }
            if (phong) {
                if (ts <= 0.0f) continue;
                const auto c = toBytes(exact);
                setPixel(expected, x, row, c);
                if (nv > 0.3f) checks.push_back(check(x, row, c, tol));
                continue;
            }
            // Flat / Gouraud: the triangle this pixel's ray meets first.
            float best = 1e30f;
            size_t tri = SIZE_MAX;
            vec3 bary;
            for (size_t k = 0; k + 2 < mesh.indices.size(); k += 3) {
                float t;
                vec3 b;
                if (hitTriangle(ray, P[mesh.indices[k]], P[mesh.indices[k + 1]], P[mesh.indices[k + 2]], t, b) && t < best)
                    best = t, tri = k, bary = b;
            }
            if (tri == SIZE_MAX) continue;
            const uint32_t i0 = mesh.indices[tri], i1 = mesh.indices[tri + 1], i2 = mesh.indices[tri + 2];
            const vec3 p = ray.org + best * ray.dir;
            vec3 c;
            if (shading == ShadingModel::Flat) {
                vec3 n = glm::normalize(glm::cross(P[i1] - P[i0], P[i2] - P[i0]));
                if (glm::dot(n, eye - p) < 0.0f) n = -n;
                c = phongRadiance(m, m.baseColor, P[i0], n, eye, f);
            } else {
                c = bary.x * vertexColour[i0] + bary.y * vertexColour[i1] + bary.z * vertexColour[i2];
            }
            const auto cb = toBytes(c);
            setPixel(expected, x, row, cb);
            // Away from the triangle's edges (window space) and from the silhouette.
            const vec2 q(float(x) + 0.5f, float(H - 1 - row) + 0.5f);
            const vec2 a = toWindow(f.camera.viewProj, P[i0], W, H), b = toWindow(f.camera.viewProj, P[i1], W, H),
                       d = toWindow(f.camera.viewProj, P[i2], W, H);
            const float s = leftOf(a, b, d) > 0 ? 1.0f : -1.0f;   // orient the edges inward
            const float edge = std::min({s * leftOf(a, b, q), s * leftOf(b, d, q), s * leftOf(d, a, q)});
            if (edge >= 1.0f && nv > 0.2f) {
                checks.push_back(check(x, row, cb, tol));
                const auto e = toBytes(exact);
                for (int ch = 0; ch < 3; ++ch) maxModelGap = std::max(maxModelGap, std::abs(double(e[size_t(ch)]) - cb[size_t(ch)]));
            }
        }
    if (!phong)
        std::printf("[sphere] %s: the %s answer differs from per-pixel Phong on the true sphere by up to %.0f/255 at the checked pixels\n",
                    scene.c_str(), std::string(toString(shading)).c_str(), maxModelGap);
    EXPECT_GT(checks.size(), 1000u) << "too few interior pixels";
    EXPECT_TRUE(testing_support::pixelsMatch(actual, expected, checks, kSuite, caseName(backend, scene)));
}

// ---------------------------------------------------------------------------------------
// Fog.

void checkFog(const std::string& backend, FogMode mode, const std::string& scene) {
    const int W = 160, H = 120;
    const FrameInput f = test_scenes::fogPlaneFrame(W, H, mode);
    rnd::Framebuffer actual;
    ASSERT_TRUE(renderBackend(backend, f, W, H, actual));
    const vec3 colour = f.meshes[0].material.baseColor;
    const float planeY = f.meshes[0].world[3][1];
    rnd::Framebuffer expected = blankImage(W, H, f.settings.background);
    std::vector<PixelCheck> checks;
    float dMin = 1e30f, dMax = 0;
    for (int row = 0; row < H; ++row)
        for (int x = 0; x < W; ++x) {
            const Ray ray = pixelRay(f.camera, W, H, x, row);
            if (ray.dir.y >= 0.0f) continue;
            const float t = (planeY - ray.org.y) / ray.dir.y;
            const vec3 p = ray.org + t * ray.dir;
            if (std::abs(p.x) > 39.0f || std::abs(p.z) > 39.0f) continue;
            // Eye-space distance = world distance from the eye (the view transform is rigid).
            const float d = glm::length(vec3(f.camera.view * vec4(p, 1.0f)));
            const float vis = fogFactor(f.settings, d);
            const auto c = toBytes(vis * colour + (1.0f - vis) * f.settings.fogColor);
            setPixel(expected, x, row, c);
            if (x % 3 == 0 && row % 3 == 0) {
                checks.push_back(check(x, row, c, 2));
                dMin = std::min(dMin, d), dMax = std::max(dMax, d);
            }
        }
    std::printf("[fog] %s: %zu pixels at eye distances %.2f .. %.2f\n", scene.c_str(), checks.size(), dMin, dMax);
    EXPECT_GT(dMax - dMin, 10.0f);
    EXPECT_TRUE(testing_support::pixelsMatch(actual, expected, checks, kSuite, caseName(backend, scene)));
}

// ---------------------------------------------------------------------------------------
// Textured quad.

void checkTexture(const std::string& backend, bool tilted, const std::string& scene) {
    const int W = 161, H = 161;
    const FrameInput f = test_scenes::texturedQuadFrame(W, H, tilted);
    rnd::Framebuffer actual;
    ASSERT_TRUE(renderBackend(backend, f, W, H, actual));
    const Texture& tex = *f.meshes[0].texture;
    const mat4& world = f.meshes[0].world;
    // quad(1): position (-1 + 2u, -1 + 2v, 0); texture row 0 is v = 1 (top).
    rnd::Framebuffer expected = blankImage(W, H, f.settings.background);
    std::vector<PixelCheck> checks;
    for (int j = 0; j < tex.height; ++j)
        for (int i = 0; i < tex.width; ++i) {
            const uint8_t* t = &tex.rgba[size_t(j * tex.width + i) * 4];
            const std::array<uint8_t, 3> c = {t[0], t[1], t[2]};
            for (float oy : {-0.3f, 0.0f, 0.3f})
                for (float ox : {-0.3f, 0.0f, 0.3f}) {
                    const float u = (float(i) + 0.5f + ox) / float(tex.width), v = 1.0f - (float(j) + 0.5f + oy) / float(tex.height);
                    const vec3 p = vec3(world * vec4(-1.0f + 2.0f * u, -1.0f + 2.0f * v, 0.0f, 1.0f));
                    const vec2 wpos = toWindow(f.camera.viewProj, p, W, H);
                    const int x = int(std::floor(wpos.x)), row = H - 1 - int(std::floor(wpos.y));
                    checks.push_back(check(x, row, c, 1));
                    if (x >= 0 && row >= 0 && x < W && row < H) setPixel(expected, x, row, c);
                }
        }
    EXPECT_TRUE(testing_support::pixelsMatch(actual, expected, checks, kSuite, caseName(backend, scene)));
}

// ---------------------------------------------------------------------------------------
// Projections, written out from the seeds (transforms.h):
//   view:  z^c = (eye - center)/|.|, x^c = up x z^c/|.|, y^c = z^c x x^c, p_e = ((p-eye).x^c, ..)
//   perspective: x_n = x_e / (aspect tan(fovy/2) (-z_e)), y_n = y_e / (tan(fovy/2) (-z_e))
//   orthographic: x_n = x_e / (h aspect), y_n = y_e / h   (h = orthoHalfHeight)
//   oblique: shear first, x' = x_e + F cos(a) (z_ref - z_e), y' = y_e + F sin(a) (z_ref - z_e),
//            z_ref = -focusDistance, then orthographic
//   window: x_w = (x_n + 1) W/2, y_w = (y_n + 1) H/2 (y up).

vec2 projectByFormula(const Projection& p, const vec3& eye, const vec3& center, float focus, const vec3& q, int W, int H) {
    const vec3 zc = glm::normalize(eye - center), xc = glm::normalize(glm::cross(vec3(0, 1, 0), zc)), yc = glm::cross(zc, xc);
    const vec3 d = q - eye;
    const float xe = glm::dot(d, xc), ye = glm::dot(d, yc), ze = glm::dot(d, zc);
    const float aspect = float(W) / float(H);
    float xn = 0, yn = 0;
    if (p.type == ProjectionType::Perspective) {
        const float t = std::tan(glm::radians(p.fovyDeg) * 0.5f);
        xn = xe / (aspect * t * -ze);
        yn = ye / (t * -ze);
    } else {
        float xs = xe, ys = ye;
        if (p.type == ProjectionType::Oblique) {
            const float a = glm::radians(p.obliqueAngleDeg), depth = -focus - ze;
            xs += p.obliqueFactor * std::cos(a) * depth;
            ys += p.obliqueFactor * std::sin(a) * depth;
        }
        xn = xs / (p.orthoHalfHeight * aspect);
        yn = ys / p.orthoHalfHeight;
    }
    return {(xn + 1.0f) * 0.5f * float(W), (yn + 1.0f) * 0.5f * float(H)};
}

void checkProjection(const std::string& backend, const Projection& proj, const std::string& scene) {
    const int W = 200, H = 150;
    const vec3 eye(0.0f, 0.0f, 5.0f), center(0.0f);   // as test_scenes::projectedBoxFrame
    const FrameInput f = test_scenes::projectedBoxFrame(W, H, proj);
    ASSERT_NEAR(glm::length(f.camera.eye - eye), 0.0f, 1e-5f);
    rnd::Framebuffer actual;
    ASSERT_TRUE(renderBackend(backend, f, W, H, actual));
    const DrawMesh& dm = f.meshes[0];
    std::vector<vec2> corners;
    for (int i = 0; i < 8; ++i) {
        const vec3 local((i & 1) ? 0.6f : -0.6f, (i & 2) ? 0.4f : -0.4f, (i & 4) ? 0.5f : -0.5f);
        const vec3 p = vec3(dm.world * vec4(local, 1.0f));
        const vec2 w = projectByFormula(f.camera.projection, eye, center, f.camera.focusDistance, p, W, H);
        // The scene graph's matrices must say the same (else the formula or the code is wrong).
        const vec2 m = toWindow(f.camera.viewProj, p, W, H);
        EXPECT_NEAR(w.x, m.x, 1e-3f) << "corner " << i << ": formula vs FrameCamera::viewProj";
        EXPECT_NEAR(w.y, m.y, 1e-3f) << "corner " << i << ": formula vs FrameCamera::viewProj";
        corners.push_back(w);
    }
    const std::vector<vec2> hull = convexHull(corners);
    rnd::Framebuffer expected = blankImage(W, H, f.settings.background);
    std::vector<PixelCheck> checks;
    const std::array<uint8_t, 3> white = {255, 255, 255}, bg = toBytes(f.settings.background);
    double sx = 0, sy = 0, n = 0;
    int minX = W, maxX = -1, minY = H, maxY = -1;   // window y of lit pixels
    for (int row = 0; row < H; ++row)
        for (int x = 0; x < W; ++x) {
            const vec2 q(float(x) + 0.5f, float(H - 1 - row) + 0.5f);
            const float d = insideDistance(hull, q);
            if (d > 0) setPixel(expected, x, row, white);
            if (d > 1.0f) checks.push_back(check(x, row, white, 2));
            if (d < -1.0f) checks.push_back(check(x, row, bg, 2));
            if (actual.pixel(x, row)[0] > 127) {
                sx += q.x, sy += q.y, n += 1;
                minX = std::min(minX, x), maxX = std::max(maxX, x);
                minY = std::min(minY, H - 1 - row), maxY = std::max(maxY, H - 1 - row);
            }
        }
    EXPECT_TRUE(testing_support::pixelsMatch(actual, expected, checks, kSuite, caseName(backend, scene)));
    ASSERT_GT(n, 0) << "nothing rendered";
    float pminX = 1e9f, pmaxX = -1e9f, pminY = 1e9f, pmaxY = -1e9f;
    for (const vec2& c : hull) pminX = std::min(pminX, c.x), pmaxX = std::max(pmaxX, c.x), pminY = std::min(pminY, c.y), pmaxY = std::max(pmaxY, c.y);
    const vec2 centroid = polygonCentroid(hull);
    std::printf(
        "[projection] %s: footprint x %d..%d y %d..%d (predicted %.2f..%.2f, %.2f..%.2f), centroid (%.2f, %.2f) predicted (%.2f, %.2f), "
        "area %.0f px predicted %.1f\n",
        scene.c_str(), minX, maxX + 1, minY, maxY + 1, pminX, pmaxX, pminY, pmaxY, sx / n, sy / n, centroid.x, centroid.y, n, polygonArea(hull));
    // Pixel edges of the lit footprint against the hull's extent (window units, y up).
    EXPECT_NEAR(float(minX), pminX, 1.0f) << scene;
    EXPECT_NEAR(float(maxX + 1), pmaxX, 1.0f) << scene;
    EXPECT_NEAR(float(minY), pminY, 1.0f) << scene;
    EXPECT_NEAR(float(maxY + 1), pmaxY, 1.0f) << scene;
    EXPECT_NEAR(sx / n, centroid.x, 1.0) << scene;
    EXPECT_NEAR(sy / n, centroid.y, 1.0) << scene;
}

// ---------------------------------------------------------------------------------------
// Anti-aliased edge.
//
// Expected: the linear value of a pixel is the covered fraction c of its square (the resolve
// averages linear colours, as shading.h says colours are linear and as the raster MSAA
// resolve does), so its byte is encodeSRGB(c). A sample-counting estimate with N samples per
// pixel errs by a multiple of 1/N plus the placement of the samples against the edge; for
// the regular or rotated patterns in use and an edge at 20 degrees the error stays below
// 0.5/sqrt(N) + 1/N per pixel (N = 4: 0.5; N = 16: 0.19) and averages below 0.25/sqrt(N)
// (N = 4: 0.125, N = 16: 0.0625) over the edge pixels. Fully covered and empty pixels must be
// exact (1/255).

void checkAntiAliasing(const std::string& backend, AAMode aa, int rate, const std::string& scene) {
    const int W = 160, H = 120;
    const FrameInput f = test_scenes::aaEdgeFrame(W, H, aa, rate);
    {
        std::string err;
        auto r = rnd::makeRenderer(backend, &err);
        ASSERT_TRUE(r) << err;
        const rnd::Capabilities caps = r->capabilities();
        const std::vector<int>& offered = aa == AAMode::MSAA ? caps.msaaSamples : caps.ssaaFactors;
        if (aa != AAMode::None && std::find(offered.begin(), offered.end(), rate) == offered.end())
            GTEST_SKIP() << backend << " does not offer " << f.settings.aaName() << " (Capabilities)";
    }
    rnd::Framebuffer actual;
    ASSERT_TRUE(renderBackend(backend, f, W, H, actual));
    std::vector<vec2> quadCorners;
    const DrawMesh& dm = f.meshes[0];
    for (const vec3& p : dm.mesh->positions) quadCorners.push_back(toWindow(f.camera.viewProj, vec3(dm.world * vec4(p, 1.0f)), W, H));
    const std::vector<vec2> poly = convexHull(quadCorners);

    const int samples = aa == AAMode::None ? 1 : aa == AAMode::MSAA ? rate : rate * rate;
    const double maxErr = 0.5 / std::sqrt(double(samples)) + 1.0 / samples, meanErrAllowed = 0.25 / std::sqrt(double(samples));
    rnd::Framebuffer expected = blankImage(W, H, f.settings.background);
    std::vector<PixelCheck> checks;
    int edgePixels = 0, halfCovered = 0, intermediate = 0, nonBinary = 0;
    double sumErr = 0, sumErrGamma = 0, worst = 0;
    for (int row = 0; row < H; ++row)
        for (int x = 0; x < W; ++x) {
            const float wy = float(H - 1 - row);
            const double cov = coveredFraction(poly, float(x), wy);
            const uint8_t* p = actual.pixel(x, row);
            if (p[0] != 0 && p[0] != 255) ++nonBinary;
            if (aa == AAMode::None) {
                // Binary: lit exactly when the pixel centre is inside (edge-grazing centres aside).
                const float d = insideDistance(poly, vec2(float(x) + 0.5f, wy + 0.5f));
                const uint8_t v = d > 0 ? 255 : 0;
                setPixel(expected, x, row, {v, v, v});
                if (std::abs(d) > 0.01f) checks.push_back(check(x, row, {v, v, v}, 0));
                continue;
            }
            const uint8_t v = uint8_t(std::lround(srgbEncode(float(cov)) * 255.0f));
            setPixel(expected, x, row, {v, v, v});
            if (cov <= 0.0 || cov >= 1.0) {
                checks.push_back(check(x, row, {v, v, v}, 1));
                continue;
            }
            ++edgePixels;
            const double est = srgbDecode(p[0] / 255.0f);   // the linear value the pixel shows
            const double err = std::abs(est - cov);
            sumErr += err;
            sumErrGamma += std::abs(p[0] / 255.0 - cov);   // as if averaged in sRGB space
            worst = std::max(worst, err);
            if (cov >= 0.3 && cov <= 0.7) {
                ++halfCovered;
                if (p[0] > 0 && p[0] < 255) ++intermediate;
            }
            // The per-pixel bound, as a byte tolerance around encodeSRGB(c).
            const auto lo = uint8_t(std::lround(srgbEncode(float(std::max(0.0, cov - maxErr))) * 255.0f));
            const auto hi = uint8_t(std::lround(srgbEncode(float(std::min(1.0, cov + maxErr))) * 255.0f));
            PixelCheck c = check(x, row, {v, v, v}, std::max(v - lo, hi - v));
            checks.push_back(c);
        }
    EXPECT_TRUE(testing_support::pixelsMatch(actual, expected, checks, kSuite, caseName(backend, scene)));
    if (aa == AAMode::None) {
        std::printf("[aa] %s: %d non-binary pixels\n", scene.c_str(), nonBinary);
        EXPECT_EQ(nonBinary, 0) << "without AA every pixel is background or the quad";
        return;
    }
    const double mean = sumErr / std::max(edgePixels, 1), meanGamma = sumErrGamma / std::max(edgePixels, 1);
    std::printf(
        "[aa] %s (%d samples): %d edge pixels, %d of the %d 30-70%% covered ones intermediate; |linear value - covered fraction| mean %.3f max %.3f "
        "(allowed mean "
        "%.3f, max %.3f); if averaged in sRGB space the mean would be %.3f\n",
        scene.c_str(), samples, edgePixels, intermediate, halfCovered, mean, worst, meanErrAllowed, maxErr, meanGamma);
    EXPECT_GT(edgePixels, 200);
    // Pixels 30-70% covered hold samples on both sides of the edge with any of the patterns.
    EXPECT_GE(intermediate, halfCovered * 95 / 100) << "pixels 30-70% covered should take intermediate values";
    EXPECT_LE(mean, meanErrAllowed) << "mean error of the edge pixels' linear value against the covered fraction"
                                    << (meanGamma < mean ? " (the pixels match an sRGB-space average better: the resolve is not linear)" : "");
}

// Whether `backend` offers the anti-aliasing mode and rate (else the case is skipped with the reason).
bool offersAA(const std::string& backend, AAMode aa, int rate) {
    if (aa == AAMode::None) return true;
    std::string err;
    auto r = rnd::makeRenderer(backend, &err);
    if (!r) return true;   // renderBackend reports it
    const rnd::Capabilities caps = r->capabilities();
    const std::vector<int>& offered = aa == AAMode::MSAA ? caps.msaaSamples : caps.ssaaFactors;
    return std::find(offered.begin(), offered.end(), rate) != offered.end();
}

// ---------------------------------------------------------------------------------------
// Exposure and tone mapping.

void checkToneMapped(const std::string& backend, ToneMapping op, float ev, AAMode aa, int rate, const std::string& scene) {
    const int W = 96, H = 64;
    Projection ortho;
    ortho.type = ProjectionType::Orthographic;
    ortho.orthoHalfHeight = 1.0f;
    FrameInput f = test_scenes::makeFrame(W, H, ortho, vec3(0, 0, 5), vec3(0.0f));
    Material m = test_scenes::unlit(vec3(0.9f, 0.5f, 0.05f));
    m.emissive = vec3(1.5f, 0.1f, 0.0f);   // unlit colour = base colour + emissive = (2.4, 0.6, 0.05)
    test_scenes::addMesh(f, test_scenes::quad(2.0f), m, glm::translate(mat4(1.0f), vec3(-2.0f, 0.0f, 0.0f)));   // x in [-4, 0]
    f.settings.background = vec3(0.9f, 0.6f, 0.3f);
    f.settings.exposure = ev;
    f.settings.toneMapping = op;
    f.settings.aa = aa;
    if (aa != AAMode::None) f.settings.aaRate = rate;
    if (!offersAA(backend, aa, rate)) GTEST_SKIP() << backend << " does not offer " << f.settings.aaName() << " (Capabilities)";
    rnd::Framebuffer actual;
    ASSERT_TRUE(renderBackend(backend, f, W, H, actual));

    const auto surface = toBytes(displayReference(m.baseColor + m.emissive, ev, op));
    const auto background = toBytes(displayReference(f.settings.background, ev, op));
    rnd::Framebuffer expected = blankImage(W, H, vec3(0.0f));
    std::vector<PixelCheck> checks;
    for (int row = 0; row < H; ++row)
        for (int x = 0; x < W; ++x) {
            const auto& want = 2 * x + 1 < W ? surface : background;   // the quad's edge is x = 0: the window's middle
            setPixel(expected, x, row, want);
            if (std::abs(float(x) + 0.5f - 0.5f * W) > 2.0f) checks.push_back(check(x, row, want, 1));
        }
    std::printf("[tonemap] %s: surface (%d, %d, %d), background (%d, %d, %d)\n", scene.c_str(), surface[0], surface[1], surface[2], background[0],
                background[1], background[2]);
    EXPECT_TRUE(testing_support::pixelsMatch(actual, expected, checks, kSuite, caseName(backend, scene)));
}

void checkExposedEdge(const std::string& backend, AAMode aa, int rate, const std::string& scene) {
    const int W = 160, H = 120;
    FrameInput f = test_scenes::aaEdgeFrame(W, H, aa, rate);
    f.settings.exposure = 2.0f;
    if (!offersAA(backend, aa, rate)) GTEST_SKIP() << backend << " does not offer " << f.settings.aaName() << " (Capabilities)";
    rnd::Framebuffer actual;
    ASSERT_TRUE(renderBackend(backend, f, W, H, actual));
    std::vector<vec2> quadCorners;
    const DrawMesh& dm = f.meshes[0];
    for (const vec3& p : dm.mesh->positions) quadCorners.push_back(toWindow(f.camera.viewProj, vec3(dm.world * vec4(p, 1.0f)), W, H));
    const std::vector<vec2> poly = convexHull(quadCorners);
    const int samples = aa == AAMode::MSAA ? rate : rate * rate;
    const double maxErr = 0.5 / std::sqrt(double(samples)) + 1.0 / samples;   // as checkAntiAliasing
    auto shown = [&](double cov) { return displayReference(vec3(float(std::clamp(cov, 0.0, 1.0))), f.settings.exposure, f.settings.toneMapping).x; };
    rnd::Framebuffer expected = blankImage(W, H, f.settings.background);
    std::vector<PixelCheck> checks;
    int halfCovered = 0, white = 0;
    for (int row = 0; row < H; ++row)
        for (int x = 0; x < W; ++x) {
            const double cov = coveredFraction(poly, float(x), float(H - 1 - row));
            const uint8_t v = uint8_t(std::lround(srgbEncode(shown(cov)) * 255.0f));
            setPixel(expected, x, row, {v, v, v});
            const auto lo = uint8_t(std::lround(srgbEncode(shown(cov - maxErr)) * 255.0f));
            const auto hi = uint8_t(std::lround(srgbEncode(shown(cov + maxErr)) * 255.0f));
            checks.push_back(check(x, row, {v, v, v}, cov <= 0.0 || cov >= 1.0 ? 1 : std::max(v - lo, hi - v)));
            if (cov >= 0.3 && cov <= 0.7) {
                ++halfCovered;
                const uint8_t* p = actual.pixel(x, row);
                white += p[0] == 255 && p[1] == 255 && p[2] == 255;
            }
        }
    std::printf("[aa+ev2] %s: %d of the %d pixels 30-70%% covered are white\n", scene.c_str(), white, halfCovered);
    EXPECT_TRUE(testing_support::pixelsMatch(actual, expected, checks, kSuite, caseName(backend, scene)));
    EXPECT_GT(halfCovered, 50);
    EXPECT_GE(white, halfCovered * 95 / 100) << "an edge pixel covered 30-70% is 4 x that after the resolve, so white; not white: the "
                                                "samples were mapped (clamped) before they were averaged";
}

// ---------------------------------------------------------------------------------------

std::map<std::string, std::function<void(const std::string&)>> referenceScenes() {
    std::map<std::string, std::function<void(const std::string&)>> s;
    for (ShadingModel sm : {ShadingModel::Flat, ShadingModel::Gouraud, ShadingModel::Phong})
        for (ReflectionModel rm : {ReflectionModel::Phong, ReflectionModel::BlinnPhong})
            for (auto light : {test_scenes::SphereLight::Directional, test_scenes::SphereLight::Point}) {
                const std::string name = "sphere_" + std::string(toString(sm)) + "_" + (rm == ReflectionModel::Phong ? "phong" : "blinn") + "_" +
                                         (light == test_scenes::SphereLight::Directional ? "directional" : "point");
                s[name] = [=](const std::string& b) { checkLitSphere(b, sm, rm, light, name); };
            }
    for (FogMode fm : {FogMode::Linear, FogMode::Exp, FogMode::Exp2}) {
        const std::string name = "fog_" + std::string(toString(fm));
        s[name] = [=](const std::string& b) { checkFog(b, fm, name); };
    }
    s["texture_headon_ortho"] = [](const std::string& b) { checkTexture(b, false, "texture_headon_ortho"); };
    s["texture_tilted_perspective"] = [](const std::string& b) { checkTexture(b, true, "texture_tilted_perspective"); };
    Projection ortho;
    ortho.type = ProjectionType::Orthographic;
    for (auto [name, p] : {std::pair{std::string("perspective"), Projection{}}, std::pair{std::string("orthographic"), ortho},
                           std::pair{std::string("cavalier"), Projection::cavalier()}, std::pair{std::string("cabinet"), Projection::cabinet()}}) {
        const std::string n = "projection_" + name;
        s[n] = [=](const std::string& b) { checkProjection(b, p, n); };
    }
    for (auto [name, mode, rate] : {std::tuple{"aa_none", AAMode::None, 1}, std::tuple{"aa_msaa4", AAMode::MSAA, 4},
                                    std::tuple{"aa_ssaa2", AAMode::SSAA, 2}, std::tuple{"aa_ssaa4", AAMode::SSAA, 4}}) {
        const std::string n = name;
        s[n] = [=](const std::string& b) { checkAntiAliasing(b, mode, rate, n); };
    }
    struct ToneCase {
        const char* name;
        ToneMapping op;
        float ev;
        AAMode aa;
        int rate;
    };
    for (const ToneCase& c : {ToneCase{"tonemap_none_ev0", ToneMapping::None, 0.0f, AAMode::None, 1},
                              ToneCase{"tonemap_none_ev1", ToneMapping::None, 1.0f, AAMode::None, 1},
                              ToneCase{"tonemap_none_ev_minus2", ToneMapping::None, -2.0f, AAMode::None, 1},
                              ToneCase{"tonemap_aces_ev0", ToneMapping::Aces, 0.0f, AAMode::None, 1},
                              ToneCase{"tonemap_aces_ev_minus1", ToneMapping::Aces, -1.0f, AAMode::None, 1},
                              ToneCase{"tonemap_aces_ev0_msaa4", ToneMapping::Aces, 0.0f, AAMode::MSAA, 4},
                              ToneCase{"tonemap_aces_ev0_ssaa2", ToneMapping::Aces, 0.0f, AAMode::SSAA, 2},
                              ToneCase{"tonemap_khr_neutral_ev0", ToneMapping::KhrNeutral, 0.0f, AAMode::None, 1},
                              ToneCase{"tonemap_khr_neutral_ev0_5", ToneMapping::KhrNeutral, 0.5f, AAMode::None, 1},
                              ToneCase{"tonemap_khr_neutral_ev1_msaa4", ToneMapping::KhrNeutral, 1.0f, AAMode::MSAA, 4}}) {
        const std::string n = c.name;
        s[n] = [=](const std::string& b) { checkToneMapped(b, c.op, c.ev, c.aa, c.rate, n); };
    }
    for (auto [name, mode, rate] :
         {std::tuple{"aa_msaa4_ev2", AAMode::MSAA, 4}, std::tuple{"aa_ssaa2_ev2", AAMode::SSAA, 2}, std::tuple{"aa_ssaa4_ev2", AAMode::SSAA, 4}}) {
        const std::string n = name;
        s[n] = [=](const std::string& b) { checkExposedEdge(b, mode, rate, n); };
    }
    return s;
}

std::vector<std::string> sceneNames() {
    std::vector<std::string> names;
    for (const auto& [name, fn] : referenceScenes()) names.push_back(name);
    return names;
}

class BackendConformance : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(BackendConformance, MatchesFormula) {
    const auto& [backend, scene] = GetParam();
    referenceScenes().at(scene)(backend);
}

INSTANTIATE_TEST_SUITE_P(Formula, BackendConformance,
                         ::testing::Combine(::testing::ValuesIn(rnd::rendererNames()), ::testing::ValuesIn(sceneNames())),
                         [](const ::testing::TestParamInfo<BackendConformance::ParamType>& info) {
                             return std::get<0>(info.param) + "_" + std::get<1>(info.param);
                         });

}   // namespace
