// diagnostic_counters_test.cpp - the per-pixel counters behind the overdraw and cost diagnostic
// views (RenderRequest::aovs' Overdraw / TraversalCost, Framebuffer::overdraw / costNodes /
// costPrims, renderers/diagnostic.h): counts worked out by hand on crafted scenes (three
// overlapping quads under an orthographic camera; a lone triangle), GL and raster agreeing on
// the demo, anti-aliased images getting the one-sample counts, the primary ray's cost growing
// with the layers it passes and not with its shadow rays, and backends without the capability
// refusing the request with an error that says which view.
#include "assets/demo.h"
#include "render_support.h"
#include "renderers/diagnostic.h"
#include "renderers/renderer.h"
#include "test_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace {

using namespace test_scenes;
using sg::mat4;
using sg::vec3;

constexpr int W = 160, H = 120;   // orthographic half height 1.5: a pixel is 0.025 scene units

// Backends whose capabilities have the counter (never decided by name).
std::vector<std::string> backendsWith(rnd::Aov aov) {
    std::vector<std::string> v;
    for (const std::string& b : rnd::rendererNames())
        if (auto r = rnd::makeRenderer(b); r && r->capabilities().aovs.has(aov)) v.push_back(b);
    return v;
}

// With the counters asked for (RenderRequest::aovs).
rnd::Framebuffer renderCounted(const std::string& backend, const sg::FrameInput& f, int w, int h, bool overdraw, bool cost) {
    rnd::RenderRequest req;
    req.aovs.set(rnd::Aov::Overdraw, overdraw).set(rnd::Aov::TraversalCost, cost);
    return testing_support::BackendImages{w, h}(backend, f, {"counted", req});
}

// Three opaque quads facing an orthographic camera at three depths, every edge on a pixel
// boundary (multiples of 0.025), so no pixel centre lies on an edge:
//   A x -1.5..0.5,  y -1..1 (z 0)      B x -0.5..1.5, y -1..1 (z 0.5)
//   C x -0.5..0.5,  y -0.25..0.75 (z 1)
// Fragments per pixel: 1 where only A or only B, 2 where both, 3 inside C, 0 elsewhere.
sg::FrameInput threeQuads() {
    sg::Projection p;
    p.type = sg::ProjectionType::Orthographic;
    p.orthoHalfHeight = 1.5f;
    sg::FrameInput f = makeFrame(W, H, p, vec3(0.0f, 0.0f, 5.0f), vec3(0.0f));
    addMesh(f, quad(1.0f), unlit(vec3(0.8f, 0.2f, 0.2f)), glm::translate(mat4(1.0f), vec3(-0.5f, 0.0f, 0.0f)));
    addMesh(f, quad(1.0f), unlit(vec3(0.2f, 0.8f, 0.2f)), glm::translate(mat4(1.0f), vec3(0.5f, 0.0f, 0.5f)));
    addMesh(f, quad(0.5f), unlit(vec3(0.2f, 0.2f, 0.8f)), glm::translate(mat4(1.0f), vec3(0.0f, 0.25f, 1.0f)));
    return f;
}

// The hand count at pixel (x, y) (top-left origin) and its distance in pixels to the nearest edge.
uint32_t expectedOverdraw(int x, int y, float* edgeDistance = nullptr) {
    const float px = -2.0f + (float(x) + 0.5f) * 0.025f, py = 1.5f - (float(y) + 0.5f) * 0.025f;
    struct Rect {
        float x0, x1, y0, y1;
    };
    const Rect rects[3] = {{-1.5f, 0.5f, -1.0f, 1.0f}, {-0.5f, 1.5f, -1.0f, 1.0f}, {-0.5f, 0.5f, -0.25f, 0.75f}};
    uint32_t n = 0;
    float d = INFINITY;
    for (const Rect& r : rects) {
        n += px > r.x0 && px < r.x1 && py > r.y0 && py < r.y1;
        for (float e : {px - r.x0, px - r.x1, py - r.y0, py - r.y1}) d = std::min(d, std::fabs(e) / 0.025f);
    }
    if (edgeDistance) *edgeDistance = d;
    return n;
}

class Overdraw : public ::testing::TestWithParam<std::string> {};

