// scene_accel.cpp - two-level BVH: cached per-mesh BLASes + per-frame TLAS over instances.
#include "raycast/scene_accel.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

namespace rnd::rt {

using namespace sg;

namespace {
// Meshes below this size have their camera packets' ties reported and traced alone (see update).
constexpr size_t kTiesBelowTriangles = 256;

// |L|_F |L^-1|_F of an instance's linear part (3 for a rotation with a uniform scale; infinite
// when singular): how much the rounding of a ray moved into the instance's space can grow when
// its hit is seen from world space.
float spreadOf(const sg::mat3& l) {
    auto frob = [](const sg::mat3& m) { return std::sqrt(glm::dot(m[0], m[0]) + glm::dot(m[1], m[1]) + glm::dot(m[2], m[2])); };
    const float d = glm::determinant(l);
    if (!(std::abs(d) > 0.0f) || !std::isfinite(d)) return std::numeric_limits<float>::infinity();
    const float s = frob(l) * frob(glm::inverse(l));
    return std::isfinite(s) ? s : std::numeric_limits<float>::infinity();
}
}   // namespace

int SceneAccel::update(const FrameInput& f) {
    m_frame = &f;
    ++m_frameCounter;
    int built = 0;
    m_instances.clear();
    m_anyPacketMesh = false;
    m_anyMesh = false;
    std::vector<vec3> bmin, bmax;
    std::vector<float> spread;   // per box, hitBoxes' Box::spread
    std::vector<Box> tight;      // hitBoxes with each mesh's root child boxes instead of its box

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
        inst.doubleSided = d.material.doubleSided;
        inst.bvh = &it->second.bvh;
        // Every mesh is traced as packets, closest hits (intersectPacket) and shadow rays
        // (occludedPacket) alike: a packet sets a mesh up once where single rays each transform,
        // set up and walk it. Where a ray meets two hits (of one mesh or of two) at exactly or
        // nearly the same distance, the one kept follows the visit order, which for a packet is
        // not the ray's own. Small meshes (walls, crates, the instances of a sphere grid; before
        // the tie rule single rays, so that their pixels stay the single rays') have such rays
        // reported and traced alone; big meshes keep the packet's first found, as they always
        // have, sparing them the reports' work (bunny, callgrind: 314.7 M instructions per warm
        // 640x360 frame with reports on every mesh, 308.8 M without, 307.1 M before the rule).
        // Small meshes in packets: tiny instances 1.56 -> 1.49, the demo 2.57 -> 2.54 (frame /
        // min_embree, 3 alternated runs). Where the kernel cannot report ties (the SSE / BVH4
        // path), small meshes stay single rays.
        inst.ties = d.mesh->triangleCount() < kTiesBelowTriangles;
        inst.packets = !inst.ties || it->second.bvh.width() == 8;
        m_anyPacketMesh |= inst.packets;
        m_anyMesh = true;
        inst.toObject = RayTransform(glm::inverse(d.world));
        Aabb wb = it->second.bvh.bounds().transformed(d.world);
        inst.boxMin = wb.min;
        inst.boxMax = wb.max;
        m_instances.push_back(inst);
        bmin.push_back(wb.min);
        bmax.push_back(wb.max);
        spread.push_back(spreadOf(sg::mat3(d.world)));
        for (const Aabb& child : it->second.bvh.rootChildBoxes()) {
            const Aabb cw = child.transformed(d.world);
            tight.push_back({cw.min, cw.max, spread.back()});
        }
    }

    for (uint32_t i = 0; i < f.analytics.size(); ++i) {
        const DrawAnalytic& a = f.analytics[i];
        Instance inst;
        inst.isMesh = false;
        inst.index = i;
        inst.toObject = RayTransform(a.invWorld);
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
        inst.boxMin = wb.min - pad;
        inst.boxMax = wb.max + pad;
        m_instances.push_back(inst);
        bmin.push_back(wb.min - pad);
        bmax.push_back(wb.max + pad);
        spread.push_back(spreadOf(sg::mat3(a.world)));
        tight.push_back({bmin.back(), bmax.back(), spread.back()});
    }
    for (auto it = m_analytics.begin(); it != m_analytics.end();)
        it = m_frameCounter - it->second.lastFrame > 8 ? m_analytics.erase(it) : std::next(it);

