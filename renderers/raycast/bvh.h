// bvh.h - the ray caster's acceleration structure: a 4-wide bounding volume hierarchy (BVH4)
// built with binned SAH, traversed front to back with SSE box tests (4 children at once), and
// a triangle BVH whose leaves are packets of 4 precomputed triangles tested at once with SSE
// (Moller-Trumbore, docs/math.md). Used for the per-mesh BVHs (object space), for the top level
// over instances (TLAS), and by the benchmark against Embree.
//
// Sections: Ray/Hit, Bvh4 (generic: boxes in, leaves of up to 4 primitive indices out),
// TriangleBvh (Bvh4 + triangle packets, closest hit and any hit).
//
// Coherent rays (camera rays of a pixel tile, shadow rays of neighbouring pixels to one light)
// can be traced as a packet of up to kMaxPacket rays (TriangleBvh::intersectPacket /
// occludedPacket), with exactly the single-ray results. What it is not: no motion blur, no
// spatial splits.
#pragma once

#include "renderers/huge_pages.h"
#include "scenegraph/math.h"

#include <xmmintrin.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

namespace rnd::rt {

// Memory for big arrays (BVH build buffers, nodes, triangle packets): huge pages from 4 MB up
// (renderers/huge_pages.h), so a 1M-triangle build takes tens of page faults instead of tens of
// thousands (Embree does the same). resize() default-initialises (no zero fill): the builders
// write every element they keep, and the first write then also faults the page in, on whichever
// thread fills it.
using rnd::hugeAlloc;
using rnd::hugeFree;
using rnd::HugeVector;

// Most rays in one packet (TriangleBvh::intersectPacket / occludedPacket).
inline constexpr int kMaxPacket = 64;

// Scratch space for one packet's rays or hits, left uninitialised: the packet functions write
// and read only the active lanes, and filling kMaxPacket default values per packet showed in
// the frame's profile. T must be an implicit-lifetime type (an aggregate such as Ray).
template <class T, int N = kMaxPacket>
struct PacketScratch {
    alignas(T) unsigned char bytes[sizeof(T) * N];
    T* data() { return reinterpret_cast<T*>(bytes); }
    T& operator[](int i) { return data()[i]; }
};

// A ray segment org + t*dir, t in [tmin, tmax]. dir need not be unit length. TriangleBvh
// treats a negative (or NaN) tmin as 0: its box test relies on tmin >= 0 (see traceTriangles8).
struct Ray {
    sg::vec3 org{0.0f};
    float tmin = 0.0f;
    sg::vec3 dir{0, 0, -1};
    float tmax = std::numeric_limits<float>::infinity();
};

// A world -> object space transform for rays: org' = M (org, 1), dir' = mat3(M) dir, the
// direction not normalised (so t is shared between the spaces). Bit for bit glm's
// mat4 * vec4(org, 1) and mat3 * dir: per lane (c0 x + c1 y) + (c2 z + c3) and
// (c0 x + c1 y) + c2 z, the same IEEE products and sums, made four lanes at a time.
struct RayTransform {
    alignas(16) float col[4][4];   // M's columns
    alignas(16) float lin[3][4];   // mat3(M)'s columns, lane 3 zero
    RayTransform() : RayTransform(sg::mat4(1.0f)) {}
    explicit RayTransform(const sg::mat4& m) {
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) col[c][r] = m[c][r];
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 4; ++r) lin[c][r] = r < 3 ? m[c][r] : 0.0f;
    }
    // r in object space, its segment ending at tmax.
    Ray apply(const Ray& r, float tmax) const {
        Ray out;
        applyTo(r, tmax, out);
        return out;
    }
    // apply(r, tmax) written into out as two 16-byte stores (org and tmin, dir and tmax): no
    // member-wise copy of a returned Ray (glm's vectors copy element by element), and a later
    // 16-byte load of either half is forwarded from one store.
    void applyTo(const Ray& r, float tmax, Ray& out) const {
        static_assert(sizeof(Ray) == 32 && offsetof(Ray, tmin) == 12 && offsetof(Ray, dir) == 16 && offsetof(Ray, tmax) == 28,
                      "Ray: org, tmin, dir, tmax packed");
        __m128 o =
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_load_ps(col[0]), _mm_set1_ps(r.org.x)), _mm_mul_ps(_mm_load_ps(col[1]), _mm_set1_ps(r.org.y))),
                       _mm_add_ps(_mm_mul_ps(_mm_load_ps(col[2]), _mm_set1_ps(r.org.z)), _mm_load_ps(col[3])));
        __m128 d =
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_load_ps(lin[0]), _mm_set1_ps(r.dir.x)), _mm_mul_ps(_mm_load_ps(lin[1]), _mm_set1_ps(r.dir.y))),
                       _mm_mul_ps(_mm_load_ps(lin[2]), _mm_set1_ps(r.dir.z)));
        o = withLane3(o, r.tmin);
        d = withLane3(d, tmax);
        _mm_storeu_ps(&out.org.x, o);
        _mm_storeu_ps(&out.dir.x, d);
    }

