// deform.cpp - morph targets and skinning on the CPU (formulas: deform.h, docs/math.md) and
// the per-instance cache of posed meshes.
#include "scenegraph/deform.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace sg {

namespace {

constexpr size_t kParallelVertices = 1u << 15;   // below this one thread is faster

// Calls f(begin, end) over [0, n), on several threads for big meshes.
template <class F>
void forVertices(size_t n, F&& f) {
    if (n < kParallelVertices) {
        f(size_t(0), n);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); });
}

vec3 normalizedOr(const vec3& v, const vec3& fallback) {
    float len = glm::length(v);
    return len > 1e-30f && std::isfinite(len) ? v / len : fallback;
}

// p += sum_k w_k dp_k (and normals, tangents), then renormalises normals and tangents.
void applyMorph(const Mesh& base, const std::vector<float>& weights, Mesh& out) {
    bool anyN = false, anyT = false;
    for (size_t k = 0; k < base.morphTargets.size() && k < weights.size(); ++k) {
        const float w = weights[k];
        if (w == 0.0f) continue;
        const MorphTarget& t = base.morphTargets[k];
        const bool useN = t.normals.size() == out.normals.size() && !out.normals.empty();
        const bool useT = t.tangents.size() == out.tangents.size() && !out.tangents.empty();
        anyN = anyN || useN;
        anyT = anyT || useT;
        forVertices(out.positions.size(), [&](size_t b, size_t e) {
            for (size_t v = b; v < e; ++v) {
                if (!t.positions.empty()) out.positions[v] += w * t.positions[v];
                if (useN) out.normals[v] += w * t.normals[v];
                if (useT) out.tangents[v] += vec4(w * t.tangents[v], 0.0f);
            }
        });
    }
    if (anyN)
        for (size_t v = 0; v < out.normals.size(); ++v) out.normals[v] = normalizedOr(out.normals[v], base.normals[v]);
    if (anyT)
        for (size_t v = 0; v < out.tangents.size(); ++v)
            out.tangents[v] = vec4(normalizedOr(vec3(out.tangents[v]), vec3(base.tangents[v])), base.tangents[v].w);
}

// M = sum_i w_i J_i / sum_i w_i over the vertex's valid influences; false when none is left.
bool blendedMatrix(const Mesh& m, size_t v, const std::vector<mat4>& joints, mat4& out) {
    mat4 sum(0.0f);
    float total = 0.0f;
    auto add = [&](const u16vec4& j, const vec4& w) {
        for (int c = 0; c < 4; ++c) {
            if (w[c] <= 0.0f || size_t(j[c]) >= joints.size()) continue;
            sum += w[c] * joints[j[c]];
            total += w[c];
        }
    };
    add(m.joints0[v], m.weights0[v]);
    if (!m.joints1.empty()) add(m.joints1[v], m.weights1[v]);
    if (!(total > 0.0f)) return false;
    out = sum * (1.0f / total);
    return true;
}

// Positions to world space through the blended joint matrix; normals by its inverse
// transpose, tangents by its 3x3.
void applySkin(const Mesh& base, const std::vector<mat4>& joints, Mesh& out) {
    forVertices(out.positions.size(), [&](size_t b, size_t e) {
        for (size_t v = b; v < e; ++v) {
            mat4 M;
            if (!blendedMatrix(base, v, joints, M)) continue;
            out.positions[v] = vec3(M * vec4(out.positions[v], 1.0f));
            if (!out.normals.empty()) out.normals[v] = normalizedOr(normalMatrix(M) * out.normals[v], out.normals[v]);
            if (!out.tangents.empty()) {
                vec3 t = normalizedOr(mat3(M) * vec3(out.tangents[v]), vec3(out.tangents[v]));
                out.tangents[v] = vec4(t, out.tangents[v].w);
            }
        }
    });
}

}   // namespace

