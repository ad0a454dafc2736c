// lane_shading_test.cpp - raycast::shadeLanes (eight mesh hits shaded at once: AVX2, or SSE2 twice) against
// the scalar shading it stands for, bit for bit: the interpolated albedo and normal of
// Tracer::shadeMeshHit, the visibility rule of Tracer::lightVisibility with the shadow packets'
// bits, and rnd::shade. Random hits, materials and lights (point with and without 1/r^2, spots
// with soft and hard cones, suns, a black light), Phong and Blinn-Phong, with and without
// shadows, textured and untextured hits, partly filled batches, points on a light and on the eye, normals too short to
// normalize and hits without vertex normals. Also raycast::hitFrames against meshHitFrame and
// raycast::shadowRays against Tracer::shadowRay and sampleReaches, bit for bit, and
// raycast::encodeLanes against the scalar sRGB bytes.
#include "raycast/lane_shading.h"
#include "raycast/tracer.h"
#include "raycast/world_vertices.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace sg;
using rnd::SurfaceCoefficients;
using rnd::raycast::LaneBatch;

namespace {

struct Expected {
    bool shaded = false;
    vec3 color{0.0f};
};

// What Tracer::trace gives lane l of b (the scalar functions the lanes stand for).
Expected scalarLane(const LaneBatch& b, int l, const FrameInput& f) {
    const float w0 = b.w[0][l], w1 = b.w[1][l], w2 = b.w[2][l];
    auto at = [&](const float(&a)[3][LaneBatch::kLanes]) { return vec3(a[0][l], a[1][l], a[2][l]); };
    const vec3 p = at(b.p), ng = at(b.ng);
    const vec3 albedo = (w0 * at(b.va[0]) + w1 * at(b.va[1]) + w2 * at(b.va[2])) * ((b.textured >> l) & 1 ? at(b.tex) : vec3(1.0f));
    vec3 n = ng;
    if (b.smooth[l]) {
        n = w0 * at(b.vn[0]) + w1 * at(b.vn[1]) + w2 * at(b.vn[2]);
        const float len = glm::length(n);
        n = len > 1e-20f ? n / len : ng;
    }
    std::vector<float> vis(f.lights.size(), 1.0f);
    Expected e;
    for (size_t i = 0; i < f.lights.size() && f.settings.shadows; ++i) {
        const bool known = (b.known[l] >> i) & 1, lit = (b.lit[l] >> i) & 1;
        if (known && lit) continue;
        if (!rnd::sampleReaches(rnd::sampleLight(f.lights[i], p), n)) continue;
        if (!known) return e;   // a shadow ray no packet traced: the lane is trace()'s
        vis[i] = 0.0f;
    }
    e.shaded = true;
    e.color = rnd::shade(*b.coeff[l], rnd::SurfacePoint{p, n, albedo}, f.camera.eye, f, vis.data());
    return e;
}

vec3 unitVector(std::mt19937& rng) {
    std::normal_distribution<float> g;
    for (;;) {
        const vec3 v(g(rng), g(rng), g(rng));
        if (glm::length(v) > 1e-3f) return glm::normalize(v);
    }
}

std::string bits(const vec3& v) {
    char s[128];
    std::snprintf(s, sizeof s, "(%a %a %a)", double(v.x), double(v.y), double(v.z));
    return s;
}

}   // namespace

