// shadow_test.cpp - shadows in every backend: the rasterizers' shadow maps
// (renderers/shadow_map.h) against the ray caster's exact shadow rays, and the maps' own pieces:
//  - the lookup on a hand-made map: under an occluder 0, beside it 1, outside the map 1;
//  - a lit plane facing the light, alone, has no shadowed pixel (no acne), in every backend and
//    under every shading model;
//  - a floating slab and a thin pole over a ground, lit by a sun or a spot light: each backend's
//    shadowed pixels (darker with shadows on than off) overlap the ray caster's (IoU >= 0.9 at
//    640 x 640), and the two rasterizers' overlap each other's (IoU >= 0.95); the same under flat
//    and Gouraud shading (the lights evaluated per triangle or per vertex, each scaled by the
//    pixel's own visibility), where the two rasterizers' images also agree pixel for pixel;
//  - the thin pole (a tenth of a unit, a few texels wide) still casts;
//  - soft shadows: a sun with an angular radius gives a penumbra as wide as the geometry says,
//    in the ray caster (several rays per light) and in the rasterizers (PCSS); a point sun none.
#include "render_support.h"
#include "renderers/diagnostic.h"
#include "renderers/renderer.h"
#include "renderers/shadow_map.h"
#include "renderers/shadow_map_view.h"
#include "scenegraph/mesh.h"
#include "scenegraph/transforms.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace {

using namespace test_scenes;
using sg::vec3;

constexpr int S = 640;

sg::Material matte(const vec3& c) {
    sg::Material m;
    m.baseColor = c;
    m.ka = 0.2f;
    m.kd = 0.8f;
    m.ks = 0.0f;
    m.doubleSided = true;
    return m;
}

enum class Caster { Sun, Spot, Point };

// The ground (10 x 10 at y = 0), a slab floating at y = 1.5 and a thin pole, seen from above at
// an angle; one light. Under flat and Gouraud shading the ground is a 32 x 32 grid (the lights
// are evaluated at its vertices: one quad's corners lie outside the spot's cone).
sg::FrameInput slabAndPole(Caster light, bool withCasters = true, sg::ShadingModel shading = sg::ShadingModel::Phong) {
    sg::Projection proj;
    sg::FrameInput f = makeFrame(S, S, proj, vec3(0.0f, 9.0f, 8.0f), vec3(0.0f, 0.0f, 0.5f));
    f.ambientLight = vec3(1.0f);
    f.settings.shading = shading;
    if (shading == sg::ShadingModel::Phong) {
        const sg::Mesh ground = quad(5.0f);   // z = 0 facing +z: turned to y = 0 facing +y
        addMesh(f, ground, matte(vec3(0.8f)), glm::rotate(sg::mat4(1.0f), -sg::kPi / 2, vec3(1, 0, 0)));
    } else {
        addMesh(f, sg::primitives::plane(5.0f, 32), matte(vec3(0.8f)));
    }
    if (withCasters) {
        addMesh(f, sg::primitives::box(vec3(1.0f, 0.1f, 0.7f)), matte(vec3(0.8f, 0.3f, 0.2f)),
                glm::translate(sg::mat4(1.0f), vec3(-1.0f, 1.5f, 0.0f)));
        addMesh(f, sg::primitives::box(vec3(0.05f, 1.25f, 0.05f)), matte(vec3(0.2f, 0.5f, 0.8f)),
                glm::translate(sg::mat4(1.0f), vec3(2.0f, 1.25f, 1.0f)));
    }
    switch (light) {
    case Caster::Sun: f.lights.push_back(directional(glm::normalize(vec3(0.35f, -1.0f, -0.25f)), vec3(1.0f))); break;
    case Caster::Spot: f.lights.push_back(spot(vec3(0.5f, 6.0f, 1.0f), glm::normalize(vec3(0.0f, -1.0f, -0.1f)), vec3(1.0f), 40.0f, 50.0f)); break;
    case Caster::Point: f.lights.push_back(point(vec3(0.5f, 4.0f, 1.5f), vec3(1.0f), false)); break;
    }
    f.settings.shadows = true;
    return f;
}

const testing_support::BackendImages render{S, S, "conformance", "shadow"};

