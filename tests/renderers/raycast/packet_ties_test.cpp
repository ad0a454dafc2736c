// Packets at ties: where a ray meets several triangles at exactly (or within a few units in the
// last place of) the same distance, the one kept follows the visit order. A packet visits leaves
// and instances in its own order, so TriangleBvh::intersectPacket and
// SceneAccel::intersectPacket must see such rays and give them exactly the single ray's hit (the
// triangle and the instance), as the pixel inspector, which traces single rays, shows them.
#include "raycast/bvh.h"
#include "raycast/scene_accel.h"
#include "scenegraph/frame.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

using namespace sg;
using namespace rnd::rt;

namespace {

// An n x n grid of unit squares in the plane z = 0, each cut along one diagonal ("/" or "\"),
// counter-clockwise seen from +z. Every triangle's normal e1 x e2 is (0, 0, 1) exactly, so a ray
// meets the two cuts of a square at bit for bit the same distance: two such meshes, or both
// cuts in one mesh, tie wherever a ray meets the grid.
void addGrid(std::vector<vec3>& pos, std::vector<uint32_t>& idx, int n, bool slash) {
    const uint32_t base = uint32_t(pos.size());
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) pos.push_back(vec3(float(i), float(j), 0.0f));
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const uint32_t a = base + uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
            if (slash)
                idx.insert(idx.end(), {a, b, d, a, d, c});
            else
                idx.insert(idx.end(), {a, b, c, b, d, c});
        }
}
// Thin upright triangles at the grid's corners, of heights between 0.1 and 4.9: the leaves that
// hold them reach up, so rays from different sides enter them in different orders.
void addSpikes(std::vector<vec3>& pos, std::vector<uint32_t>& idx, int n) {
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const float h = 0.1f + 0.2f * float((i * 7 + j * 13) % 25);
            const uint32_t base = uint32_t(pos.size());
            pos.insert(pos.end(), {vec3(float(i), float(j), 0.0f), vec3(float(i) + 0.01f, float(j), 0.0f), vec3(float(i), float(j), h)});
            idx.insert(idx.end(), {base, base + 1, base + 2});
        }
}
// One far triangle at (farX, 0, 3): it stretches the mesh's box to one side.
void addFar(std::vector<vec3>& pos, std::vector<uint32_t>& idx, float farX) {
    const uint32_t base = uint32_t(pos.size());
    pos.insert(pos.end(), {vec3(farX, 0, 3), vec3(farX + 1, 0, 3), vec3(farX, 1, 3)});
    idx.insert(idx.end(), {base, base + 1, base + 2});
}

std::shared_ptr<Mesh> meshOf(const std::vector<vec3>& pos, const std::vector<uint32_t>& idx) {
    auto m = std::make_shared<Mesh>();
    m->positions = pos;
    m->indices = idx;
    m->normals.assign(pos.size(), vec3(0, 0, 1));
    return m;
}

// Packets of 4 x 4 rays from eyes around and above the grid, aimed at points of the grid spaced
// so that neighbouring rays cross other squares (some packets with mixed direction signs, whose
// odd rays are traced alone); calls check(rays, n) for each. A third of them end at t = 1 + i /
// 100: ray 0 then ends exactly where it meets the grid.
template <class Check>
void eachPacket(int gridN, Check&& check) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f);
    for (int p = 0; p < 300; ++p) {
        const float g = float(gridN);
        const vec3 eye(0.5f * g + 1.5f * g * U(rng), 0.5f * g + 1.5f * g * U(rng), 0.5f + 8.0f * std::abs(U(rng)));
        const vec3 aim(0.5f * g + 0.4f * g * U(rng), 0.5f * g + 0.4f * g * U(rng), 0.0f);
        const float step = 0.05f + 1.5f * std::abs(U(rng));
        Ray rays[16];
        for (int i = 0; i < 16; ++i) {
            rays[i].org = eye;
            rays[i].dir = aim + step * vec3(float(i % 4), float(i / 4), 0.0f) - eye;
            rays[i].tmin = 0.0f;
            rays[i].tmax = p % 3 ? 1.0f + 0.01f * float(i) : std::numeric_limits<float>::infinity();
        }
        check(rays, 16);
    }
}

}   // namespace

