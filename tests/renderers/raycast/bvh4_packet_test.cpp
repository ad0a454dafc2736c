// Bvh4::traversePacket (the top level's walk for a packet of rays) against Bvh4::traverse, ray
// by ray: every leaf a ray's own traversal tests is reached, and no leaf beyond what that
// traversal tests with a far end a hair further out.
#include "raycast/bvh.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <set>
#include <utility>
#include <vector>

using namespace rnd::rt;
using sg::vec3;

namespace {

using LeafSet = std::set<std::pair<uint32_t, uint32_t>>;   // (first, count) of each leaf

template <bool AnyHit>
LeafSet visits(const Bvh4& bvh, const Ray& r) {
    LeafSet out;
    float tmax = r.tmax;
    bvh.traverse<AnyHit>(r, tmax, [&](uint32_t first, uint32_t count, float&) {
        out.insert({first, count});
        return false;
    });
    return out;
}

}   // namespace

TEST(RaycastTest, Bvh4PacketWalkReachesWhatEachRayTraversalTests) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-10.0f, 10.0f), size(0.05f, 2.0f), unit(-1.0f, 1.0f);
    // Boxes of instances in a scene: spread, overlapping, some flat (a ground plane).
    std::vector<vec3> lo, hi;
    for (int i = 0; i < 300; ++i) {
        const vec3 c(u(rng), u(rng), u(rng)), e(size(rng), i % 17 == 0 ? 0.0f : size(rng), size(rng));
        lo.push_back(c - e);
        hi.push_back(c + e);
    }
    Bvh4::BuildOptions o;
    o.maxLeafSize = 2;   // as SceneAccel's top level
    o.parallel = false;
    Bvh4 bvh;
    bvh.build(lo.data(), hi.data(), lo.size(), o);
    ASSERT_GT(bvh.depth(), 2);

    size_t reachedPairs = 0, extraPairs = 0;
    for (int p = 0; p < 200; ++p) {
        // A packet: rays from one eye (camera rays) or from points nearby (shadow rays), short
        // and infinite segments, and some inactive lanes.
        Ray rays[kMaxPacket];
        const int n = 1 + p % kMaxPacket;
        const vec3 eye(u(rng), u(rng), u(rng)), toward(unit(rng), unit(rng), unit(rng));
        for (int i = 0; i < n; ++i) {
            rays[i].org = p % 2 ? eye : eye + 0.3f * vec3(unit(rng), unit(rng), unit(rng));
            rays[i].dir = toward + 0.4f * vec3(unit(rng), unit(rng), unit(rng));
            if (i % 7 == 3) rays[i].dir.y = 0.0f;   // along a slab
            rays[i].tmin = 0.0f;
            rays[i].tmax = i % 3 == 0 ? std::numeric_limits<float>::infinity() : 1.0f + 30.0f * std::abs(unit(rng));
        }
        const uint64_t active = (p % 5 == 0 ? 0xAAAAAAAAAAAAAAAAull : ~uint64_t(0)) & (n == 64 ? ~uint64_t(0) : (uint64_t(1) << n) - 1);
        std::vector<LeafSet> reached(static_cast<size_t>(n));
        bvh.traversePacket(rays, active, [&](uint32_t first, uint32_t count, uint64_t reach) {
            EXPECT_EQ(reach & ~active, 0u) << "an inactive ray reached a leaf";
            for (uint64_t m = reach; m; m &= m - 1) EXPECT_TRUE(reached[size_t(__builtin_ctzll(m))].insert({first, count}).second) << "a leaf twice";
            return false;
        });
        for (int i = 0; i < n; ++i) {
            if (!((active >> i) & 1)) continue;
            Ray further = rays[i];
            further.tmax *= 1.0f + 1e-5f;
            for (const LeafSet& own : {visits<false>(bvh, rays[i]), visits<true>(bvh, rays[i])})
                for (const auto& leaf : own) EXPECT_TRUE(reached[size_t(i)].count(leaf)) << "packet " << p << " ray " << i << " missed a leaf";
            const LeafSet bound = visits<false>(bvh, further);
            for (const auto& leaf : reached[size_t(i)]) EXPECT_TRUE(bound.count(leaf)) << "packet " << p << " ray " << i << " reached a leaf too far";
            reachedPairs += reached[size_t(i)].size();
            extraPairs += reached[size_t(i)].size() - visits<false>(bvh, rays[i]).size();
        }
    }
    EXPECT_GT(reachedPairs, 2000u);   // the rays do reach leaves
    EXPECT_LE(extraPairs, reachedPairs / 100);
}

