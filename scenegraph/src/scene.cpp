// scene.cpp - scene graph storage, structural edits and the world-matrix update.
//
// Sections: LocalTransform | structure edits | pre-order rebuild | world update | queries |
//           sceneDifference
#include "scenegraph/scene.h"

#include "scenegraph/deform.h"
#include "scenegraph/transforms.h"

#include <glm/gtx/matrix_decompose.hpp>

#include <tbb/parallel_for.h>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <sstream>

namespace sg {

// --- LocalTransform ---------------------------------------------------------------------

mat4 LocalTransform::toMatrix() const {
    if (mode == Mode::Matrix) return matrix;
    mat4 r = glm::mat4_cast(rotation);
    // T * R * S without building three matrices: columns of R scaled, then translation.
    r[0] *= scale.x;
    r[1] *= scale.y;
    r[2] *= scale.z;
    r[3] = vec4(translation, 1.0f);
    return r;
}

vec3 LocalTransform::eulerDegrees() const {
    // R = Rz * Ry * Rx; recover angles from the rotation matrix.
    mat3 m = glm::mat3_cast(rotation);
    // m[c][r]; entry (2,0) = -sin(y)
    float sy = -m[0][2];
    sy = std::clamp(sy, -1.0f, 1.0f);
    float y = std::asin(sy), x, z;
    if (std::abs(sy) < 0.99999f) {
        x = std::atan2(m[1][2], m[2][2]);
        z = std::atan2(m[0][1], m[0][0]);
    } else {   // gimbal lock: put everything into x
        z = 0;
        x = std::atan2(-m[2][1], m[1][1]);
    }
    return vec3(degrees(x), degrees(y), degrees(z));
}

void LocalTransform::setEulerDegrees(const vec3& d) {
    quat qx = glm::angleAxis(radians(d.x), vec3(1, 0, 0));
    quat qy = glm::angleAxis(radians(d.y), vec3(0, 1, 0));
    quat qz = glm::angleAxis(radians(d.z), vec3(0, 0, 1));
    rotation = glm::normalize(qz * qy * qx);
}

LocalTransform LocalTransform::fromTRS(const vec3& t, const quat& r, const vec3& s) {
    LocalTransform lt;
    lt.translation = t;
    lt.rotation = r;
    lt.scale = s;
    return lt;
}

LocalTransform LocalTransform::fromMatrix(const mat4& m) {
    LocalTransform lt;
    lt.mode = Mode::Matrix;
    lt.matrix = m;
    return lt;
}

bool LocalTransform::tryMakeTRS() {
    if (mode == Mode::TRS) return true;
    const mat4& m = matrix;
    if (m[0][3] != 0 || m[1][3] != 0 || m[2][3] != 0 || m[3][3] != 1) return false;
    vec3 c0(m[0]), c1(m[1]), c2(m[2]);
    vec3 s(glm::length(c0), glm::length(c1), glm::length(c2));
    if (s.x < 1e-12f || s.y < 1e-12f || s.z < 1e-12f) return false;
    c0 /= s.x;
    c1 /= s.y;
    c2 /= s.z;
    const float tol = 1e-4f;   // columns must be orthogonal: no shear
    if (std::abs(glm::dot(c0, c1)) > tol || std::abs(glm::dot(c0, c2)) > tol || std::abs(glm::dot(c1, c2)) > tol) return false;
    if (glm::dot(glm::cross(c0, c1), c2) < 0) {
        s.z = -s.z;
        c2 = -c2;
    }   // mirror as negative scale
    mat3 rot(c0, c1, c2);
    LocalTransform t = fromTRS(vec3(m[3]), glm::normalize(glm::quat_cast(rot)), s);
    // Accept only if it reproduces the matrix.
    mat4 back = t.toMatrix();
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (std::abs(back[c][r] - m[c][r]) > 1e-4f * (1.0f + std::abs(m[c][r]))) return false;
    *this = t;
    return true;
}

std::string_view payloadKind(const Payload& p) {
    static constexpr std::string_view names[] = {"group", "mesh", "camera", "light", "implicit", "csg", "parametric", "grid"};
    return names[p.index()];
}

// --- structure edits ---------------------------------------------------------------------

Scene::Scene() : m_deform(std::make_shared<DeformCache>()) {
    Node root;
    root.name = "root";
    root.uid = newResourceId();
    root.alive = true;
    m_nodes.push_back(std::move(root));
    m_aliveCount = 1;
}

Scene::Scene(const Scene& o) { *this = o; }

Scene& Scene::operator=(const Scene& o) {
    if (this == &o) return *this;
    name = o.name;
    materials = o.materials;
    textures = o.textures;
    skins = o.skins;
    settings = o.settings;
    activeCamera = o.activeCamera;
    // Meshes are deep-copied so editing one scene never changes the other.
    meshes.clear();
    for (const auto& m : o.meshes) meshes.push_back(m ? std::make_shared<Mesh>(*m) : nullptr);
    m_nodes = o.m_nodes;
    for (Node& n : m_nodes) {
        n.uid = newResourceId();
        if (auto* g = std::get_if<GridPayload>(&n.payload); g && g->grid) g->grid = std::make_shared<DensityGrid>(*g->grid);
    }
    m_aliveCount = o.m_aliveCount;
    m_deform = std::make_shared<DeformCache>();   // posed meshes are keyed by node uid: none carry over
    m_structureVersion = o.m_structureVersion + 1;
    m_orderValid = false;
    m_allDirty = true;
    return *this;
}

void Scene::markStructureDirty() {
    ++m_structureVersion;
    m_orderValid = false;
    m_allDirty = true;
}

NodeId Scene::addNode(std::string nodeName, NodeId parent, Payload payload) {
    if (!valid(parent)) parent = root();
    NodeId id = NodeId(m_nodes.size());
    Node n;
    n.name = std::move(nodeName);
    n.parent = parent;
    n.payload = std::move(payload);
    n.uid = newResourceId();
    n.alive = true;
    m_nodes.push_back(std::move(n));
    m_nodes[parent].children.push_back(id);
    ++m_aliveCount;
    markStructureDirty();
    return id;
}

bool Scene::removeNode(NodeId id) {
    if (!valid(id) || id == root()) return false;
    auto& siblings = m_nodes[m_nodes[id].parent].children;
    siblings.erase(std::find(siblings.begin(), siblings.end(), id));
    std::vector<NodeId> stack{id};
    while (!stack.empty()) {
        NodeId n = stack.back();
        stack.pop_back();
        for (NodeId c : m_nodes[n].children) stack.push_back(c);
        m_nodes[n] = Node{};   // frees payload and children; alive = false
        --m_aliveCount;
        if (activeCamera == n) activeCamera = kNoNode;
    }
    markStructureDirty();
    return true;
}

DetachedSubtree Scene::detach(NodeId id) {
    DetachedSubtree d;
    if (!valid(id) || id == root()) return d;
    d.id = id;
    d.parent = m_nodes[id].parent;
    d.index = childIndex(id);
    auto& siblings = m_nodes[d.parent].children;
    siblings.erase(siblings.begin() + std::ptrdiff_t(d.index));
    // Parents first: a breadth-first walk over the subtree.
    d.nodes.emplace_back(id, Node{});
    for (size_t i = 0; i < d.nodes.size(); ++i) {
        NodeId n = d.nodes[i].first;
        for (NodeId c : m_nodes[n].children) d.nodes.emplace_back(c, Node{});
        if (activeCamera == n) {
            d.activeCamera = n;
            activeCamera = kNoNode;
        }
        d.nodes[i].second = std::move(m_nodes[n]);
        m_nodes[n] = Node{};   // alive = false
        --m_aliveCount;
    }
    markStructureDirty();
    return d;
}

bool Scene::reattach(DetachedSubtree d) {
    if (d.id == kNoNode || d.nodes.empty() || d.nodes.front().first != d.id || !valid(d.parent)) return false;
    for (const auto& [n, node] : d.nodes)
        if (n >= m_nodes.size() || m_nodes[n].alive || !node.alive) return false;
    auto& siblings = m_nodes[d.parent].children;
    siblings.insert(siblings.begin() + std::ptrdiff_t(std::min(d.index, siblings.size())), d.id);
    for (auto& [n, node] : d.nodes) {
        m_nodes[n] = std::move(node);
        ++m_aliveCount;
    }
    m_nodes[d.id].parent = d.parent;
    if (d.activeCamera != kNoNode && valid(d.activeCamera)) activeCamera = d.activeCamera;
    markStructureDirty();
    return true;
}

size_t Scene::childIndex(NodeId id) const {
    if (!valid(id) || id == root()) return 0;
    const auto& siblings = m_nodes[m_nodes[id].parent].children;
    return size_t(std::find(siblings.begin(), siblings.end(), id) - siblings.begin());
}

NodeId Scene::duplicate(NodeId id) {
    if (!valid(id) || id == root()) return kNoNode;
    // Copy breadth-first, mapping old ids to new ids; parents are created before children.
    std::vector<std::pair<NodeId, NodeId>> queue{{id, m_nodes[id].parent}};
    NodeId first = kNoNode;
    for (size_t i = 0; i < queue.size(); ++i) {
        auto [src, dstParent] = queue[i];
        Node copy = m_nodes[src];   // copy before addNode reallocates
        NodeId n = addNode(src == id ? copy.name + " copy" : copy.name, dstParent, copy.payload);
        if (auto* g = std::get_if<GridPayload>(&m_nodes[n].payload); g && g->grid) g->grid = std::make_shared<DensityGrid>(*g->grid);
        m_nodes[n].local = copy.local;
        m_nodes[n].visible = copy.visible;
        if (first == kNoNode) first = n;
        for (NodeId c : copy.children) queue.push_back({c, n});
    }
    return first;
}

bool Scene::isAncestor(NodeId ancestor, NodeId n) const {
    if (!valid(ancestor) || !valid(n)) return false;
    for (NodeId p = n; p != kNoNode; p = m_nodes[p].parent)
        if (p == ancestor) return true;
    return false;
}

bool Scene::reparent(NodeId id, NodeId newParent, bool keepWorld, std::string* error) {
    auto fail = [&](const char* why) {
        if (error) *error = why;
        return false;
    };
    if (!valid(id) || !valid(newParent)) return fail("invalid node");
    if (id == root()) return fail("the root cannot be moved");
    if (isAncestor(id, newParent)) return fail("a node cannot be moved under itself or its descendants");
    mat4 worldBefore = world(id);
    mat4 parentWorld = world(newParent);
    auto& oldSiblings = m_nodes[m_nodes[id].parent].children;
    oldSiblings.erase(std::find(oldSiblings.begin(), oldSiblings.end(), id));
    m_nodes[id].parent = newParent;
    m_nodes[newParent].children.push_back(id);
    if (keepWorld) {
        // local' = parentWorld^-1 * worldBefore keeps the world transform.
        LocalTransform lt = LocalTransform::fromMatrix(glm::inverse(parentWorld) * worldBefore);
        if (m_nodes[id].local.mode == LocalTransform::Mode::TRS) lt.tryMakeTRS();
        m_nodes[id].local = lt;
    }
    markStructureDirty();
    return true;
}

NodeId Scene::findByName(std::string_view n) const {
    for (NodeId id : depthFirstOrder())
        if (m_nodes[id].name == n) return id;
    return kNoNode;
}

// --- per-node edits ------------------------------------------------------------------------

void Scene::setName(NodeId id, std::string n) {
    if (valid(id)) m_nodes[id].name = std::move(n);
}

void Scene::setVisible(NodeId id, bool v) {
    if (valid(id)) m_nodes[id].visible = v;
}

void Scene::markDirty(NodeId id) {
    if (!m_orderValid) return;   // the rebuild reads every local transform anyway
    uint32_t slot = m_slotOf[id];
    m_localM[slot] = m_nodes[id].local.toMatrix();
    if (m_allDirty) return;   // a full update is pending anyway
    if (!m_dirty[slot]) {
        m_dirty[slot] = 1;
        m_dirtySlots.push_back(slot);
    }
}

void Scene::setLocal(NodeId id, const LocalTransform& t) {
    if (!valid(id)) return;
    m_nodes[id].local = t;
    markDirty(id);
}

void Scene::setPayload(NodeId id, Payload p) {
    if (!valid(id)) return;
    m_nodes[id].payload = std::move(p);
    ++m_nodes[id].payloadVersion;
}

Payload& Scene::editPayload(NodeId id) {
    ++m_nodes[id].payloadVersion;
    return m_nodes[id].payload;
}

void Scene::lookAt(NodeId id, const vec3& eye, const vec3& center, const vec3& up) {
    if (!valid(id)) return;
    mat4 camToWorld = glm::inverse(sg::lookAt(eye, center, up));
    NodeId parent = m_nodes[id].parent;
    // The parent's world along its chain: adding a node and aiming it (an importer's default
    // light and camera) must not rebuild the order of a scene of a million nodes each time.
    mat4 local = parent == kNoNode ? camToWorld : glm::inverse(worldByChain(parent)) * camToWorld;
    LocalTransform lt = LocalTransform::fromMatrix(local);
    lt.tryMakeTRS();
    setLocal(id, lt);
    if (auto* cam = std::get_if<Camera>(&m_nodes[id].payload)) cam->focusDistance = glm::length(center - eye);
}

// --- pre-order rebuild ----------------------------------------------------------------------

const std::vector<NodeId>& Scene::depthFirstOrder() const {
    if (!m_orderValid) rebuildOrder();
    return m_order;
}

void Scene::rebuildOrder() const {
    size_t n = m_aliveCount;
    m_order.clear();
    m_order.reserve(n);
    m_slotOf.assign(m_nodes.size(), ~0u);
    m_parentSlot.resize(n);
    m_subtreeSize.assign(n, 1);
    // Iterative pre-order: children pushed in reverse so the first child comes out first.
    std::vector<NodeId> stack{root()};
    while (!stack.empty()) {
        NodeId id = stack.back();
        stack.pop_back();
        uint32_t slot = uint32_t(m_order.size());
        m_order.push_back(id);
        m_slotOf[id] = slot;
        NodeId p = m_nodes[id].parent;
        m_parentSlot[slot] = p == kNoNode ? -1 : int32_t(m_slotOf[p]);
        const auto& ch = m_nodes[id].children;
        for (auto it = ch.rbegin(); it != ch.rend(); ++it) stack.push_back(*it);
    }
    // Subtree sizes: children come after parents, so accumulate backwards.
    for (size_t s = n; s-- > 1;) m_subtreeSize[m_parentSlot[s]] += m_subtreeSize[s];
    m_localM.resize(n);
    m_worldM.resize(n);
    m_dirty.assign(n, 0);
    m_dirtySlots.clear();
    for (size_t s = 0; s < n; ++s) m_localM[s] = m_nodes[m_order[s]].local.toMatrix();
    m_orderValid = true;
    m_allDirty = true;
}

// --- world update ------------------------------------------------------------------------------

namespace {
// world = parent * local for affine matrices (last rows 0 0 0 1): 36 multiply-adds instead
// of 64. SSE version: each output column is (a0*b.x + a1*b.y) + (a2*b.z [+ a3]), four lanes
// at once, summed as a tree to shorten the dependency chain parent -> child (deep chains are
// latency bound); the scalar fallback does the same operations in the same order, so both
// give bit-identical results (no FMA contraction without -march).
inline void mulAffine(const mat4& a, const mat4& b, mat4& out) {
#if defined(__SSE2__)
    const float* pa = &a[0][0];
    const float* pb = &b[0][0];
    float* po = &out[0][0];
    const __m128 a0 = _mm_loadu_ps(pa), a1 = _mm_loadu_ps(pa + 4), a2 = _mm_loadu_ps(pa + 8), a3 = _mm_loadu_ps(pa + 12);
    for (int c = 0; c < 4; ++c) {
        const __m128 bc = _mm_loadu_ps(pb + 4 * c);
        const __m128 r01 = _mm_add_ps(_mm_mul_ps(a0, _mm_shuffle_ps(bc, bc, 0x00)), _mm_mul_ps(a1, _mm_shuffle_ps(bc, bc, 0x55)));
        __m128 r2 = _mm_mul_ps(a2, _mm_shuffle_ps(bc, bc, 0xAA));
        if (c == 3) r2 = _mm_add_ps(r2, a3);
        _mm_storeu_ps(po + 4 * c, _mm_add_ps(r01, r2));
    }
#else
    for (int c = 0; c < 4; ++c) {
        vec4 r01 = a[0] * b[c][0] + a[1] * b[c][1];
        vec4 r2 = a[2] * b[c][2];
        if (c == 3) r2 += a[3];
        out[c] = r01 + r2;
    }
#endif
}

}   // namespace

mat4 Scene::worldByChain(NodeId id) const {
    std::vector<NodeId> chain;
    for (NodeId p = id; p != kNoNode; p = m_nodes[p].parent) chain.push_back(p);
    mat4 w = m_nodes[chain.back()].local.toMatrix();   // the root: world = local, as in WorldUpdater::serial
    for (size_t i = chain.size() - 1; i-- > 0;) {
        mat4 out;
        mulAffine(w, m_nodes[chain[i]].local.toMatrix(), out);
        w = out;
    }
    return w;
}

namespace {

// Updates dirty subtrees. A subtree is the contiguous slot range [root, root + size); its
// children's subtrees are consecutive sub-ranges. Large subtrees are split over threads by
// their children (TBB): every node's world is still parent x local computed the same way, so
// the result does not depend on the number of threads. Chains and caterpillars are walked
// iteratively; recursion only happens where at least two parts of >= kGrain nodes each run in
// parallel, so its depth is at most n / kGrain.
struct WorldUpdater {
    static constexpr size_t kGrain = 16384;
    const int32_t* parent;
    const uint32_t* subtreeSize;
    const mat4* local;
    mat4* world;

