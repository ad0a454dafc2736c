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
// Cost: the demo scene at resolution 64 takes ~0.1-0.2 s in total (bench_tessellate).
#pragma once

#include "scenegraph/frame.h"

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

Tessellation tessellate(const sg::DrawAnalytic& a, int resolution);

// Caches tessellations by (geometryKey, resolution); thread-safe. Entries not used for
// `maxAgeFrames` calls of nextFrame() are dropped.
class TessellationCache {
public:
    const Tessellation& get(const sg::DrawAnalytic& a, int resolution);
    void nextFrame(int maxAgeFrames = 8);
    size_t size() const;

private:
    struct Entry {
        Tessellation t;
        uint64_t lastUsed = 0;
    };
    mutable std::mutex m_mutex;
    std::unordered_map<uint64_t, Entry> m_entries;
    uint64_t m_frame = 0;
};

}   // namespace rnd