// Raster: exactly the hand count at every pixel; GL: exactly away from the edges (within a
// pixel of one, the two rasterizers' edge rules may differ) and on >= 99.5% of all pixels.
TEST_P(Overdraw, ThreeOverlappingQuadsCountedByHand) {
    const sg::FrameInput f = threeQuads();
    const rnd::Framebuffer fb = renderCounted(GetParam(), f, W, H, true, false);
    ASSERT_TRUE(fb.has(rnd::Aov::Overdraw));
    int exact = 0, interiorWrong = 0, seen[4] = {0, 0, 0, 0};
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float edge = 0;
            const uint32_t want = expectedOverdraw(x, y, &edge);
            const uint32_t got = fb.overdraw[size_t(y) * W + x];
            ++seen[want];
            exact += got == want;
            if (got != want && edge > 1.0f) {
                if (++interiorWrong <= 5) ADD_FAILURE() << GetParam() << " pixel " << x << "," << y << ": " << got << " fragments, expected " << want;
            }
        }
    for (int k = 0; k < 4; ++k) EXPECT_GT(seen[k], 500) << "the scene has a region of every count " << k;
    EXPECT_EQ(interiorWrong, 0);
    if (GetParam() == "raster")
        EXPECT_EQ(exact, W * H) << "raster rasterizes every fragment at the pixel centre: exact everywhere";
    else
        EXPECT_GE(double(exact) / (W * H), 0.995) << GetParam();
    // The heat map: black where nothing was drawn, blue for 1, red-free green for 3.
    const rnd::DiagnosticImage view = rnd::diagnosticImage(rnd::DiagnosticView::Overdraw, f, fb);
    EXPECT_NE(view.legend.find("overdraw"), std::string::npos);
    EXPECT_NE(view.legend.find("max 3"), std::string::npos) << view.legend;
    const uint8_t* corner = view.image.pixel(2, 2);
    EXPECT_EQ(corner[0] + corner[1] + corner[2], 0);
    const uint8_t* beside = view.image.pixel(10, 60);   // x -1.74: left of every quad
    EXPECT_EQ(beside[0] + beside[1] + beside[2], 0);
    const uint8_t* single = view.image.pixel(30, 60);   // x -1.24: A only
    EXPECT_GT(single[2], 200);
    EXPECT_LT(single[0], 40);
    const uint8_t* three = view.image.pixel(80, 40);   // x 0.01, y 0.49: inside C
    EXPECT_EQ(expectedOverdraw(80, 40), 3u);
    EXPECT_GT(three[1], three[0]);
}

// An anti-aliased image gets the counts of a one-sample pass (render()'s second pass), the same
// as the plain image's, and the culled back of a one-sided quad adds no fragment.
TEST_P(Overdraw, AntiAliasedAndCulledCountsAreTheOneSampleOnes) {
    sg::FrameInput f = threeQuads();
    const rnd::Framebuffer plain = renderCounted(GetParam(), f, W, H, true, false);
    f.settings.aa = sg::AAMode::MSAA;
    f.settings.aaRate = 4;
    const rnd::Framebuffer msaa = renderCounted(GetParam(), f, W, H, true, false);
    ASSERT_TRUE(msaa.has(rnd::Aov::Overdraw));
    EXPECT_EQ(msaa.overdraw, plain.overdraw);
    f.settings.aa = sg::AAMode::None;
    f.settings.culling = sg::CullMode::On;
    f.meshes[2].world = glm::translate(mat4(1.0f), vec3(0.0f, 0.25f, 1.0f)) * glm::rotate(mat4(1.0f), glm::radians(180.0f), vec3(0, 1, 0));
    f.meshes[2].normal = sg::normalMatrix(f.meshes[2].world);
    const rnd::Framebuffer culled = renderCounted(GetParam(), f, W, H, true, false);
    ASSERT_TRUE(culled.has(rnd::Aov::Overdraw));
    EXPECT_EQ(culled.overdraw[size_t(40) * W + 80], 2u) << "C turned away and culled: A and B only";
}

INSTANTIATE_TEST_SUITE_P(Rasterizers, Overdraw, ::testing::ValuesIn(backendsWith(rnd::Aov::Overdraw)), [](const auto& info) { return info.param; });

