// tessellate.h - triangle meshes for analytic drawables, shared by the GL backend and the CPU
// rasterizer so both draw exactly the same triangles:
//   * implicit primitives (sphere, box, cylinder, cone, torus, plane): analytic tessellation
//     with `resolution` segments;
//   * quadrics, CSG trees and density grids: marching tetrahedra (each cube of a resolution^3
//     grid over the bounds split into 6 tetrahedra; no ambiguous cases, so closed surfaces are
//     watertight), vertices refined onto the exact surface, normals from the gradient (CSG:
//     from the leaf the vertex lies on; crease vertices are duplicated per leaf);
//   * parametric surfaces: a resolution x resolution (u, v) grid, normals dPdu x dPdv.
// Triangles are counter-clockwise seen from outside; normals point outward. Analytic
// primitives have bit-exact seams and poles (watertight after welding by position).
// Meshes are in the drawable's local frame (apply DrawAnalytic::world), except CSG, whose
// leaves carry their own transforms: CSG meshes are in world space (use identity).
// Cost: the demo scene at resolution 64 takes ~0.1-0.2 s in total (bench_tessellate); the
// marched shapes grow with resolution^3 (seconds at 256), so a rebuild can report its progress
// and be stopped (TessellationProgress).
#pragma once

#include "scenegraph/frame.h"

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <unordered_map>

namespace rnd {

struct Tessellation {
    std::shared_ptr<const sg::Mesh> mesh;
    bool worldSpace = false;   // true for CSG
    // Per-triangle material index into `materials` (CSG faces take the material of the leaf
    // they lie on); empty = whole mesh uses the drawable's material.
    std::vector<uint16_t> triangleMaterial;
    std::vector<sg::Material> materials;
};

// What a long tessellation reports and whether it should stop.
struct TessellationProgress {
    // Called with the share of the work done so far (0..1): strictly increasing from call to
    // call, 1 at the end of a tessellation that was not stopped; one call at a time, from any
    // thread. May be empty.
    std::function<void(float)> report;
    // Checked between slices of the work: once set, the tessellation stops early and its
    // (incomplete) mesh is neither returned to the cache's callers nor kept.
    const std::atomic<bool>* cancel = nullptr;
    bool cancelled() const { return cancel && cancel->load(std::memory_order_relaxed); }
};

Tessellation tessellate(const sg::DrawAnalytic& a, int resolution, const TessellationProgress* progress = nullptr);
// The relative cost of tessellate(a, resolution), to weigh shapes against each other in a
// rebuild's progress: resolution^3 for the marched shapes (quadrics, CSG, density grids),
// resolution^2 for the others.
double tessellationWork(const sg::DrawAnalytic& a, int resolution);

// Caches tessellations by (geometryKey, resolution); thread-safe. Entries not used for
// `maxAgeFrames` calls of nextFrame() are dropped.
class TessellationCache {
public:
    // A cancelled tessellation (progress->cancel) returns an empty Tessellation, not kept.
    const Tessellation& get(const sg::DrawAnalytic& a, int resolution, const TessellationProgress* progress = nullptr);
    // Whether get(a, resolution) would return without tessellating.
    bool contains(const sg::DrawAnalytic& a, int resolution) const;
    void nextFrame(int maxAgeFrames = 8);
    size_t size() const;

private:
    struct Entry {
        Tessellation t;
        uint64_t lastUsed = 0;
    };
    static uint64_t keyOf(const sg::DrawAnalytic& a, int resolution) { return a.geometryKey * 1315423911u + uint64_t(resolution); }
    mutable std::mutex m_mutex;
    std::unordered_map<uint64_t, Entry> m_entries;
    uint64_t m_frame = 0;
};

}   // namespace rnd
