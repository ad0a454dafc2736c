// frame.h - FrameInput: the flattened, plain-data description of one frame that every renderer
// consumes (world and normal matrices per drawable, lights in world space, camera matrices,
// settings). Built by flatten(); holds shared pointers to mesh/texture data, never GL handles.
#pragma once

#include "scenegraph/scene.h"

#include <memory>
#include <vector>

namespace sg {

// A material's textures other than the base colour (null when absent), resolved from the
// Material's indices; they sample the same UVs as the diffuse texture.
struct MaterialMaps {
    TexturePtr emissive, occlusion, metallicRoughness, normal;
    bool any() const { return emissive || occlusion || metallicRoughness || normal; }
};

struct DrawMesh {
    NodeId node = kNoNode;
    uint64_t nodeUid = 0;
    MeshPtr mesh;
    Material material;
    TexturePtr texture;   // diffuse texture or null
    MaterialMaps maps;
    mat4 world{1.0f};
    mat3 normal{1.0f};       // inverse transpose of world's 3x3
    bool mirrored = false;   // det(world) < 0: winding flips
};

struct DrawLight {
    NodeId node = kNoNode;   // the light's node (what the window's selection names)
    LightType type = LightType::Point;
    vec3 position{0.0f};                      // world (point, spot)
    vec3 direction{0, 0, -1};                 // world, unit: direction light travels (directional, spot)
    vec3 radiance{1.0f};                      // colour * intensity
    bool inverseSquare = false;               // 1/r^2 applies (already combined with settings.attenuation)
    float cosInner = 1.0f, cosOuter = 1.0f;   // spot cone
    float range = 0.0f;                       // Light::range (pbr only; 0 = none)
    float radius = 0.0f;                      // point, spot: the source's radius (world)
    float tanAngularRadius = 0.0f;            // directional: tan of the source's angular radius
    // The source has a size: soft shadows.
    bool hasSize() const { return type == LightType::Directional ? tanAngularRadius > 0.0f : radius > 0.0f; }
};

// CSG tree flattened into an array; leaves are implicit shapes in world space.
struct CsgTree {
    struct Node {
        int op = -1;   // -1 = leaf, else int(CsgOp)
        std::vector<int> children;
        ImplicitShape shape;   // leaf
        mat4 world{1.0f}, invWorld{1.0f};
        mat3 normal{1.0f};
        Material material;
        TexturePtr texture;
    };
    std::vector<Node> nodes;
    int root = -1;
};

// Analytic geometry that the ray caster intersects exactly and the rasterizers tessellate.
struct DrawAnalytic {
    enum class Kind { Implicit, Csg, Parametric, Grid };
    Kind kind = Kind::Implicit;
    NodeId node = kNoNode;
    // Cache key of the geometry (not the transform): changes when the payload or, for CSG,
    // anything in its subtree changes.
    uint64_t geometryKey = 0;
    Material material;
    TexturePtr texture;
    mat4 world{1.0f}, invWorld{1.0f};
    mat3 normal{1.0f};
    Aabb worldBounds;
    ImplicitShape implicit;                    // Kind::Implicit
    ParametricSurface parametric;              // Kind::Parametric
    std::shared_ptr<const DensityGrid> grid;   // Kind::Grid
    std::shared_ptr<const CsgTree> csg;        // Kind::Csg (leaves in world space)
};

struct FrameCamera {
    Projection projection;
    float aspect = 1.0f;
    float focusDistance = 5.0f;
    mat4 view{1.0f};          // world -> eye
    mat4 viewInverse{1.0f};   // eye -> world (the camera node's world matrix)
    mat4 proj{1.0f};          // eye -> clip
    mat4 viewProj{1.0f};
    vec3 eye{0.0f};   // world position
};

struct FrameInput {
    std::vector<DrawMesh> meshes;
    std::vector<DrawAnalytic> analytics;
    std::vector<DrawLight> lights;
    vec3 ambientLight{1.0f};
    FrameCamera camera;
    RenderSettings settings;
    size_t triangleCount() const;
};

// Flattens the scene as seen by `cameraNode` (the active camera, or a default framing camera
// when kNoNode and the scene has none) for a viewport of the given aspect (width/height).
FrameInput flatten(const Scene& scene, float aspect, NodeId cameraNode = kNoNode);
// Camera matrices from a world-space camera frame (used by the viewer's orbit camera).
FrameCamera makeFrameCamera(const mat4& cameraWorld, const Projection& p, float aspect, float focusDistance);

}   // namespace sg