private:
    // (v0, v1, v2, s)
    static __m128 withLane3(__m128 v, float s) {
        const __m128 hi = _mm_shuffle_ps(v, _mm_set_ss(s), _MM_SHUFFLE(0, 0, 2, 2));   // (v2, v2, s, s)
        return _mm_shuffle_ps(v, hi, _MM_SHUFFLE(2, 0, 1, 0));                         // (v0, v1, v2, s)
    }
};

// tmax widened by 32 units in the last place (about 2^-18 of it; +inf at and beyond the
// largest float; +inf, NaN and values below 0 as they are): the window in which a packet's ray
// looks for hits whose order could decide which one is kept (see closestLaneTies). The bit
// pattern of a float in [+0, +inf) plus k is k floats further.
inline float widenTmax(float tmax) {
    uint32_t b;
    std::memcpy(&b, &tmax, 4);
    if (b < 0x7F800000u) b = std::min(b + 32u, 0x7F800000u);
    float r;
    std::memcpy(&r, &b, 4);
    return r;
}

// Work of one ray (the cost view, rnd::Framebuffer::costNodes/costPrims): BVH nodes visited
// (inner nodes whose child boxes were tested, top level and mesh BVHs alike) and primitives
// tested (triangle lanes of the leaf packets; an analytic shape counts one).
struct TraversalCount {
    uint32_t nodes = 0, prims = 0;
};

// Closest hit: distance, primitive (triangle index in the mesh) and barycentrics (b1, b2) of
// p = (1-b1-b2) p0 + b1 p1 + b2 p2.
struct TriHit {
    float t = std::numeric_limits<float>::infinity();
    uint32_t prim = ~0u;
    float b1 = 0, b2 = 0;
    bool valid() const { return prim != ~0u; }
};

// Per-ray data the SIMD box test needs: reciprocal direction, origin * reciprocal and which
// slab (min or max) is the near one per axis.
// The triangle kernels compute a slab distance with one fused multiply-subtract,
// t = b * rdir - org * rdir. Its rounding error is absolute, not relative to t: about 2^-24
// (|b| + |org|) |rdir| from rdir, org * rdir and the result, which matters when the origin or
// the box is far from the world origin, and their boxes may have zero thickness (flat,
// axis-aligned geometry). So the origin terms carry a margin E = 2^-20 (|org| + max |b|) |rdir|
// per axis (4x that error; max |b| over the tree's bounds): near planes use orgRdirNear =
// org * rdir + E, far planes orgRdirFar = org * rdir - E. Every computed slab interval then
// contains the exact one, at no cost per node (the margin lives in constants).
struct RayPre {
    alignas(16) float org[4], rdir[4], orgRdir[4];   // lane 3 unused
    alignas(16) float orgRdirNear[4], orgRdirFar[4];
    int nearX, nearY, nearZ;   // offsets (0 or 1) into Node4::b[axis*2 + ...]
    // boxAbsMax: max |coordinate| per axis (x, y, z, unused) of the boxes to be tested; nullptr
    // leaves the margins without that term (for traversals that do not use them).
    RayPre(const Ray& r, const float* boxAbsMax);
};

// W-wide node (W = 4 or 8): bounds of up to W children stored SoA (b[0]=minx, b[1]=maxx,
// b[2]=miny, ...). child[i] >= 0: inner node index (TriangleBvh's BVH8: the node's byte
// offset, index * sizeof(Node8), so the traversal adds no arithmetic between loading a child
// reference and loading the child's bounds). Leaf: kLeafBit | (first << 3) | count,
// count in 1..7 (Bvh4: primitives, TriangleBvh: packets); kEmpty: unused slot (its bounds are empty so it is never entered).
struct NodeBits {
    static constexpr uint32_t kLeafBit = 0x80000000u;
    static constexpr uint32_t kEmpty = 0xffffffffu;
};
template <int W>
struct alignas(64) NodeW : NodeBits {
    float b[6][W];
    uint32_t child[W];
};
using Node4 = NodeW<4>;
using Node8 = NodeW<8>;