std::vector<float> instanceMorphWeights(const Mesh& mesh, const MeshInstance& inst) {
    const std::vector<float>& src = inst.weights.empty() ? mesh.morphWeights : inst.weights;
    std::vector<float> w(mesh.morphTargets.size(), 0.0f);
    for (size_t k = 0; k < w.size() && k < src.size(); ++k) w[k] = std::isfinite(src[k]) ? src[k] : 0.0f;
    return w;
}

std::vector<mat4> skinMatrices(const Scene& scene, const Skin& skin) {
    std::vector<mat4> out(skin.joints.size(), mat4(1.0f));
    for (size_t i = 0; i < skin.joints.size(); ++i) {
        if (!scene.valid(skin.joints[i]) || i >= skin.inverseBind.size()) continue;
        out[i] = scene.world(skin.joints[i]) * skin.inverseBind[i];
    }
    return out;
}

bool isSkinned(const Scene& scene, const MeshInstance& inst) {
    if (inst.skin < 0 || size_t(inst.skin) >= scene.skins.size()) return false;
    if (inst.mesh < 0 || size_t(inst.mesh) >= scene.meshes.size() || !scene.meshes[size_t(inst.mesh)]) return false;
    return scene.meshes[size_t(inst.mesh)]->skinned();
}

bool isDeformed(const Scene& scene, const MeshInstance& inst) {
    if (inst.mesh < 0 || size_t(inst.mesh) >= scene.meshes.size() || !scene.meshes[size_t(inst.mesh)]) return false;
    if (isSkinned(scene, inst)) return true;
    const Mesh& m = *scene.meshes[size_t(inst.mesh)];
    if (m.morphTargets.empty()) return false;
    for (float w : instanceMorphWeights(m, inst))
        if (w != 0.0f) return true;
    return false;
}

Mesh deformMesh(const Mesh& base, const std::vector<float>& weights, const std::vector<mat4>& joints) {
    Mesh out;
    out.name = base.name;
    out.mode = base.mode;
    out.positions = base.positions;
    out.normals = base.normals;
    out.uv0 = base.uv0;
    out.uv1 = base.uv1;
    out.colors = base.colors;
    out.tangents = base.tangents;
    out.indices = base.indices;
    if (!base.validateDeformation().empty()) return out;   // inconsistent data: the base shape
    applyMorph(base, weights, out);
    if (!joints.empty() && base.skinned()) applySkin(base, joints, out);
    return out;
}

// --- DeformCache ---------------------------------------------------------------------------

MeshPtr DeformCache::posed(const Scene& scene, NodeId id, const MeshInstance& inst, bool& worldSpace) {
    const MeshPtr base = scene.meshes[size_t(inst.mesh)];
    worldSpace = isSkinned(scene, inst);
    std::vector<float> weights = instanceMorphWeights(*base, inst);
    std::vector<mat4> joints = worldSpace ? skinMatrices(scene, scene.skins[size_t(inst.skin)]) : std::vector<mat4>{};
    std::lock_guard<std::mutex> lock(m_mutex);
    Entry& e = m_entries[scene.node(id).uid];
    e.lastUse = m_generation;
    if (e.result && e.base == base && e.baseVersion == base->version && e.weights == weights && e.joints == joints) return e.result;
    auto mesh = std::make_shared<Mesh>(deformMesh(*base, weights, joints));
    if (e.result) {   // same identity, next version: backends replace their cached data
        mesh->id = e.result->id;
        mesh->version = e.result->version + 1;
    }
    e.base = base;
    e.baseVersion = base->version;
    e.weights = std::move(weights);
    e.joints = std::move(joints);
    e.result = std::move(mesh);
    ++m_evaluations;
    return e.result;
}

void DeformCache::trim() {
    std::lock_guard<std::mutex> lock(m_mutex);
    for (auto it = m_entries.begin(); it != m_entries.end();) it = it->second.lastUse + 1 < m_generation ? m_entries.erase(it) : std::next(it);
    ++m_generation;
}

uint64_t DeformCache::evaluations() const {
    std::lock_guard<std::mutex> lock(m_mutex);
    return m_evaluations;
}

}   // namespace sg