    void serial(size_t begin, size_t end) const {
        // Only the root (slot 0, always first in its range) has no parent: no branch in the loop.
        if (begin < end && parent[begin] < 0) {
            world[begin] = local[begin];
            ++begin;
        }
        for (size_t i = begin; i < end; ++i) mulAffine(world[parent[i]], local[i], world[i]);
    }

    void subtree(size_t begin, size_t end) const {
        struct Part {
            size_t begin, end;
            bool tree;
        };
        std::vector<Part> parts;
        while (end - begin >= 2 * kGrain) {
            serial(begin, begin + 1);
            // Children subtrees: big ones are parts of their own, runs of small ones are batched.
            parts.clear();
            size_t heavy = 0;
            for (size_t c = begin + 1; c < end; c += subtreeSize[c]) {
                size_t ce = c + subtreeSize[c];
                if (ce - c >= kGrain) {
                    parts.push_back({c, ce, true});
                    ++heavy;
                } else if (!parts.empty() && !parts.back().tree && parts.back().end - parts.back().begin < kGrain) {
                    parts.back().end = ce;
                    if (ce - parts.back().begin >= kGrain) ++heavy;
                } else {
                    parts.push_back({c, ce, false});
                }
            }
            if (heavy >= 2) {
                tbb::parallel_for(size_t(0), parts.size(), [&](size_t k) {
                    if (parts[k].tree)
                        subtree(parts[k].begin, parts[k].end);
                    else
                        serial(parts[k].begin, parts[k].end);
                });
                return;
            }
            // At most one big part: the small ones here, then continue down the big one.
            const Part* next = nullptr;
            for (const Part& pt : parts) {
                if (pt.tree)
                    next = &pt;
                else
                    serial(pt.begin, pt.end);
            }
            if (!next) return;
            begin = next->begin;
            end = next->end;
        }
        serial(begin, end);
    }
};
}   // namespace

size_t updateWorldImpl(const Scene& s) {
    if (!s.m_orderValid) s.rebuildOrder();
    const size_t n = s.m_order.size();
    WorldUpdater up{s.m_parentSlot.data(), s.m_subtreeSize.data(), s.m_localM.data(), s.m_worldM.data()};
    size_t count = 0;
    auto updateRange = [&](size_t begin, size_t end) {
        count += end - begin;
        up.subtree(begin, end);
    };
    if (s.m_allDirty) {
        updateRange(0, n);
        s.m_allDirty = false;
    } else if (!s.m_dirtySlots.empty()) {
        // Dirty subtrees are contiguous slot ranges; process them in order, skipping nested ones.
        std::sort(s.m_dirtySlots.begin(), s.m_dirtySlots.end());
        size_t coveredEnd = 0;
        for (uint32_t slot : s.m_dirtySlots) {
            if (slot < coveredEnd) continue;
            coveredEnd = slot + s.m_subtreeSize[slot];
            updateRange(slot, coveredEnd);
        }
    }
    for (uint32_t slot : s.m_dirtySlots) s.m_dirty[slot] = 0;
    s.m_dirtySlots.clear();
    s.m_lastUpdated = count;
    return count;
}

size_t Scene::updateWorld() const { return updateWorldImpl(*this); }

const mat4& Scene::world(NodeId id) const {
    static const mat4 kIdentity(1.0f);
    if (!valid(id)) return kIdentity;   // removed or out-of-range ids have no slot
    if (!m_orderValid || m_allDirty || !m_dirtySlots.empty()) updateWorldImpl(*this);
    return m_worldM[m_slotOf[id]];
}

bool Scene::effectiveVisible(NodeId id) const {
    for (NodeId p = id; p != kNoNode; p = m_nodes[p].parent)
        if (!m_nodes[p].visible) return false;
    return valid(id);
}

// --- queries ---------------------------------------------------------------------------------

Aabb Scene::localBounds(NodeId id) const {
    if (!valid(id)) return {};
    const Payload& p = m_nodes[id].payload;
    if (auto* mi = std::get_if<MeshInstance>(&p)) {
        if (mi->mesh >= 0 && size_t(mi->mesh) < meshes.size() && meshes[mi->mesh]) return meshes[mi->mesh]->bounds();
    } else if (auto* ip = std::get_if<ImplicitPayload>(&p)) {
        return ip->shape.localBounds();
    } else if (auto* pp = std::get_if<ParametricPayload>(&p)) {
        return pp->surface.localBounds();
    } else if (auto* gp = std::get_if<GridPayload>(&p)) {
        if (gp->grid) return gp->grid->bounds;
    }
    return {};
}

Aabb Scene::worldBounds() const {
    // Effective visibility in one pre-order pass (parents come first): asking
    // effectiveVisible() per node walks all ancestors and is quadratic on deep chains.
    const auto& order = depthFirstOrder();
    std::vector<uint8_t> hidden(m_nodes.size(), 0);
    Aabb b;
    for (NodeId id : order) {
        const Node& n = m_nodes[id];
        hidden[id] = !n.visible || (n.parent != kNoNode && hidden[n.parent]);
        if (hidden[id]) continue;
        // Children of CSG nodes are part of the CSG solid; their bounds count too.
        if (std::holds_alternative<ImplicitPayload>(n.payload)) {
            const auto& shape = std::get<ImplicitPayload>(n.payload).shape;
            if (shape.type == ImplicitType::Plane) continue;   // infinite: don't let it dominate framing
        }
        b.extend(nodeWorldBounds(id));
    }
    return b;
}

Aabb Scene::nodeWorldBounds(NodeId id) const {
    if (!valid(id)) return {};
    if (std::holds_alternative<MeshInstance>(m_nodes[id].payload)) {
        bool worldSpace = false;
        MeshPtr m = posedMesh(id, &worldSpace);
        if (!m) return {};
        return worldSpace ? m->bounds() : m->bounds().transformed(world(id));
    }
    Aabb lb = localBounds(id);
    return lb.empty() ? lb : lb.transformed(world(id));
}

MeshPtr Scene::posedMesh(NodeId id, bool* worldSpace) const {
    if (worldSpace) *worldSpace = false;
    if (!valid(id)) return nullptr;
    const auto* mi = std::get_if<MeshInstance>(&m_nodes[id].payload);
    if (!mi || mi->mesh < 0 || size_t(mi->mesh) >= meshes.size() || !meshes[size_t(mi->mesh)]) return nullptr;
    if (!isDeformed(*this, *mi)) return meshes[size_t(mi->mesh)];
    bool ws = false;
    MeshPtr m;
    if (m_deform) {
        m = m_deform->posed(*this, id, *mi, ws);
    } else {   // a moved-from scene: no cache
        DeformCache once;
        m = once.posed(*this, id, *mi, ws);
    }
    if (worldSpace) *worldSpace = ws;
    return m;
}

void Scene::trimPoseCache() const {
    if (m_deform) m_deform->trim();
}

uint64_t Scene::poseEvaluations() const { return m_deform ? m_deform->evaluations() : 0; }

std::vector<NodeId> Scene::cameras() const {
    std::vector<NodeId> out;
    for (NodeId id : depthFirstOrder())
        if (std::holds_alternative<Camera>(m_nodes[id].payload)) out.push_back(id);
    return out;
}

const Material& Scene::material(int index) const {
    static const Material kDefault;
    if (index < 0 || size_t(index) >= materials.size()) return kDefault;
    return materials[index];
}

Camera Scene::framingCamera(mat4& cameraWorld) const { return framingCamera(worldBounds(), cameraWorld); }

Camera Scene::framingCamera(const Aabb& bounds, mat4& cameraWorld) {
    Aabb b = bounds;
    if (b.empty()) b = {vec3(-1.0f), vec3(1.0f)};
    vec3 c = b.center();
    float radius = std::max(0.5f * glm::length(b.extent()), 1e-3f);
    Camera cam;
    cam.projection.fovyDeg = 45.0f;
    float dist = radius / std::sin(radians(0.5f * cam.projection.fovyDeg)) * 1.1f;
    cam.projection.zNear = std::max(dist - radius * 2.0f, dist * 0.01f);
    cam.projection.zFar = dist + radius * 2.0f;
    cam.projection.orthoHalfHeight = radius * 1.1f;
    vec3 dir = glm::normalize(vec3(0.5f, 0.4f, 1.0f));
    cam.focusDistance = dist;
    cameraWorld = glm::inverse(sg::lookAt(c + dir * dist, c, vec3(0, 1, 0)));
    return cam;
}

NodeId Scene::addDefaultCamera() { return addDefaultCamera(worldBounds()); }

NodeId Scene::addDefaultCamera(const Aabb& bounds) {
    mat4 camWorld;
    Camera cam = framingCamera(bounds, camWorld);
    NodeId id = addNode("default camera", root(), cam);
    vec3 eye = vec3(camWorld[3]), c = eye - vec3(camWorld[2]) * cam.focusDistance;
    lookAt(id, eye, c);
    activeCamera = id;
    return id;
}

// --- sceneDifference ---------------------------------------------------------------------------

namespace {
bool near(const mat4& a, const mat4& b, float eps = 1e-5f) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (std::abs(a[c][r] - b[c][r]) > eps * (1 + std::abs(a[c][r]))) return false;
    return true;
}

// Skins: names, inverse bind matrices and joints (node ids mapped from a to b).
std::string skinDifference(const Scene& a, const Scene& b, const std::vector<NodeId>& mapAB) {
    if (a.skins.size() != b.skins.size()) return "skin count differs";
    auto mapped = [&](NodeId n) { return a.valid(n) ? mapAB[n] : kNoNode; };
    for (size_t i = 0; i < a.skins.size(); ++i) {
        const Skin &x = a.skins[i], &y = b.skins[i];
        std::string where = "skin " + std::to_string(i) + " (" + x.name + "): ";
        if (x.name != y.name) return where + "name differs";
        if (x.joints.size() != y.joints.size() || x.inverseBind.size() != y.inverseBind.size()) return where + "joint count differs";
        for (size_t j = 0; j < x.joints.size(); ++j)
            if (mapped(x.joints[j]) != (b.valid(y.joints[j]) ? y.joints[j] : kNoNode)) return where + "joint " + std::to_string(j) + " differs";
        for (size_t j = 0; j < x.inverseBind.size(); ++j)
            if (!near(x.inverseBind[j], y.inverseBind[j])) return where + "inverse bind matrix " + std::to_string(j) + " differs";
        if (mapped(x.skeleton) != (b.valid(y.skeleton) ? y.skeleton : kNoNode)) return where + "skeleton differs";
    }
    return {};
}
}   // namespace

