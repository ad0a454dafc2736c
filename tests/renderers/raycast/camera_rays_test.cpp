// camera_rays_test.cpp - CameraRays::grid (a packet's camera rays, the unprojection done two
// doubles at a time) against CameraRays::ray, bit for bit, for every projection, far planes at
// infinity, window positions inside and far outside the image, and grids wider than the
// columns it keeps.
#include "raycast/camera_rays.h"

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
                const int nx = 1 + trial % 11, ny = 1 + trial % 5;   // up to 11 columns: more than grid keeps
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
                    }
            }
        }
    // Both kinds of ray were compared: those with a far end and those without one.
    EXPECT_GT(fallbacks, 0);
    EXPECT_GT(rays - fallbacks, 0);
}
