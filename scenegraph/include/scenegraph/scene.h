// scene.h - the scene graph: nodes with a name, a local transform, a payload and children.
//
// Storage: node records live in a vector indexed by NodeId (ids are never reused within a
// scene). The hot data for world-matrix updates (parent slot, local and world matrices,
// dirty flags) lives in arrays kept in depth-first pre-order, so that
//   * world = parent world x local is one forward pass over contiguous memory, and
//   * a node's subtree is the contiguous slot range [slot, slot + subtreeSize): editing one
//     node recomputes exactly its subtree.
// The order is rebuilt lazily after structural edits (add, remove, reparent). All traversals
// are iterative, so a 1M-deep chain is fine. Cycles are impossible by construction: nodes are
// always created under an existing parent and reparent() refuses to move a node under itself.
#pragma once

#include "scenegraph/light.h"
#include "scenegraph/material.h"
#include "scenegraph/mesh.h"
#include "scenegraph/projection.h"
#include "scenegraph/settings.h"
#include "scenegraph/shapes.h"

#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace sg {

using NodeId = uint32_t;
constexpr NodeId kNoNode = ~NodeId(0);

// Local transform: TRS (with Euler angles for editing) or a general affine 4x4 (shear, mirror).
struct LocalTransform {
    enum class Mode { TRS, Matrix };
    Mode mode = Mode::TRS;
    vec3 translation{0.0f};
    quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
    vec3 scale{1.0f};
    mat4 matrix{1.0f};   // used when mode == Matrix; must be affine (last row 0 0 0 1)

    bool operator==(const LocalTransform&) const = default;

    mat4 toMatrix() const;   // T * R * S for TRS
    // Euler angles in degrees, applied X then Y then Z (R = Rz * Ry * Rx).
    vec3 eulerDegrees() const;
    void setEulerDegrees(const vec3& deg);

    static LocalTransform fromTRS(const vec3& t, const quat& r = quat(1, 0, 0, 0), const vec3& s = vec3(1.0f));
    static LocalTransform fromMatrix(const mat4& m);
    // Converts to TRS when the matrix is translation * rotation * (positive or mirrored) scale
    // without shear; returns false (and leaves *this unchanged) otherwise.
    bool tryMakeTRS();
};

struct MeshInstance {
    int mesh = -1;       // index into Scene::meshes
    int material = -1;   // index into Scene::materials, -1 = default material
    int skin = -1;       // index into Scene::skins, -1 = not skinned (used when the mesh has joints)
    // Morph weights of this instance (glTF node.weights, animated by "weights" channels):
    // empty = the mesh's own Mesh::morphWeights; missing entries count as 0.
    std::vector<float> weights;
    bool operator==(const MeshInstance&) const = default;
};

// A skin (glTF skins[i]): joints by node id and their inverse bind matrices. A skinned
// instance's vertices go straight to world space through sum_i w_i J_i with
// J_i = world(joint_i) * inverseBind_i (docs/math.md, scenegraph/deform.h): the instance
// node's own transform does not move them. A joint that is not (or no longer) in the scene
// contributes J_i = identity.
struct Skin {
    std::string name;
    std::vector<NodeId> joints;
    std::vector<mat4> inverseBind;   // one per joint
    NodeId skeleton = kNoNode;       // the file's skeleton root, if it named one (informational)
    bool operator==(const Skin&) const = default;
};

class DeformCache;   // scenegraph/deform.h

// Camera payload. The view matrix is the inverse of the node's world matrix: the camera looks
// down its local -z with +y up.
struct Camera {
    Projection projection;
    float focusDistance = 5.0f;   // orbit pivot distance and oblique reference plane
    bool operator==(const Camera&) const = default;
};

// Geometry payloads carry their material.
struct ImplicitPayload {
    ImplicitShape shape;
    int material = -1;
    bool operator==(const ImplicitPayload&) const = default;
};
struct CsgPayload {
    CsgNode csg;
    int material = -1;   // used for faces of children that have none
    bool operator==(const CsgPayload&) const = default;
};
struct ParametricPayload {
    ParametricSurface surface;
    int material = -1;
    bool operator==(const ParametricPayload&) const = default;
};
struct GridPayload {
    std::shared_ptr<DensityGrid> grid;
    int material = -1;
    bool operator==(const GridPayload& o) const { return material == o.material && (grid == o.grid || (grid && o.grid && *grid == *o.grid)); }
};