// Stopping: the walk ends as soon as the leaf function says so.
TEST(RaycastTest, Bvh4PacketWalkStopsWhenAsked) {
    std::vector<vec3> lo, hi;
    for (int i = 0; i < 50; ++i) {
        lo.push_back(vec3(float(i), 0, 0));
        hi.push_back(vec3(float(i) + 0.5f, 1, 1));
    }
    Bvh4 bvh;
    bvh.build(lo.data(), hi.data(), lo.size());
    Ray rays[2];
    for (Ray& r : rays) {
        r.org = vec3(-1, 0.5f, 0.5f);
        r.dir = vec3(1, 0, 0);
    }
    int calls = 0;
    bvh.traversePacket(rays, 3, [&](uint32_t, uint32_t, uint64_t reach) {
        EXPECT_EQ(reach, 3u);
        return ++calls == 2;
    });
    EXPECT_EQ(calls, 2);
    int all = 0;
    bvh.traversePacket(rays, 3, [&](uint32_t, uint32_t count, uint64_t) {
        all += int(count);
        return false;
    });
    EXPECT_EQ(all, 50);
    bvh.traversePacket(rays, 0, [&](uint32_t, uint32_t, uint64_t) {
        ADD_FAILURE() << "no active ray";
        return false;
    });
}

// Bvh4PacketTest::mayReach, the whole packet's interval test below the root: a child it rules
// out is reached by no ray's own test (the per-group test, lane by lane), for coherent packets
// of camera and shadow rays against random boxes (flat, tiny, huge, behind the rays), and it
// rules out children that none reaches. Packets it cannot bound (mixed direction signs, NaN,
// origins beyond 1e30) are left to the per-group tests.
TEST(RaycastTest, Bvh4PacketIntervalNeverRulesOutAReachedChild) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-20.0f, 20.0f), unit(-1.0f, 1.0f), size(0.0f, 3.0f);
    std::uniform_int_distribution<int> pick(0, 9);
    size_t reachedChildren = 0, ruledOut = 0, unbounded = 0;
    for (int p = 0; p < 4000; ++p) {
        Ray rays[kMaxPacket];
        const int n = 1 + p % 16;
        const vec3 eye(u(rng), u(rng), u(rng));
        vec3 toward(unit(rng), unit(rng), unit(rng));
        const float spread = p % 3 == 0 ? 0.02f : 0.2f;
        for (int i = 0; i < n; ++i) {
            Ray& r = rays[i];
            r.org = p % 2 ? eye : eye + 0.5f * vec3(unit(rng), unit(rng), unit(rng));   // one eye, or shadow rays' points
            r.dir = toward + spread * vec3(unit(rng), unit(rng), unit(rng));
            r.tmin = p % 4 == 0 ? 0.5f : 0.0f;
            r.tmax = i % 3 == 0 ? std::numeric_limits<float>::infinity() : 1.0f + 40.0f * std::abs(unit(rng));
            switch (p % 97 == 5 ? pick(rng) : -1) {   // now and then a hostile lane
            case 0: r.dir.x = std::numeric_limits<float>::quiet_NaN(); break;
            case 1: r.org.y = 3e30f; break;
            case 2: r.tmax = std::numeric_limits<float>::quiet_NaN(); break;
            case 3: r.dir = vec3(0.0f, 0.0f, 1e-35f); break;
            case 4: r.tmax = -1.0f; break;   // a camera ray that meets nothing
            default: break;
            }
        }
        const uint64_t active = (p % 5 == 0 ? 0x5555ull : ~uint64_t(0)) & ((uint64_t(1) << n) - 1);
        if (!active) continue;
        Bvh4PacketTest test(rays, active);
        test.setWhole(active);
        if (!test.whole) {
            ++unbounded;
            continue;
        }
        Node4 node;
        for (int c = 0; c < 4; ++c) {
            const vec3 centre = eye + (p % 7 == 0 ? -1.0f : 1.0f) * u(rng) * toward + vec3(u(rng), u(rng), u(rng)) * 0.3f;
            vec3 e(size(rng), size(rng), size(rng));
            if (c == 1) e.y = 0.0f;       // flat (a ground plane)
            if (p % 11 == 0) e *= 1e4f;   // huge
            for (int a = 0; a < 3; ++a) {
                node.b[2 * a][c] = centre[a] - e[a];
                node.b[2 * a + 1][c] = centre[a] + e[a];
            }
            node.child[c] = uint32_t(c);
        }
        const int may = test.mayReach(node);
        for (int c = 0; c < 4; ++c) {
            uint64_t reach = 0;
            for (int k = 0; k < Bvh4PacketTest::kGroups; ++k) {
                if (!((active >> (4 * k)) & 15u)) continue;
                __m128 tn;
                reach |= uint64_t(test.reaches(node, c, k, tn)) << (4 * k);
            }
            reach &= active;
            if (reach) {
                ++reachedChildren;
                EXPECT_TRUE((may >> c) & 1) << "packet " << p << " child " << c << ": rays 0x" << std::hex << reach << " reach it";
            } else if (!((may >> c) & 1)) {
                ++ruledOut;
            }
        }
    }
    EXPECT_GT(reachedChildren, 1000u);
    EXPECT_GT(ruledOut, 2000u);   // the test does rule children out
    EXPECT_GT(unbounded, 10u);    // and declines packets it cannot bound
}

