// frame.cpp - flatten(): the scene graph turned into the FrameInput every renderer draws (see
// frame.h), in one pass over the pre-order that skips hidden subtrees: posed meshes with their
// world and normal matrices, lights in world space, analytic shapes (implicit, parametric,
// density grid, and the CSG tree built below each CSG node, with a geometry key for the
// backends' caches) and the camera (the one asked for, else the active one, else the first,
// else a view framing the geometry). Also makeFrameCamera(), the camera matrices of one frame.
#include "scenegraph/frame.h"

#include "scenegraph/transforms.h"

#include <cstring>
#include <functional>

namespace sg {

size_t FrameInput::triangleCount() const {
    size_t n = 0;
    for (const DrawMesh& m : meshes) n += m.mesh ? m.mesh->triangleCount() : 0;
    return n;
}

FrameCamera makeFrameCamera(const mat4& cameraWorld, const Projection& p, float aspect, float focusDistance) {
    FrameCamera c;
    c.projection = p;
    c.aspect = aspect;
    c.focusDistance = focusDistance;
    c.viewInverse = cameraWorld;
    c.view = glm::inverse(cameraWorld);
    c.proj = p.matrix(aspect, focusDistance);
    c.viewProj = c.proj * c.view;
    c.eye = vec3(cameraWorld[3]);
    return c;
}

namespace {

TexturePtr textureAt(const Scene& s, int i) { return i < 0 || size_t(i) >= s.textures.size() ? nullptr : s.textures[size_t(i)]; }
TexturePtr textureOf(const Scene& s, const Material& m) { return textureAt(s, m.diffuseTexture); }
MaterialMaps mapsOf(const Scene& s, const Material& m) {
    return {textureAt(s, m.emissiveTexture), textureAt(s, m.occlusionTexture), textureAt(s, m.metallicRoughnessTexture),
            textureAt(s, m.normalTexture)};
}

// Builds the CSG tree below `csgNode`; leaves are implicit shapes in world space.
// Returns the index of the subtree's root in tree.nodes (or -1 if it has no solid children).
int buildCsg(const Scene& s, NodeId id, CsgTree& tree, uint64_t& key, int inheritedMaterial) {
    // Iterative post-order would be needed for pathological depth; CSG trees are small and
    // user-built, so depth is bounded by kMaxCsgDepth instead.
    constexpr int kMaxCsgDepth = 64;
    std::function<int(NodeId, int, int)> rec = [&](NodeId n, int depth, int mat) -> int {
        const Node& node = s.node(n);
        key = key * 1000003u ^ node.uid ^ (node.payloadVersion << 20);
        if (!node.visible || depth > kMaxCsgDepth) return -1;
        if (auto* ip = std::get_if<ImplicitPayload>(&node.payload)) {
            CsgTree::Node leaf;
            leaf.shape = ip->shape;
            leaf.world = s.world(n);
            leaf.invWorld = glm::inverse(leaf.world);
            leaf.normal = normalMatrix(leaf.world);
            int m = ip->material >= 0 ? ip->material : mat;
            leaf.material = s.material(m);
            leaf.texture = textureOf(s, leaf.material);
            tree.nodes.push_back(std::move(leaf));
            return int(tree.nodes.size() - 1);
        }
        if (auto* cp = std::get_if<CsgPayload>(&node.payload)) {
            int m = cp->material >= 0 ? cp->material : mat;
            std::vector<int> kids;
            for (NodeId c : node.children) {
                int k = rec(c, depth + 1, m);
                if (k >= 0) kids.push_back(k);
            }
            if (kids.empty()) return -1;
            if (kids.size() == 1 && cp->csg.op != CsgOp::Difference) return kids[0];
            CsgTree::Node op;
            op.op = int(cp->csg.op);
            op.children = std::move(kids);
            tree.nodes.push_back(std::move(op));
            return int(tree.nodes.size() - 1);
        }
        return -1;   // other payloads are not solids
    };
    return rec(id, 0, inheritedMaterial);
}

Aabb csgBounds(const CsgTree& t, int i) {
    const CsgTree::Node& n = t.nodes[i];
    if (n.op < 0) return n.shape.localBounds().transformed(n.world);
    if (n.children.empty()) return {};
    if (CsgOp(n.op) == CsgOp::Difference) return csgBounds(t, n.children[0]);   // only A can add volume
    Aabb b = csgBounds(t, n.children[0]);
    for (size_t k = 1; k < n.children.size(); ++k) {
        Aabb c = csgBounds(t, n.children[k]);
        if (CsgOp(n.op) == CsgOp::Union)
            b.extend(c);
        else {
            b.min = glm::max(b.min, c.min);
            b.max = glm::min(b.max, c.max);
        }
    }
    return b;
}

// The draw of a MeshInstance: its posed mesh (skinned ones are already in world space, so
// they are drawn with the identity; morphed ones with the node's world matrix). False when
// the instance has no mesh.
bool drawMeshOf(const Scene& scene, NodeId id, const MeshInstance& mi, const mat4& w, DrawMesh& d) {
    bool worldSpace = false;
    d.mesh = scene.posedMesh(id, &worldSpace);
    if (!d.mesh) return false;
    const mat4 world = worldSpace ? mat4(1.0f) : w;
    d.node = id;
    d.nodeUid = scene.node(id).uid;
    d.material = scene.material(mi.material);
    d.texture = textureOf(scene, d.material);
    d.maps = mapsOf(scene, d.material);
    d.world = world;
    d.normal = normalMatrix(world);
    d.mirrored = glm::determinant(mat3(world)) < 0.0f;
    return true;
}

}   // namespace

FrameInput flatten(const Scene& scene, float aspect, NodeId cameraNode) {
    FrameInput f;
    f.settings = scene.settings;
    f.ambientLight = scene.settings.ambientLight;
    const auto& order = scene.depthFirstOrder();
    scene.updateWorld();
    scene.trimPoseCache();

    // One pass over the pre-order (parents come first): per-id flags
    // bit 0 = hidden (self or an ancestor), bit 1 = a CSG node or inside one.
    // Groups and cameras are skipped before touching their world matrix (cache misses are
    // most of the cost on large scenes).
    std::vector<uint8_t> flags(scene.idCapacity(), 0);
    for (NodeId id : order) {
        const Node& n = scene.node(id);
        uint8_t pf = n.parent != kNoNode ? flags[n.parent] : 0;
        bool hidden = (pf & 1) || !n.visible;
        bool inCsg = (pf & 2) != 0;
        flags[id] = uint8_t((hidden ? 1 : 0) | (inCsg || std::holds_alternative<CsgPayload>(n.payload) ? 2 : 0));
        if (hidden) continue;
        if (std::holds_alternative<std::monostate>(n.payload) || std::holds_alternative<Camera>(n.payload)) continue;
        const mat4& w = scene.world(id);
        if (auto* mi = std::get_if<MeshInstance>(&n.payload)) {
            DrawMesh d;
            if (drawMeshOf(scene, id, *mi, w, d)) f.meshes.push_back(std::move(d));
        } else if (auto* lp = std::get_if<Light>(&n.payload)) {
            DrawLight l;
            l.node = id;
            l.type = lp->type;
            l.position = vec3(w[3]);
            vec3 dir = vec3(w * vec4(0, 0, -1, 0));
            l.direction = glm::length(dir) > 0 ? glm::normalize(dir) : vec3(0, 0, -1);
            l.radiance = lp->color * lp->intensity;
            l.inverseSquare = lp->inverseSquare && scene.settings.attenuation;
            l.cosInner = std::cos(radians(std::min(lp->spotInnerDeg, lp->spotOuterDeg)));
            l.cosOuter = std::cos(radians(lp->spotOuterDeg));
            l.range = lp->range;
            l.radius = std::max(lp->radius, 0.0f);
            l.tanAngularRadius = std::tan(radians(std::clamp(lp->angularRadiusDeg, 0.0f, 45.0f)));
            f.lights.push_back(l);
        } else if (!inCsg) {
            DrawAnalytic a;
            a.node = id;
            a.world = w;
            a.invWorld = glm::inverse(w);
            a.normal = normalMatrix(w);
            a.geometryKey = n.uid * 1000003u ^ n.payloadVersion;
            int mat = -1;
            Aabb local;
            if (auto* ip = std::get_if<ImplicitPayload>(&n.payload)) {
                a.kind = DrawAnalytic::Kind::Implicit;
                a.implicit = ip->shape;
                mat = ip->material;
                local = ip->shape.localBounds();
            } else if (auto* pp = std::get_if<ParametricPayload>(&n.payload)) {
                a.kind = DrawAnalytic::Kind::Parametric;
                a.parametric = pp->surface;
                mat = pp->material;
                local = pp->surface.localBounds();
            } else if (auto* gp = std::get_if<GridPayload>(&n.payload)) {
                if (!gp->grid) continue;
                a.kind = DrawAnalytic::Kind::Grid;
                a.grid = gp->grid;
                mat = gp->material;
                local = gp->grid->bounds;
            } else if (auto* cp = std::get_if<CsgPayload>(&n.payload)) {
                auto tree = std::make_shared<CsgTree>();
                uint64_t key = n.uid;
                tree->root = buildCsg(scene, id, *tree, key, cp->material);
                if (tree->root < 0) continue;
                a.kind = DrawAnalytic::Kind::Csg;
                a.geometryKey = key;   // includes leaf transforms via the world matrices below
                for (const auto& leaf : tree->nodes)
                    if (leaf.op < 0)
                        for (int c = 0; c < 4; ++c)
                            for (int r = 0; r < 4; ++r) {
                                uint32_t bits;
                                std::memcpy(&bits, &leaf.world[c][r], 4);
                                a.geometryKey = a.geometryKey * 31 + bits;
                            }
                a.worldBounds = csgBounds(*tree, tree->root);
                mat = cp->material;
                a.csg = std::move(tree);
            } else {
                continue;   // groups and cameras draw nothing
            }
            a.material = scene.material(mat);
            a.texture = textureOf(scene, a.material);
            if (a.kind != DrawAnalytic::Kind::Csg) a.worldBounds = local.transformed(w);
            f.analytics.push_back(std::move(a));
        }
    }

    // Camera: the requested one, else the active one, else a default framing camera.
    NodeId cam = scene.valid(cameraNode) && std::holds_alternative<Camera>(scene.node(cameraNode).payload) ? cameraNode : scene.activeCamera;
    if (!scene.valid(cam) || !std::holds_alternative<Camera>(scene.node(cam).payload)) {
        std::vector<NodeId> cams = scene.cameras();
        cam = cams.empty() ? kNoNode : cams.front();
    }
    if (cam != kNoNode) {
        const Camera& c = std::get<Camera>(scene.node(cam).payload);
        f.camera = makeFrameCamera(scene.world(cam), c.projection, aspect, c.focusDistance);
    } else {
        // No camera in the scene: frame the geometry (without copying the scene).
        mat4 camWorld;
        Camera c = scene.framingCamera(camWorld);
        f.camera = makeFrameCamera(camWorld, c.projection, aspect, c.focusDistance);
    }
    return f;
}

}   // namespace sg
