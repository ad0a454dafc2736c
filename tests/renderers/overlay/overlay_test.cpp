// overlay_test.cpp - the overlay pass's integer algorithms held to worked examples computed by
// hand from the formulations in docs/math.md ("Overlays"): Bresenham's decision variable
// D = 2*dy - dx (step when D > 0), the midpoint circle's d = 1 - r, and near-plane clipping
// in clip space (a segment that crosses behind the camera does not wrap around).
#include "renderers/overlay.h"
#include "scenegraph/mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <memory>

using rnd::overlay::bresenhamPixels;
using rnd::overlay::midpointCirclePixels;
using Pixels = std::vector<std::pair<int, int>>;

namespace {

Pixels sorted(Pixels p) {
    std::sort(p.begin(), p.end());
    return p;
}

// (0,0) -> (5,2): D starts at 2*2 - 5 = -1; at x = 0..4 D = -1, 3 (step), -3, 1 (step), -5:
// y = 0, 0, 1, 1, 2, 2 (the nearest rows to y = 0.4 x).
TEST(OverlayBresenhamTest, FirstOctantWorkedExample) {
    EXPECT_EQ(bresenhamPixels(0, 0, 5, 2), sorted({{0, 0}, {1, 0}, {2, 1}, {3, 1}, {4, 2}, {5, 2}}));
}

TEST(OverlayBresenhamTest, SteepOctantSwapsTheAxes) {
    EXPECT_EQ(bresenhamPixels(0, 0, 2, 5), sorted({{0, 0}, {0, 1}, {1, 2}, {1, 3}, {2, 4}, {2, 5}}));
    EXPECT_EQ(bresenhamPixels(0, 0, -2, 5), sorted({{0, 0}, {0, 1}, {-1, 2}, {-1, 3}, {-2, 4}, {-2, 5}}));
}

TEST(OverlayBresenhamTest, NegativeSlopeStepsDown) {
    EXPECT_EQ(bresenhamPixels(0, 0, 5, -2), sorted({{0, 0}, {1, 0}, {2, -1}, {3, -1}, {4, -2}, {5, -2}}));
    EXPECT_EQ(bresenhamPixels(0, 0, 2, -5), sorted({{0, 0}, {0, -1}, {1, -2}, {1, -3}, {2, -4}, {2, -5}}));
}

// Walked from the lower major coordinate: (0,0) -> (-5,-2) is drawn as (-5,-2) -> (0,0), and
// a segment gives the same pixels as its reverse in every octant.
TEST(OverlayBresenhamTest, AllOctantsSamePixelsBothWays) {
    EXPECT_EQ(bresenhamPixels(0, 0, -5, -2), sorted({{-5, -2}, {-4, -2}, {-3, -1}, {-2, -1}, {-1, 0}, {0, 0}}));
    for (auto [x, y] : Pixels{{5, 2}, {2, 5}, {-2, 5}, {-5, 2}, {-5, -2}, {-2, -5}, {2, -5}, {5, -2}, {7, 0}, {0, -7}, {4, 4}, {-4, 4}}) {
        Pixels fwd = bresenhamPixels(0, 0, x, y), back = bresenhamPixels(x, y, 0, 0);
        EXPECT_EQ(fwd, back) << "to " << x << "," << y;
        EXPECT_EQ(fwd.size(), size_t(std::max(std::abs(x), std::abs(y)) + 1)) << "one pixel per major step, both endpoints";
        EXPECT_TRUE(std::count(fwd.begin(), fwd.end(), std::pair{x, y}) == 1 && std::count(fwd.begin(), fwd.end(), std::pair{0, 0}) == 1);
    }
}

// A tie (the line through the midpoint (1, 0.5)): D = 0 is not > 0, the row is kept.
TEST(OverlayBresenhamTest, TieKeepsTheRow) { EXPECT_EQ(bresenhamPixels(0, 0, 2, 1), sorted({{0, 0}, {1, 0}, {2, 1}})); }

TEST(OverlayBresenhamTest, DegenerateLines) {
    EXPECT_EQ(bresenhamPixels(3, 4, 3, 4), Pixels({{3, 4}}));
    EXPECT_EQ(bresenhamPixels(0, 0, 3, 0), Pixels({{0, 0}, {1, 0}, {2, 0}, {3, 0}}));
    EXPECT_EQ(bresenhamPixels(0, 0, 3, 3), Pixels({{0, 0}, {1, 1}, {2, 2}, {3, 3}}));
}

// r = 3: d = -2 (x=0, y=3), 1 (x=1, y=3; step), 2 (x=2, y=2): octant points (0,3), (1,3),
// (2,2) mirrored eight ways: 16 pixels.
TEST(OverlayMidpointCircleTest, RadiusThreeWorkedExample) {
    Pixels want;
    for (auto [a, b] : Pixels{{0, 3}, {1, 3}, {2, 2}})
        for (int sa : {1, -1})
            for (int sb : {1, -1}) {
                want.push_back({sa * a, sb * b});
                want.push_back({sb * b, sa * a});
            }
    std::sort(want.begin(), want.end());
    want.erase(std::unique(want.begin(), want.end()), want.end());
    ASSERT_EQ(want.size(), 16u);
    EXPECT_EQ(midpointCirclePixels(0, 0, 3), want);
}

TEST(OverlayMidpointCircleTest, SmallRadiiAndCentre) {
    EXPECT_EQ(midpointCirclePixels(0, 0, 0), Pixels({{0, 0}}));
    EXPECT_EQ(midpointCirclePixels(10, 20, 1), Pixels({{9, 20}, {10, 19}, {10, 21}, {11, 20}}));
    EXPECT_TRUE(midpointCirclePixels(0, 0, -1).empty());
}

// Every pixel of a radius-r circle lies within half a pixel of the true circle (|x^2+y^2-r^2|
// <= r: the midpoint criterion), and the circle is 8-way symmetric.
TEST(OverlayMidpointCircleTest, PixelsHugTheCircle) {
    for (int r : {2, 5, 6, 17}) {
        Pixels p = midpointCirclePixels(0, 0, r);
        for (auto [x, y] : p) {
            EXPECT_LE(std::abs(x * x + y * y - r * r), r) << "r=" << r << " at " << x << "," << y;
            EXPECT_TRUE(std::binary_search(p.begin(), p.end(), std::pair{y, -x}));
        }
    }
}

TEST(OverlayClipTest, NearPlaneCrossingKeepsTheFrontPart) {
    sg::vec4 a(0, 0, 1, 2), b(0, 0, -3, -1);   // a: z + w = 3 (in front), b: -4 (behind)
    float t0 = -1, t1 = -1;
    ASSERT_TRUE(rnd::overlay::clipToNear(a, b, &t0, &t1));
    EXPECT_FLOAT_EQ(t0, 0.0f);
    EXPECT_FLOAT_EQ(t1, 3.0f / 7.0f);
    EXPECT_NEAR(b.z + b.w, 0.0f, 1e-6f);
    sg::vec4 c(0, 0, -3, -1), d(0, 0, -5, 1);
    EXPECT_FALSE(rnd::overlay::clipToNear(c, d)) << "both behind the near plane";
}

TEST(OverlayParseTest, NamesAndErrors) {
    rnd::OverlayOptions o;
    std::string err;
    ASSERT_TRUE(rnd::parseOverlayList("grid,axes,lights,bounds,selection,cameras", o, err)) << err;
    EXPECT_TRUE(o.grid && o.axes && o.lights && o.bounds && o.selection && o.cameras);
    EXPECT_FALSE(o.gridOnTop) << "the grid is depth-tested unless asked";
    rnd::OverlayOptions top;
    ASSERT_TRUE(rnd::parseOverlayList("grid-on-top", top, err)) << err;
    EXPECT_TRUE(top.grid && top.gridOnTop);
    for (std::string bad : {"", "grid,", "grid,,axes", "gird"}) {
        rnd::OverlayOptions p;
        EXPECT_FALSE(rnd::parseOverlayList(bad, p, err)) << bad;
        EXPECT_NE(err.find("grid, axes, lights, cameras, bounds, selection"), std::string::npos) << err;
        EXPECT_EQ(err.find('\n'), std::string::npos);
    }
}

// A camera at the origin looking down -z, 64x64, depth cleared to far.
struct Scene {
    sg::FrameInput frame;
    rnd::Framebuffer fb;
    Scene() {
        frame.camera = sg::makeFrameCamera(sg::mat4(1.0f), sg::Projection{}, 1.0f, 5.0f);
        fb.resize(64, 64);
        const uint8_t black[4] = {0, 0, 0, 255};
        fb.clear(black, 1.0f);
    }
    void addBox(const sg::vec3& lo, const sg::vec3& hi, sg::NodeId node = 1) {
        auto m = std::make_shared<sg::Mesh>();
        m->positions = {lo, hi};
        sg::DrawMesh d;
        d.mesh = m;
        d.node = node;
        frame.meshes.push_back(d);
    }
    int litPixels(int x0, int x1) const {   // overlay pixels in columns [x0, x1)
        int n = 0;
        for (int y = 0; y < fb.height; ++y)
            for (int x = x0; x < x1; ++x) n += fb.pixel(x, y)[0] || fb.pixel(x, y)[1] || fb.pixel(x, y)[2];
        return n;
    }
};

// A box to the right of the camera, reaching from in front of it to far behind: projected
// without clipping, the corners behind the eye (w < 0) flip to the left half of the image.
TEST(OverlayClipTest, SegmentBehindCameraDoesNotWrapAround) {
    Scene s;
    s.addBox({1, -0.5f, -10}, {2, 0.5f, 10});
    rnd::OverlayOptions o;
    o.bounds = true;
    rnd::drawOverlays(s.frame, o, s.fb);
    EXPECT_GT(s.litPixels(32, 64), 20);
    EXPECT_EQ(s.litPixels(0, 32), 0);
}

// Bounds are hidden behind geometry; light gizmos always show.
TEST(OverlayDepthTest, OccludedLinesHiddenGizmosShown) {
    Scene s;
    s.addBox({-1, -1, -6}, {1, 1, -4});
    std::fill(s.fb.depth.begin(), s.fb.depth.end(), 0.0f);   // a surface right at the near plane
    sg::DrawLight light;
    light.position = {0, 0, -5};
    s.frame.lights.push_back(light);
    rnd::OverlayOptions o;
    o.bounds = o.grid = o.axes = true;
    rnd::drawOverlays(s.frame, o, s.fb);
    EXPECT_EQ(s.litPixels(0, 64), 0);
    o.lights = true;
    rnd::drawOverlays(s.frame, o, s.fb);
    EXPECT_EQ(size_t(s.litPixels(0, 64)), midpointCirclePixels(32, 32, 6).size()) << "the radius-6 midpoint circle about the centre";
}

// The grid is hidden behind a surface like bounds and axes, and drawn over it with gridOnTop
// (in its colour, and only the grid: the bounds stay hidden).
TEST(OverlayDepthTest, GridOnTopShowsThroughSurfaces) {
    Scene s;
    s.addBox({-1, -2, -6}, {1, 2, -4});   // the grid (y = 0) crosses the view
    std::fill(s.fb.depth.begin(), s.fb.depth.end(), 0.0f);
    rnd::OverlayOptions o;
    o.grid = o.bounds = true;
    rnd::drawOverlays(s.frame, o, s.fb);
    EXPECT_EQ(s.litPixels(0, 64), 0);
    o.gridOnTop = true;
    rnd::drawOverlays(s.frame, o, s.fb);
    const int lit = s.litPixels(0, 64);
    EXPECT_GT(lit, 10);
    int gridColoured = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const uint8_t* p = s.fb.pixel(x, y);
            gridColoured += p[0] == 20 && p[1] == 175 && p[2] == 190;
        }
    EXPECT_EQ(gridColoured, lit);
}

