// scene_accel.h - the two-level structure the ray caster traces against: one TriangleBvh per
// mesh (object space, cached across frames by Mesh::id + version, so moving an instance never
// rebuilds it), per-geometry accelerators for parametric surfaces and density grids (cached by
// DrawAnalytic::geometryKey), and a top-level BVH4 (TLAS) over the world bounds of all
// instances, rebuilt every frame (cheap: one box per instance). Rays are transformed into each
// instance's object space with its inverse world matrix (t is preserved since the direction is
// transformed unnormalised).
#pragma once

#include "raycast/analytic.h"
#include "raycast/bvh.h"
#include "scenegraph/frame.h"

#include <cstddef>
#include <memory>
#include <mutex>
#include <unordered_map>

namespace rnd::rt {

// What a ray hit. For meshes: instance = index into FrameInput::meshes, prim/b1/b2 from the
// triangle test. For analytics: instance = index into FrameInput::analytics, normal = world
// outward normal (not yet flipped toward the ray), csgLeaf/flip for CSG, (u, v) parametric.
struct SceneHit {
    enum class Kind : uint8_t { None, Mesh, Analytic };
    Kind kind = Kind::None;
    float t = std::numeric_limits<float>::infinity();
    uint32_t instance = 0;
    uint32_t prim = 0;
    float b1 = 0, b2 = 0;
    sg::vec3 normal{0, 1, 0};
    int csgLeaf = -1;
    float u = 0, v = 0;
};

class SceneAccel {
public:
    // Builds/fetches BLASes for this frame and rebuilds the TLAS. Not thread-safe; call before
    // tracing. Returns the number of mesh BVHs (re)built this call.
    int update(const sg::FrameInput& frame);
    // Closest hit in (ray.tmin, ray.tmax). Thread-safe after update(). `culling` skips mesh
    // triangles seen from their back (RenderSettings::culling: every mesh, none, or those whose
    // material is single-sided; analytic solids are closed, so culling would not change what
    // they show).
    // count: when given, the BVH nodes visited (top level and mesh BVHs) and the primitives
    // tested are added to it (the cost view; an analytic shape counts as one primitive).
    bool intersect(const Ray& worldRay, SceneHit& hit, sg::CullMode culling = sg::CullMode::Off, TraversalCount* count = nullptr) const;
    // Any hit in (ray.tmin, ray.tmax).
    bool occluded(const Ray& worldRay) const;
    // Closest hits of a packet of coherent world rays (camera rays of a pixel tile): rays[0, n)
    // (n <= kMaxPacket) with bit i of `active` set; for each, exactly what intersect(rays[i],
    // hits[i], culling) gives. Mesh instances are traced as packets (TriangleBvh::intersectPacket,
    // the rays in each instance's object space), analytic shapes one ray at a time. Between hits
    // at exactly the same distance the one kept can follow the packet's visit order instead of
    // the ray's own; rays that a small mesh's packet sees at such a tie are traced alone, so
    // small meshes' pixels are exactly the single rays' (see update). Returns the mask of rays
    // that hit (hits[i] is written only for them).
    uint64_t intersectPacket(const Ray* worldRays, int n, uint64_t active, SceneHit* hits, sg::CullMode culling = sg::CullMode::Off) const;
    // Any hits of a packet of world rays (the shadow rays of a pixel tile toward one light): for
    // each active ray exactly what occluded(rays[i]) gives; returns the mask of blocked rays.
    // The top level is walked once for the packet (Bvh4::traversePacket: each ray reaches the
    // instances its own traversal would); each instance is tested as the walk meets it, for the
    // rays that reach it and are not blocked yet (a mesh of any size as a packet,
    // TriangleBvh::occludedPacket), and blocked rays leave the walk.
    uint64_t occludedPacket(const Ray* worldRays, int n, uint64_t active) const;

    // Boxes that hold every hit a ray can have (the ray caster's packet culling): with up to 16
    // instances, each mesh's root child boxes in world space (TriangleBvh::rootChildBoxes; the
    // instances' boxes where that makes more than 32) and each analytic shape's box; with more,
    // one box around them all. spread: the largest |L|_F |L^-1|_F of their instances' linear
    // parts (see CameraRays::windowBounds).
    struct Box {
        sg::vec3 lo, hi;
        float spread = 3.0f;
    };
    const std::vector<Box>& hitBoxes() const { return m_hitBoxes; }

    size_t cachedMeshes() const { return m_meshes.size(); }
    uint64_t buildsTotal() const { return m_buildsTotal; }

private:
    struct MeshEntry {
        sg::MeshPtr mesh;   // keeps the data alive (the BVH refers to it by index only)
        uint64_t version = 0;
        bool valid = false;   // Mesh::validate() passed
        TriangleBvh bvh;
        uint64_t lastFrame = 0;
    };
    struct AnalyticEntry {
        std::shared_ptr<ParametricAccel> param;
        std::shared_ptr<GridAccel> grid;
        uint64_t lastFrame = 0;
    };
    struct Instance {
        bool isMesh = true;
        uint32_t index = 0;   // into frame meshes / analytics
        const TriangleBvh* bvh = nullptr;
        bool packets = false;       // a mesh traced as packets by intersectPacket (occludedPacket takes every mesh)
        bool ties = false;          // a small mesh: intersectPacket has its ties reported (see update)
        bool doubleSided = false;   // a mesh's material.doubleSided (culling), kept here: the draw's record is cold
        const ParametricAccel* param = nullptr;
        const GridAccel* grid = nullptr;
        RayTransform toObject;                 // the inverse world matrix, for rays
        sg::vec3 boxMin{0.0f}, boxMax{0.0f};   // its box in the top level (world)
    };

    // intersect() without and with counting (Count: the cost view), so rays that are not
    // counted run the traversal without the counters.
    template <bool Count>
    bool closestHit(const Ray& r, SceneHit& hit, sg::CullMode culling, TraversalCount* cost) const;
    // Any hit of a world ray in one instance in (tmin, tmax).
    bool instanceOccluded(const Instance& inst, const Ray& r) const;
    // Where a world ray (inv: 1 / its direction) enters the instance's box (+inf: never).
    float boxEntry(const Instance& inst, const Ray& r, const sg::vec3& inv) const;
    bool intersectInstance(const Instance& inst, const Ray& r, float tmax, SceneHit& hit, bool cull = false, TraversalCount* count = nullptr) const;

    const sg::FrameInput* m_frame = nullptr;
    std::unordered_map<uint64_t, MeshEntry> m_meshes;          // by Mesh::id
    std::unordered_map<uint64_t, AnalyticEntry> m_analytics;   // by geometryKey
    std::vector<Instance> m_instances;
    bool m_anyPacketMesh = false;   // some instance has packets set
    bool m_anyMesh = false;         // some instance is a mesh
    std::vector<Box> m_hitBoxes;    // see hitBoxes()
    Bvh4 m_tlas;
    uint64_t m_frameCounter = 0;
    uint64_t m_buildsTotal = 0;
};

}   // namespace rnd::rt
