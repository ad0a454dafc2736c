// nodes.cpp - the glTF node hierarchy -> our nodes: which scene's roots are loaded, one node per
// glTF node with its local transform, the MeshInstances of its mesh's primitives (with skin and
// morph weights), its camera and its KHR_lights_punctual light.
#include "gltf_internal.h"
#include "scenegraph/params.h"

#include <cmath>

namespace assets::detail::gltf {

namespace {

// The node's matrix, or its TRS with the rotation normalised, as our LocalTransform.
sg::LocalTransform localOf(const tinygltf::Node& n) {
    if (n.matrix.size() == 16) {
        sg::mat4 mm;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) mm[c][r] = float(n.matrix[size_t(c * 4 + r)]);
        return sg::LocalTransform::fromMatrix(mm);
    }
    sg::vec3 t(0.0f), s(1.0f);
    sg::quat q(1, 0, 0, 0);
    if (n.translation.size() == 3) t = sg::vec3(float(n.translation[0]), float(n.translation[1]), float(n.translation[2]));
    if (n.scale.size() == 3) s = sg::vec3(float(n.scale[0]), float(n.scale[1]), float(n.scale[2]));
    if (n.rotation.size() == 4) {
        q = sg::quat(float(n.rotation[3]), float(n.rotation[0]), float(n.rotation[1]), float(n.rotation[2]));
        float len = glm::length(q);
        q = len > 1e-12f ? q / len : sg::quat(1, 0, 0, 0);
    }
    return sg::LocalTransform::fromTRS(t, q, s);
}

}   // namespace

std::vector<int> chooseRoots(const tinygltf::Model& model, const std::string& file, LoadResult& result) {
    for (size_t i = 0; i < model.scenes.size(); ++i)
        result.sceneNames.push_back(model.scenes[i].name.empty() ? "scene " + std::to_string(i) : model.scenes[i].name);
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        result.loadedScene = model.defaultScene >= 0 ? model.defaultScene : 0;
        roots = model.scenes[size_t(result.loadedScene)].nodes;
        if (model.scenes.size() > 1) {
            std::string others;
            for (size_t i = 0; i < model.scenes.size(); ++i)
                if (int(i) != result.loadedScene) others += (others.empty() ? "'" : ", '") + result.sceneNames[i] + "'";
            result.warnings.push_back(file + ": loaded scene '" + result.sceneNames[size_t(result.loadedScene)] + "'; other scenes: " + others);
        }
        return roots;
    }
    std::vector<uint8_t> isChild(model.nodes.size(), 0);
    for (const auto& n : model.nodes)
        for (int c : n.children) isChild[size_t(c)] = 1;
    for (size_t i = 0; i < model.nodes.size(); ++i)
        if (!isChild[i]) roots.push_back(int(i));
    result.warnings.push_back(
        file + (roots.empty() ? ": the file contains no nodes" : ": no scenes; loading all " + std::to_string(roots.size()) + " root nodes"));
    return roots;
}

sg::Camera Converter::camera(int ci) const {
    const tinygltf::Camera& c = m.cameras[size_t(ci)];
    sg::Camera cam;
    if (c.type == "perspective") {
        cam.projection.type = sg::ProjectionType::Perspective;
        const sg::Param<sg::Projection>& fovy = *sg::findParam<sg::Projection>("fovy");
        cam.projection.fovyDeg = std::clamp(sg::degrees(float(c.perspective.yfov)), float(fovy.min), float(fovy.max));
        // The author's framing: a narrower viewport widens the vertical field to keep it whole.
        if (c.perspective.aspectRatio > 0 && std::isfinite(c.perspective.aspectRatio))
            cam.projection.aspectRatio = std::clamp(float(c.perspective.aspectRatio), 0.01f, 100.0f);
        cam.projection.zNear = std::max(float(c.perspective.znear), float(sg::findParam<sg::Projection>("near")->min));
        cam.projection.zFar = c.perspective.zfar > 0 ? float(c.perspective.zfar) : std::max(1000.0f * cam.projection.zNear, 100.0f);
    } else {
        cam.projection.type = sg::ProjectionType::Orthographic;
        cam.projection.orthoHalfHeight = std::abs(float(c.orthographic.ymag));
        cam.projection.zNear = float(c.orthographic.znear);
        cam.projection.zFar = float(c.orthographic.zfar);
    }
    return cam;
}