// GL and raster count the same fragments on the demo (meshes, tessellated analytic shapes, a
// blended surface, points and lines): equal counts on >= 99% of the pixels.
TEST(OverdrawAgreement, GlAndRasterAgreeOnTheDemo) {
    const std::vector<std::string> both = backendsWith(rnd::Aov::Overdraw);
    ASSERT_EQ(both.size(), 2u) << "gl and raster count fragments";
    sg::Scene scene = assets::makeDemoScene();
    constexpr int DW = 192, DH = 170;
    const sg::FrameInput f = sg::flatten(scene, float(DW) / float(DH));
    const rnd::Framebuffer a = renderCounted(both[0], f, DW, DH, true, false);
    const rnd::Framebuffer b = renderCounted(both[1], f, DW, DH, true, false);
    ASSERT_TRUE(a.has(rnd::Aov::Overdraw) && b.has(rnd::Aov::Overdraw));
    size_t same = 0, covered = 0, layered = 0;
    for (size_t k = 0; k < a.overdraw.size(); ++k) {
        same += a.overdraw[k] == b.overdraw[k];
        covered += a.overdraw[k] > 0;
        layered += a.overdraw[k] > 1;
    }
    EXPECT_GT(covered, a.overdraw.size() / 2) << "the demo covers most of the image";
    EXPECT_GT(layered, 1000u) << "and has overlapping surfaces";
    EXPECT_GE(double(same) / double(a.overdraw.size()), 0.99) << both[0] << " vs " << both[1];
}

// One triangle, seen in perspective: a primary ray that misses the top level's children
// visits 1 node (the top-level root) and tests no triangle; one that enters the instance's box
// visits the top-level root and the mesh BVH's root and tests the one triangle.
TEST(TraversalCost, LoneTriangleCountedByHand) {
    const std::vector<std::string> counting = backendsWith(rnd::Aov::TraversalCost);
    ASSERT_FALSE(counting.empty());
    sg::Projection p;
    p.fovyDeg = 45.0f;
    sg::FrameInput f = makeFrame(W, H, p, vec3(0.0f, 0.0f, 4.0f), vec3(0.0f));
    sg::Mesh tri;
    tri.positions = {{-1.0f, -0.8f, 0.0f}, {1.0f, -0.8f, 0.0f}, {0.0f, 0.9f, 0.0f}};
    tri.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    tri.indices = {0, 1, 2};
    addMesh(f, tri, unlit(vec3(1.0f)));
    for (const std::string& b : counting) {
        SCOPED_TRACE(b);
        const rnd::Framebuffer fb = renderCounted(b, f, W, H, false, true);
        ASSERT_TRUE(fb.has(rnd::Aov::TraversalCost));
        int misses = 0, entered = 0;
        for (size_t k = 0; k < fb.costNodes.size(); ++k) {
            const uint32_t n = fb.costNodes[k], t = fb.costPrims[k];
            if (n == 1 && t == 0)
                ++misses;
            else if (n == 2 && t == 1)
                ++entered;
            else
                ADD_FAILURE() << "pixel " << k << ": " << n << " nodes, " << t << " triangles";
        }
        EXPECT_EQ(fb.costNodes[0], 1u) << "the corner ray misses the triangle's box";
        EXPECT_EQ(fb.costPrims[0], 0u);
        const size_t centre = size_t(H / 2) * W + W / 2;   // on the triangle
        EXPECT_EQ(fb.costNodes[centre], 2u);
        EXPECT_EQ(fb.costPrims[centre], 1u);
        EXPECT_GT(misses, W * H / 3);
        EXPECT_GT(entered, W * H / 10);
        const rnd::DiagnosticImage view = rnd::diagnosticImage(rnd::DiagnosticView::Cost, f, fb);
        EXPECT_NE(view.legend.find("1 blue .. 3 red"), std::string::npos) << view.legend;
        EXPECT_GT(view.image.pixel(W / 2, H / 2)[0], 200) << "the most work: red";
        EXPECT_GT(view.image.pixel(0, 0)[2], 200) << "one node: blue";
    }
}