using Payload = std::variant<std::monostate, MeshInstance, Camera, Light, ImplicitPayload, CsgPayload, ParametricPayload, GridPayload>;
std::string_view payloadKind(const Payload& p);   // "group", "mesh", "camera", ...

struct Node {
    std::string name;
    NodeId parent = kNoNode;
    std::vector<NodeId> children;
    LocalTransform local;
    Payload payload;
    bool visible = true;
    uint64_t uid = 0;              // process-unique, for backend caches
    uint64_t payloadVersion = 1;   // bumped on payload edits
    bool alive = false;
};

// A subtree taken out of a scene by Scene::detach, kept whole with its node ids so that
// Scene::reattach puts it back exactly (undo of a removal, redo of an addition). Ids are never
// reused within a scene, so the ids of a detached subtree stay free until it is reattached.
struct DetachedSubtree {
    NodeId id = kNoNode;                          // the subtree's top node (kNoNode: nothing detached)
    NodeId parent = kNoNode;                      // where it hung ...
    size_t index = 0;                             // ... and its place among the parent's children
    NodeId activeCamera = kNoNode;                // the scene's active camera when it was inside
    std::vector<std::pair<NodeId, Node>> nodes;   // every node of the subtree, parents first
};

class Scene {
public:
    Scene();
    Scene(const Scene&);
    Scene& operator=(const Scene&);
    Scene(Scene&&) noexcept = default;
    Scene& operator=(Scene&&) noexcept = default;

    std::string name = "scene";
    std::vector<std::shared_ptr<Mesh>> meshes;
    std::vector<Material> materials;
    std::vector<std::shared_ptr<Texture>> textures;
    std::vector<Skin> skins;
    RenderSettings settings;
    NodeId activeCamera = kNoNode;

    // --- structure ---------------------------------------------------------------------
    NodeId root() const { return 0; }
    NodeId addNode(std::string name, NodeId parent = 0, Payload payload = {});
    // Room for `count` more nodes without moving the node array (an importer that knows how
    // many it adds: one allocation instead of doubling, whose old and new arrays would both be
    // alive at the peak).
    void reserveNodes(size_t count) { m_nodes.reserve(m_nodes.size() + count); }
    // Removes the node and its subtree (not the root). Returns false for invalid ids.
    bool removeNode(NodeId id);
    // removeNode that keeps what it removed; an empty result (id kNoNode) for invalid ids / the root.
    DetachedSubtree detach(NodeId id);
    // Puts a detached subtree back under d.parent at d.index (clamped; the parent may differ from
    // the one it was detached from) with the same ids, restoring the active camera when it was
    // inside. Refuses (returns false, nothing changes) when the parent is gone or an id is taken.
    bool reattach(DetachedSubtree d);
    size_t childIndex(NodeId id) const;   // place among its parent's children (0 for the root)
    // Deep copy of the subtree under the same parent; returns the copy's id.
    NodeId duplicate(NodeId id);
    // Moves `id` under `newParent` (appended last). keepWorld: adjust the local transform so
    // the world transform is unchanged (the local becomes a Matrix when TRS can't express it).
    // Refuses (returns false and sets *error) to move the root or a node under itself.
    bool reparent(NodeId id, NodeId newParent, bool keepWorld, std::string* error = nullptr);
    bool isAncestor(NodeId ancestor, NodeId node) const;   // true if ancestor == node too
    bool valid(NodeId id) const { return id < m_nodes.size() && m_nodes[id].alive; }
    const Node& node(NodeId id) const { return m_nodes[id]; }
    size_t nodeCount() const { return m_aliveCount; }
    NodeId idCapacity() const { return NodeId(m_nodes.size()); }
    NodeId findByName(std::string_view name) const;   // first in depth-first order
    // Depth-first pre-order of all alive nodes (root first); parents precede children.
    const std::vector<NodeId>& depthFirstOrder() const;
    uint64_t structureVersion() const { return m_structureVersion; }

