// min_embree.h - the minimal Embree 3 renderer that bench_raycast_frame holds our ray caster's
// whole frame to: the frame's triangles (meshes, and analytic shapes as their tessellation) in
// world space in one Embree scene (or, for comparison, instanced: two levels as ours); camera
// rays as 4x4 packets (rtcIntersect16, coherent context), one shadow ray per light a packet at a
// time (rtcOccluded16), the Phong / Blinn-Phong model of renderers/common/shading.cpp for plain
// materials (ka, kd, ks, shininess, specular colour, base colour texture filtered with the
// pixel's footprint as ours: rnd::SampledTexture),
// fog, sRGB bytes; 16x16-pixel tiles over oneTBB. No reflections, alpha, pbr or material maps:
// scenes that use them are not its work.
#pragma once

#include "scenegraph/frame.h"

#include <memory>
#include <string>
#include <vector>

namespace bench {

class MinimalEmbree {
public:
    MinimalEmbree();
    ~MinimalEmbree();
    MinimalEmbree(const MinimalEmbree&) = delete;
    MinimalEmbree& operator=(const MinimalEmbree&) = delete;
    // Builds the Embree scene of the frame's triangles (analytic shapes tessellated at
    // `tessellation`, as the rasterizers draw them) on a device with `config` (e.g. "isa=avx2").
    // instanced: two levels, as our ray caster keeps them (each mesh's triangles once, in its
    // object space, in a scene of their own; each draw an Embree instance of it with its world
    // matrix) instead of every draw's triangles copied into world space. The shading reads the
    // same world-space copies either way. Returns "" or why it failed.
    // nearestTextures: colour textures at level 0, nearest texel (the reference as first written)
    // instead of filtered as our ray caster filters them (rnd::SampledTexture::sample with the uv
    // footprint of the neighbouring pixels' rays on the hit triangle's plane).
    std::string setup(const sg::FrameInput& f, int tessellation, const std::string& config = "", bool instanced = false,
                      bool nearestTextures = false);
    // One frame of f's camera and lights: RGBA8, rows top to bottom (as rnd::Framebuffer::color).
    void render(const sg::FrameInput& f, int width, int height, std::vector<uint8_t>& rgba) const;
    size_t triangles() const;

private:
    struct State;
    std::unique_ptr<State> m;
};

}   // namespace bench
