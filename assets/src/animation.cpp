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
}   // namespace

sg::vec4 sampleChannel(const AnimationChannel& ch, float t) {
    const size_t n = ch.times.size();
    const bool cubic = ch.interpolation == AnimationInterpolation::CubicSpline;
    const bool rot = ch.path == AnimationPath::Rotation;
    auto value = [&](size_t k) { return cubic ? ch.values[3 * k + 1] : ch.values[k]; };
    if (n == 0 || ch.values.size() < (cubic ? 3 * n : n)) return rot ? sg::vec4(0, 0, 0, 1) : sg::vec4(0);
    if (!(t > ch.times.front())) return rot ? normalizeRot(value(0)) : value(0);   // also NaN
    if (t >= ch.times.back()) return rot ? normalizeRot(value(n - 1)) : value(n - 1);
    // Key k with times[k] <= t < times[k+1].
    size_t k = size_t(std::upper_bound(ch.times.begin(), ch.times.end(), t) - ch.times.begin()) - 1;
    float t0 = ch.times[k], t1 = ch.times[k + 1];
    float dt = t1 - t0;
    float u = dt > 0.0f ? (t - t0) / dt : 0.0f;
    switch (ch.interpolation) {
    case AnimationInterpolation::Step: return rot ? normalizeRot(value(k)) : value(k);
    case AnimationInterpolation::Linear:
        if (rot) return fromQuat(glm::normalize(glm::slerp(toQuat(normalizeRot(value(k))), toQuat(normalizeRot(value(k + 1))), u)));
        return glm::mix(value(k), value(k + 1), u);
    case AnimationInterpolation::CubicSpline: {
        sg::vec4 p0 = ch.values[3 * k + 1], m0 = ch.values[3 * k + 2] * dt;
        sg::vec4 p1 = ch.values[3 * (k + 1) + 1], m1 = ch.values[3 * (k + 1)] * dt;
        float u2 = u * u, u3 = u2 * u;
        sg::vec4 v = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1;
        return rot ? normalizeRot(v) : v;
    }
    }
    return value(k);
}

void applyAnimation(sg::Scene& scene, const AnimationClip& clip, float t) {
    for (const AnimationChannel& ch : clip.channels) {
        if (!scene.valid(ch.node)) continue;
        sg::LocalTransform local = scene.node(ch.node).local;
        if (local.mode == sg::LocalTransform::Mode::Matrix && !local.tryMakeTRS()) continue;
        sg::vec4 v = sampleChannel(ch, t);
        switch (ch.path) {
        case AnimationPath::Translation: local.translation = sg::vec3(v); break;
        case AnimationPath::Rotation: local.rotation = toQuat(v); break;
        case AnimationPath::Scale: local.scale = sg::vec3(v); break;
        }
        scene.setLocal(ch.node, local);
    }
}

}   // namespace assets