// Generic BVH4 over axis-aligned boxes. After build(), primIndex lists the primitives in leaf
// order; a leaf covers primIndex[first .. first+count).
class Bvh4 {
public:
    struct BuildOptions {
        int maxLeafSize = 4;   // 1..4: primitives per block (TriangleBvh: always 4, a packet)
        // Leaves of up to this many blocks where the SAH prefers one leaf to a split
        // (Bvh4: at most 7 primitives in all; TriangleBvh: at most 7 packets).
        int maxLeafBlocks = 1;
        float traversalCost = 1.0f;   // SAH cost of a node visit, in block tests
        int bins = 16;                // SAH bins per axis
        bool parallel = true;         // oneTBB tasks for big subtrees
        // TriangleBvh's BVH8 refers to inner nodes by byte offset in 31 bits: at most 2^23
        // nodes (about 270M triangles with the default leaves). A tree with more nodes than
        // this (capped at 2^23) is built as a BVH4 instead; tests lower it to reach that path.
        uint32_t maxWideNodes = 1u << 23;
    };
    // Boxes given as SoA-friendly min/max arrays; n = count. Empty/invalid boxes are skipped.
    void build(const sg::vec3* boxMin, const sg::vec3* boxMax, size_t n, const BuildOptions& opt);
    void build(const sg::vec3* boxMin, const sg::vec3* boxMax, size_t n) { build(boxMin, boxMax, n, BuildOptions{}); }

    bool empty() const { return m_nodes.empty(); }
    const sg::Aabb& bounds() const { return m_bounds; }
    const std::vector<Node4>& nodes() const { return m_nodes; }
    std::vector<Node4>& nodes() { return m_nodes; }
    const std::vector<uint32_t>& primIndex() const { return m_primIndex; }
    size_t memoryBytes() const { return m_nodes.size() * sizeof(Node4) + m_primIndex.size() * 4; }
    int depth() const;

    // Front-to-back traversal. leaf(first, count, tmax&) tests a leaf and may shrink tmax;
    // returns true to stop the traversal (any-hit queries).
    // AnyHit = true skips the front-to-back sort (any hit ends the query anyway).
    // Count: add the inner nodes visited to *visited (the cost view; a separate instantiation,
    // so the uncounted traversal is unchanged).
    template <bool AnyHit = false, bool Count = false, class LeafFn>
    void traverse(const Ray& ray, float& tmax, LeafFn&& leaf, uint32_t* visited = nullptr) const;
    // The leaves that the rays[i] with bit i of `active` set reach (each ray's tmax as given,
    // never shortened), the tree walked once for all of them: leaf(first, count, rays) gets each
    // leaf reached once, with the mask of the rays that reach it; returns true to stop. A ray
    // reaches a leaf where traverse() with the same tmax would test it (the same box test,
    // node by node), or where traverse() skips it only because its entry distance lies between
    // tmax and the grown far end (a ray can then not hit anything in it before tmax). Leaves
    // come nearest first for the packet's first ray. live (optional): the rays still wanted,
    // which the leaf function may clear as it goes (an occlusion query's blocked rays); nodes
    // are then walked for those alone, and skipped where none is left.
    template <class LeafFn>
    void traversePacket(const Ray* rays, uint64_t active, LeafFn&& leaf, const uint64_t* live = nullptr) const;

private:
    std::vector<Node4> m_nodes;   // m_nodes[0] is the root (a leaf root is wrapped in a node)
    std::vector<uint32_t> m_primIndex;
    sg::Aabb m_bounds;
};

// Four triangles, SoA: vertex 0, the edges e1 = p1 - p0, e2 = p2 - p0 and the unnormalised
// normal N = e1 x e2 (precomputed: the test then needs one cross product instead of two).
// Exactly three cache lines, aligned to them; the triangle ids live in a separate array (read
// only on a hit), which keeps a leaf of k packets at 3k lines instead of about 4k.
struct alignas(64) TriPacket4 {
    float v0[3][4], e1[3][4], e2[3][4], n[3][4];
};
static_assert(sizeof(TriPacket4) == 192);