// Pixels darker with shadows on than off by more than a fifth of the lit value: shadowed.
std::vector<uint8_t> shadowMask(const rnd::Framebuffer& on, const rnd::Framebuffer& off) {
    std::vector<uint8_t> m(size_t(on.width) * size_t(on.height), 0);
    for (int y = 0; y < on.height; ++y)
        for (int x = 0; x < on.width; ++x) {
            const int a = on.pixel(x, y)[0] + on.pixel(x, y)[1] + on.pixel(x, y)[2];
            const int b = off.pixel(x, y)[0] + off.pixel(x, y)[1] + off.pixel(x, y)[2];
            m[size_t(y) * size_t(on.width) + size_t(x)] = b > 30 && a < b - b / 5;
        }
    return m;
}

double iou(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
    size_t inter = 0, uni = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        inter += a[i] && b[i];
        uni += a[i] || b[i];
    }
    return uni ? double(inter) / double(uni) : 1.0;
}

size_t count(const std::vector<uint8_t>& m) {
    size_t n = 0;
    for (uint8_t v : m) n += v;
    return n;
}

const char* name(Caster c) { return c == Caster::Sun ? "sun" : c == Caster::Spot ? "spot" : "point"; }
const char* name(sg::ShadingModel s) { return s == sg::ShadingModel::Flat ? "flat" : s == sg::ShadingModel::Gouraud ? "gouraud" : "phong"; }

// The shadowed pixels of `backend`'s image; `on`: the image with shadows (when given).
std::vector<uint8_t> maskOf(const std::string& backend, Caster light, sg::ShadingModel shading = sg::ShadingModel::Phong,
                            rnd::Framebuffer* on = nullptr) {
    sg::FrameInput f = slabAndPole(light, true, shading);
    const std::string tag = std::string(name(light)) + (shading == sg::ShadingModel::Phong ? "" : std::string("-") + name(shading));
    const rnd::Framebuffer withShadows = render(backend, f, tag + "-on");
    f.settings.shadows = false;
    const rnd::Framebuffer off = render(backend, f, tag + "-off");
    if (on) *on = withShadows;
    return shadowMask(withShadows, off);
}

// --- the lookup on a hand-made plan --------------------------------------------------------

TEST(ShadowMapTest, LookupAnswersUnderBesideAndOutsideTheOccluder) {
    // A sun straight down over a 4 x 4 ground; a 1 x 1 occluder at y = 1 over the origin.
    sg::FrameInput f = makeFrame(64, 64, sg::Projection{}, vec3(0, 10, 0.01f), vec3(0));
    f.lights.push_back(directional(vec3(0, -1, 0), vec3(1.0f)));
    f.settings.shadowMapSize = 256;
    f.settings.shadowFilter = sg::ShadowFilter::None;
    const sg::Aabb casters{vec3(-2, 0, -2), vec3(2, 1, 2)};
    const rnd::ShadowPlan plan = rnd::planShadows(f, casters);
    ASSERT_EQ(plan.views.size(), 1u);
    ASSERT_EQ(plan.viewCount, std::vector<int>{1});
    const std::vector<vec3> pos = {{-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {-0.5f, 1, 0.5f}};
    const std::vector<uint32_t> idx = {0, 1, 2, 0, 2, 3};
    rnd::ShadowCaster c;
    c.positions = pos.data();
    c.stride = sizeof(vec3);
    c.idx = idx.data();
    c.triangles = 2;
    c.vertices = 4;
    rnd::ShadowMaps maps;
    maps.size = plan.size;
    maps.depth.resize(size_t(plan.size) * size_t(plan.size));
    rnd::renderShadowDepth(plan.views[0], plan.size, {c}, maps.map(0));
    const vec3 up(0, 1, 0);
    EXPECT_EQ(rnd::shadowVisibility(plan, maps, f.lights[0], 0, vec3(0, 0, 0), up), 0.0f);
    EXPECT_EQ(rnd::shadowVisibility(plan, maps, f.lights[0], 0, vec3(0.4f, 0, -0.4f), up), 0.0f);
    EXPECT_EQ(rnd::shadowVisibility(plan, maps, f.lights[0], 0, vec3(1.5f, 0, 0), up), 1.0f);
    EXPECT_EQ(rnd::shadowVisibility(plan, maps, f.lights[0], 0, vec3(0, 0, -1.5f), up), 1.0f);
    EXPECT_EQ(rnd::shadowVisibility(plan, maps, f.lights[0], 0, vec3(0, 1, 0), up), 1.0f) << "the occluder itself is lit (acne)";
    EXPECT_EQ(rnd::shadowVisibility(plan, maps, f.lights[0], 0, vec3(0, 1.5f, 0), up), 1.0f) << "above the occluder";
    EXPECT_EQ(rnd::shadowVisibility(plan, maps, f.lights[0], 0, vec3(40, 0, 0), up), 1.0f) << "outside the map";
    // PCF 3 x 3 across the occluder's edge: between 0 and 1.
    f.settings.shadowFilter = sg::ShadowFilter::Pcf;
    const rnd::ShadowPlan pcf = rnd::planShadows(f, casters);
    ASSERT_EQ(pcf.pcf, 3);
    const float edge = rnd::shadowVisibility(pcf, maps, f.lights[0], 0, vec3(0.5f, 0, 0), up);
    EXPECT_GT(edge, 0.0f);
    EXPECT_LT(edge, 1.0f);
    // No shadows when they are off.
    f.settings.shadows = false;
    EXPECT_TRUE(rnd::planShadows(f, casters).empty());
}

TEST(ShadowMapTest, PointLightFacesCoverEveryDirection) {
    EXPECT_EQ(rnd::pointLightFace(vec3(1, 0.2f, -0.3f)), 0);
    EXPECT_EQ(rnd::pointLightFace(vec3(-1, 0.2f, -0.3f)), 1);
    EXPECT_EQ(rnd::pointLightFace(vec3(0.1f, 2, -0.3f)), 2);
    EXPECT_EQ(rnd::pointLightFace(vec3(0.1f, -2, -0.3f)), 3);
    EXPECT_EQ(rnd::pointLightFace(vec3(0.1f, 0.2f, 3)), 4);
    EXPECT_EQ(rnd::pointLightFace(vec3(0.1f, 0.2f, -3)), 5);
    sg::FrameInput f = makeFrame(64, 64, sg::Projection{}, vec3(0, 10, 0.01f), vec3(0));
    f.lights.push_back(point(vec3(0, 1, 0), vec3(1.0f), true));
    const rnd::ShadowPlan plan = rnd::planShadows(f, sg::Aabb{vec3(-2, 0, -2), vec3(2, 3, 2)});
    ASSERT_EQ(plan.views.size(), 6u);
    // Every face's view projects its own axis direction to the map's centre.
    const vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int k = 0; k < 6; ++k) {
        const sg::vec4 c = plan.views[size_t(k)].viewProj * sg::vec4(vec3(0, 1, 0) + axes[k], 1.0f);
        EXPECT_NEAR(c.x / c.w, 0.0f, 1e-5f) << k;
        EXPECT_NEAR(c.y / c.w, 0.0f, 1e-5f) << k;
    }
}

