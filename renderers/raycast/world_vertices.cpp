// world_vertices.cpp - WorldVertexCache: the world-space vertices of the ray caster's meshes,
// made once per instance and matrix, in parallel.
#include "raycast/world_vertices.h"

#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <cstring>

namespace rnd::rt {

using namespace sg;

namespace {
uint64_t mix(uint64_t h, const void* data, size_t bytes) {   // FNV-1a
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
    return h;
}

bool sameBits(const void* a, const void* b, size_t bytes) { return std::memcmp(a, b, bytes) == 0; }

// What Tracer's shading computes per hit (tracer.h: meshHitFrame and shadeMeshHit's vertex
// normals), here once per vertex.
void fill(const DrawMesh& d, WorldVertices& v) {
    const Mesh& mesh = *d.mesh;
    const size_t n = mesh.positions.size();
    const bool hasN = mesh.normals.size() == n;
    v.positions.resize(n);
    v.normals.resize(hasN ? n : 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
        const unsigned csr = _mm_getcsr();
        _mm_setcsr(csr | 0x8040);   // FTZ | DAZ, as the tiles that would compute them (denormals flush alike)
        for (size_t i = r.begin(); i != r.end(); ++i) {
            v.positions[i] = vec3(d.world * vec4(mesh.positions[i], 1.0f));
            if (!hasN) continue;
            const vec3 nn = d.normal * mesh.normals[i];
            const float l = glm::length(nn);
            v.normals[i] = l > 1e-20f ? nn / l : vec3(0.0f);
        }
        _mm_setcsr(csr);
    });
}
}   // namespace

const std::vector<const WorldVertices*>& WorldVertexCache::update(const FrameInput& f) {
    ++m_frame;
    m_perMesh.assign(f.meshes.size(), nullptr);
    std::vector<std::pair<const DrawMesh*, Entry*>> missing;
    const size_t minTriangles = f.meshes.size() <= kMaxSmallInstances ? 1 : kSmallMesh;
    for (size_t i = 0; i < f.meshes.size(); ++i) {
        const DrawMesh& d = f.meshes[i];
        if (!d.mesh || d.mesh->mode != PrimitiveMode::Triangles || d.mesh->triangleCount() < minTriangles) continue;
        uint64_t key = mix(0xcbf29ce484222325ull, &d.mesh->id, sizeof d.mesh->id);
        key = mix(key, &d.world, sizeof d.world);
        key = mix(key, &d.normal, sizeof d.normal);
        Entry* e = nullptr;
        for (auto [it, end] = m_entries.equal_range(key); it != end && !e; ++it) {
            Entry& c = it->second;
            if (c.mesh == d.mesh && sameBits(&c.world, &d.world, sizeof d.world) && sameBits(&c.normal, &d.normal, sizeof d.normal)) e = &c;
        }
        const size_t n = d.mesh->positions.size();
        const bool seenBefore = e != nullptr;
        const uint64_t last = e ? e->lastFrame : 0;
        if (!e) {   // first seen: remembered, not copied yet
            e = &m_entries.emplace(key, Entry{})->second;
            e->mesh = d.mesh;
            e->world = d.world;
            e->normal = d.normal;
        }
        e->lastFrame = m_frame;
        if (e->made && (e->version != d.mesh->version || e->count != n)) {   // the mesh was edited: dropped
            m_vertices -= e->count;
            e->count = 0;
            e->made = false;
            e->v = {};
        }
        if (!e->made) {
            // Copied only when seen unchanged in the frame before too: an instance being dragged or
            // a mesh being edited changes every frame, and would pay a copy per frame for nothing.
            const bool steady = seenBefore && last + 1 == m_frame && e->version == d.mesh->version;
            e->version = d.mesh->version;
            if (!steady || m_vertices + n > kMaxVertices) continue;   // shaded from the mesh itself
            e->made = true;
            e->count = n;
            m_vertices += n;
            missing.emplace_back(&d, e);
        }
        m_perMesh[i] = &e->v;
    }
    for (auto& [d, e] : missing) fill(*d, e->v);   // each fills in parallel
    for (auto it = m_entries.begin(); it != m_entries.end();) {
        if (m_frame - it->second.lastFrame > 8) {
            m_vertices -= it->second.count;
            it = m_entries.erase(it);
        } else {
            ++it;
        }
    }
    return m_perMesh;
}

}   // namespace rnd::rt