// The selection outlines only the selected node's drawables, through geometry.
TEST(OverlaySelectionTest, OnlyTheSelectedNode) {
    Scene s;
    s.addBox({-3, -1, -8}, {-2, 1, -6}, 1);   // left of centre
    s.addBox({2, -1, -8}, {3, 1, -6}, 2);     // right of centre
    std::fill(s.fb.depth.begin(), s.fb.depth.end(), 0.0f);
    rnd::OverlayOptions o;
    o.selection = true;
    o.selected = {2};
    rnd::drawOverlays(s.frame, o, s.fb);
    EXPECT_EQ(s.litPixels(0, 32), 0);
    EXPECT_GT(s.litPixels(32, 64), 20);
}

// Bad input draws nothing and never crashes: empty framebuffer, non-finite camera.
TEST(OverlayRobustnessTest, BadInputIsIgnored) {
    Scene s;
    s.addBox({-1, -1, -6}, {1, 1, -4});
    rnd::OverlayOptions o;
    o.bounds = o.grid = o.axes = o.lights = true;
    rnd::Framebuffer empty;
    rnd::drawOverlays(s.frame, o, empty);
    Scene huge;   // coordinates that overflow to infinity in clip space
    huge.addBox({-1e38f, -1e38f, -1e38f}, {1e38f, 1e38f, 3e38f});
    huge.frame.lights.push_back(sg::DrawLight{sg::kNoNode, sg::LightType::Point, {1e38f, 0, -3e38f}});
    rnd::drawOverlays(huge.frame, o, huge.fb);
    s.frame.camera.viewProj[0][0] = std::numeric_limits<float>::quiet_NaN();
    rnd::drawOverlays(s.frame, o, s.fb);
    EXPECT_EQ(s.litPixels(0, 64), 0);
}

}   // namespace
