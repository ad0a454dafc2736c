// debug_switches.h - the environment variables that change how a backend works, for
// benchmarks, debugging and tests of the code paths only; read here and nowhere else in
// renderers/. None changes what an image should be: each forces one of two paths that the tests
// hold to the same pixels (or times a stage).
//
//   VIEWER_GL_PLATFORM=egl|glfw|auto      headless GL: EGL surfaceless, a hidden GLFW window, or
//                                         EGL then GLFW (default auto)
//   VIEWER_RASTER_TIMING=1                the CPU rasterizer prints its per-stage times per frame
//   VIEWER_RASTER_REFERENCE_SHADING=1     the CPU rasterizer shades every fragment with rnd::shade
//                                         (slow; checks the batched path)
//   VIEWER_RASTER_SSE=1                   the CPU rasterizer's SSE2 kernels even where AVX2 runs
//                                         (its shadow depth pass's too)
//   VIEWER_RASTER_SHADOW_REUSE=0          the CPU rasterizer draws its shadow maps every frame,
//                                         also when the plan and the casters are the last frame's
//   VIEWER_GL_SHADOW_REUSE=0              the GL backend draws its shadow maps every frame (as
//                                         VIEWER_RASTER_SHADOW_REUSE=0)
//   VIEWER_RAYCAST_SSE=1                  the ray caster's BVH4/SSE traversal even where AVX2 runs
//   VIEWER_RAYCAST_AVX2=1                 the ray caster's AVX2 packet kernel even where AVX-512
//                                         runs (each ray alone at a leaf, not 16 per triangle test)
//   VIEWER_RAYCAST_PACKETS=0              the ray caster traces camera rays one by one (no packets)
//   VIEWER_RAYCAST_SHADOW_PACKETS=0       the ray caster traces shadow rays one by one (camera rays
//                                         still in packets)
//   VIEWER_RAYCAST_PACKET_CULL=0          the ray caster traces every camera packet, also those
//                                         whose region misses every box of the scene
//   VIEWER_RAYCAST_WORLD_VERTICES=0       the ray caster transforms a hit's vertices per hit
//                                         instead of keeping world-space copies (WorldVertexCache)
//   VIEWER_RAYCAST_LANES=0                the ray caster shades every hit one by one (Tracer::trace)
//                                         instead of four plain Phong hits at a time (lane_shading.h)
#pragma once

#include <string>

namespace rnd {

struct DebugSwitches {
    std::string glPlatform = "auto";
    bool rasterTiming = false;
    bool rasterReferenceShading = false;
    bool rasterForceSse = false;
    bool rasterShadowReuse = true;
    bool glShadowReuse = true;
    bool raycastForceSse = false;
    bool raycastForceAvx2 = false;
    bool raycastPackets = true;
    bool raycastShadowPackets = true;
    bool raycastPacketCull = true;
    bool raycastWorldVertices = true;
    bool raycastLanes = true;
};

// The switches as the environment sets them now (a few getenv calls: backends ask when they
// are made or start a frame; the kernel choices are fixed at the first ask).
DebugSwitches debugSwitches();

}   // namespace rnd
