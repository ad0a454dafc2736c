// camera_rays_test.cpp - CameraRays::grid (a packet's camera rays, the unprojection done two
// doubles at a time, or a row of four rays per vector with AVX2) and CameraRays::neighbours (a pixel's neighbours) against CameraRays::ray,
// bit for bit, for every projection, far planes at infinity, window positions inside and far
// outside the image, and grids wider than the columns it keeps; CameraRays::windowBounds (the window rectangle that holds every camera ray
// that can meet a box) against the rays' own box tests, boxes grazed by rays included; and
// TriangleBvh::rootChildBoxes, the tighter boxes the culling uses, holding every triangle.
#include "raycast/camera_rays.h"
#include "raycast/bvh.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

using namespace sg;
using namespace rnd::rt;

namespace {

bool sameBits(const Ray& a, const Ray& b) { return std::memcmp(&a, &b, sizeof(Ray)) == 0; }

std::string describe(const Ray& r) {
    char s[256];
    std::snprintf(s, sizeof s, "org (%a %a %a) dir (%a %a %a) t [%a %a]", double(r.org.x), double(r.org.y), double(r.org.z), double(r.dir.x),
                  double(r.dir.y), double(r.dir.z), double(r.tmin), double(r.tmax));
    return s;
}

}   // namespace

TEST(CameraRaysTest, GridGivesEachRayBitForBit) {
    const int w = 320, h = 200;
    std::vector<std::pair<std::string, Projection>> projections;
    Projection p;
    projections.push_back({"perspective", p});
    p.type = ProjectionType::Orthographic;
    projections.push_back({"orthographic", p});
    projections.push_back({"cabinet", Projection::cabinet()});
    for (float zNear : {1e-3f, 1e-5f, 1e-6f}) {   // the last two: far plane at infinity in float
        Projection q;
        q.zNear = zNear;
        q.zFar = 1000.0f;
        projections.push_back({"near " + std::to_string(zNear), q});
    }
    const mat4 cameras[] = {glm::inverse(glm::lookAt(vec3(3, 2, 6), vec3(0, 0, 0), vec3(0, 1, 0))),
                            glm::inverse(glm::lookAt(vec3(312.0f, 205.0f, 488.0f), vec3(311.7f, 204.8f, 487.0f), vec3(0, 1, 0))),
                            glm::inverse(glm::lookAt(vec3(0, 0, 0), vec3(0, 0, -1), vec3(0, 1, 0)))};   // axis-aligned: zero components
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> inside(0.0f, 1.0f), outside(-3.0f, 4.0f);
    int rays = 0, fallbacks = 0;
    for (const auto& [name, proj] : projections)
        for (const mat4& camWorld : cameras) {
            const FrameCamera cam = makeFrameCamera(camWorld, proj, float(w) / h, 5.0f);
            const CameraRays cr(cam, w, h);
            for (int trial = 0; trial < 40; ++trial) {
                // Up to 11 columns (more than grid keeps); often 4, a packet's rows (four rays per
                // vector where the CPU has AVX2).
                const int nx = trial % 3 == 0 ? 4 : 1 + trial % 11, ny = 1 + trial % 5;
                std::uniform_real_distribution<float>& d = trial % 4 == 3 ? outside : inside;
                std::vector<float> wx(static_cast<size_t>(nx)), wy(static_cast<size_t>(ny));
                for (float& x : wx) x = trial % 2 ? std::floor(d(rng) * w) + 0.5f : d(rng) * w;
                for (float& y : wy) y = trial % 2 ? std::floor(d(rng) * h) + 0.5f : d(rng) * h;
                std::vector<Ray> out(size_t(nx * ny));
                cr.grid(wx.data(), nx, wy.data(), ny, out.data());
                for (int j = 0; j < ny; ++j)
                    for (int i = 0; i < nx; ++i) {
                        const Ray one = cr.ray(wx[size_t(i)], wy[size_t(j)]);
                        const Ray& got = out[size_t(j * nx + i)];
                        ++rays;
                        fallbacks += one.tmax != 1.0f;
                        EXPECT_TRUE(sameBits(got, one))
                            << name << " at (" << wx[size_t(i)] << ", " << wy[size_t(j)] << "): grid " << describe(got) << ", ray " << describe(one);
                        Ray right, up;   // a texture footprint's neighbours
                        cr.neighbours(wx[size_t(i)], wy[size_t(j)], right, up);
                        EXPECT_TRUE(sameBits(right, cr.ray(wx[size_t(i)] + 1.0f, wy[size_t(j)])) &&
                                    sameBits(up, cr.ray(wx[size_t(i)], wy[size_t(j)] + 1.0f)))
                            << name << ": the neighbours of (" << wx[size_t(i)] << ", " << wy[size_t(j)] << ")";
                    }
            }
        }
    // Both kinds of ray were compared: those with a far end and those without one.
    EXPECT_GT(fallbacks, 0);
    EXPECT_GT(rays - fallbacks, 0);
}

namespace {

// Whether ray r meets box [lo, hi] within [tmin, tmax], as the ray caster's top level tests it
// (Bvh4RayTest: slabs with the far end grown by kGrow).
bool reaches(const Ray& r, const vec3& lo, const vec3& hi) {
    Node4 n{};
    for (int c = 0; c < 4; ++c)
        for (int a = 0; a < 3; ++a) {
            n.b[2 * a][c] = c == 0 ? lo[a] : 1.0f;   // children 1-3: empty boxes
            n.b[2 * a + 1][c] = c == 0 ? hi[a] : -1.0f;
        }
    __m128 tn;
    return Bvh4RayTest(r).children(n, r.tmax, tn) & 1;
}

}   // namespace

