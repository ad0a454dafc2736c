// mesh.h - shared triangle mesh and texture data. Plain data: no GPU handles. Backends cache
// their derived data (GPU buffers, BVHs) keyed by (id, version); bump version on every edit.
#pragma once

#include "scenegraph/math.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace sg {

// Unique across the process; never reused.
uint64_t newResourceId();

enum class PrimitiveMode : uint8_t { Triangles, Lines, Points };

// One morph target (glTF mesh.primitives[].targets[k]): per-vertex displacements, each array
// empty or one per position. Tangent deltas move xyz of Mesh::tangents (w is kept).
struct MorphTarget {
    std::vector<vec3> positions, normals, tangents;
    bool operator==(const MorphTarget&) const = default;
};

struct Mesh {
    uint64_t id = newResourceId();
    uint64_t version = 1;
    std::string name;
    PrimitiveMode mode = PrimitiveMode::Triangles;
    std::vector<vec3> positions;
    std::vector<vec3> normals;   // empty or one per position
    std::vector<vec2> uv0;       // empty or one per position
    std::vector<vec2> uv1;
    std::vector<vec4> colors;   // empty or one per position (linear RGBA)
    // Empty or one per position: xyz the unit tangent (direction of increasing u), w = +-1 the
    // handedness, bitangent = w cross(normal, tangent) (glTF's TANGENT; direction of increasing v).
    std::vector<vec4> tangents;
    std::vector<uint32_t> indices;   // 3 per triangle (2 per line, 1 per point)
    // Skinning (glTF JOINTS_0/1, WEIGHTS_0/1): up to 8 influences per vertex, four per set.
    // Joint numbers index the Skin of the instance (MeshInstance::skin); each array is empty or
    // one per position, set 1 only with set 0. Weights >= 0; they are normalised to sum 1 when
    // the mesh is deformed (sg::deformMesh, scenegraph/deform.h).
    std::vector<u16vec4> joints0, joints1;
    std::vector<vec4> weights0, weights1;
    // Morph targets and their default weights (glTF mesh.weights: empty = all 0, else one per
    // target); an instance's own weights (MeshInstance::weights) take precedence.
    std::vector<MorphTarget> morphTargets;
    std::vector<float> morphWeights;

    size_t triangleCount() const { return mode == PrimitiveMode::Triangles ? indices.size() / 3 : 0; }
    bool skinned() const { return !joints0.empty() && !weights0.empty(); }
    Aabb bounds() const;
    // Area-weighted smooth normals from the triangles (replaces `normals`).
    void computeNormals();
    // Per-vertex tangents from the positions, normals and the UV set the normal map samples
    // (uvSet 0: uv0, 1: uv1) (Lengyel's method: each triangle's dP/du and dP/dv summed at its
    // corners, Gram-Schmidt against the normal, handedness from dP/dv). Needs normals and that
    // UV set; leaves `tangents` empty otherwise.
    void computeTangents(int uvSet = 0);
    // Checks index ranges and attribute counts; returns an empty string when valid.
    std::string validate() const;
    std::string validateDeformation() const;   // the skin and morph part of validate()
    void touch() { ++version; }
};
using MeshPtr = std::shared_ptr<const Mesh>;

enum class WrapMode : uint8_t { Repeat, ClampToEdge, MirroredRepeat };
enum class FilterMode : uint8_t { Nearest, Bilinear, Trilinear };

// RGBA8 texture, rows top to bottom (row 0 is v = 1 in GL terms: see textureRow()).
struct Texture {
    uint64_t id = newResourceId();
    uint64_t version = 1;
    std::string name;
    std::string sourcePath;   // where it was loaded from (for saving), may be empty
    int width = 0, height = 0;
    std::vector<uint8_t> rgba;   // width*height*4, as stored in the file
    // Colour textures (base colour, emissive) hold sRGB-encoded colour, decoded to linear when
    // sampled; data textures (metallic-roughness, occlusion, normal) hold linear values.
    bool srgb = true;
    WrapMode wrapS = WrapMode::Repeat, wrapT = WrapMode::Repeat;
    FilterMode filter = FilterMode::Trilinear;
};
using TexturePtr = std::shared_ptr<const Texture>;

// Small generated meshes used by the demo scene, tests and tessellation of implicit shapes.
namespace primitives {
Mesh box(const vec3& halfExtents);                                      // 24 vertices, flat faces, uvs
Mesh plane(float halfSize, int subdivisions);                           // y = 0, normal +y, uvs
Mesh uvSphere(float radius, int slices, int stacks);                    // smooth normals, uvs
Mesh cylinder(float radius, float halfHeight, int slices, bool caps);   // axis y
Mesh cone(float radius, float halfHeight, int slices, bool cap);        // apex at +halfHeight
Mesh torus(float majorRadius, float minorRadius, int majorSegments, int minorSegments);
}   // namespace primitives

}   // namespace sg