// --- every backend -------------------------------------------------------------------------

class Shadows : public ::testing::TestWithParam<std::string> {};

// A lit ground facing the light and nothing above it: shadows on and off give the same image,
// under per-pixel, flat and Gouraud shading.
TEST_P(Shadows, LitPlaneFacingTheLightHasNoAcne) {
    for (sg::ShadingModel shading : {sg::ShadingModel::Phong, sg::ShadingModel::Flat, sg::ShadingModel::Gouraud})
        for (Caster light : {Caster::Sun, Caster::Spot, Caster::Point}) {
            sg::FrameInput f = slabAndPole(light, false, shading);
            const std::string tag = std::string("acne-") + name(light) + "-" + name(shading);
            const rnd::Framebuffer on = render(GetParam(), f, tag + "-on");
            f.settings.shadows = false;
            const rnd::Framebuffer off = render(GetParam(), f, tag + "-off");
            EXPECT_EQ(count(shadowMask(on, off)), 0u) << name(light) << " " << name(shading);
        }
}

// A lone tessellated sphere over nothing: its lit side shadows nothing of itself (a receiver
// tilted against the light, faceted, with smooth normals: where acne shows first). The
// terminator, where n.l reaches 0, is dark either way and not counted (shadowMask).
TEST_P(Shadows, CurvedSurfaceHasNoAcne) {
    for (Caster light : {Caster::Sun, Caster::Spot, Caster::Point}) {
        sg::Projection proj;
        sg::FrameInput f = makeFrame(S, S, proj, vec3(0.0f, 3.0f, 6.0f), vec3(0.0f, 1.0f, 0.0f));
        f.ambientLight = vec3(1.0f);
        addMesh(f, sg::primitives::uvSphere(1.0f, 48, 24), matte(vec3(0.8f)), glm::translate(sg::mat4(1.0f), vec3(0.0f, 1.0f, 0.0f)));
        f.lights = slabAndPole(light).lights;
        f.settings.shadows = true;
        const rnd::Framebuffer on = render(GetParam(), f, std::string("acne-sphere-") + name(light) + "-on");
        f.settings.shadows = false;
        const rnd::Framebuffer off = render(GetParam(), f, std::string("acne-sphere-") + name(light) + "-off");
        EXPECT_LE(count(shadowMask(on, off)), 40u) << name(light);
    }
}