TEST(LaneShadingTest, LanesGiveTheScalarShadingBitForBit) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), s(-4.0f, 4.0f);
    std::vector<SurfaceCoefficients> coeffs(4);
    coeffs[0].specularTinted = true;
    coeffs[1].emissive = vec3(0.2f, 0.0f, 0.1f);
    coeffs[1].specularColor = vec3(1.0f, 0.5f, 0.25f);
    coeffs[1].shininess = 180.0f;
    coeffs[2].ks = 0.0f;
    coeffs[2].shininess = 1.0f;
    coeffs[3].ka = 0.7f;
    coeffs[3].kd = 0.05f;
    coeffs[3].ks = 1.0f;
    coeffs[3].shininess = 3.5f;

    size_t shaded = 0, leftToTrace = 0, dark = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        FrameInput f;
        f.settings.reflection = trial % 2 ? ReflectionModel::BlinnPhong : ReflectionModel::Phong;
        f.settings.shadows = trial % 3 != 0;
        f.ambientLight = vec3(u(rng), u(rng), u(rng)) * 0.3f;
        f.camera.eye = vec3(s(rng), s(rng), s(rng)) * 2.0f;
        const int lights = 1 + int(rng() % 6);
        for (int i = 0; i < lights; ++i) {
            DrawLight L;
            L.type = LightType(rng() % 3);
            L.position = vec3(s(rng), s(rng), s(rng));
            L.direction = unitVector(rng);
            L.radiance = rng() % 9 == 0 ? vec3(0.0f) : vec3(u(rng), u(rng), u(rng)) * 3.0f;
            L.inverseSquare = rng() % 2;
            L.cosOuter = std::cos(0.2f + u(rng));
            L.cosInner = rng() % 4 == 0 ? L.cosOuter : std::cos(0.1f + 0.1f * u(rng));   // equal cones: a hard edge
            f.lights.push_back(L);
        }
        LaneBatch b;
        b.count = 1 + int(rng() % LaneBatch::kLanes);
        for (int l = 0; l < b.count; ++l) {
            vec3 p(s(rng), s(rng), s(rng));
            if (rng() % 40 == 0) p = f.lights[0].position;   // on a light: toward it (0, 1, 0)
            if (rng() % 40 == 0) p = f.camera.eye;           // on the eye: toward it (0, 0, 1)
            const vec3 ng = unitVector(rng);
            float b1 = u(rng), b2 = u(rng);
            if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
            const float w[3] = {1.0f - b1 - b2, b1, b2};
            vec3 vn[3];
            for (vec3& v : vn) v = glm::normalize(ng + 0.4f * unitVector(rng));
            if (rng() % 30 == 0)
                for (vec3& v : vn) v *= 1e-22f;   // too short to normalize: ng
            b.smooth[l] = rng() % 8 != 0;
            const bool textured = rng() % 2;
            b.textured = (b.textured & ~(1u << l)) | (unsigned(textured) << l);
            for (int a = 0; a < 3; ++a) {
                b.tex[a][l] = textured ? u(rng) : 1e30f;   // (not read without the bit)
                b.p[a][l] = p[a];
                b.ng[a][l] = ng[a];
                b.w[a][l] = w[a];
                for (int k = 0; k < 3; ++k) {
                    b.vn[k][a][l] = vn[k][a];
                    b.va[k][a][l] = u(rng);
                }
            }
            b.coeff[l] = &coeffs[rng() % coeffs.size()];
            b.known[l] = rng() % 5 == 0 ? 0 : (uint64_t(rng()) & ((uint64_t(1) << lights) - 1));
            b.lit[l] = uint64_t(rng()) & b.known[l];
        }
        const LaneBatch in = b;
        float rgb[3][LaneBatch::kLanes];
        const unsigned got = rnd::raycast::shadeLanes(b, f, rgb);
        EXPECT_EQ(got >> b.count, 0u) << "trial " << trial;
        for (int l = 0; l < in.count; ++l) {
            const Expected e = scalarLane(in, l, f);
            ASSERT_EQ(bool((got >> l) & 1), e.shaded) << "trial " << trial << " lane " << l;
            if (!e.shaded) {
                ++leftToTrace;
                continue;
            }
            ++shaded;
            const vec3 c(rgb[0][l], rgb[1][l], rgb[2][l]);
            dark += e.color == vec3(0.0f);
            ASSERT_EQ(std::memcmp(&c, &e.color, sizeof c), 0) << "trial " << trial << " lane " << l << ": " << bits(c) << " vs " << bits(e.color);
        }
    }
    // Both outcomes occur, and most shaded lanes are lit (not zero against zero).
    EXPECT_GT(shaded, size_t(3000));
    EXPECT_GT(leftToTrace, size_t(100));
    EXPECT_LT(dark, shaded / 4);
}

