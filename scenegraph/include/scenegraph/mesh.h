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

    size_t triangleCount() const { return mode == PrimitiveMode::Triangles ? indices.size() / 3 : 0; }
    Aabb bounds() const;
    // Area-weighted smooth normals from the triangles (replaces `normals`).
    void computeNormals();
    // Per-vertex tangents from the positions, normals and uv0 (Lengyel's method: each
    // triangle's dP/du and dP/dv summed at its corners, Gram-Schmidt against the normal,
    // handedness from dP/dv). Needs normals and uv0; leaves `tangents` empty otherwise.
    void computeTangents();
    // Checks index ranges and attribute counts; returns an empty string when valid.
    std::string validate() const;
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