// Every pixel centre whose camera ray reaches a box lies in the box's window rectangle, for
// perspective, orthographic and oblique cameras, near and far from the origin, boxes inside,
// across the image's edge and grazed by rays (a corner or a face put on a pixel's ray); a box
// that reaches behind the eye has no rectangle.
TEST(CameraRaysTest, WindowBoundsHoldEveryRayThatMeetsTheBox) {
    const int w = 64, h = 48;
    std::vector<std::pair<std::string, Projection>> projections;
    projections.push_back({"perspective", Projection{}});
    Projection o;
    o.type = ProjectionType::Orthographic;
    projections.push_back({"orthographic", o});
    projections.push_back({"cabinet", Projection::cabinet()});
    Projection tight;
    tight.zNear = 1e-5f;
    tight.zFar = 1000.0f;
    projections.push_back({"near 1e-5", tight});
    const vec3 eyes[] = {vec3(3, 2, 6), vec3(3000.0f, -2000.0f, 6000.0f)};
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f), S(0.001f, 1.0f);
    int reached = 0, outside = 0, unbounded = 0, grazes = 0;
    for (const auto& [name, proj] : projections)
        for (const vec3& eye : eyes) {
            const vec3 target = eye + vec3(-0.5f, -0.3f, -1.0f) * glm::length(eye) * 0.3f;
            const FrameCamera cam =
                makeFrameCamera(glm::inverse(glm::lookAt(eye, target, vec3(0, 1, 0))), proj, float(w) / h, glm::length(target - eye));
            const CameraRays cr(cam, w, h);
            std::vector<Ray> rays;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) rays.push_back(cr.ray(float(x) + 0.5f, float(y) + 0.5f));
            const float size = glm::length(target - eye);
            for (int trial = 0; trial < 150; ++trial) {
                vec3 lo, hi;
                const Ray& pick = rays[size_t(rng() % rays.size())];
                if (trial % 3 == 0) {   // a box with a corner or a face on a pixel's ray, some small and near
                    const bool small = trial % 9 == 0;
                    const vec3 p = pick.org + std::uniform_real_distribution<float>(small ? 1e-4f : 0.05f, small ? 1e-3f : 0.9f)(rng) * pick.dir;
                    const vec3 e = S(rng) * (small ? 1e-4f : 0.2f) * size * vec3(S(rng), S(rng), S(rng));
                    lo = trial % 2 ? p : p - e;
                    hi = trial % 2 ? p + e : vec3(p.x, p.y + e.y, p.z + e.z);
                    ++grazes;
                } else {
                    const vec3 c = target + 0.8f * size * vec3(U(rng), U(rng), U(rng));
                    const vec3 e = 0.3f * size * vec3(S(rng), S(rng), S(rng));
                    lo = c - e;
                    hi = c + e;
                }
                float rect[4];
                const bool bounded = cr.windowBounds(lo, hi, 3.0f, rect);
                if (!bounded) ++unbounded;
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) {
                        const float wx = float(x) + 0.5f, wy = float(y) + 0.5f;
                        const bool in = bounded && wx >= rect[0] && wx <= rect[2] && wy >= rect[1] && wy <= rect[3];
                        if (reaches(rays[size_t(y * w + x)], lo, hi)) {
                            ++reached;
                            if (bounded) {
                                EXPECT_TRUE(in) << name << ", eye " << eye.x << ": pixel (" << x << ", " << y
                                                << ") reaches the box outside its rectangle";
                            }
                        } else if (!in) {
                            ++outside;
                        }
                    }
            }
        }
    // The rectangles do leave pixels out, the grazing boxes were made, and boxes behind the eye
    // came up.
    EXPECT_GT(reached, 10000);
    EXPECT_GT(outside, 100000);
    EXPECT_GT(grazes, 100);
    EXPECT_GT(unbounded, 0);
}

// Every triangle of a mesh lies wholly in one of its BVH's root child boxes (the packet
// culling's boxes for a mesh), for meshes of a few triangles (one leaf) to many, and a soup of
// random triangles of every size.
TEST(CameraRaysTest, RootChildBoxesHoldEveryTriangle) {
    std::mt19937 rng(31);
    std::uniform_real_distribution<float> U(-10.0f, 10.0f), E(0.001f, 3.0f);
    for (int triangles : {1, 3, 40, 700, 20000}) {
        std::vector<vec3> pos;
        std::vector<uint32_t> idx;
        for (int t = 0; t < triangles; ++t) {
            const vec3 c(U(rng), U(rng), U(rng));
            const float e = E(rng);
            for (int k = 0; k < 3; ++k) {
                idx.push_back(uint32_t(pos.size()));
                pos.push_back(c + e * vec3(U(rng), U(rng), U(rng)) / 10.0f);
            }
        }
        TriangleBvh bvh;
        bvh.build(pos.data(), idx.data(), size_t(triangles));
        const std::vector<Aabb> boxes = bvh.rootChildBoxes();
        ASSERT_FALSE(boxes.empty()) << triangles;
        EXPECT_LE(boxes.size(), size_t(bvh.width()));
        for (int t = 0; t < triangles; ++t) {
            bool held = false;
            for (const Aabb& b : boxes) {
                bool all = true;
                for (int k = 0; k < 3; ++k) {
                    const vec3& p = pos[idx[size_t(3 * t + k)]];
                    all = all && glm::all(glm::greaterThanEqual(p, b.min)) && glm::all(glm::lessThanEqual(p, b.max));
                }
                held = held || all;
            }
            EXPECT_TRUE(held) << triangles << " triangles: triangle " << t << " is in no root child box";
        }
    }
}