std::string sceneDifference(const Scene& a, const Scene& b) {
    std::ostringstream why;
    if (a.name != b.name) return "scene name differs";
    if (!(a.settings == b.settings)) return "render settings differ";
    if (a.materials != b.materials) return "materials differ";
    if (a.meshes.size() != b.meshes.size()) return "mesh count differs";
    for (size_t i = 0; i < a.meshes.size(); ++i) {
        const Mesh &x = *a.meshes[i], &y = *b.meshes[i];
        if (x.name != y.name || x.mode != y.mode || x.positions != y.positions || x.normals != y.normals || x.uv0 != y.uv0 || x.uv1 != y.uv1 ||
            x.colors != y.colors || x.indices != y.indices)
            return "mesh " + std::to_string(i) + " (" + x.name + ") differs";
        if (x.tangents != y.tangents || x.joints0 != y.joints0 || x.joints1 != y.joints1 || x.weights0 != y.weights0 || x.weights1 != y.weights1 ||
            x.morphTargets != y.morphTargets || x.morphWeights != y.morphWeights)
            return "mesh " + std::to_string(i) + " (" + x.name + "): tangents, skin or morph data differ";
    }
    if (a.textures.size() != b.textures.size()) return "texture count differs";
    for (size_t i = 0; i < a.textures.size(); ++i) {
        const Texture &x = *a.textures[i], &y = *b.textures[i];
        if (x.width != y.width || x.height != y.height || x.rgba != y.rgba || x.wrapS != y.wrapS || x.wrapT != y.wrapT || x.filter != y.filter)
            return "texture " + std::to_string(i) + " differs";
    }
    const auto &oa = a.depthFirstOrder(), &ob = b.depthFirstOrder();
    if (oa.size() != ob.size()) return "node count differs (" + std::to_string(oa.size()) + " vs " + std::to_string(ob.size()) + ")";
    std::vector<NodeId> mapAB(a.idCapacity(), kNoNode);
    for (size_t i = 0; i < oa.size(); ++i) mapAB[oa[i]] = ob[i];
    for (size_t i = 0; i < oa.size(); ++i) {
        const Node &x = a.node(oa[i]), &y = b.node(ob[i]);
        std::string where = "node '" + x.name + "': ";
        if (x.name != y.name) return where + "name differs ('" + y.name + "')";
        if ((x.parent == kNoNode) != (y.parent == kNoNode) || (x.parent != kNoNode && mapAB[x.parent] != y.parent)) return where + "parent differs";
        if (x.visible != y.visible) return where + "visibility differs";
        if (x.local.mode != y.local.mode) return where + "transform mode differs";
        if (!near(x.local.toMatrix(), y.local.toMatrix())) return where + "local transform differs";
        if (!(x.payload == y.payload)) return where + std::string(payloadKind(x.payload)) + " payload differs";
    }
    if (std::string e = skinDifference(a, b, mapAB); !e.empty()) return e;
    bool camA = a.activeCamera != kNoNode, camB = b.activeCamera != kNoNode;
    if (camA != camB || (camA && mapAB[a.activeCamera] != b.activeCamera)) return "active camera differs";
    return {};
}

}   // namespace sg