// bvh4Reach (8 or 16 lanes per test where the CPU has AVX2 or AVX-512; CTest runs this test a
// second time with VIEWER_RAYCAST_AVX2=1) against the four-lane test, child by child: the same
// rays reach each child and the first ray's entry distance is the same bit for bit, for packets
// of up to 64 rays with gaps, mixed direction signs, rays along a slab, NaN and infinite lanes.
TEST(RaycastTest, Bvh4PacketWideTestsEqualFourLanes) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-20.0f, 20.0f), unit(-1.0f, 1.0f), size(0.0f, 3.0f);
    std::uniform_int_distribution<int> pick(0, 11);
    size_t reached = 0, missed = 0;
    for (int p = 0; p < 3000; ++p) {
        Ray rays[kMaxPacket];
        const int n = 1 + (p * 7) % kMaxPacket;
        const vec3 eye(u(rng), u(rng), u(rng)), toward(unit(rng), unit(rng), unit(rng));
        const float spread = p % 3 == 0 ? 0.05f : p % 3 == 1 ? 0.4f : 2.0f;   // the last: mixed signs
        for (int i = 0; i < n; ++i) {
            Ray& r = rays[i];
            r.org = p % 2 ? eye : eye + 0.5f * vec3(unit(rng), unit(rng), unit(rng));
            r.dir = toward + spread * vec3(unit(rng), unit(rng), unit(rng));
            r.tmin = p % 4 == 0 ? 0.5f : 0.0f;
            r.tmax = i % 3 == 0 ? std::numeric_limits<float>::infinity() : 1.0f + 40.0f * std::abs(unit(rng));
            switch (p % 13 == 5 ? pick(rng) : -1) {
            case 0: r.dir.x = std::numeric_limits<float>::quiet_NaN(); break;
            case 1: r.org.y = 3e30f; break;
            case 2: r.tmax = std::numeric_limits<float>::quiet_NaN(); break;
            case 3: r.dir = vec3(0.0f, 0.0f, 1e-35f); break;
            case 4: r.tmax = -1.0f; break;
            case 5: r.dir.y = 0.0f; break;    // along a slab
            case 6: r.dir.z = -0.0f; break;   // a negative zero
            case 7: r.dir.x = std::numeric_limits<float>::infinity(); break;
            default: break;
            }
        }
        uint64_t active = n == 64 ? ~uint64_t(0) : (uint64_t(1) << n) - 1;
        if (p % 5 == 0) active &= 0x5555555555555555ull;
        if (p % 7 == 0) active &= 0xF0F0F0F00000FFFFull;
        if (!active) continue;
        const Bvh4PacketTest test(rays, active);
        // The walk asks for a subset of the packet's rays at nodes below the root.
        const uint64_t subset = p % 4 == 3 ? active & (0x0123456789ABCDEFull * uint64_t(p + 1)) : active;
        if (!subset) continue;
        Node4 node;
        for (int c = 0; c < 4; ++c) {
            const vec3 centre = eye + u(rng) * toward + vec3(u(rng), u(rng), u(rng)) * 0.3f;
            vec3 e(size(rng), size(rng), size(rng));
            if (c == 1) e.y = 0.0f;
            for (int a = 0; a < 3; ++a) {
                node.b[2 * a][c] = centre[a] - e[a];
                node.b[2 * a + 1][c] = centre[a] + e[a];
            }
            node.child[c] = c == 3 && p % 6 == 0 ? Node4::kEmpty : uint32_t(c);
        }
        const int may = p % 8 == 0 ? 5 : 15;
        const int first = __builtin_ctzll(subset);
        uint64_t want[4] = {0, 0, 0, 0}, got[4] = {0, 0, 0, 0};
        float wantLead[4] = {-1, -1, -1, -1}, gotLead[4] = {-2, -2, -2, -2};
        test.reachChildren4(node, subset, may, want, wantLead, first);
        bvh4Reach(test, node, subset, may, got, gotLead, first);
        for (int c = 0; c < 4; ++c) {
            EXPECT_EQ(got[c], want[c]) << "packet " << p << " child " << c << " (" << kernelName() << ")";
            EXPECT_EQ(got[c] & ~subset, 0u);
            if ((want[c] >> first) & 1) { EXPECT_EQ(std::memcmp(&gotLead[c], &wantLead[c], sizeof(float)), 0) << "packet " << p << " child " << c; }
            reached += size_t(__builtin_popcountll(want[c]));
            missed += size_t(__builtin_popcountll(subset & ~want[c]));
        }
    }
    EXPECT_GT(reached, 5000u);   // both outcomes are exercised
    EXPECT_GT(missed, 10000u);
}
