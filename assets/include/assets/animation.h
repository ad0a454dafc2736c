// animation.h - node TRS animation clips (from glTF animations) and their evaluation.
//   A clip is a set of channels; each channel drives one node's translation, rotation or
//   scale with keyframes (times in seconds, strictly increasing) and an interpolation:
//     Step        : value of the last key at or before t
//     Linear      : lerp (translation/scale), shortest-path slerp (rotation)
//     CubicSpline : glTF's Hermite spline; values hold 3 entries per key
//                   (in-tangent, value, out-tangent), tangents scaled by the key interval.
//   t outside [first key, last key] clamps to the ends. applyAnimation() writes TRS locals
//   (a node with a Matrix local is converted to TRS first when possible, else skipped).
#pragma once

#include "scenegraph/scene.h"

#include <string>
#include <vector>

namespace assets {

enum class AnimationPath : uint8_t { Translation, Rotation, Scale };
enum class AnimationInterpolation : uint8_t { Step, Linear, CubicSpline };

struct AnimationChannel {
    sg::NodeId node = sg::kNoNode;
    AnimationPath path = AnimationPath::Translation;
    AnimationInterpolation interpolation = AnimationInterpolation::Linear;
    std::vector<float> times;
    // xyz for translation/scale, xyzw (quaternion x,y,z,w as in glTF) for rotation;
    // 3 per key for CubicSpline.
    std::vector<sg::vec4> values;
};

struct AnimationClip {
    std::string name;
    float start = 0.0f;      // earliest key time
    float duration = 0.0f;   // latest key time (seconds; glTF clips usually start at 0)
    std::vector<AnimationChannel> channels;
};

// Value of a channel at time t (xyz or xyzw as stored; rotations normalised).
sg::vec4 sampleChannel(const AnimationChannel& channel, float t);
// Applies all channels of the clip at time t to the scene's node locals.
void applyAnimation(sg::Scene& scene, const AnimationClip& clip, float t);

}   // namespace assets