TEST(LaneShadingTest, FramesAndShadowRaysInLanesAreTheScalarOnesBitForBit) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), s(-50.0f, 50.0f);
    size_t reached = 0, missed = 0, backs = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        // Frames: up to eight triangles (one degenerate now and then), mirrored or not, seen from either side.
        constexpr int kL = rnd::raycast::FrameLanes::kLanes;
        rnd::raycast::FrameLanes fl;
        fl.count = 1 + int(rng() % kL);
        DrawMesh dm[kL];
        rnd::rt::WorldVertices wv[kL];
        rnd::rt::SceneHit h[kL];
        rnd::rt::Ray r[kL];
        for (int l = 0; l < fl.count; ++l) {
            auto mesh = std::make_shared<Mesh>();
            for (int v = 0; v < 3; ++v) mesh->positions.push_back(vec3(s(rng), s(rng), s(rng)));
            if (trial % 25 == 0) mesh->positions[2] = mesh->positions[1];   // no area: the normal is (0, 1, 0)
            mesh->indices = {0, 1, 2};
            dm[l].mesh = mesh;
            dm[l].mirrored = rng() % 3 == 0;
            wv[l].positions = mesh->positions;
            h[l].kind = rnd::rt::SceneHit::Kind::Mesh;
            h[l].b1 = u(rng), h[l].b2 = u(rng) * (1.0f - h[l].b1);
            r[l].dir = unitVector(rng) * (0.5f + u(rng));
            for (int v = 0; v < 3; ++v)
                for (int a = 0; a < 3; ++a) fl.P[v][a][l] = mesh->positions[size_t(v)][a];
            fl.b1[l] = h[l].b1, fl.b2[l] = h[l].b2;
            for (int a = 0; a < 3; ++a) fl.dir[a][l] = r[l].dir[a];
            fl.mirrored |= unsigned(dm[l].mirrored) << l;
        }
        rnd::raycast::hitFrames(fl);
        for (int l = 0; l < fl.count; ++l) {
            const rnd::raycast::MeshHitFrame fr = rnd::raycast::meshHitFrame(dm[l], h[l], r[l], &wv[l]);
            const vec3 p(fl.p[0][l], fl.p[1][l], fl.p[2][l]), gn(fl.gn[0][l], fl.gn[1][l], fl.gn[2][l]), ng(fl.ng[0][l], fl.ng[1][l], fl.ng[2][l]);
            ASSERT_EQ(std::memcmp(&p, &fr.p, sizeof p), 0) << "trial " << trial << " lane " << l << ": " << bits(p) << " vs " << bits(fr.p);
            ASSERT_EQ(std::memcmp(&gn, &fr.gn, sizeof gn), 0) << "trial " << trial << " lane " << l;
            ASSERT_EQ(std::memcmp(&ng, &fr.ng, sizeof ng), 0) << "trial " << trial << " lane " << l;
            ASSERT_EQ(bool((fl.back >> l) & 1), fr.back) << "trial " << trial << " lane " << l;
            backs += fr.back;
        }

        // Shadow rays toward one light from up to eight points, far from the origin now and then.
        DrawLight L;
        L.type = LightType(rng() % 3);
        L.position = vec3(s(rng), s(rng), s(rng));
        L.direction = unitVector(rng);
        L.radiance = rng() % 9 == 0 ? vec3(0.0f) : vec3(1.0f);
        L.inverseSquare = rng() % 2;
        L.cosOuter = std::cos(0.3f + u(rng));
        L.cosInner = rng() % 4 == 0 ? L.cosOuter : std::cos(0.1f + 0.1f * u(rng));
        rnd::raycast::ShadowLanes sl;
        sl.count = 1 + int(rng() % rnd::raycast::ShadowLanes::kLanes);
        vec3 p[rnd::raycast::ShadowLanes::kLanes], ng[rnd::raycast::ShadowLanes::kLanes];
        for (int l = 0; l < sl.count; ++l) {
            p[l] = vec3(s(rng), s(rng), s(rng)) * (rng() % 5 == 0 ? 1000.0f : 1.0f);
            if (rng() % 30 == 0) p[l] = L.position;   // on the light: a zero distance
            ng[l] = unitVector(rng);
            for (int a = 0; a < 3; ++a) sl.p[a][l] = p[l][a], sl.ng[a][l] = ng[l][a];
        }
        rnd::raycast::shadowRays(sl, L);
        EXPECT_EQ(sl.reaches >> sl.count, 0u);
        for (int l = 0; l < sl.count; ++l) {
            const rnd::LightSample ls = rnd::sampleLight(L, p[l]);
            const bool reaches = rnd::sampleReaches(ls, ng[l]);
            ASSERT_EQ(bool((sl.reaches >> l) & 1), reaches) << "trial " << trial << " lane " << l;
            if (!reaches) {
                ++missed;
                continue;
            }
            ++reached;
            const rnd::rt::Ray want = rnd::raycast::Tracer::shadowRay(ls, p[l], ng[l]);
            ASSERT_EQ(std::memcmp(&sl.rays[l], &want, sizeof want), 0)
                << "trial " << trial << " lane " << l << ": org " << bits(sl.rays[l].org) << " vs " << bits(want.org) << ", tmax " << sl.rays[l].tmax
                << " vs " << want.tmax;
        }
    }
    EXPECT_GT(reached, size_t(1000));
    EXPECT_GT(missed, size_t(500));
    EXPECT_GT(backs, size_t(500));
}

