// instances.h - instance ids of a frame for segmentation and picking: one id per scene node
// that draws something, k = 1, 2, ... in the order the node first appears among the frame's
// drawables (frame.meshes, then frame.analytics); 0 is the background. A glTF node with
// several primitives is several drawables and one instance. The ids follow from the frame
// alone, so every backend, the id export and the pixel inspector number nodes the same way.
#pragma once

#include "scenegraph/frame.h"

#include <string>
#include <vector>

namespace sg {

struct InstanceTable {
    // Drawable k (1-based as in rnd::Framebuffer::drawable: meshes[k-1], then analytics) ->
    // instance id; ofDrawable[0] = 0 (nothing drawn).
    std::vector<uint32_t> ofDrawable;
    // Instance id k -> its node; node[0] = kNoNode.
    std::vector<NodeId> node;

    uint32_t instanceOf(uint32_t drawable) const { return drawable < ofDrawable.size() ? ofDrawable[drawable] : 0u; }
    NodeId nodeOf(uint32_t drawable) const { return node[instanceOf(drawable)]; }
};
InstanceTable instanceTable(const FrameInput& frame);

// "/a/b/c": the names of the node's ancestors below the root and its own, or "" for kNoNode
// and dead ids. The root itself is "/".
std::string nodePath(const Scene& scene, NodeId id);

}   // namespace sg
