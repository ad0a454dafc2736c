// instances.cpp - instanceTable() and nodePath() (see instances.h).
#include "scenegraph/instances.h"

#include <algorithm>
#include <unordered_map>

namespace sg {

InstanceTable instanceTable(const FrameInput& frame) {
    InstanceTable t;
    t.node.push_back(kNoNode);
    t.ofDrawable.reserve(frame.meshes.size() + frame.analytics.size() + 1);
    t.ofDrawable.push_back(0);
    std::unordered_map<NodeId, uint32_t> seen;
    auto add = [&](NodeId n) {
        auto [it, fresh] = seen.emplace(n, uint32_t(t.node.size()));
        if (fresh) t.node.push_back(n);
        t.ofDrawable.push_back(it->second);
    };
    for (const DrawMesh& m : frame.meshes) add(m.node);
    for (const DrawAnalytic& a : frame.analytics) add(a.node);
    return t;
}

std::string nodePath(const Scene& scene, NodeId id) {
    if (!scene.valid(id)) return {};
    if (id == scene.root()) return "/";
    std::vector<const std::string*> names;
    for (NodeId n = id; n != kNoNode && n != scene.root() && scene.valid(n); n = scene.node(n).parent) names.push_back(&scene.node(n).name);
    std::string path;
    for (auto it = names.rbegin(); it != names.rend(); ++it) path += "/" + **it;
    return path;
}

}   // namespace sg