// Triangle BVH whose leaves are runs of 1-7 TriPacket4s (leaf "first" = packet index; leaves of
// more than one packet where the SAH prefers them to another node level). With the
// AVX2+FMA kernel it is 8-wide (BVH8, one AVX box test per node), else 4-wide (BVH4, SSE).
class TriangleBvh {
public:
    void build(const sg::vec3* positions, const uint32_t* indices, size_t triangleCount, const Bvh4::BuildOptions& opt);
    void build(const sg::vec3* positions, const uint32_t* indices, size_t triangleCount) {
        build(positions, indices, triangleCount, defaultOptions());
    }
    // Leaves of up to 4 packets where the SAH (a node visit costs 2 packet tests) prefers them
    // to another level. Measured on the 1M-triangle benchmark scene against 1-packet leaves:
    // 1/3 of the nodes, primary rays +15-20%, shadow +20%, build +10%. Rechecked after nodes
    // were filled before the leaf test: a node visit costing 1 packet test gives SAH 18.0
    // instead of 18.9 but 1.8x the nodes, and rays were no faster (primary 0.82-0.95 of
    // Embree against 0.97-0.98).
    static Bvh4::BuildOptions defaultOptions() {
        Bvh4::BuildOptions o;
        o.maxLeafBlocks = 4;
        o.traversalCost = 2.0f;
        return o;
    }
    // Closest hit in (ray.tmin, ray.tmax); returns true and fills hit when found.
    // cullBack: ignore triangles seen from their back (CW from the ray's side, in the BVH's
    // own frame; for an instance traced in object space this is the world-space back side
    // for mirrored transforms too, since mirroring flips both the winding and the cross product).
    // count: when given, the nodes visited and triangles tested are added to it.
    bool intersect(const Ray& ray, TriHit& hit, bool cullBack = false, TraversalCount* count = nullptr) const;
    // Any hit in (ray.tmin, ray.tmax).
    bool occluded(const Ray& ray) const;
    // Packets: rays[0, n) (n <= kMaxPacket), those with bit i of `active` set. For each such ray
    // exactly what intersect(rays[i], hits[i], cullBack) / occluded(rays[i]) gives; returns the
    // mask of rays that hit (hits[i] is written only for them). Pays off for coherent rays whose
    // directions share their signs (a ray with other signs is traced on its own): the packet
    // shares inner-node tests and each ray is tested alone only at the leaves its packet reaches
    // (BVH8 with AVX2; otherwise one ray at a time). Between hits at exactly (or within a few
    // units in the last place of) the same distance the one kept follows the visit order, which
    // for a packet is not the ray's own: without `ties` the packet's first found is kept; with
    // it (BVH8), the rays where that could be so are reported there, also those whose hit or
    // miss was decided within that of their tmax (another mesh's hit, for a caller tracing
    // several), for the caller to trace alone; about 2.5% more instructions in a frame of one big mesh. (BVH4
    // traces each ray alone, so only such tmax ties could differ there: none are reported.)
    // move: the rays are world rays, each traced as move->apply(rays[i], tmax ? tmax[i] :
    // rays[i].tmax) (bit for bit; the kernel moves them eight at a time as it gathers them).
    uint64_t intersectPacket(const Ray* rays, int n, uint64_t active, TriHit* hits, bool cullBack = false, uint64_t* ties = nullptr,
                             const RayTransform* move = nullptr, const float* tmax = nullptr) const;
    uint64_t occludedPacket(const Ray* rays, int n, uint64_t active, const RayTransform* move = nullptr) const;

    bool empty() const { return m_packets.empty(); }
    const sg::Aabb& bounds() const { return m_bounds; }
    // The boxes of the root's children, in the mesh's frame: every point of every triangle lies
    // in one of them (a tighter bound than bounds(), for the ray caster's packet culling).
    std::vector<sg::Aabb> rootChildBoxes() const;
    size_t memoryBytes() const {
        return m_nodes4.size() * sizeof(Node4) + m_nodes8.size() * sizeof(Node8) + m_packets.size() * sizeof(TriPacket4) + m_prims.size() * 4;
    }
    int width() const { return m_nodes8.empty() ? 4 : 8; }

    // Shape of the tree (benchmark output, tests): inner nodes, leaves, packets, filled triangle
    // lanes, used child slots, the depth, the most packets in one leaf, and the SAH cost as
    // Embree's statistics (verbose=2) print it: sum of node areas (node visits) and of leaf
    // areas times their packets (packet tests), both relative to the root's area.
    struct Stats {
        size_t nodes = 0, leaves = 0, packets = 0, lanes = 0, childSlots = 0;
        int depth = 0, maxLeafPackets = 0;
        double sahNodes = 0, sahLeaves = 0;
    };
    Stats stats() const;

private:
    HugeVector<Node4> m_nodes4;
    HugeVector<Node8> m_nodes8;
    HugeVector<TriPacket4> m_packets;
    HugeVector<uint32_t> m_prims;   // 4 per packet: triangle index per lane, ~0u = empty lane
    sg::Aabb m_bounds;
    float m_absMax[4] = {0, 0, 0, 0};   // max |coordinate| per axis of m_bounds (RayPre margins)
};

// Which triangle kernel runs: "avx2+fma" (picked at run time when the CPU has it) or "sse"
// (forced with VIEWER_RAYCAST_SSE=1).
const char* kernelName();
// Whether the ray caster's AVX2 builds run (its kernels, the camera rays' rows of four, the
// shading lanes): the CPU has AVX2 and FMA and VIEWER_RAYCAST_SSE is not 1. Read once; safe to
// call from other files' static initializers.
bool useAvx2();

// Brute-force reference (tests): closest hit over all triangles with the same test.
bool intersectBruteForce(const sg::vec3* positions, const uint32_t* indices, size_t triangleCount, const Ray& ray, TriHit& hit);

}   // namespace rnd::rt

#include "raycast/bvh_traverse.inl"
