// debug_switches.cpp - reads the environment variables of debug_switches.h.
#include "renderers/debug_switches.h"

#include <cstdlib>

namespace rnd {

namespace {
bool is(const char* name, char value) {
    const char* e = std::getenv(name);
    return e && e[0] == value;
}
}   // namespace

DebugSwitches debugSwitches() {
    DebugSwitches d;
    if (const char* e = std::getenv("VIEWER_GL_PLATFORM"); e && *e) d.glPlatform = e;
    d.rasterTiming = is("VIEWER_RASTER_TIMING", '1');
    d.rasterReferenceShading = is("VIEWER_RASTER_REFERENCE_SHADING", '1');
    d.rasterForceSse = is("VIEWER_RASTER_SSE", '1');
    d.rasterShadowReuse = !is("VIEWER_RASTER_SHADOW_REUSE", '0');
    d.glShadowReuse = !is("VIEWER_GL_SHADOW_REUSE", '0');
    d.raycastForceSse = is("VIEWER_RAYCAST_SSE", '1');
    d.raycastForceAvx2 = is("VIEWER_RAYCAST_AVX2", '1');
    d.raycastPackets = !is("VIEWER_RAYCAST_PACKETS", '0');
    d.raycastShadowPackets = !is("VIEWER_RAYCAST_SHADOW_PACKETS", '0');
    d.raycastPacketCull = !is("VIEWER_RAYCAST_PACKET_CULL", '0');
    d.raycastWorldVertices = !is("VIEWER_RAYCAST_WORLD_VERTICES", '0');
    d.raycastLanes = !is("VIEWER_RAYCAST_LANES", '0');
    return d;
}

}   // namespace rnd