// The slab and the pole cast, with a sun, a spot and a point light; the pole's shadow, a few
// texels wide, is there (its pixels beside the slab's shadow).
TEST_P(Shadows, SlabAndThinPoleCast) {
    for (Caster light : {Caster::Sun, Caster::Spot, Caster::Point}) {
        const std::vector<uint8_t> m = maskOf(GetParam(), light);
        EXPECT_GT(count(m), size_t(S * S / 200)) << name(light);
        // The pole's shadow: in the right half of the image (the slab's is left of centre).
        size_t right = 0;
        for (int y = 0; y < S; ++y)
            for (int x = S * 5 / 8; x < S; ++x) right += m[size_t(y) * S + size_t(x)];
        EXPECT_GT(right, 200u) << name(light) << ": the thin pole casts no shadow";
    }
}

// Flat and Gouraud shading: the lights evaluated at the triangle's first vertex or at its three
// vertices, each scaled by the visibility at the pixel's own point (the ray caster's shadow ray
// from the hit, the rasterizers' map lookup there); the shadowed pixels overlap the ray
// caster's as under per-pixel shading.
TEST_P(Shadows, FlatAndGouraudShadowLikeTheRays) {
    for (sg::ShadingModel shading : {sg::ShadingModel::Flat, sg::ShadingModel::Gouraud})
        for (Caster light : {Caster::Sun, Caster::Spot}) {
            const std::vector<uint8_t> m = maskOf(GetParam(), light, shading);
            EXPECT_GT(count(m), size_t(S * S / 200)) << name(light) << " " << name(shading) << ": nothing shadowed";
            if (GetParam() == "raycast") continue;
            const std::vector<uint8_t> rays = maskOf("raycast", light, shading);
            const double overlap = iou(m, rays);
            std::printf("shadows %s %s: IoU %s~raycast %.4f (%zu / %zu pixels)\n", name(shading), name(light), GetParam().c_str(), overlap, count(m),
                        count(rays));
            EXPECT_GE(overlap, 0.9) << name(light) << " " << name(shading);
        }
}

// The visibility of a sun with angular radius `deg` along a ground line across the slab's
// shadow's right edge (x from 0.54 - 1 to 0.54 + 1 at z = -0.36: the edge of the slab's upper
// right corner, x = 1.55 * 0.35, cast along the sun's direction (0.35, -1, -0.25)).
std::vector<float> edgeProfile(const std::string& backend, float deg, std::vector<float>& xs) {
    sg::FrameInput f = slabAndPole(Caster::Sun);
    f.lights[0].tanAngularRadius = std::tan(deg * sg::kPi / 180.0f);
    f.settings.shadowFilter = sg::ShadowFilter::Pcss;
    f.settings.shadowPcfSize = 5;
    f.settings.shadowRays = 64;
    std::string err;
    auto r = rnd::makeRenderer(backend, &err);
    EXPECT_TRUE(r) << err;
    if (!r) return {};
    rnd::Framebuffer fb;
    EXPECT_TRUE(r->render(f, S, S, fb).ok);
    testing_support::writeImage(fb, "conformance", "shadow-" + backend + "-soft-" + std::to_string(int(deg)));
    std::vector<float> v;
    xs.clear();
    for (float x = 0.54f - 1.0f; x <= 0.54f + 1.0f; x += 0.02f) {
        const std::vector<float> lv = r->lightVisibility(f, vec3(x, 0.0f, -0.36f), vec3(0.0f, 1.0f, 0.0f));
        EXPECT_EQ(lv.size(), 1u) << backend;
        xs.push_back(x);
        v.push_back(lv.empty() ? -1.0f : lv[0]);
    }
    return v;
}

// Where a profile first rises past `level` (x; NaN: never).
float crossing(const std::vector<float>& xs, const std::vector<float>& v, float level) {
    for (size_t i = 0; i < v.size(); ++i)
        if (v[i] >= level) return xs[i];
    return std::nanf("");
}

