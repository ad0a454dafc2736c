// world_vertices.h - the ray caster's world-space copies of its meshes' vertices, kept across
// frames. Shading a triangle hit reads its three vertices in world space: the positions through
// the instance's world matrix and the normals through its normal matrix, normalized. Made per
// hit, that is three matrix products and three square roots and divisions per pixel; a camera
// that orbits a still scene asks for the same values frame after frame. The copies hold exactly
// what the per-hit code computes (the same operations on the same inputs), so images do not
// change by a bit.
#pragma once

#include "scenegraph/frame.h"

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace rnd::rt {

// One instance's vertices in world space.
struct WorldVertices {
    // vec3(world * vec4(p, 1)) for each position p.
    std::vector<sg::vec3> positions;
    // normal * n / |normal * n| for each vertex normal n, or exactly (0, 0, 0) where that length
    // is not above 1e-20 (the shading then takes the face normal). Empty when the mesh has no
    // normals per vertex.
    std::vector<sg::vec3> normals;
};

class WorldVertexCache {
public:
    // Meshes below kSmallMesh triangles are copied only in frames of at most kMaxSmallInstances
    // mesh instances: a wall of 12 triangles may fill much of a view (each of its pixels would
    // transform and normalize three vertices), but a frame of a million small instances would
    // pay a hash and an entry per instance and frame for copies the vertex budget cannot hold.
    static constexpr size_t kSmallMesh = 256, kMaxSmallInstances = 4096;
    // At most this many vertices are kept over all instances (24 bytes each with normals).
    static constexpr size_t kMaxVertices = size_t(1) << 21;

    // The copies for this frame, one per f.meshes entry (null: none, the shading transforms the
    // vertices itself). An instance is copied (in parallel) when its mesh (id, version) and
    // matrices are the same bit for bit as in the frame before: a still scene seen by a moving
    // camera from its second frame on, never an instance dragged or a mesh edited frame after
    // frame. A copy is kept while they stay the same and dropped after 8 frames unused. Not
    // thread-safe; the returned pointers stay valid until the next update.
    const std::vector<const WorldVertices*>& update(const sg::FrameInput& f);

private:
    struct Entry {
        sg::MeshPtr mesh;
        uint64_t version = 0;   // the mesh's version when last seen (made: the one copied)
        bool made = false;      // v holds the copy
        size_t count = 0;       // vertices held (what m_vertices counts)
        sg::mat4 world{1.0f};
        sg::mat3 normal{1.0f};
        WorldVertices v;
        uint64_t lastFrame = 0;
    };
    std::unordered_multimap<uint64_t, Entry> m_entries;   // by a hash of mesh id and matrices
    std::vector<const WorldVertices*> m_perMesh;
    uint64_t m_frame = 0;
    size_t m_vertices = 0;
};

}   // namespace rnd::rt