    // --- per-node edits ------------------------------------------------------------------
    void setName(NodeId id, std::string name);
    void setVisible(NodeId id, bool visible);
    void setLocal(NodeId id, const LocalTransform& t);
    void setLocalMatrix(NodeId id, const mat4& m) { setLocal(id, LocalTransform::fromMatrix(m)); }
    void setPayload(NodeId id, Payload p);
    // Mutable access; bumps the payload version (backends re-derive their data).
    Payload& editPayload(NodeId id);
    // Places a camera (or any node) at eye looking at center (sets a TRS local transform so
    // that the world transform is the inverse of lookAt, accounting for the parent).
    void lookAt(NodeId id, const vec3& eye, const vec3& center, const vec3& up = vec3(0, 1, 0));

    // --- world matrices ------------------------------------------------------------------
    // Recomputes world matrices of dirty subtrees. Returns the number recomputed.
    size_t updateWorld() const;
    const mat4& world(NodeId id) const;   // updates first if needed
    mat3 normalMatrixOf(NodeId id) const { return normalMatrix(world(id)); }
    bool effectiveVisible(NodeId id) const;   // hidden if any ancestor is hidden

    // --- queries -------------------------------------------------------------------------
    Aabb localBounds(NodeId id) const;   // payload bounds in the node's frame (empty if none)
    Aabb worldBounds() const;            // all visible geometry (skinned and morphed meshes as posed)
    // World bounds of the node's own payload as drawn (posed meshes included; empty if none).
    Aabb nodeWorldBounds(NodeId id) const;

    // --- skins and morph targets ---------------------------------------------------------
    // The mesh a MeshInstance node draws at the current pose: for a skinned or morphed
    // instance a deformed copy (computed on the CPU once per pose and cached: the same pointer
    // while nothing it depends on changes; a new pose gives a new object with the same
    // Mesh::id and a higher version, so backend caches replace their entry), else the scene's
    // mesh; null for other payloads. *worldSpace: the result is already in world space (skinned:
    // draw it with the identity). Safe to call from several threads.
    MeshPtr posedMesh(NodeId id, bool* worldSpace = nullptr) const;
    // Drops cached posed meshes that were not used since the call before last (flatten calls
    // it once per frame).
    void trimPoseCache() const;
    // Posed meshes computed so far (tests: a still pose computes none).
    uint64_t poseEvaluations() const;
    std::vector<NodeId> cameras() const;
    const Material& material(int index) const;   // default material for -1 or out of range

    // Creates a camera node framing the visible geometry and makes it active. Returns it.
    NodeId addDefaultCamera();
    // The same for bounds the caller already has (worldBounds(); an empty box frames -1..1).
    NodeId addDefaultCamera(const Aabb& bounds);
    // The camera addDefaultCamera() would add, and its world matrix, without editing the scene.
    Camera framingCamera(mat4& cameraWorld) const;
    static Camera framingCamera(const Aabb& bounds, mat4& cameraWorld);

private:
    // world(id) computed along its ancestor chain (the same products as the world update, so
    // the same bits) without rebuilding the whole scene's order and matrices.
    mat4 worldByChain(NodeId id) const;

    void markStructureDirty();
    void rebuildOrder() const;
    void markDirty(NodeId id);

    std::vector<Node> m_nodes;
    size_t m_aliveCount = 0;
    std::shared_ptr<DeformCache> m_deform;   // never shared between scenes (a copy starts empty)
    uint64_t m_structureVersion = 1;

    // Hot arrays in depth-first pre-order ("slots"); mutable: rebuilt/updated lazily.
    mutable bool m_orderValid = false;
    mutable std::vector<NodeId> m_order;           // slot -> id
    mutable std::vector<uint32_t> m_slotOf;        // id -> slot
    mutable std::vector<int32_t> m_parentSlot;     // slot -> parent slot (-1 for root)
    mutable std::vector<uint32_t> m_subtreeSize;   // slot -> size of subtree incl. itself
    mutable std::vector<mat4> m_localM;            // slot -> local matrix
    mutable std::vector<mat4> m_worldM;            // slot -> world matrix
    mutable std::vector<uint8_t> m_dirty;          // slot -> local changed since last update
    mutable std::vector<uint32_t> m_dirtySlots;    // slots marked dirty (unsorted, may repeat)
    mutable bool m_allDirty = true;
    mutable size_t m_lastUpdated = 0;
    friend size_t updateWorldImpl(const Scene&);
};

// First difference between two scenes ("" when equal): structure, names, transforms,
// payloads, materials, mesh data, textures, settings. Node ids may differ.
std::string sceneDifference(const Scene& a, const Scene& b);

}   // namespace sg