// A sun of angular radius 8 degrees: the penumbra across the slab's straight edge spans
// 1.55 (tan(alpha + 8) - tan(alpha - 8)) = 0.49 units on the ground (tan alpha = 0.35), centred
// near x = 0.55. The visibility rises from 0 to 1 across it, in the ray caster by counting rays
// and in the rasterizers by PCSS's estimate; with a point sun (radius 0) the edge is hard.
TEST_P(Shadows, PenumbraFollowsTheLightsSize) {
    std::vector<float> xs;
    const std::vector<float> soft = edgeProfile(GetParam(), 8.0f, xs);
    ASSERT_FALSE(soft.empty());
    std::string profile;
    for (size_t i = 0; i < soft.size(); i += 5) profile += " " + std::to_string(soft[i]).substr(0, 4);
    const float lo = crossing(xs, soft, 0.1f), mid = crossing(xs, soft, 0.5f), hi = crossing(xs, soft, 0.9f);
    std::printf("%s: soft edge 0.1 at %.2f, 0.5 at %.2f, 0.9 at %.2f:%s\n", GetParam().c_str(), lo, mid, hi, profile.c_str());
    EXPECT_NEAR(mid, 0.55f, 0.1f) << profile;
    EXPECT_GT(hi - lo, 0.2f) << "no penumbra:" << profile;
    EXPECT_LT(hi - lo, 0.7f) << profile;
    EXPECT_LT(soft.front(), 0.05f) << "inside the shadow" << profile;
    EXPECT_GT(soft.back(), 0.95f) << "outside the shadow" << profile;
    const std::vector<float> hard = edgeProfile(GetParam(), 0.0f, xs);
    const float hlo = crossing(xs, hard, 0.1f), hhi = crossing(xs, hard, 0.9f);
    EXPECT_LT(hhi - hlo, 0.1f) << "a point sun's edge is hard";
    EXPECT_NEAR(crossing(xs, hard, 0.5f), 0.54f, 0.05f);
}

// The ray caster's shadow rays to a light with a size end on the source: a directional light's
// within its angular radius of the light's direction, a sphere light's on the disc of its
// radius facing the point; their mean is the centre (the samples are stratified).
TEST(ShadowMapTest, SoftShadowRaysCoverTheSource) {
    sg::DrawLight sun = directional(glm::normalize(vec3(0.3f, -1.0f, 0.2f)), vec3(1.0f));
    sun.tanAngularRadius = std::tan(5.0f * sg::kPi / 180.0f);
    sg::DrawLight bulb = point(vec3(1.0f, 4.0f, -2.0f), vec3(1.0f), false);
    bulb.radius = 0.5f;
    const vec3 p(0.2f, 0.0f, 0.1f);
    for (int n : {1, 16, 64}) {
        vec3 meanSun(0.0f), meanBulb(0.0f);
        for (int k = 0; k < n; ++k) {
            const rnd::ShadowRayTarget s = rnd::softShadowRay(sun, p, k, n, sg::vec2(0.37f, 0.81f));
            EXPECT_GE(glm::dot(s.dir, -sun.direction), std::cos(5.0f * sg::kPi / 180.0f) - 1e-5f);
            EXPECT_TRUE(std::isinf(s.distance));
            meanSun += s.dir;
            const rnd::ShadowRayTarget b = rnd::softShadowRay(bulb, p, k, n, sg::vec2(0.37f, 0.81f));
            const vec3 target = p + b.dir * b.distance;
            EXPECT_LE(glm::length(target - bulb.position), 0.5f + 1e-4f);
            EXPECT_NEAR(glm::dot(target - bulb.position, glm::normalize(bulb.position - p)), 0.0f, 1e-4f) << "on the disc facing p";
            meanBulb += target;
        }
        if (n >= 16) {
            EXPECT_GT(glm::dot(glm::normalize(meanSun), -sun.direction), std::cos(1.0f * sg::kPi / 180.0f)) << n;
            EXPECT_LT(glm::length(meanBulb / float(n) - bulb.position), 0.08f) << n;
        }
    }
}

