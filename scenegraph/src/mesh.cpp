// mesh.cpp - Mesh's own operations (see mesh.h): bounds, area-weighted vertex normals,
// per-vertex tangents from a uv set (for normal maps), validate() and validateDeformation()
// (attribute counts, index ranges, finite positions, skin weights, morph targets),
// newResourceId() for the backends' cache keys, and the primitives (box, plane, uv sphere,
// cylinder, cone, torus).
#include "scenegraph/mesh.h"

#include <atomic>
#include <cmath>

namespace sg {

uint64_t newResourceId() {
    static std::atomic<uint64_t> next{1};
    return next.fetch_add(1, std::memory_order_relaxed);
}

Aabb Mesh::bounds() const {
    Aabb b;
    for (const vec3& p : positions) b.extend(p);
    return b;
}

void Mesh::computeNormals() {
    normals.assign(positions.size(), vec3(0.0f));
    if (mode == PrimitiveMode::Triangles) {
        for (size_t i = 0; i + 2 < indices.size(); i += 3) {
            uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
            if (a >= positions.size() || b >= positions.size() || c >= positions.size()) continue;
            // Cross product length is twice the area: area weighting comes for free.
            vec3 n = glm::cross(positions[b] - positions[a], positions[c] - positions[a]);
            normals[a] += n;
            normals[b] += n;
            normals[c] += n;
        }
    }
    for (vec3& n : normals) {
        float len = glm::length(n);
        n = len > 0.0f ? n / len : vec3(0, 1, 0);
    }
}

void Mesh::computeTangents(int uvSet) {
    tangents.clear();
    const size_t n = positions.size();
    const std::vector<vec2>& uv = uvSet == 1 ? uv1 : uv0;
    if (mode != PrimitiveMode::Triangles || normals.size() != n || uv.size() != n) return;
    std::vector<vec3> du(n, vec3(0.0f)), dv(n, vec3(0.0f));
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
        const uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
        if (a >= n || b >= n || c >= n) continue;
        const vec3 e1 = positions[b] - positions[a], e2 = positions[c] - positions[a];
        const vec2 t1 = uv[b] - uv[a], t2 = uv[c] - uv[a];
        const float det = t1.x * t2.y - t2.x * t1.y;
        if (!(std::fabs(det) > 1e-20f)) continue;   // no uv area (or NaN): no direction
        const vec3 su = (e1 * t2.y - e2 * t1.y) / det, sv = (e2 * t1.x - e1 * t2.x) / det;
        if (!isFinite(su) || !isFinite(sv)) continue;
        for (uint32_t v : {a, b, c}) {
            du[v] += su;
            dv[v] += sv;
        }
    }
    tangents.resize(n);
    for (size_t v = 0; v < n; ++v) {
        const vec3& nn = normals[v];
        vec3 t = du[v] - nn * glm::dot(nn, du[v]);
        float len = glm::length(t);
        if (!(len > 1e-20f)) {   // any direction perpendicular to the normal
            t = std::fabs(nn.x) < 0.9f ? glm::cross(nn, vec3(1, 0, 0)) : glm::cross(nn, vec3(0, 1, 0));
            len = glm::length(t);
        }
        t = len > 0 ? t / len : vec3(1, 0, 0);
        tangents[v] = vec4(t, glm::dot(glm::cross(nn, t), dv[v]) < 0.0f ? -1.0f : 1.0f);
    }
}

std::string Mesh::validate() const {
    size_t n = positions.size();
    if (!normals.empty() && normals.size() != n) return "normal count differs from position count";
    if (!uv0.empty() && uv0.size() != n) return "uv0 count differs from position count";
    if (!uv1.empty() && uv1.size() != n) return "uv1 count differs from position count";
    if (!colors.empty() && colors.size() != n) return "color count differs from position count";
    if (!tangents.empty() && tangents.size() != n) return "tangent count differs from position count";
    if (std::string e = validateDeformation(); !e.empty()) return e;
    size_t per = mode == PrimitiveMode::Triangles ? 3 : mode == PrimitiveMode::Lines ? 2 : 1;
    if (indices.size() % per != 0) return "index count is not a multiple of " + std::to_string(per);
    for (uint32_t i : indices)
        if (i >= n) return "index " + std::to_string(i) + " out of range (" + std::to_string(n) + " vertices)";
    for (const vec3& p : positions)
        if (!isFinite(p)) return "non-finite vertex position";
    return {};
}

