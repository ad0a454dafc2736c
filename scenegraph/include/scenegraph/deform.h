// deform.h - skins and morph targets, evaluated on the CPU once per pose and shared by every
// backend (docs/math.md, "Skinning and morph targets"):
//   morph:  p = p_base + sum_k w_k dp_k     n = normalize(n_base + sum_k w_k dn_k)
//           t.xyz = normalize(t_base.xyz + sum_k w_k dt_k), t.w kept
//   skin:   M = sum_i w_i J_i / sum_i w_i, J_i = world(joint_i) * inverseBind_i
//           p' = M p (world space)   n' = normalize(inverse transpose(M_3x3) n)
//           t'.xyz = normalize(M_3x3 t.xyz)
// Morphing comes first, then skinning (glTF). flatten() (frame.cpp) draws a deformed instance
// with the mesh Scene::posedMesh returns, which goes through the DeformCache below.
#pragma once

#include "scenegraph/scene.h"

#include <mutex>
#include <unordered_map>
#include <vector>

namespace sg {

// The morph weights an instance uses, one per target of `mesh`: the instance's own weights
// when it has any (glTF node.weights override mesh.weights), else the mesh's defaults; entries
// missing from either count as 0.
std::vector<float> instanceMorphWeights(const Mesh& mesh, const MeshInstance& inst);
// J_i = world(joint_i) * inverseBind_i for every joint of the skin; the identity for a joint
// that is not in the scene or has no inverse bind matrix.
std::vector<mat4> skinMatrices(const Scene& scene, const Skin& skin);
// Whether `inst` is skinned: a valid skin index and a mesh with joints and weights.
bool isSkinned(const Scene& scene, const MeshInstance& inst);
// Whether drawing `inst` needs a deformed copy of its mesh (skinned, or a non-zero weight on a
// morph target).
bool isDeformed(const Scene& scene, const MeshInstance& inst);
// A new plain mesh (positions, normals, tangents, uvs, colours, indices; no joints or morph
// targets) with the base morphed by `weights` (one per target, missing = 0) and then skinned
// by `joints` (J_i per joint; empty = not skinned). Influences naming a joint >= joints.size()
// are ignored; a vertex whose remaining weights sum to 0 keeps its morphed position.
Mesh deformMesh(const Mesh& base, const std::vector<float>& weights, const std::vector<mat4>& joints);

// The posed meshes of a scene's deformed instances, by node uid. An entry is reused while the
// base mesh (pointer and version), the weights and the joint matrices are exactly what they
// were; otherwise it is recomputed into a new Mesh object that keeps the entry's Mesh::id and
// bumps its version (the GL and ray-caster caches key by id + version, so they replace that
// one entry: the ray caster rebuilds only the BVH of a mesh that moved). Thread-safe.
class DeformCache {
public:
    // The posed mesh of the instance on node `id` (Scene::posedMesh does the checks).
    MeshPtr posed(const Scene& scene, NodeId id, const MeshInstance& inst, bool& worldSpace);
    // Drops entries not used since the call before last.
    void trim();
    uint64_t evaluations() const;

private:
    struct Entry {
        MeshPtr base;
        uint64_t baseVersion = 0;
        std::vector<float> weights;
        std::vector<mat4> joints;
        MeshPtr result;
        uint64_t lastUse = 0;
    };
    mutable std::mutex m_mutex;
    std::unordered_map<uint64_t, Entry> m_entries;
    uint64_t m_generation = 1;
    uint64_t m_evaluations = 0;
};

}   // namespace sg