    // One instance per leaf: the rays a leaf's box passes are then exactly those that reach its
    // instance's box, so a packet calls an instance's kernel (rays moved into its space, the
    // packet set up) only for rays that can meet it. With two per leaf, every packet reaching
    // the ground under the bunny also set the bunny's kernel up for nothing.
    Bvh4::BuildOptions o;
    o.maxLeafSize = 1;
    o.parallel = false;
    m_tlas.build(bmin.data(), bmax.data(), bmin.size(), o);
    constexpr size_t kMaxHitBoxes = 16, kMaxTightBoxes = 32;
    m_hitBoxes.clear();
    if (bmin.size() <= kMaxHitBoxes && tight.size() <= kMaxTightBoxes) {
        m_hitBoxes = std::move(tight);
    } else if (bmin.size() <= kMaxHitBoxes) {
        for (size_t i = 0; i < bmin.size(); ++i) m_hitBoxes.push_back({bmin[i], bmax[i], spread[i]});
    } else {
        Box all{bmin[0], bmax[0], spread[0]};
        for (size_t i = 1; i < bmin.size(); ++i) {
            all.lo = glm::min(all.lo, bmin[i]);
            all.hi = glm::max(all.hi, bmax[i]);
            all.spread = std::max(all.spread, spread[i]);
        }
        m_hitBoxes.push_back(all);
    }
    return built;
}

namespace {
// Where ray r (inv = 1 / r.dir) enters the box [lo, hi]: the largest of the three slabs' near
// distances. A NaN (0 * inf: the origin on a slab plane of an axis the ray runs along) never
// raises it, so the answer errs toward entering early, never late; +inf: the ray never enters.
float slabEntry(const vec3& lo, const vec3& hi, const Ray& r, const vec3& inv) {
    float entry = -std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a) {
        const float t0 = (lo[a] - r.org[a]) * inv[a], t1 = (hi[a] - r.org[a]) * inv[a];
        if (std::isnan(t0) || std::isnan(t1)) continue;
        const float near = t0 < t1 ? t0 : t1;
        if (near > entry) entry = near;
    }
    return entry;
}

// The mask of the rays of `active` for which hit(i) is true (the packets' one-ray-at-a-time paths).
template <class Hit>
uint64_t eachRay(uint64_t active, Hit&& hit) {
    uint64_t mask = 0;
    for (uint64_t m = active; m; m &= m - 1) {
        const int i = __builtin_ctzll(m);
        if (hit(i)) mask |= uint64_t(1) << i;
    }
    return mask;
}

// A triangle hit of mesh draw `instance` as a scene hit.
void setMeshHit(SceneHit& hit, const TriHit& th, uint32_t instance) {
    hit.kind = SceneHit::Kind::Mesh;
    hit.t = th.t;
    hit.instance = instance;
    hit.prim = th.prim;
    hit.b1 = th.b1;
    hit.b2 = th.b2;
}
}   // namespace

float SceneAccel::boxEntry(const Instance& inst, const Ray& r, const vec3& inv) const { return slabEntry(inst.boxMin, inst.boxMax, r, inv); }