// The shadow-map view (renderers/shadow_map_view.h) of the slab and pole under a sun: with the
// default biases the map and the shadow rays disagree only along the shadows' edges; without
// bias the lit ground shadows itself (acne: the map alone shadows, red); with a bias of many
// texels the shadows come loose from their casters (the map alone lets light through, blue);
// a map 8 times finer has 8 times the texels per pixel. A backend without maps cannot make it.
rnd::ShadowMapViewCounts shadowMapCounts(const std::string& backend, sg::FrameInput f, const std::string& tag) {
    rnd::ShadowMapViewCounts c;
    std::string err;
    auto r = rnd::makeRenderer(backend, &err);
    EXPECT_TRUE(r) << err;
    if (!r) return c;
    rnd::Framebuffer fb;
    rnd::RenderRequest req;
    rnd::requestFor(rnd::DiagnosticView::ShadowMap, req);
    EXPECT_TRUE(r->render(f, S, S, fb, nullptr, req).ok);
    const std::unique_ptr<rnd::Renderer> exact = rnd::makeExactShadowBackend();
    EXPECT_TRUE(exact) << "no backend with shadow rays";
    const int light = rnd::shadowMapViewLight(f);
    EXPECT_EQ(light, 0);
    const rnd::DiagnosticImage view = rnd::shadowMapView(f, fb, light, *r, exact.get(), &c);
    testing_support::writeImage(view.image, "conformance", "shadow-map-view-" + backend + "-" + tag);
    std::printf("%s %s: %s\n", backend.c_str(), tag.c_str(), view.legend.c_str());
    return c;
}

TEST_P(Shadows, ShadowMapViewShowsAcnePeterPanningAndTexels) {
    sg::FrameInput f = slabAndPole(Caster::Sun);
    const bool maps = rnd::diagnosticViewSupported(rnd::DiagnosticView::ShadowMap, rnd::makeRenderer(GetParam())->capabilities());
    EXPECT_EQ(maps, rnd::makeRenderer(GetParam())->capabilities().shadowMaps);
    if (!maps) return;   // (checked: the ray caster has no maps to show)
    f.settings.shadowFilter = sg::ShadowFilter::None;
    const rnd::ShadowMapViewCounts good = shadowMapCounts(GetParam(), f, "default");
    ASSERT_GT(good.facing, size_t(S * S / 4));
    const double goodWrong = double(good.mapOnlyShadow + good.mapOnlyLight) / double(good.facing);
    EXPECT_LT(goodWrong, 0.01) << "the map and the rays disagree beyond the shadows' edges";
    EXPECT_GT(good.shadowedByMap, size_t(S * S / 200)) << "the slab and the pole cast";

    sg::FrameInput noBias = f;
    noBias.settings.shadowDepthBias = 0.0f;
    noBias.settings.shadowNormalBias = 0.0f;
    const rnd::ShadowMapViewCounts acne = shadowMapCounts(GetParam(), noBias, "no-bias");
    EXPECT_GT(double(acne.mapOnlyShadow) / double(acne.facing), 0.02) << "no bias: the ground shadows itself";
    EXPECT_GT(acne.mapOnlyShadow, 10 * std::max<size_t>(good.mapOnlyShadow, 1));

    sg::FrameInput loose = f;
    loose.settings.shadowDepthBias = 40.0f;
    loose.settings.shadowNormalBias = 40.0f;
    const rnd::ShadowMapViewCounts leak = shadowMapCounts(GetParam(), loose, "large-bias");
    EXPECT_GT(leak.mapOnlyLight, 4 * std::max<size_t>(good.mapOnlyLight, 50)) << "a large bias lets light under the casters";

    sg::FrameInput coarse = f;
    coarse.settings.shadowMapSize = 256;
    sg::FrameInput fine = f;
    fine.settings.shadowMapSize = 2048;
    const float dCoarse = shadowMapCounts(GetParam(), coarse, "256").texelsPerPixel;
    const float dFine = shadowMapCounts(GetParam(), fine, "2048").texelsPerPixel;
    EXPECT_GT(dCoarse, 0.0f);
    EXPECT_NEAR(dFine / dCoarse, 8.0f, 0.5f);
}

INSTANTIATE_TEST_SUITE_P(EveryBackend, Shadows, ::testing::ValuesIn(rnd::rendererNames()), [](const auto& info) { return info.param; });

// The shadow maps against the exact shadow rays, and the two rasterizers against each other.
// (Needs every backend: the gl label.)
TEST(ShadowAgreementGLTest, RasterizersMatchTheRayCasterAndEachOther) {
    for (Caster light : {Caster::Sun, Caster::Spot, Caster::Point}) {
        std::map<std::string, std::vector<uint8_t>> masks;
        for (const std::string& b : rnd::rendererNames()) masks[b] = maskOf(b, light);
        ASSERT_TRUE(masks.count("raycast") && masks.count("raster") && masks.count("gl"));
        const double rasterRay = iou(masks["raster"], masks["raycast"]), glRay = iou(masks["gl"], masks["raycast"]);
        const double glRaster = iou(masks["gl"], masks["raster"]);
        std::printf("shadows %s: IoU raster~raycast %.4f gl~raycast %.4f gl~raster %.4f (%zu / %zu / %zu pixels)\n", name(light), rasterRay, glRay,
                    glRaster, count(masks["raycast"]), count(masks["raster"]), count(masks["gl"]));
        EXPECT_GE(rasterRay, 0.9) << name(light);
        EXPECT_GE(glRay, 0.9) << name(light);
        EXPECT_GE(glRaster, 0.95) << name(light);
    }
}