std::string Mesh::validateDeformation() const {
    size_t n = positions.size();
    auto sized = [n](size_t k) { return k == 0 || k == n; };
    if (!sized(joints0.size()) || !sized(weights0.size()) || !sized(joints1.size()) || !sized(weights1.size()))
        return "joint/weight count differs from position count";
    if (joints0.empty() != weights0.empty() || joints1.empty() != weights1.empty()) return "joints and weights must come together";
    if (!joints1.empty() && joints0.empty()) return "joints1/weights1 without joints0/weights0";
    for (const auto* w : {&weights0, &weights1})
        for (const vec4& v : *w)
            if (!(v.x >= 0 && v.y >= 0 && v.z >= 0 && v.w >= 0 && std::isfinite(v.x + v.y + v.z + v.w)))
                return "skin weights must be finite and >= 0";
    for (size_t k = 0; k < morphTargets.size(); ++k) {
        const MorphTarget& t = morphTargets[k];
        if (!sized(t.positions.size()) || !sized(t.normals.size()) || !sized(t.tangents.size()))
            return "morph target " + std::to_string(k) + ": count differs from position count";
        for (const auto* a : {&t.positions, &t.normals, &t.tangents})
            for (const vec3& d : *a)
                if (!isFinite(d)) return "morph target " + std::to_string(k) + ": non-finite displacement";
    }
    if (!morphWeights.empty() && morphWeights.size() != morphTargets.size()) return "morph weight count differs from morph target count";
    for (float w : morphWeights)
        if (!std::isfinite(w)) return "non-finite morph weight";
    return {};
}

namespace primitives {

Mesh box(const vec3& h) {
    Mesh m;
    m.name = "box";
    // One quad per face, outward normals, counter-clockwise seen from outside.
    const vec3 axes[6][3] = {
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}}, {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}},
        {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}, {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    for (auto& f : axes) {
        vec3 n = f[0], u = f[1], v = f[2];
        uint32_t base = uint32_t(m.positions.size());
        const float su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
        for (int k = 0; k < 4; ++k) {
            m.positions.push_back((n + su[k] * u + sv[k] * v) * h);
            m.normals.push_back(n);
            m.uv0.push_back(vec2(0.5f * (su[k] + 1), 0.5f * (sv[k] + 1)));
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    }
    return m;
}

Mesh plane(float halfSize, int sub) {
    Mesh m;
    m.name = "plane";
    sub = std::max(sub, 1);
    for (int j = 0; j <= sub; ++j)
        for (int i = 0; i <= sub; ++i) {
            float u = float(i) / sub, v = float(j) / sub;
            m.positions.push_back(vec3((u * 2 - 1) * halfSize, 0, (1 - v * 2) * halfSize));
            m.normals.push_back(vec3(0, 1, 0));
            m.uv0.push_back(vec2(u, v));
        }
    for (int j = 0; j < sub; ++j)
        for (int i = 0; i < sub; ++i) {
            uint32_t a = j * (sub + 1) + i, b = a + 1, c = a + sub + 1, d = c + 1;
            for (uint32_t k : {a, b, d, a, d, c}) m.indices.push_back(k);
        }
    return m;
}

Mesh uvSphere(float r, int slices, int stacks) {
    Mesh m;
    m.name = "sphere";
    slices = std::max(slices, 3);
    stacks = std::max(stacks, 2);
    for (int j = 0; j <= stacks; ++j) {
        float v = float(j) / stacks, theta = v * kPi;
        for (int i = 0; i <= slices; ++i) {
            float u = float(i) / slices, phi = u * 2 * kPi;
            vec3 n(std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi));
            m.positions.push_back(r * n);
            m.normals.push_back(n);
            m.uv0.push_back(vec2(u, 1 - v));
        }
    }
    for (int j = 0; j < stacks; ++j)
        for (int i = 0; i < slices; ++i) {
            uint32_t a = j * (slices + 1) + i, b = a + 1, c = a + slices + 1, d = c + 1;
            if (j != 0)
                for (uint32_t k : {a, c, b}) m.indices.push_back(k);
            if (j != stacks - 1)
                for (uint32_t k : {b, c, d}) m.indices.push_back(k);
        }
    return m;
}