bool SceneAccel::intersectInstance(const Instance& inst, const Ray& wr, float tmax, SceneHit& hit, bool cull, TraversalCount* count) const {
    const Ray lr = inst.toObject.apply(wr, tmax);
    if (inst.isMesh) {
        TriHit th;
        if (!inst.bvh->intersect(lr, th, cull, count)) return false;
        setMeshHit(hit, th, inst.index);
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
            const bool cull = inst.isMesh && sg::cullsBackFaces(culling, inst.doubleSided);
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

uint64_t SceneAccel::intersectPacket(const Ray* rays, int n, uint64_t active, SceneHit* hits, sg::CullMode culling) const {
    n = std::clamp(n, 0, kMaxPacket);
    if (n < kMaxPacket) active &= (uint64_t(1) << n) - 1;
    if (m_tlas.empty() || !active) return 0;
    auto oneByOne = [&](int i) { return intersect(rays[i], hits[i], culling); };
    if (!m_anyPacketMesh) return eachRay(active, oneByOne);   // no mesh to share
    uint64_t found = 0;
    const std::vector<uint32_t>& prims = m_tlas.primIndex();
    // Phase 1: the big mesh instances (Instance::packets) whose world boxes the rays reach (the
    // top level walked once for the packet, each ray tested at each node as its own traversal
    // tests it, not cut short by hits), nearest first for the packet's first ray, and which rays
    // reach each; each is traced once as a packet, every ray limited to the closest mesh hit
    // found so far, and its hits are kept per ray.
    constexpr int kMaxMeshes = 16;
    struct Touched {
        uint32_t instance;
        uint64_t rays, found;
    };
    Touched touched[kMaxMeshes];
    int k = 0;
    bool overflow = false;
    uint64_t others = 0;   // rays that reach an instance not traced as a packet
    // The instances not traced as packets that each ray reaches, in the order the walk meets
    // them (phase 2 tests them without a second traversal); rays that reach more than kListed
    // are in listFull and traverse again.
    constexpr int kListed = 6;
    uint32_t listed[kMaxPacket][kListed];
    uint8_t listedN[kMaxPacket];
    uint64_t listFull = 0;
    std::memset(listedN, 0, sizeof listedN);
    m_tlas.traversePacket(rays, active, [&](uint32_t first, uint32_t count, uint64_t reach) {
        for (uint32_t c = 0; c < count; ++c) {
            const uint32_t j = prims[first + c];
            if (!m_instances[j].packets) {
                others |= reach;
                for (uint64_t m = reach; m; m &= m - 1) {
                    const int i = __builtin_ctzll(m);
                    if (listedN[i] < kListed)
                        listed[i][listedN[i]++] = j;
                    else
                        listFull |= uint64_t(1) << i;
                }
                continue;
            }
            if (k == kMaxMeshes) {   // instances are unique in the top level: each leaf's are new
                overflow = true;
                return true;
            }
            touched[k++] = {j, reach, 0};
        }
        return false;
    });
    if (overflow) return eachRay(active, oneByOne);   // too many meshes under one packet
    // Hits per touched mesh and ray, written by the packet trace where found and read only there
    // (default values for k x kMaxPacket of them showed in the frame's profile).
    PacketScratch<TriHit, kMaxMeshes * kMaxPacket> hitScratch;
    TriHit* const meshHits = hitScratch.data();
    float bound[kMaxPacket];
    for (int i = 0; i < n; ++i) bound[i] = rays[i].tmax;
    // Rays whose hit could depend on the order in which meshes and leaves are visited, as the
    // small meshes report them (hits at exactly or nearly the same distance,
    // TriangleBvh::intersectPacket's ties; a mesh traced after another sees the other's hit as
    // its tmax): closestHit keeps the one its own walk meets first, so they are traced alone.
    uint64_t tied = 0;
    for (int s = 0; s < k; ++s) {
        const Instance& inst = m_instances[touched[s].instance];
        const bool cull = sg::cullsBackFaces(culling, inst.doubleSided);
        uint64_t meshTies = 0;
        // Each ray moved into the mesh's space with its segment ending at bound[i], as intersectInstance.
        touched[s].found = inst.bvh->intersectPacket(rays, n, touched[s].rays, meshHits + s * kMaxPacket, cull, inst.ties ? &meshTies : nullptr,
                                                     &inst.toObject, bound);
        tied |= meshTies;
        for (uint64_t m = touched[s].found; m; m &= m - 1) {
            const int i = __builtin_ctzll(m);
            bound[i] = std::min(bound[i], meshHits[s * kMaxPacket + i].t);
        }
    }
    tied &= active;
    // Phase 2: each ray's closestHit, with a mesh instance's hit looked up instead of traced. The
    // kept hit is the instance's closest below the bound it was traced with; closestHit asks for
    // its closest below tm, the closest hit so far. Where tm exceeds that bound, a mesh hit
    // at or below the bound is still to come, so a hit in between would not be kept either.
    // Rays that reach packet meshes only: their closest hit is the closest kept one (the first
    // found of equal ones, as closestHit keeps the first it visits).
    uint64_t foundAny = 0;
    for (int s = 0; s < k; ++s) foundAny |= touched[s].found;
    for (uint64_t m = active & ~others & foundAny & ~tied; m; m &= m - 1) {
        const int i = __builtin_ctzll(m);
        int best = -1;
        for (int s = 0; s < k; ++s)
            if (((touched[s].found >> i) & 1) && (best < 0 || meshHits[s * kMaxPacket + i].t < meshHits[best * kMaxPacket + i].t)) best = s;
        const TriHit& th = meshHits[best * kMaxPacket + i];
        SceneHit& h = hits[i];
        h = SceneHit{};
        h.kind = SceneHit::Kind::Mesh;
        h.t = th.t;
        h.instance = m_instances[touched[best].instance].index;
        h.prim = th.prim;
        h.b1 = th.b1;
        h.b2 = th.b2;
        found |= uint64_t(1) << i;
    }
    // Rays that reach a few other instances: the closest kept mesh hit, then each listed instance
    // that may hold a closer hit (its box entered before the closest so far), as closestHit
    // would test it. Only between hits at exactly the same distance can the one kept differ
    // from closestHit's (of two big meshes, or a mesh's and an analytic shape's; ties that a
    // small mesh saw went to `tied`).
    for (uint64_t m = active & others & ~listFull & ~tied; m; m &= m - 1) {
        const int i = __builtin_ctzll(m);
        const Ray& r = rays[i];
        float tm = r.tmax;
        bool any = false;
        for (int s = 0; s < k; ++s)
            if (((touched[s].found >> i) & 1) && meshHits[s * kMaxPacket + i].t < tm) {
                const TriHit& th = meshHits[s * kMaxPacket + i];
                tm = th.t;
                SceneHit h;
                setMeshHit(h, th, m_instances[touched[s].instance].index);
                hits[i] = h;
                any = true;
            }
        const vec3 inv = 1.0f / r.dir;
        for (int c = 0; c < listedN[i]; ++c) {
            const Instance& inst = m_instances[listed[i][c]];
            if (boxEntry(inst, r, inv) > tm * (1.0f + 1e-5f)) continue;   // no hit before tm in there
            SceneHit h;
            const bool cull = inst.isMesh && sg::cullsBackFaces(culling, inst.doubleSided);
            if (!intersectInstance(inst, r, tm, h, cull) || !(h.t < tm)) continue;
            tm = h.t;
            hits[i] = h;
            any = true;
        }
        if (any) found |= uint64_t(1) << i;
    }
    for (uint64_t m = active & others & listFull & ~tied; m; m &= m - 1) {
        const int i = __builtin_ctzll(m);
        const Ray& r = rays[i];
        float tmax = r.tmax;
        bool any = false;
        m_tlas.traverse<false>(r, tmax, [&](uint32_t first, uint32_t count, float& tm) {
            for (uint32_t c = 0; c < count; ++c) {
                const uint32_t j = prims[first + c];
                const Instance& inst = m_instances[j];
                SceneHit h;
                int s = 0;
                while (s < k && touched[s].instance != j) ++s;
                if (s < k && ((touched[s].rays >> i) & 1)) {   // a mesh this ray was traced through in phase 1
                    if (!((touched[s].found >> i) & 1)) continue;
                    const TriHit& th = meshHits[s * kMaxPacket + i];
                    if (!(th.t < tm)) continue;
                    setMeshHit(h, th, inst.index);
                } else {   // as closestHit
                    const bool cull = inst.isMesh && sg::cullsBackFaces(culling, inst.doubleSided);
                    if (!intersectInstance(inst, r, tm, h, cull)) continue;
                }
                if (h.t < tm) {
                    tm = h.t;
                    hits[i] = h;
                    any = true;
                }
            }
            return false;
        });
        if (any) found |= uint64_t(1) << i;
    }
    return found | eachRay(tied, oneByOne);
}

uint64_t SceneAccel::occludedPacket(const Ray* rays, int n, uint64_t active) const {
    n = std::clamp(n, 0, kMaxPacket);
    if (n < kMaxPacket) active &= (uint64_t(1) << n) - 1;
    if (m_tlas.empty() || !active) return 0;
    if (!m_anyMesh) return eachRay(active, [&](int i) { return occluded(rays[i]); });   // no mesh to share
    uint64_t blocked = 0, open = active;                                                // open: the rays not blocked yet
    const std::vector<uint32_t>& prims = m_tlas.primIndex();
    // The top level walked once for the packet (each ray tested at each node as occluded()
    // tests it), nearest first for its first ray; each instance met is tested for the rays that
    // reach it and are not blocked yet (a mesh as a packet, moved into its space by the packet
    // kernel), and blocked rays leave the walk. Which rays are blocked does not depend on the
    // order the instances are tested in.
    m_tlas.traversePacket(
        rays, active,
        [&](uint32_t first, uint32_t count, uint64_t reach) {
            for (uint32_t c = 0; c < count; ++c) {
                const uint64_t todo = reach & open;
                if (!todo) break;
                const Instance& inst = m_instances[prims[first + c]];
                if (inst.isMesh) {
                    blocked |= inst.bvh->occludedPacket(rays, n, todo, &inst.toObject);
                } else {
                    for (uint64_t m = todo; m; m &= m - 1) {
                        const int i = __builtin_ctzll(m);
                        if (instanceOccluded(inst, rays[i])) blocked |= uint64_t(1) << i;
                    }
                }
                open = active & ~blocked;
            }
            return open == 0;
        },
        &open);
    return blocked;
}

bool SceneAccel::instanceOccluded(const Instance& inst, const Ray& r) const {
    if (inst.isMesh || inst.param) {   // any-hit tests; a parametric surface's stops at its first sub-patch hit
        const Ray lr = inst.toObject.apply(r, r.tmax);
        return inst.isMesh ? inst.bvh->occluded(lr) : inst.param->occluded(lr);
    }
    SceneHit h;
    return intersectInstance(inst, r, r.tmax, h);
}

bool SceneAccel::occluded(const Ray& r) const {
    if (m_tlas.empty()) return false;
    float tmax = r.tmax;
    bool any = false;
    const std::vector<uint32_t>& prims = m_tlas.primIndex();
    m_tlas.traverse<true>(r, tmax, [&](uint32_t first, uint32_t count, float&) {
        for (uint32_t k = 0; k < count; ++k) {
            if (instanceOccluded(m_instances[prims[first + k]], r)) {
                any = true;
                return true;
            }
        }
        return false;
    });
    return any;
}

}   // namespace rnd::rt
