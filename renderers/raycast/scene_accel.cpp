// scene_accel.cpp - two-level BVH: cached per-mesh BLASes + per-frame TLAS over instances.
#include "raycast/scene_accel.h"

#include <tbb/parallel_for.h>

namespace rnd::rt {

using namespace sg;

int SceneAccel::update(const FrameInput& f) {
    m_frame = &f;
    ++m_frameCounter;
    int built = 0;
    m_instances.clear();
    std::vector<vec3> bmin, bmax;

    // Mesh BVHs: (id, version) keyed, built in parallel when several are missing.
    std::vector<MeshEntry*> toBuild;
    for (uint32_t i = 0; i < f.meshes.size(); ++i) {
        const DrawMesh& d = f.meshes[i];
        if (!d.mesh || d.mesh->mode != PrimitiveMode::Triangles || d.mesh->triangleCount() == 0) continue;
        MeshEntry& e = m_meshes[d.mesh->id];
        if (e.mesh != d.mesh || e.version != d.mesh->version) {
            e.mesh = d.mesh;
            e.version = d.mesh->version;
            e.valid = d.mesh->validate().empty();   // bad indices: never traced (no crash)
            e.bvh = TriangleBvh();
            if (e.valid) toBuild.push_back(&e);
        }
        e.lastFrame = m_frameCounter;
    }
    // Missing BVHs are built in parallel (each big one also splits its build into tasks).
    tbb::parallel_for(size_t(0), toBuild.size(), [&](size_t i) {
        MeshEntry* e = toBuild[i];
        e->bvh.build(e->mesh->positions.data(), e->mesh->indices.data(), e->mesh->triangleCount());
    });
    built = int(toBuild.size());
    m_buildsTotal += uint64_t(built);
    for (auto it = m_meshes.begin(); it != m_meshes.end();)   // drop meshes unused for a while
        it = m_frameCounter - it->second.lastFrame > 8 ? m_meshes.erase(it) : std::next(it);

    for (uint32_t i = 0; i < f.meshes.size(); ++i) {
        const DrawMesh& d = f.meshes[i];
        if (!d.mesh) continue;
        auto it = m_meshes.find(d.mesh->id);
        if (it == m_meshes.end() || !it->second.valid || it->second.bvh.empty() || it->second.mesh != d.mesh) continue;
        if (!isInvertible(d.world)) continue;
        Instance inst;
        inst.isMesh = true;
        inst.index = i;
        inst.bvh = &it->second.bvh;
        inst.invWorld = glm::inverse(d.world);
        Aabb wb = it->second.bvh.bounds().transformed(d.world);
        m_instances.push_back(inst);
        bmin.push_back(wb.min);
        bmax.push_back(wb.max);
    }

    for (uint32_t i = 0; i < f.analytics.size(); ++i) {
        const DrawAnalytic& a = f.analytics[i];
        Instance inst;
        inst.isMesh = false;
        inst.index = i;
        inst.invWorld = a.invWorld;
        if (a.kind != DrawAnalytic::Kind::Csg && !isInvertible(a.world)) continue;
        if (a.kind == DrawAnalytic::Kind::Parametric || a.kind == DrawAnalytic::Kind::Grid) {
            AnalyticEntry& e = m_analytics[a.geometryKey];
            if (a.kind == DrawAnalytic::Kind::Parametric && !e.param) e.param = std::make_shared<ParametricAccel>(a.parametric);
            if (a.kind == DrawAnalytic::Kind::Grid) {
                if (!a.grid) continue;
                if (!e.grid || &e.grid->grid() != a.grid.get()) e.grid = std::make_shared<GridAccel>(a.grid);
            }
            e.lastFrame = m_frameCounter;
            inst.param = e.param.get();
            inst.grid = e.grid.get();
        }
        Aabb wb = a.worldBounds;
        if (a.kind == DrawAnalytic::Kind::Implicit && a.implicit.type == ImplicitType::Plane) {
            // Infinite for rays: a huge box in x/z around the plane's frame.
            ImplicitShape big = a.implicit;
            big.planeHalfSize = 1e6f;
            wb = big.localBounds().transformed(a.world);
        }
        if (wb.empty()) continue;
        vec3 pad = 1e-4f * (glm::abs(wb.min) + glm::abs(wb.max)) + vec3(1e-6f);
        m_instances.push_back(inst);
        bmin.push_back(wb.min - pad);
        bmax.push_back(wb.max + pad);
    }
    for (auto it = m_analytics.begin(); it != m_analytics.end();)
        it = m_frameCounter - it->second.lastFrame > 8 ? m_analytics.erase(it) : std::next(it);

    Bvh4::BuildOptions o;
    o.maxLeafSize = 2;
    o.parallel = false;
    m_tlas.build(bmin.data(), bmax.data(), bmin.size(), o);
    return built;
}

namespace {
// The world ray in the instance's object space (the direction not normalised, so t is shared).
Ray localRay(const mat4& invWorld, const Ray& wr, float tmax) {
    Ray lr;
    lr.org = vec3(invWorld * vec4(wr.org, 1.0f));
    lr.dir = mat3(invWorld) * wr.dir;
    lr.tmin = wr.tmin;
    lr.tmax = tmax;
    return lr;
}
}   // namespace

bool SceneAccel::intersectInstance(const Instance& inst, const Ray& wr, float tmax, SceneHit& hit, bool cull, TraversalCount* count) const {
    const Ray lr = localRay(inst.invWorld, wr, tmax);
    if (inst.isMesh) {
        TriHit th;
        if (!inst.bvh->intersect(lr, th, cull, count)) return false;
        hit.kind = SceneHit::Kind::Mesh;
        hit.t = th.t;
        hit.instance = inst.index;
        hit.prim = th.prim;
        hit.b1 = th.b1;
        hit.b2 = th.b2;
        return true;
    }
    if (count) ++count->prims;   // an analytic shape: one primitive test
    const DrawAnalytic& a = m_frame->analytics[inst.index];
    switch (a.kind) {
    case DrawAnalytic::Kind::Implicit: {
        SpanList spans;
        implicitSpans(a.implicit, lr, spans);
        Bound b;
        if (!firstBoundary(spans, wr.tmin, tmax, b)) return false;
        vec3 pl = lr.org + b.t * lr.dir;
        hit.normal = glm::normalize(a.normal * implicitNormal(a.implicit, pl, b.tag));
        hit.t = b.t;
        hit.csgLeaf = -1;
        break;
    }
    case DrawAnalytic::Kind::Csg: {
        if (!a.csg) return false;
        SpanList spans;
        csgSpans(*a.csg, wr, spans);
        Bound b;
        if (!firstBoundary(spans, wr.tmin, tmax, b)) return false;
        if (b.leaf < 0 || size_t(b.leaf) >= a.csg->nodes.size()) return false;
        const CsgTree::Node& leaf = a.csg->nodes[size_t(b.leaf)];
        vec3 pw = wr.org + b.t * wr.dir;
        vec3 pl = vec3(leaf.invWorld * vec4(pw, 1.0f));
        vec3 n = glm::normalize(leaf.normal * implicitNormal(leaf.shape, pl, b.tag));
        hit.normal = b.flip ? -n : n;
        hit.t = b.t;
        hit.csgLeaf = b.leaf;
        break;
    }
    case DrawAnalytic::Kind::Parametric: {
        if (!inst.param) return false;
        float t, u, v;
        if (!inst.param->intersect(lr, t, u, v)) return false;
        hit.normal = glm::normalize(a.normal * a.parametric.normal(u, v));
        hit.t = t;
        hit.u = u;
        hit.v = v;
        break;
    }
    case DrawAnalytic::Kind::Grid: {
        if (!inst.grid) return false;
        float t;
        if (!inst.grid->intersect(lr, t)) return false;
        hit.normal = glm::normalize(a.normal * inst.grid->normal(lr.org + t * lr.dir));
        hit.t = t;
        break;
    }
    }
    if (!std::isfinite(hit.normal.x)) hit.normal = vec3(0, 1, 0);
    hit.kind = SceneHit::Kind::Analytic;
    hit.instance = inst.index;
    return true;
}

template <bool Count>
bool SceneAccel::closestHit(const Ray& r, SceneHit& hit, sg::CullMode culling, TraversalCount* cost) const {
    float tmax = r.tmax;
    bool found = false;
    const std::vector<uint32_t>& prims = m_tlas.primIndex();
    auto leaf = [&](uint32_t first, uint32_t count, float& tm) {
        for (uint32_t k = 0; k < count; ++k) {
            SceneHit h;
            const Instance& inst = m_instances[prims[first + k]];
            const bool cull = inst.isMesh && sg::cullsBackFaces(culling, m_frame->meshes[inst.index].material.doubleSided);
            if (intersectInstance(inst, r, tm, h, cull, cost) && h.t < tm) {
                tm = h.t;
                hit = h;
                found = true;
            }
        }
        return false;
    };
    m_tlas.traverse<false, Count>(r, tmax, leaf, Count ? &cost->nodes : nullptr);
    return found;
}

bool SceneAccel::intersect(const Ray& r, SceneHit& hit, sg::CullMode culling, TraversalCount* cost) const {
    if (m_tlas.empty()) return false;
    return cost ? closestHit<true>(r, hit, culling, cost) : closestHit<false>(r, hit, culling, nullptr);
}

bool SceneAccel::occluded(const Ray& r) const {
    if (m_tlas.empty()) return false;
    float tmax = r.tmax;
    bool any = false;
    const std::vector<uint32_t>& prims = m_tlas.primIndex();
    m_tlas.traverse<true>(r, tmax, [&](uint32_t first, uint32_t count, float&) {
        for (uint32_t k = 0; k < count; ++k) {
            const Instance& inst = m_instances[prims[first + k]];
            if (inst.isMesh || inst.param) {   // any-hit tests; a parametric surface's stops at its first sub-patch hit
                const Ray lr = localRay(inst.invWorld, r, r.tmax);
                if (inst.isMesh ? inst.bvh->occluded(lr) : inst.param->occluded(lr)) {
                    any = true;
                    return true;
                }
            } else {
                SceneHit h;
                if (intersectInstance(inst, r, r.tmax, h)) {
                    any = true;
                    return true;
                }
            }
        }
        return false;
    });
    return any;
}

}   // namespace rnd::rt
