// gl_context.h - headless OpenGL contexts for the "gl" backend, tests and tools.
//
// A GlContext is an OpenGL 3.3+ core context with no window of its own: render into FBOs.
// Platforms, tried in this order by "auto":
//   * "egl":  EGL surfaceless on Mesa (EGL_PLATFORM_SURFACELESS_MESA through
//             eglGetPlatformDisplayEXT); needs no X server (llvmpipe without a GPU);
//   * "glfw": a hidden GLFW window (needs an X server, e.g. Xvfb).
// The environment variable VIEWER_GL_PLATFORM (auto, egl, glfw) overrides the default choice.
// No GL/EGL/GLFW types appear here: the implementation keeps them in gl_context.cpp.
#pragma once

#include <memory>
#include <string>
#include <string_view>

namespace rnd::gl {

class GlContext {
public:
    virtual ~GlContext() = default;
    // Makes the context current on the calling thread; false (with *error) on failure.
    virtual bool makeCurrent(std::string* error = nullptr) = 0;
    // Releases the context from the calling thread (no context current afterwards).
    virtual void release() = 0;
    virtual bool isCurrent() const = 0;
    // "egl-surfaceless" or "glfw-hidden".
    virtual std::string platform() const = 0;
};

// Creates a headless context on `platform` ("auto", "egl", "glfw"; empty = VIEWER_GL_PLATFORM
// or "auto"). On failure returns null and sets *error to one line naming every platform tried
// and why it failed. The new context is NOT left current.
std::unique_ptr<GlContext> createHeadlessContext(const std::string& platform = "", std::string* error = nullptr);

// Whether some OpenGL context (ours, a GLFW window's, any EGL or GLX one) is current on the
// calling thread.
bool anyContextCurrent();
// An opaque identity of the context current on this thread (null when none): GL objects are
// only valid in the context that made them.
const void* currentContextHandle();

// Loads the GL entry points (glad) for the context current on this thread and checks that it
// is OpenGL 3.3 core or newer. Returns "" or the reason.
std::string loadGLFunctions();

// "OpenGL 4.5 (Core Profile) Mesa ..., llvmpipe" of the current context (after loading).
std::string describeCurrentContext();

// What the OpenGL that createHeadlessContext("") would give runs on, found without rendering;
// probed once per process (thread-safe), for choosing a default backend.
//   1. When the platform is auto or egl and Mesa's EGL lists its devices (EGL_EXT_device_
//      enumeration) and every one is its software device (EGL_MESA_device_software: no GPU
//      render node), GL here is software. This loads libEGL only (~4 MB, a few ms); making a
//      context would load llvmpipe and LLVM (~60 MB resident, ~50 ms).
//   2. Otherwise makes a headless context and reads its GL_RENDERER (rnd::isSoftwareGLRenderer).
struct HeadlessGl {
    bool usable = false;     // a context can be made (step 1 does not try: true there)
    bool software = false;   // usable, and emulated on the CPU
    std::string renderer;    // GL_RENDERER (step 2), or "Mesa's software device, no GPU" (step 1)
    std::string error;       // why not usable
};
HeadlessGl probeHeadlessGl();

// The driver's limits the backend's Capabilities state (MSAA samples, largest image side), read
// once per process from the context current on this thread (the window's) or from a headless
// context made for it; 0 where no context can be made (then nothing is known to be limited).
struct GlLimits {
    int maxSamples = 0;
    int maxSize = 0;
};
GlLimits glLimits();

}   // namespace rnd::gl
