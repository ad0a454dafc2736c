// lane_shading.h - the ray caster's smooth Phong / Blinn-Phong shading of eight mesh hits at once
// (AVX2 lanes, or SSE2's four twice), for the commonest primary hit: an opaque, lit, untextured
// triangle seen in a frame without pbr, reflections or lights with a size under shadows (a
// colour texture, sampled per lane by the caller, is fine; the other material maps are not).
// Every lane performs the IEEE operations of Tracer::shadeMeshHit and rnd::shadeTerms in their order (no FMA, no
// reciprocal for a division, libm's powf per lane), so a pixel shaded here has the bytes of one
// shaded by Tracer::trace; RaycastTest checks that byte for byte, and VIEWER_RAYCAST_LANES=0
// turns the lanes off.
//
// What the lanes do not compute comes in per lane, made by Tracer's own functions: the hit's frame
// (meshHitFrame), the vertex normals and albedos, and the hard shadows of the tile's shadow packets.
#pragma once

#include "raycast/bvh.h"
#include "renderers/shading.h"
#include "scenegraph/frame.h"

#include <cstdint>

namespace rnd::raycast {

struct LaneBatch {
    static constexpr int kLanes = 8;
    int count = 0;   // lanes filled, from 0
    // Per lane: the hit point p and geometric normal ng toward the ray (meshHitFrame), the
    // barycentric weights w, the texel tex, the three vertex normals facing the ray (smooth: a vertex normal
    // per vertex; otherwise the shading normal is ng) and vertex albedos, the coefficients.
    alignas(32) float p[3][kLanes], ng[3][kLanes];
    alignas(32) float w[3][kLanes];
    alignas(32) float vn[3][3][kLanes];   // [vertex][axis][lane]
    alignas(32) float va[3][3][kLanes];   // [vertex][channel][lane]
    alignas(32) float tex[3][kLanes];     // the colour texture's texel, in the lanes of `textured`
    unsigned textured = 0;                // bit l: lane l has a texel (the others' texColor is 1)
    bool smooth[kLanes] = {};
    const SurfaceCoefficients* coeff[kLanes] = {};
    // With shadows: the light bits of the tile's shadow packets (Tracer::PresetVisibility) for
    // this p and ng: known (traced) and lit.
    uint64_t known[kLanes] = {}, lit[kLanes] = {};
};

// Whether a frame's hits may be shaded in lanes at all (the per-mesh conditions are the caller's):
// smooth shading, Phong or Blinn-Phong, at most 64 lights, and under shadows every light's shadow
// ray a hard one from the shadow packets (shadowPackets).
bool laneShadingApplies(const sg::FrameInput& f, bool shadowPackets);

// Shades lanes [0, b.count): their linear colours (rnd::shade's) into rgb[channel][lane]. Returns
// the lanes it shaded as bits; a lane it leaves (a light that reaches the shading normal but not
// the geometric one, so that no packet traced its shadow ray) is for Tracer::trace. The lanes
// past b.count are filled with lane 0's inputs first.
unsigned shadeLanes(LaneBatch& b, const sg::FrameInput& f, float rgb[3][LaneBatch::kLanes]);

// The bytes encodePixel (raycast_renderer.cpp) gives lanes [0, count) of linear colours
// rgb[channel][lane] under an identity display transform, as RGBA words: toByteSRGB of each
// channel (SrgbEncoder's packed table, one gathered word per channel), alpha 255, and magenta
// (255, 0, 255) where a channel is not finite.
void encodeLanes(const float rgb[3][LaneBatch::kLanes], int count, uint32_t out[LaneBatch::kLanes]);

// The frames of up to eight triangle hits (tracer.h's meshHitFrame in lanes): in, each hit's
// world vertices, barycentrics b1 b2 and ray direction, and whether its instance is mirrored;
// out, the point p, the outward geometric normal gn, that normal on the ray's side ng, and
// whether the ray sees the back.
struct FrameLanes {
    static constexpr int kLanes = 8;
    int count = 0;
    alignas(32) float P[3][3][kLanes];   // [vertex][axis][lane]
    alignas(32) float b1[kLanes], b2[kLanes], dir[3][kLanes];
    unsigned mirrored = 0;   // bit l: lane l
    alignas(32) float p[3][kLanes], gn[3][kLanes], ng[3][kLanes];
    unsigned back = 0;   // bit l: lane l
};
void hitFrames(FrameLanes& b);

// Tracer::shadowRay toward light L (sampleLight's sample) from up to eight points p with
// geometric normals ng, where the light reaches ng's side (sampleReaches, the Phong models'
// rule): out, those lanes as bits (reaches) and their rays.
struct ShadowLanes {
    static constexpr int kLanes = 8;
    int count = 0;
    alignas(32) float p[3][kLanes], ng[3][kLanes];
    unsigned reaches = 0;
    rt::PacketScratch<rt::Ray, kLanes> rays;   // (uninitialized: written where reached)
};
void shadowRays(ShadowLanes& b, const sg::DrawLight& L);

}   // namespace rnd::raycast
