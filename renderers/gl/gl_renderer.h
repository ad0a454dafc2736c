// gl_renderer.h - factory for the "gl" backend (see renderers/renderer.h) and its GPU-cache
// counters (for tests and the UI's statistics).
//
// The backend renders with OpenGL 3.3+ core into its own FBO. When no context is current on
// the calling thread, render() makes a headless one (see gl/gl_context.h) and releases it
// afterwards; when one is current (the viewer's window) it uses it and restores the state the
// caller relies on (framebuffer bindings, viewport, program, ...).
#pragma once

#include "renderers/renderer.h"

#include <cstdint>
#include <string>

namespace rnd {

std::unique_ptr<Renderer> makeGlRenderer();

// GPU cache activity of a renderer made by makeGlRenderer() (all zero for other renderers).
// Meshes (including tessellations of analytic drawables) and textures are uploaded once per
// (id, version) and reused by every instance and frame.
struct GlCacheCounters {
    uint64_t meshUploads = 0;      // vertex/index buffers built, since the renderer was made
    uint64_t textureUploads = 0;   // textures built
    size_t meshesCached = 0;
    size_t texturesCached = 0;
    std::string context;    // "OpenGL 4.5 (Core Profile) Mesa ..., llvmpipe ..." once rendered
    std::string platform;   // "egl-surfaceless", "glfw-hidden" or "caller" (a context was current)
};
GlCacheCounters glCacheCounters(const Renderer& r);

// "#define SHADING_PHONG 2\n..." for every settings enum value the shaders see (shading and
// reflection models, fog modes, light types), with the C++ enums' values; and the shader
// sources, so a test can check that the shaders handle every one of them.
std::string glslEnumDefines();
std::string glslSources();

}   // namespace rnd
