// animation.cpp - glTF animations -> assets::AnimationClip: node translation / rotation / scale
// and morph weights channels (LINEAR, STEP, CUBICSPLINE) with checked keyframes; a channel
// that cannot be used is skipped with a warning.
#include "gltf_internal.h"

#include <cmath>
#include <limits>

namespace assets::detail::gltf {

// The morph target count of a node's mesh (its first primitive; glTF requires all
// primitives of a mesh to have the same number), 0 without a mesh.
size_t Converter::targetCount(int node) const {
    int mi = m.nodes[size_t(node)].mesh;
    if (mi < 0 || m.meshes[size_t(mi)].primitives.empty()) return 0;
    return m.meshes[size_t(mi)].primitives[0].targets.size();
}

// Path, target node and interpolation of channel `ci` into `out`; "" or why it is skipped.
std::string Converter::channelTarget(const tinygltf::Animation& ga, size_t ci, AnimationChannel& out) const {
    const auto& ch = ga.channels[ci];
    if (ch.target_path == "translation")
        out.path = AnimationPath::Translation;
    else if (ch.target_path == "rotation")
        out.path = AnimationPath::Rotation;
    else if (ch.target_path == "scale")
        out.path = AnimationPath::Scale;
    else if (ch.target_path == "weights")
        out.path = AnimationPath::Weights;
    else
        return "'" + ch.target_path + "' animation is not supported";
    if (ch.sampler < 0 || size_t(ch.sampler) >= ga.samplers.size()) return "sampler does not exist";
    if (ch.target_node < 0 || size_t(ch.target_node) >= m.nodes.size()) return "target node does not exist";
    const auto& s = ga.samplers[size_t(ch.sampler)];
    if (s.interpolation == "STEP")
        out.interpolation = AnimationInterpolation::Step;
    else if (s.interpolation == "CUBICSPLINE")
        out.interpolation = AnimationInterpolation::CubicSpline;
    else if (s.interpolation == "LINEAR" || s.interpolation.empty())
        out.interpolation = AnimationInterpolation::Linear;
    else
        return "unknown interpolation '" + s.interpolation + "'";
    if (out.path == AnimationPath::Weights && (out.width = targetCount(ch.target_node)) == 0) return "weights of a node without morph targets";
    return {};
}

// Key times and values of the channel's sampler (types and counts checked, times finite and
// increasing, values finite); "" or why the channel is skipped.
std::string Converter::readKeys(const tinygltf::AnimationSampler& s, AnimationChannel& out) {
    if (s.input < 0 || size_t(s.input) >= m.accessors.size() || s.output < 0 || size_t(s.output) >= m.accessors.size())
        return "sampler accessors do not exist";
    const auto& in = m.accessors[size_t(s.input)];
    const auto& op = m.accessors[size_t(s.output)];
    const bool weights = out.path == AnimationPath::Weights;
    int want = weights ? TINYGLTF_TYPE_SCALAR : out.path == AnimationPath::Rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3;
    uint64_t perKey = (out.interpolation == AnimationInterpolation::CubicSpline ? 3 : 1) * (weights ? out.width : 1);
    if (in.type != TINYGLTF_TYPE_SCALAR || in.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || op.type != want || in.count == 0 ||
        op.count != in.count * perKey)
        return "sampler input/output accessors have the wrong type or count";
    std::vector<sg::vec4> t4, v4;
    if (!readVectors(m, size_t(s.input), 1, progress, t4).empty() || !readVectors(m, size_t(s.output), weights ? 1 : 4, progress, v4).empty())
        return "cannot read keyframes";
    out.times.resize(t4.size());
    bool ok = true;
    for (size_t k = 0; k < t4.size(); ++k) {
        out.times[k] = t4[k].x;
        if (!std::isfinite(out.times[k]) || (k > 0 && out.times[k] <= out.times[k - 1])) ok = false;
    }
    for (const auto& v : v4)
        if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z) || !std::isfinite(v.w)) ok = false;
    if (!ok) return "key times must be finite and increasing, values finite";
    if (weights)
        for (const auto& v : v4) out.weights.push_back(v.x);
    else
        out.values = std::move(v4);
    return {};
}

std::vector<AnimationClip> Converter::animations() {
    std::vector<AnimationClip> clips;
    for (size_t ai = 0; ai < m.animations.size(); ++ai) {
        const tinygltf::Animation& ga = m.animations[ai];
        AnimationClip clip;
        clip.name = ga.name.empty() ? "animation " + std::to_string(ai) : ga.name;
        float tmin = std::numeric_limits<float>::infinity(), tmax = 0.0f;
        for (size_t ci = 0; ci < ga.channels.size(); ++ci) {
            std::string id = "animation " + std::to_string(ai) + " channel " + std::to_string(ci) + ": ";
            AnimationChannel out;
            std::string why = channelTarget(ga, ci, out);
            if (why.empty()) {
                out.node = sgOf[size_t(ga.channels[ci].target_node)];
                if (out.node == sg::kNoNode) continue;   // node not in the loaded scene
                why = readKeys(ga.samplers[size_t(ga.channels[ci].sampler)], out);
            }
            if (!why.empty()) {
                warnOnce(id + why + "; channel skipped");
                continue;
            }
            tmin = std::min(tmin, out.times.front());
            tmax = std::max(tmax, out.times.back());
            if (out.path != AnimationPath::Weights) {
                clip.channels.push_back(std::move(out));
                continue;
            }
            // Morph weights go to every MeshInstance of the node (one per primitive).
            for (sg::NodeId inst : instancesOf[size_t(ga.channels[ci].target_node)]) {
                clip.channels.push_back(out);
                clip.channels.back().node = inst;
            }
        }
        if (clip.channels.empty()) continue;
        clip.start = std::isfinite(tmin) ? tmin : 0.0f;
        clip.duration = tmax;
        clips.push_back(std::move(clip));
    }
    return clips;
}

}   // namespace assets::detail::gltf