namespace {
void addDisk(Mesh& m, float r, float y, int slices, bool up) {
    uint32_t center = uint32_t(m.positions.size());
    vec3 n(0, up ? 1.0f : -1.0f, 0);
    m.positions.push_back(vec3(0, y, 0));
    m.normals.push_back(n);
    m.uv0.push_back(vec2(0.5f));
    for (int i = 0; i <= slices; ++i) {
        float phi = 2 * kPi * i / slices;
        m.positions.push_back(vec3(r * std::sin(phi), y, r * std::cos(phi)));
        m.normals.push_back(n);
        m.uv0.push_back(vec2(0.5f + 0.5f * std::sin(phi), 0.5f + 0.5f * std::cos(phi)));
    }
    for (int i = 0; i < slices; ++i) {
        uint32_t a = center + 1 + i, b = a + 1;
        if (up) {
            m.indices.insert(m.indices.end(), {center, a, b});
        } else {
            m.indices.insert(m.indices.end(), {center, b, a});
        }
    }
}
}   // namespace

Mesh cylinder(float r, float hh, int slices, bool caps) {
    Mesh m;
    m.name = "cylinder";
    slices = std::max(slices, 3);
    for (int i = 0; i <= slices; ++i) {
        float phi = 2 * kPi * i / slices;
        vec3 n(std::sin(phi), 0, std::cos(phi));
        for (int k = 0; k < 2; ++k) {
            m.positions.push_back(vec3(r * n.x, k ? hh : -hh, r * n.z));
            m.normals.push_back(n);
            m.uv0.push_back(vec2(float(i) / slices, float(k)));
        }
    }
    for (int i = 0; i < slices; ++i) {
        uint32_t a = 2 * i, b = a + 1, c = a + 2, d = a + 3;
        m.indices.insert(m.indices.end(), {a, c, d, a, d, b});
    }
    if (caps) {
        addDisk(m, r, hh, slices, true);
        addDisk(m, r, -hh, slices, false);
    }
    return m;
}

Mesh cone(float r, float hh, int slices, bool cap) {
    Mesh m;
    m.name = "cone";
    slices = std::max(slices, 3);
    float slope = r / (2 * hh);   // normal tilts up by atan(r / height)
    for (int i = 0; i <= slices; ++i) {
        float phi = 2 * kPi * (i + 0.5f * 0) / slices;
        vec3 n = glm::normalize(vec3(std::sin(phi), slope, std::cos(phi)));
        m.positions.push_back(vec3(r * std::sin(phi), -hh, r * std::cos(phi)));
        m.normals.push_back(n);
        m.uv0.push_back(vec2(float(i) / slices, 0));
        m.positions.push_back(vec3(0, hh, 0));   // apex, one per slice for its own normal
        m.normals.push_back(n);
        m.uv0.push_back(vec2(float(i) / slices, 1));
    }
    for (int i = 0; i < slices; ++i) {
        uint32_t a = 2 * i, apex = a + 1, c = a + 2;
        m.indices.insert(m.indices.end(), {a, c, apex});
    }
    if (cap) addDisk(m, r, -hh, slices, false);
    return m;
}

Mesh torus(float R, float r, int nu, int nv) {
    Mesh m;
    m.name = "torus";
    nu = std::max(nu, 3);
    nv = std::max(nv, 3);
    for (int j = 0; j <= nv; ++j) {
        float v = 2 * kPi * j / nv;
        for (int i = 0; i <= nu; ++i) {
            float u = 2 * kPi * i / nu;
            vec3 dir(std::sin(u), 0, std::cos(u));
            vec3 n = std::cos(v) * dir + vec3(0, std::sin(v), 0);
            m.positions.push_back(R * dir + r * n);
            m.normals.push_back(n);
            m.uv0.push_back(vec2(float(i) / nu, float(j) / nv));
        }
    }
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            uint32_t a = j * (nu + 1) + i, b = a + 1, c = a + nu + 1, d = c + 1;
            m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
        }
    return m;
}

}   // namespace primitives
}   // namespace sg
