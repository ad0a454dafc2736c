// animation.cpp - evaluation of AnimationClip (see animation.h).
#include "assets/animation.h"

#include <algorithm>

namespace assets {

namespace {
sg::quat toQuat(const sg::vec4& v) { return sg::quat(v.w, v.x, v.y, v.z); }
sg::vec4 fromQuat(const sg::quat& q) { return sg::vec4(q.x, q.y, q.z, q.w); }
sg::vec4 normalizeRot(const sg::vec4& v) {
    float l = glm::length(v);
    return l > 1e-20f ? v / l : sg::vec4(0, 0, 0, 1);
}

// Where t falls among the key times: before the first key or at/after the last (k = that key,
// u = 0), else between keys k and k + 1 (times[k] <= t < times[k+1]) at fraction u, with
// dt = times[k+1] - times[k]. Returns true in the middle case. NaN counts as before.
bool locateKey(const std::vector<float>& times, float t, size_t& k, float& u, float& dt) {
    const size_t n = times.size();
    u = 0.0f;
    dt = 0.0f;
    if (!(t > times.front())) {
        k = 0;
        return false;
    }
    if (t >= times.back()) {
        k = n - 1;
        return false;
    }
    k = size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
    dt = times[k + 1] - times[k];
    u = dt > 0.0f ? (t - times[k]) / dt : 0.0f;
    return true;
}

// glTF's cubic Hermite spline between p0 and p1 with tangents already scaled by dt.
template <class T>
T hermite(const T& p0, const T& m0, const T& p1, const T& m1, float u) {
    float u2 = u * u, u3 = u2 * u;
    return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1;
}

}   // namespace

std::vector<float> sampleWeights(const AnimationChannel& ch, float t) {
    const size_t n = ch.times.size(), w = ch.width;
    const bool cubic = ch.interpolation == AnimationInterpolation::CubicSpline;
    const size_t per = cubic ? 3 * w : w;
    if (n == 0 || w == 0 || ch.weights.size() != n * per) return {};
    // Key k's value i (cubic: the middle block), in-tangent and out-tangent.
    auto value = [&](size_t k, size_t i) { return ch.weights[k * per + (cubic ? w : 0) + i]; };
    auto inTangent = [&](size_t k, size_t i) { return ch.weights[k * per + i]; };
    auto outTangent = [&](size_t k, size_t i) { return ch.weights[k * per + 2 * w + i]; };
    std::vector<float> out(w);
    size_t k = 0;
    float u = 0.0f, dt = 0.0f;
    const bool between = locateKey(ch.times, t, k, u, dt);
    for (size_t i = 0; i < w; ++i) {
        if (!between || ch.interpolation == AnimationInterpolation::Step)
            out[i] = value(k, i);
        else if (ch.interpolation == AnimationInterpolation::Linear)
            out[i] = glm::mix(value(k, i), value(k + 1, i), u);
        else
            out[i] = hermite(value(k, i), outTangent(k, i) * dt, value(k + 1, i), inTangent(k + 1, i) * dt, u);
    }
    return out;
}

sg::vec4 sampleChannel(const AnimationChannel& ch, float t) {
    const size_t n = ch.times.size();
    const bool cubic = ch.interpolation == AnimationInterpolation::CubicSpline;
    const bool rot = ch.path == AnimationPath::Rotation;
    auto value = [&](size_t k) { return cubic ? ch.values[3 * k + 1] : ch.values[k]; };
    if (n == 0 || ch.values.size() < (cubic ? 3 * n : n)) return rot ? sg::vec4(0, 0, 0, 1) : sg::vec4(0);
    size_t k = 0;
    float u = 0.0f, dt = 0.0f;
    if (!locateKey(ch.times, t, k, u, dt)) return rot ? normalizeRot(value(k)) : value(k);   // clamped (also NaN)
    switch (ch.interpolation) {
    case AnimationInterpolation::Step: return rot ? normalizeRot(value(k)) : value(k);
    case AnimationInterpolation::Linear:
        if (rot) return fromQuat(glm::normalize(glm::slerp(toQuat(normalizeRot(value(k))), toQuat(normalizeRot(value(k + 1))), u)));
        return glm::mix(value(k), value(k + 1), u);
    case AnimationInterpolation::CubicSpline: {
        sg::vec4 v = hermite(ch.values[3 * k + 1], ch.values[3 * k + 2] * dt, ch.values[3 * (k + 1) + 1], ch.values[3 * (k + 1)] * dt, u);
        return rot ? normalizeRot(v) : v;
    }
    }
    return value(k);
}

namespace {
// A Weights channel: the morph weights of the node's MeshInstance (only written when they change).
void applyWeights(sg::Scene& scene, const AnimationChannel& ch, float t) {
    const auto* mi = std::get_if<sg::MeshInstance>(&scene.node(ch.node).payload);
    if (!mi) return;
    std::vector<float> w = sampleWeights(ch, t);
    if (w.empty() || w == mi->weights) return;
    std::get<sg::MeshInstance>(scene.editPayload(ch.node)).weights = std::move(w);
}
}   // namespace

void applyAnimation(sg::Scene& scene, const AnimationClip& clip, float t) {
    for (const AnimationChannel& ch : clip.channels) {
        if (!scene.valid(ch.node)) continue;
        if (ch.path == AnimationPath::Weights) {
            applyWeights(scene, ch, t);
            continue;
        }
        sg::LocalTransform local = scene.node(ch.node).local;
        if (local.mode == sg::LocalTransform::Mode::Matrix && !local.tryMakeTRS()) continue;
        sg::vec4 v = sampleChannel(ch, t);
        switch (ch.path) {
        case AnimationPath::Translation: local.translation = sg::vec3(v); break;
        case AnimationPath::Rotation: local.rotation = toQuat(v); break;
        case AnimationPath::Scale: local.scale = sg::vec3(v); break;
        case AnimationPath::Weights: break;
        }
        scene.setLocal(ch.node, local);
    }
}

}   // namespace assets