// raycast::encodeLanes against the scalar bytes (toByteSRGB per channel, magenta where a channel
// is not finite, alpha 255), for colours around every byte's threshold, outside [0, 1], -0,
// denormals, NaN and infinities, in batches of every length.
TEST(LaneShadingTest, EncodedLanesAreTheScalarBytes) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-0.2f, 1.2f);
    std::uniform_int_distribution<int> byte(1, 255);
    const float special[] = {0.0f,
                             -0.0f,
                             1e-40f,
                             0x1p-13f,
                             1.0f,
                             0x1.fffffep-1f,
                             7.5f,
                             -3.0f,
                             std::numeric_limits<float>::quiet_NaN(),
                             std::numeric_limits<float>::infinity(),
                             -std::numeric_limits<float>::infinity()};
    size_t magenta = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        constexpr int kL = LaneBatch::kLanes;
        alignas(32) float rgb[3][kL];
        const int count = 1 + trial % kL;
        for (int a = 0; a < 3; ++a)
            for (int l = 0; l < kL; ++l) {
                float x = u(rng);
                switch (rng() % 8) {
                case 0: x = special[rng() % (sizeof special / sizeof special[0])]; break;
                case 1: x = std::nextafter(rnd::srgbByteThreshold(byte(rng)), rng() % 2 ? 2.0f : -1.0f); break;   // a hair off a threshold
                case 2: x = rnd::srgbByteThreshold(byte(rng)); break;
                default: break;
                }
                rgb[a][l] = x;
            }
        uint32_t words[kL];
        rnd::raycast::encodeLanes(rgb, count, words);
        for (int l = 0; l < count; ++l) {
            vec3 c(rgb[0][l], rgb[1][l], rgb[2][l]);
            const bool finite = isFinite(c);
            magenta += !finite;
            if (!finite) c = vec3(1, 0, 1);
            const uint8_t want[4] = {rnd::toByteSRGB(c.x), rnd::toByteSRGB(c.y), rnd::toByteSRGB(c.z), 255};
            uint8_t got[4];
            std::memcpy(got, &words[l], 4);
            ASSERT_EQ(std::memcmp(got, want, 4), 0) << "trial " << trial << " lane " << l << ": " << bits(vec3(rgb[0][l], rgb[1][l], rgb[2][l]))
                                                    << " -> " << int(got[0]) << " " << int(got[1]) << " " << int(got[2]) << " " << int(got[3]);
        }
    }
    EXPECT_GT(magenta, 100u);
}