sg::Light Converter::light(int li) const {
    const tinygltf::Light& l = m.lights[size_t(li)];
    sg::Light o;
    o.type = l.type == "directional" ? sg::LightType::Directional : l.type == "spot" ? sg::LightType::Spot : sg::LightType::Point;
    if (l.color.size() == 3) o.color = glm::max(sg::vec3(float(l.color[0]), float(l.color[1]), float(l.color[2])), sg::vec3(0.0f));
    o.intensity = float(std::min(l.intensity, 1e6));
    o.inverseSquare = o.type != sg::LightType::Directional;
    if (o.type != sg::LightType::Directional && std::isfinite(l.range) && l.range > 0) o.range = float(std::min(l.range, 1e9));
    if (o.type == sg::LightType::Spot) {
        o.spotOuterDeg = sg::degrees(float(l.spot.outerConeAngle));
        o.spotInnerDeg = std::min(sg::degrees(float(l.spot.innerConeAngle)), o.spotOuterDeg);
    }
    return o;
}

// A node's skin (the index is the same in our Scene::skins) and its own morph weights.
void Converter::setSkinAndWeights(const tinygltf::Node& n, sg::MeshInstance& inst) {
    const sg::Mesh& mesh = *scene.meshes[size_t(inst.mesh)];
    if (n.skin >= 0 && mesh.skinned()) {
        inst.skin = n.skin;
        const size_t joints = m.skins[size_t(n.skin)].joints.size();
        uint16_t most = 0;
        for (const auto* set : {&mesh.joints0, &mesh.joints1})
            for (const sg::u16vec4& j : *set) most = std::max({most, j.x, j.y, j.z, j.w});
        if (most >= joints)
            warnOnce("mesh '" + mesh.name + "' names joint " + std::to_string(most) + " of skin " + std::to_string(n.skin) + ", which has " +
                     std::to_string(joints) + " joints; those influences are ignored");
    }
    for (double w : n.weights) inst.weights.push_back(std::isfinite(w) ? float(w) : 0.0f);
}

std::string Converter::buildNodes(const std::vector<int>& roots) {
    sgOf.assign(m.nodes.size(), sg::kNoNode);
    instancesOf.assign(m.nodes.size(), {});
    scene.reserveNodes(std::min<size_t>(m.nodes.size(), kMaxNodes) + 8);   // one node each at least, and the default camera and light
    std::vector<std::pair<int, sg::NodeId>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, scene.root()});
    size_t done = 0, created = 0;
    while (!stack.empty()) {
        auto [gi, parent] = stack.back();
        stack.pop_back();
        if ((++done & 4095) == 0) {
            if (progress.cancelled()) return "cancelled";
            progress.set(0.5f + 0.4f * float(done) / float(std::max<size_t>(m.nodes.size(), 1)));
        }
        const tinygltf::Node& n = m.nodes[size_t(gi)];
        std::string name = n.name.empty() ? "node " + std::to_string(gi) : n.name;
        const std::vector<std::pair<int, int>>* prims = nullptr;
        if (n.mesh >= 0) {
            std::string e = meshPrimitives(size_t(n.mesh), prims);
            if (!e.empty()) return e;
        }
        int li = nodeLight(n);
        size_t payloads = (prims ? prims->size() : 0) + (n.camera >= 0) + (li >= 0);
        if (++created + payloads > kMaxNodes) return "node budget of " + std::to_string(kMaxNodes) + " exceeded";
        sg::NodeId id = scene.addNode(name, parent);
        scene.setLocal(id, localOf(n));
        sgOf[size_t(gi)] = id;
        bool onNode = payloads == 1;
        if (prims) {
            for (size_t k = 0; k < prims->size(); ++k) {
                sg::MeshInstance inst{(*prims)[k].first, (*prims)[k].second};
                setSkinAndWeights(n, inst);
                if (onNode)
                    scene.setPayload(id, inst);
                else
                    scene.addNode(name + "#" + std::to_string(k), id, inst), ++created;
                instancesOf[size_t(gi)].push_back(onNode ? id : scene.node(id).children.back());
            }
        }
        if (n.camera >= 0) {
            sg::NodeId cid = onNode ? id : scene.addNode(name + " camera", id);
            scene.setPayload(cid, camera(n.camera));
            if (!scene.valid(scene.activeCamera)) scene.activeCamera = cid;
        }
        if (li >= 0) {
            sg::NodeId lid = onNode ? id : scene.addNode(name + " light", id);
            scene.setPayload(lid, light(li));
        }
        for (auto it = n.children.rbegin(); it != n.children.rend(); ++it) stack.push_back({*it, id});
    }
    return {};
}

}   // namespace assets::detail::gltf