// Both cuts of every square in one mesh (and thin upright triangles among them): every ray that
// meets the grid meets two triangles at exactly the same distance, which intersectPacket must
// report when asked (and then leave as the packet found it) and otherwise resolve as the single
// ray does.
TEST(RaycastTest, MeshPacketsKeepTheSingleRayTriangleAtTies) {
    std::vector<vec3> pos;
    std::vector<uint32_t> idx;
    addGrid(pos, idx, 24, true);
    addGrid(pos, idx, 24, false);
    const uint32_t gridPrims = uint32_t(idx.size() / 3);   // the grids' triangles come first
    addSpikes(pos, idx, 24);
    addFar(pos, idx, 40.0f);
    TriangleBvh bvh;
    bvh.build(pos.data(), idx.data(), idx.size() / 3);
    int hits = 0, reported = 0;
    eachPacket(24, [&](const Ray* rays, int n) {
        TriHit ph[16], pt[16];
        uint64_t ties = 0;
        const uint64_t found = bvh.intersectPacket(rays, n, 0xFFFF, ph);
        const uint64_t foundT = bvh.intersectPacket(rays, n, 0xFFFF, pt, false, &ties);
        EXPECT_EQ(found, foundT);
        for (int i = 0; i < n; ++i) {
            TriHit a;
            const bool ha = bvh.intersect(rays[i], a);
            ASSERT_EQ(bool((found >> i) & 1), ha) << "ray " << i;
            if (!ha) continue;
            ++hits;
            EXPECT_EQ(ph[i].t, a.t);
            EXPECT_EQ(ph[i].prim, a.prim) << "ray " << i << ": another triangle at the same distance";
            EXPECT_EQ(ph[i].b1, a.b1);
            EXPECT_EQ(ph[i].b2, a.b2);
            EXPECT_EQ(pt[i].t, a.t);
            if (a.prim >= gridPrims) continue;   // a spike or the far triangle: no tie
            EXPECT_TRUE((ties >> i) & 1) << "ray " << i << " not reported";
            reported += (ties >> i) & 1;
        }
    });
    EXPECT_GT(hits, 3000);
    EXPECT_GT(reported, 3000);
}

// One cut per mesh, the two meshes' boxes stretched to opposite sides (so rays meet them in
// different orders) and both at the same place: every ray that meets the grid ties between the
// two instances. Small meshes (SceneAccel reports their ties: 33 and 243 triangles), with a
// third instance elsewhere. (Big meshes keep the packet's first found at ties.)
TEST(RaycastTest, ScenePacketsKeepTheSingleRayInstanceAtTies) {
    for (const int gridN : {4, 11}) {
        std::vector<vec3> pa, pb;
        std::vector<uint32_t> ia, ib;
        addGrid(pa, ia, gridN, true);
        addFar(pa, ia, 3.0f * float(gridN));
        addGrid(pb, ib, gridN, false);
        addFar(pb, ib, -3.0f * float(gridN));
        FrameInput f;
        DrawMesh a, b;
        a.mesh = meshOf(pa, ia);
        b.mesh = meshOf(pb, ib);
        f.meshes = {a, b};
        DrawMesh other = a;   // a copy of the first mesh moved up and aside: no ties with it
        other.world = glm::translate(mat4(1.0f), vec3(0.5f * float(gridN), 0.3f, 1.0f));
        other.normal = glm::transpose(glm::inverse(mat3(other.world)));
        f.meshes.push_back(other);
        SceneAccel acc;
        acc.update(f);
        int hits = 0, first = 0, second = 0;
        eachPacket(gridN, [&](const Ray* rays, int n) {
            SceneHit ph[16];
            const uint64_t found = acc.intersectPacket(rays, n, 0xFFFF, ph);
            for (int i = 0; i < n; ++i) {
                SceneHit s;
                const bool hs = acc.intersect(rays[i], s);
                ASSERT_EQ(bool((found >> i) & 1), hs) << "ray " << i;
                if (!hs) continue;
                ++hits;
                EXPECT_EQ(ph[i].t, s.t);
                EXPECT_EQ(ph[i].instance, s.instance) << "grid " << gridN << " ray " << i << ": another instance at the same distance";
                EXPECT_EQ(ph[i].prim, s.prim);
                EXPECT_EQ(ph[i].b1, s.b1);
                EXPECT_EQ(ph[i].b2, s.b2);
                first += s.instance == 0;
                second += s.instance == 1;
            }
        });
        EXPECT_GT(hits, 3000) << "grid " << gridN;
        // The single rays' walks keep each of the two tied instances somewhere.
        EXPECT_GT(first, 100) << "grid " << gridN;
        EXPECT_GT(second, 100) << "grid " << gridN;
    }
}