// Flat and Gouraud shading: both rasterizers against the ray caster and each other, the
// shadowed pixels and the whole images (the same formulas, the same maps).
TEST(ShadowAgreementGLTest, FlatAndGouraudRasterizersMatchTheRayCasterAndEachOther) {
    for (sg::ShadingModel shading : {sg::ShadingModel::Flat, sg::ShadingModel::Gouraud})
        for (Caster light : {Caster::Sun, Caster::Spot}) {
            rnd::Framebuffer glOn, rasterOn;
            const std::vector<uint8_t> rays = maskOf("raycast", light, shading);
            const std::vector<uint8_t> raster = maskOf("raster", light, shading, &rasterOn);
            const std::vector<uint8_t> gl = maskOf("gl", light, shading, &glOn);
            const double rasterRay = iou(raster, rays), glRay = iou(gl, rays), glRaster = iou(gl, raster);
            std::printf("shadows %s %s: IoU raster~raycast %.4f gl~raycast %.4f gl~raster %.4f (%zu / %zu / %zu pixels)\n", name(shading),
                        name(light), rasterRay, glRay, glRaster, count(rays), count(raster), count(gl));
            const std::string what = std::string(name(shading)) + " " + name(light);
            EXPECT_GE(rasterRay, 0.9) << what;
            EXPECT_GE(glRay, 0.9) << what;
            EXPECT_GE(glRaster, 0.95) << what;
            EXPECT_TRUE(testing_support::imagesClose(glOn, rasterOn, testing_support::agreementTolerance(testing_support::Agreement::SameMethod),
                                                     "conformance", std::string("shadow-gl-raster-") + name(shading) + "-" + name(light)))
                << what;
        }
}

// Gouraud carries the shadowed lights' terms apart in GL's vertex outputs, for at most two
// lights (rnd::kGouraudShadowedLights, the first with maps); a third is summed unshadowed, in
// both rasterizers alike, where flat shading still shadows it. Two dim spots on a far corner of
// the ground come first, the sun third: under Gouraud the slab and the pole cast nothing. With
// nine lights (GL's loop over the lights, not calls per light) the sun comes first and casts.
TEST(ShadowAgreementGLTest, GouraudShadowsTheFirstTwoLightsWithMapsInBothRasterizers) {
    const vec3 corner(-4.0f, 0.0f, 4.0f);
    auto cornerSpot = [&] { return spot(corner + vec3(0.0f, 2.0f, 0.0f), vec3(0.0f, -1.0f, 0.0f), vec3(0.2f), 20.0f, 30.0f); };
    struct Case {
        const char* tag;
        std::vector<sg::DrawLight> lights;
        sg::ShadingModel shading;
        bool sunCasts;
    };
    const sg::DrawLight sun = slabAndPole(Caster::Sun).lights[0];
    std::vector<sg::DrawLight> many = {sun, cornerSpot()};
    for (int k = 0; k < 7; ++k) many.push_back(directional(glm::normalize(vec3(0.1f * float(k - 3), -1.0f, 0.2f)), vec3(0.01f)));
    const Case cases[] = {{"third-gouraud", {cornerSpot(), cornerSpot(), sun}, sg::ShadingModel::Gouraud, false},
                          {"third-flat", {cornerSpot(), cornerSpot(), sun}, sg::ShadingModel::Flat, true},
                          {"nine-gouraud", many, sg::ShadingModel::Gouraud, true}};
    for (const Case& c : cases) {
        std::map<std::string, std::vector<uint8_t>> masks;
        std::map<std::string, rnd::Framebuffer> images;
        for (const std::string b : {"raster", "gl"}) {
            sg::FrameInput f = slabAndPole(Caster::Sun, true, c.shading);
            f.lights = c.lights;
            const rnd::Framebuffer on = render(b, f, std::string("lights-") + c.tag + "-on");
            f.settings.shadows = false;
            masks[b] = shadowMask(on, render(b, f, std::string("lights-") + c.tag + "-off"));
            images[b] = on;
        }
        std::printf("shadows %s: %zu / %zu pixels (raster / gl), IoU %.4f\n", c.tag, count(masks["raster"]), count(masks["gl"]),
                    iou(masks["gl"], masks["raster"]));
        for (const std::string b : {"raster", "gl"}) {
            if (c.sunCasts)
                EXPECT_GT(count(masks[b]), size_t(S * S / 200)) << c.tag << " " << b << ": the sun casts nothing";
            else
                EXPECT_EQ(count(masks[b]), 0u) << c.tag << " " << b << ": the third light with a map is shadowed under Gouraud";
        }
        EXPECT_GE(iou(masks["gl"], masks["raster"]), 0.95) << c.tag;
        EXPECT_TRUE(testing_support::imagesClose(images["gl"], images["raster"],
                                                 testing_support::agreementTolerance(testing_support::Agreement::SameMethod), "conformance",
                                                 std::string("shadow-gl-raster-lights-") + c.tag))
            << c.tag;
    }
}

}   // namespace

