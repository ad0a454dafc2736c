// draw_list.h - one draw preparation for both rasterizers (GL and the CPU rasterizer).
//
// A frame's triangle meshes and its analytic shapes (implicit primitives, quadrics, CSG,
// parametric surfaces, density grids: tessellated by renderers/tessellate.h at the resolved
// tessellation level) become one list of draws with the same transform, normal matrix,
// winding (mirrored), material, texture and per-triangle materials, so both backends draw
// exactly the same triangles with the same materials. The ray caster intersects analytic
// shapes exactly and does not use this.
#pragma once

#include "renderers/renderer.h"
#include "renderers/tessellate.h"
#include "scenegraph/frame.h"

#include <memory>
#include <vector>

namespace rnd {

struct PreparedDraw {
    std::shared_ptr<const sg::Mesh> mesh;   // never null, never empty
    const sg::mat4* world = nullptr;        // object -> world (identity for world-space CSG meshes)
    sg::mat3 normal{1.0f};                  // inverse transpose of world's 3x3
    bool mirrored = false;                  // det(world) < 0: front faces wind clockwise
    const sg::Material* material = nullptr;
    sg::TexturePtr texture;   // null when none, and for per-triangle materials
    sg::MaterialMaps maps;    // the material's other textures (meshes only)
    // Per-triangle material indices into *materials (CSG faces take their leaf's material),
    // both null when the whole mesh uses *material.
    const std::vector<uint16_t>* triangleMaterial = nullptr;
    const std::vector<sg::Material>* materials = nullptr;
    sg::NodeId node = sg::kNoNode;
    bool analytic = false;   // from frame.analytics (tessellated)
    uint32_t drawable = 0;   // Framebuffer::drawable of its pixels: meshes[k-1], or analytics[k-1-M]
};

// Meshes first (in frame.meshes order), then analytic shapes (in frame.analytics order).
// Pointers refer into `frame` and `cache`: valid until either changes (cache.nextFrame()).
// control: shapes not in the cache at this level are tessellated as the render's Shapes stage
// (control->progress counts their work, then the stage goes back to Image at 0); when
// control->cancel is set meanwhile the list is incomplete and the caller must give up.
std::vector<PreparedDraw> prepareDraws(const sg::FrameInput& frame, int tessellation, TessellationCache& cache, RenderControl* control = nullptr);
// The meshes only (no tessellation); pointers refer into `frame`.
std::vector<PreparedDraw> prepareMeshDraws(const sg::FrameInput& frame);

}   // namespace rnd