// The primary ray's cost: a blended layer in front adds its nodes and triangles to the pixels
// it covers (the ray passes through it), the shadow rays of a lit, shadowed scene add nothing,
// an anti-aliased image gets the one-sample counts, and a mesh of many triangles is tested
// against a small part of them per ray (the BVH culls).
TEST(TraversalCost, LayersCountShadowRaysDoNot) {
    sg::Projection p;
    p.fovyDeg = 45.0f;
    sg::FrameInput f = makeFrame(W, H, p, vec3(0.0f, 0.0f, 4.0f), vec3(0.0f));
    f.settings.shadows = false;
    sg::Mesh grid;   // 40 x 40 quads of the plane z = 0, 3200 triangles
    constexpr int N = 40;
    for (int j = 0; j <= N; ++j)
        for (int i = 0; i <= N; ++i) {
            grid.positions.push_back(vec3(-2.0f + 4.0f * float(i) / N, -2.0f + 4.0f * float(j) / N, 0.0f));
            grid.normals.push_back(vec3(0, 0, 1));
        }
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
            const uint32_t a = uint32_t(j * (N + 1) + i), b = a + 1, c = a + N + 1, d = c + 1;
            grid.indices.insert(grid.indices.end(), {a, b, d, a, d, c});
        }
    addMesh(f, grid, unlit(vec3(0.7f)));
    f.lights.push_back(directional(vec3(-0.3f, -0.4f, -1.0f), vec3(0.9f)));
    const std::vector<std::string> counting = backendsWith(rnd::Aov::TraversalCost);
    ASSERT_FALSE(counting.empty());
    const std::string b = counting.front();
    const rnd::Framebuffer base = renderCounted(b, f, W, H, false, true);
    ASSERT_TRUE(base.has(rnd::Aov::TraversalCost));
    const size_t centre = size_t(H / 2) * W + W / 2;
    EXPECT_GE(base.costPrims[centre], 1u);
    EXPECT_LT(base.costPrims[centre], 200u) << "of 3200 triangles: the BVH culls";
    EXPECT_GE(base.costNodes[centre], 3u) << "the top-level root, the mesh BVH's root and deeper nodes";

    sg::FrameInput shadowed = f;
    shadowed.settings.shadows = true;
    const rnd::Framebuffer withShadows = renderCounted(b, shadowed, W, H, false, true);
    EXPECT_EQ(withShadows.costNodes, base.costNodes) << "shadow rays are not the primary ray's cost";
    EXPECT_EQ(withShadows.costPrims, base.costPrims);

    sg::FrameInput aa = f;
    aa.settings.aa = sg::AAMode::MSAA;
    aa.settings.aaRate = 4;
    const rnd::Framebuffer antiAliased = renderCounted(b, aa, W, H, false, true);
    EXPECT_EQ(antiAliased.costNodes, base.costNodes) << "one centre ray per pixel, as without anti-aliasing";
    EXPECT_EQ(antiAliased.costPrims, base.costPrims);

    sg::FrameInput layered = f;
    sg::Material veil = unlit(vec3(1.0f));
    veil.alphaMode = sg::AlphaMode::Blend;
    veil.alpha = 0.5f;
    addMesh(layered, quad(0.5f), veil, glm::translate(mat4(1.0f), vec3(0.0f, 0.0f, 1.0f)));
    const rnd::Framebuffer more = renderCounted(b, layered, W, H, false, true);
    ASSERT_TRUE(more.has(rnd::Aov::TraversalCost));
    EXPECT_GE(more.costPrims[centre], base.costPrims[centre] + 2) << "the veil's two triangles, then the grid behind it";
    EXPECT_GT(more.costNodes[centre], base.costNodes[centre]);
    uint64_t sumBase = 0, sumMore = 0;
    for (size_t k = 0; k < base.costPrims.size(); ++k) {
        sumBase += base.costPrims[k];
        sumMore += more.costPrims[k];
    }
    EXPECT_GT(sumMore, sumBase);
}

// A backend without the capability refuses the request, naming itself and the view; asking
// for nothing leaves the counters empty in every backend.
TEST(DiagnosticCounters, UnsupportedRequestsFailClearly) {
    const sg::FrameInput f = threeQuads();
    for (const std::string& b : rnd::rendererNames()) {
        SCOPED_TRACE(b);
        auto r = rnd::makeRenderer(b, nullptr);
        ASSERT_TRUE(r);
        const rnd::Capabilities caps = r->capabilities();
        EXPECT_EQ(rnd::diagnosticViewSupported(rnd::DiagnosticView::Overdraw, caps), caps.aovs.has(rnd::Aov::Overdraw));
        EXPECT_EQ(rnd::diagnosticViewSupported(rnd::DiagnosticView::Cost, caps), caps.aovs.has(rnd::Aov::TraversalCost));
        rnd::Framebuffer fb;
        const rnd::RenderStats plain = r->render(f, W, H, fb);
        ASSERT_TRUE(plain.ok) << plain.error;
        EXPECT_TRUE(fb.overdraw.empty() && fb.costNodes.empty() && fb.costPrims.empty()) << "counted without being asked";
        for (bool overdraw : {true, false}) {
            rnd::RenderRequest req;
            const rnd::Aov counter = overdraw ? rnd::Aov::Overdraw : rnd::Aov::TraversalCost;
            req.aovs.add(counter);
            const bool can = caps.aovs.has(counter);
            const rnd::RenderStats st = r->render(f, W, H, fb, nullptr, req);
            EXPECT_EQ(st.ok, can) << st.error;
            if (can) continue;
            EXPECT_EQ(st.error.rfind(b + ": ", 0), 0u) << st.error;
            EXPECT_NE(st.error.find(overdraw ? "overdraw view" : "cost view"), std::string::npos) << st.error;
        }
    }
}

}   // namespace