// Both rasterizers keep their shadow maps while a frame's plan and casters are the last
// frame's, and draw them again when either changes; every frame of a sequence matches a new
// renderer's image of it. A spot light's map does not follow the camera (a camera move keeps
// it); a sun's map is fitted to the view (a camera move draws it again).
TEST(ShadowAgreementGLTest, KeptMapsMatchNewlyDrawnOnesInBothRasterizers) {
    constexpr int W = 160;
    for (const char* backend : {"raster", "gl"})
        for (Caster light : {Caster::Spot, Caster::Sun}) {
            SCOPED_TRACE(std::string(backend) + " " + name(light));
            sg::FrameInput f = slabAndPole(light);
            auto slab = std::make_shared<sg::Mesh>(f.meshes[1].mesh ? *f.meshes[1].mesh : sg::Mesh{});
            f.meshes[1].mesh = slab;
            auto r = rnd::makeRenderer(backend);
            ASSERT_TRUE(r);
            auto step = [&](const sg::FrameInput& frame, bool drawn, const char* what) {
                rnd::Framebuffer kept, fresh;
                const rnd::RenderStats st = r->render(frame, W, W, kept);
                EXPECT_TRUE(st.ok) << what << ": " << st.error;
                EXPECT_EQ(st.shadowMapsDrawn > 0, drawn) << what << ": " << st.shadowMapsDrawn << " maps drawn";
                EXPECT_TRUE(rnd::makeRenderer(backend)->render(frame, W, W, fresh).ok);
                EXPECT_TRUE(kept.color == fresh.color) << what;
                return kept;
            };
            const rnd::Framebuffer first = step(f, true, "first frame");
            step(f, false, "the same frame again");
            sg::FrameInput turned = f;
            turned.camera = makeFrame(S, S, sg::Projection{}, vec3(1.0f, 8.0f, 8.5f), vec3(0.0f, 0.0f, 0.5f)).camera;
            step(turned, light == Caster::Sun, "the camera moved");
            sg::FrameInput moved = turned;
            moved.meshes[1].world = glm::translate(sg::mat4(1.0f), vec3(-0.6f, 1.5f, 0.4f));
            const rnd::Framebuffer m = step(moved, true, "a caster moved");
            step(moved, false, "the moved caster again");
            for (vec3& q : slab->positions) q.y *= 2.0f;   // the mesh edited in place (a new version)
            slab->touch();
            step(moved, true, "the caster's mesh edited");
            EXPECT_FALSE(first.color == m.color);
        }
    // A sun and a spot: a camera move draws the sun's map again and keeps the spot's.
    for (const char* backend : {"raster", "gl"}) {
        SCOPED_TRACE(backend);
        sg::FrameInput f = slabAndPole(Caster::Sun);
        f.lights.push_back(slabAndPole(Caster::Spot).lights[0]);
        sg::FrameInput turned = f;
        turned.camera = makeFrame(S, S, sg::Projection{}, vec3(1.0f, 8.0f, 8.5f), vec3(0.0f, 0.0f, 0.5f)).camera;
        auto r = rnd::makeRenderer(backend);
        ASSERT_TRUE(r);
        rnd::Framebuffer a, b, fresh;
        EXPECT_EQ(r->render(f, W, W, a).shadowMapsDrawn, 2);
        EXPECT_EQ(r->render(turned, W, W, b).shadowMapsDrawn, 1);
        EXPECT_TRUE(rnd::makeRenderer(backend)->render(turned, W, W, fresh).ok);
        EXPECT_TRUE(b.color == fresh.color);
    }
}
