// animation.h - animation clips (from glTF animations) and their evaluation.
//   A clip is a set of channels; each channel drives one node's translation, rotation or
//   scale, or the morph weights of the node's MeshInstance, with keyframes (times in seconds,
//   strictly increasing) and an interpolation:
//     Step        : value of the last key at or before t
//     Linear      : lerp (translation/scale/weights), shortest-path slerp (rotation)
//     CubicSpline : glTF's Hermite spline; values hold 3 entries per key
//                   (in-tangent, value, out-tangent), tangents scaled by the key interval.
//   t outside [first key, last key] clamps to the ends. applyAnimation() writes TRS locals
//   (a node with a Matrix local is converted to TRS first when possible, else skipped) and
//   MeshInstance::weights; skinned and morphed meshes follow when the scene is next
//   flattened (Scene::posedMesh), so posing a scene at time t is this one call, for the CLI's
//   --time and the UI's animation bar alike.
#pragma once

#include "scenegraph/scene.h"

#include <string>
#include <vector>

namespace assets {

enum class AnimationPath : uint8_t { Translation, Rotation, Scale, Weights };
enum class AnimationInterpolation : uint8_t { Step, Linear, CubicSpline };

struct AnimationChannel {
    sg::NodeId node = sg::kNoNode;
    AnimationPath path = AnimationPath::Translation;
    AnimationInterpolation interpolation = AnimationInterpolation::Linear;
    std::vector<float> times;
    // xyz for translation/scale, xyzw (quaternion x,y,z,w as in glTF) for rotation;
    // 3 per key for CubicSpline.
    std::vector<sg::vec4> values;
    // Weights: `width` floats (one per morph target) per key, in glTF's layout: per key
    // w_1..w_width, or for CubicSpline in-tangents a_1..a_width, values v_1..v_width,
    // out-tangents b_1..b_width.
    size_t width = 0;
    std::vector<float> weights;
};

struct AnimationClip {
    std::string name;
    float start = 0.0f;      // earliest key time
    float duration = 0.0f;   // latest key time (seconds; glTF clips usually start at 0)
    std::vector<AnimationChannel> channels;
};

// Value of a channel at time t (xyz or xyzw as stored; rotations normalised).
sg::vec4 sampleChannel(const AnimationChannel& channel, float t);
// Morph weights of a Weights channel at time t (`width` values; empty when the keys are
// inconsistent).
std::vector<float> sampleWeights(const AnimationChannel& channel, float t);
// Applies all channels of the clip at time t to the scene's node locals.
void applyAnimation(sg::Scene& scene, const AnimationClip& clip, float t);

}   // namespace assets
