// gl_context.cpp - headless GL contexts: EGL surfaceless (Mesa) first, hidden GLFW window
// second. The only file that talks to EGL and GLFW directly.
//
// Sections: 1. EGL display (process-wide)  2. EglContext  3. GlfwContext
//           4. createHeadlessContext  5. current-context queries and GL loading
//           6. what headless GL runs on (probeHeadlessGl)
#include "gl/gl_context.h"
#include "renderers/debug_switches.h"

#include "renderers/renderer.h"

#include <glad/egl.h>
#include <glad/gl.h>
// GLFW must not pull in a GL header of its own (glad's gl.h is already there).
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <sstream>
#include <vector>

namespace rnd::gl {

namespace {

// --- 1. EGL display -------------------------------------------------------------------------
// One surfaceless display per process, initialised on first use and never terminated
// (eglTerminate would pull the rug from under every context on it).
std::mutex g_eglMutex;
bool g_eglLibLoaded = false;   // libEGL found and its EGL 1.0 entry points loaded
EGLDisplay g_eglDisplay = EGL_NO_DISPLAY;
std::string g_eglError;   // why the display could not be made (sticky)
bool g_eglTried = false;

// Loads libEGL's entry points (without a display). Caller holds g_eglMutex.
bool loadEglLibrary() {
    if (!g_eglLibLoaded) g_eglLibLoaded = gladLoaderLoadEGL(EGL_NO_DISPLAY) != 0;
    return g_eglLibLoaded;
}

std::string eglErrorName(EGLint e) {
    switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return "EGL error " + std::to_string(e);
    }
}

EGLDisplay surfacelessDisplay(std::string& error) {
    std::lock_guard lock(g_eglMutex);
    if (g_eglTried) {
        error = g_eglError;
        return g_eglDisplay;
    }
    g_eglTried = true;
    if (!loadEglLibrary()) {
        g_eglError = "libEGL could not be loaded";
    } else {
        const char* clientExt = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
        std::string ext = clientExt ? clientExt : "";
        auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (ext.find("EGL_MESA_platform_surfaceless") == std::string::npos || !getPlatformDisplay) {
            g_eglError = "EGL has no EGL_MESA_platform_surfaceless (not Mesa?)";
        } else {
            EGLDisplay d = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
            EGLint major = 0, minor = 0;
            if (d == EGL_NO_DISPLAY) {
                g_eglError = "eglGetPlatformDisplayEXT(surfaceless) failed: " + eglErrorName(eglGetError());
            } else if (!eglInitialize(d, &major, &minor)) {
                g_eglError = "eglInitialize failed: " + eglErrorName(eglGetError());
            } else {
                // Before eglInitialize glad could only load EGL 1.0; now load the rest.
                gladLoaderLoadEGL(d);
                g_eglDisplay = d;
            }
        }
    }
    error = g_eglError;
    return g_eglDisplay;
}

// --- 2. EglContext ---------------------------------------------------------------------------
class EglContext final : public GlContext {
public:
    EglContext(EGLDisplay d, EGLContext c) : m_display(d), m_context(c) {}
    ~EglContext() override {
        if (isCurrent()) release();
        eglDestroyContext(m_display, m_context);
    }
    bool makeCurrent(std::string* error) override {
        if (eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, m_context)) return true;
        if (error) *error = "eglMakeCurrent failed: " + eglErrorName(eglGetError());
        return false;
    }
    void release() override { eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }
    bool isCurrent() const override { return eglGetCurrentContext() == m_context; }
    std::string platform() const override { return "egl-surfaceless"; }

private:
    EGLDisplay m_display;
    EGLContext m_context;
};

std::unique_ptr<GlContext> createEgl(std::string& error) {
    EGLDisplay d = surfacelessDisplay(error);
    if (d == EGL_NO_DISPLAY) return nullptr;
    if (!eglBindAPI(EGL_OPENGL_API)) {
        error = "eglBindAPI(EGL_OPENGL_API) failed: " + eglErrorName(eglGetError());
        return nullptr;
    }
    const EGLint configAttribs[] = {
        EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!eglChooseConfig(d, configAttribs, &config, 1, &count) || count < 1) {
        // Surfaceless needs no config when EGL_KHR_no_config_context is there.
        config = EGL_NO_CONFIG_KHR;
    }
    // Ask for 3.3 core: Mesa answers with the highest core version it has (4.5 on llvmpipe).
    const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION,           3,       EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                     EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext c = eglCreateContext(d, config, EGL_NO_CONTEXT, contextAttribs);
    if (c == EGL_NO_CONTEXT) {
        error = "eglCreateContext(OpenGL 3.3 core) failed: " + eglErrorName(eglGetError());
        return nullptr;
    }
    return std::make_unique<EglContext>(d, c);
}

// --- 3. GlfwContext --------------------------------------------------------------------------
// glfwInit is never undone here: the viewer's window may share the library.
class GlfwContext final : public GlContext {
public:
    explicit GlfwContext(GLFWwindow* w) : m_window(w) {}
    ~GlfwContext() override {
        if (isCurrent()) release();
        glfwDestroyWindow(m_window);
    }
    bool makeCurrent(std::string*) override {
        glfwMakeContextCurrent(m_window);
        return true;
    }
    void release() override { glfwMakeContextCurrent(nullptr); }
    bool isCurrent() const override { return glfwGetCurrentContext() == m_window; }
    std::string platform() const override { return "glfw-hidden"; }

private:
    GLFWwindow* m_window;
};

std::string glfwLastError(const char* what) {
    const char* desc = nullptr;
    int code = glfwGetError(&desc);
    std::string s = what;
    if (code != GLFW_NO_ERROR && desc) s += std::string(": ") + desc;
    return s;
}

std::unique_ptr<GlContext> createGlfw(std::string& error) {
    if (!glfwInit()) {
        error = glfwLastError("glfwInit failed");
        return nullptr;
    }
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    GLFWwindow* w = glfwCreateWindow(16, 16, "viewer-offscreen", nullptr, nullptr);
    glfwDefaultWindowHints();
    if (!w) {
        error = glfwLastError("glfwCreateWindow(hidden, OpenGL 3.3 core) failed");
        return nullptr;
    }
    return std::make_unique<GlfwContext>(w);
}

}   // namespace

// --- 4. createHeadlessContext ----------------------------------------------------------------
std::unique_ptr<GlContext> createHeadlessContext(const std::string& requested, std::string* error) {
    std::string platform = requested;
    if (platform.empty()) { platform = debugSwitches().glPlatform; }
    std::string eglError, glfwError;
    if (platform == "egl" || platform == "auto") {
        if (auto c = createEgl(eglError)) return c;
        if (platform == "egl") {
            if (error) *error = "no headless GL context: EGL surfaceless: " + eglError;
            return nullptr;
        }
    }
    if (platform == "glfw" || platform == "auto") {
        if (auto c = createGlfw(glfwError)) return c;
        if (error) {
            *error = "no headless GL context: ";
            if (platform == "auto") *error += "EGL surfaceless: " + eglError + "; ";
            *error += "hidden GLFW window: " + glfwError;
        }
        return nullptr;
    }
    if (error) *error = "unknown GL platform '" + platform + "' (VIEWER_GL_PLATFORM): expected auto, egl or glfw";
    return nullptr;
}

// --- 5. Current-context queries and GL loading ----------------------------------------------
namespace {

enum class CurrentKind { None, Egl, Glfw, Glx };

using GetCurrentFn = void* (*)();
GetCurrentFn glxGetCurrentContextFn() {
    // Only when libGLX/libGL is already in the process (someone made a GLX context).
    for (const char* lib : {"libGLX.so.0", "libGL.so.1"}) {
        if (void* h = dlopen(lib, RTLD_LAZY | RTLD_NOLOAD)) {
            void* f = dlsym(h, "glXGetCurrentContext");
            dlclose(h);
            if (f) return reinterpret_cast<GetCurrentFn>(f);
        }
    }
    return nullptr;
}

CurrentKind currentKind(const void** handle = nullptr) {
    const void* h = nullptr;
    CurrentKind kind = CurrentKind::None;
    {
        std::lock_guard lock(g_eglMutex);
        if (loadEglLibrary() && eglGetCurrentContext && (h = eglGetCurrentContext()) != EGL_NO_CONTEXT) kind = CurrentKind::Egl;
    }
    if (kind == CurrentKind::None) {
        // Without glfwInit this returns null (and records GLFW_NOT_INITIALIZED, which we clear).
        if ((h = glfwGetCurrentContext()))
            kind = CurrentKind::Glfw;
        else
            glfwGetError(nullptr);
    }
    if (kind == CurrentKind::None) {
        if (GetCurrentFn f = glxGetCurrentContextFn(); f && (h = f())) kind = CurrentKind::Glx;
    }
    if (handle) *handle = h;
    return kind;
}

GLADapiproc eglLoad(const char* name) { return reinterpret_cast<GLADapiproc>(eglGetProcAddress(name)); }
GLADapiproc glfwLoad(const char* name) { return reinterpret_cast<GLADapiproc>(glfwGetProcAddress(name)); }

}   // namespace

bool anyContextCurrent() { return currentKind() != CurrentKind::None; }

const void* currentContextHandle() {
    const void* h = nullptr;
    currentKind(&h);
    return h;
}

std::string loadGLFunctions() {
    int version = 0;
    switch (currentKind()) {
    case CurrentKind::None: return "no OpenGL context is current";
    case CurrentKind::Egl: version = gladLoadGL(eglLoad); break;
    case CurrentKind::Glfw: version = gladLoadGL(glfwLoad); break;
    case CurrentKind::Glx: version = gladLoaderLoadGL(); break;
    }
    if (version == 0) return "could not load the OpenGL entry points of the current context";
    int major = GLAD_VERSION_MAJOR(version), minor = GLAD_VERSION_MINOR(version);
    if (major < 3 || (major == 3 && minor < 3))
        return "OpenGL " + std::to_string(major) + "." + std::to_string(minor) + " context: the gl backend needs 3.3 core or newer";
    return {};
}

std::string describeCurrentContext() {
    if (!glGetString) return "(GL not loaded)";
    auto str = [](GLenum e) {
        const GLubyte* s = glGetString(e);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
    };
    return "OpenGL " + str(GL_VERSION) + ", " + str(GL_RENDERER);
}

// --- 6. What headless GL runs on ------------------------------------------------------------
namespace {

bool hasToken(const char* list, std::string_view token) {
    std::istringstream words(list ? list : "");
    for (std::string w; words >> w;)
        if (w == token) return true;
    return false;
}

// Step 1 of probeHeadlessGl: true when Mesa's EGL, which the surfaceless display comes from,
// lists only its software device. Lists devices without loading a driver.
bool onlySoftwareEglDevices() {
    std::lock_guard lock(g_eglMutex);
    if (!loadEglLibrary()) return false;
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!hasToken(client, "EGL_EXT_device_enumeration") || !hasToken(client, "EGL_MESA_platform_surfaceless")) return false;
    auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto queryDeviceString = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    if (!queryDevices || !queryDeviceString) return false;
    EGLint n = 0;
    if (!queryDevices(0, nullptr, &n) || n <= 0) return false;
    std::vector<EGLDeviceEXT> devices(size_t(n), nullptr);
    if (!queryDevices(n, devices.data(), &n) || n <= 0) return false;
    for (EGLint i = 0; i < n; ++i)
        if (!hasToken(queryDeviceString(devices[size_t(i)], EGL_EXTENSIONS), "EGL_MESA_device_software")) return false;
    return true;
}

HeadlessGl probeUncached() {
    HeadlessGl r;
    const std::string platform = debugSwitches().glPlatform;
    if ((platform == "auto" || platform == "egl") && onlySoftwareEglDevices()) {
        r.usable = r.software = true;
        r.renderer = "Mesa's software device, no GPU";
        return r;
    }
    // A context current on this thread (the viewer's window) is the one the backend would use:
    // read that one, and leave it current.
    std::unique_ptr<GlContext> ctx;
    if (!anyContextCurrent()) {
        if (!(ctx = createHeadlessContext("", &r.error)) || !ctx->makeCurrent(&r.error)) return r;
    }
    r.error = loadGLFunctions();
    if (r.error.empty()) {
        const GLubyte* s = glGetString(GL_RENDERER);
        r.renderer = s ? reinterpret_cast<const char*>(s) : "";
        r.usable = true;
        r.software = isSoftwareGLRenderer(r.renderer);
    }
    if (ctx) ctx->release();
    return r;
}

}   // namespace

GlLimits glLimits() {
    static std::once_flag once;
    static GlLimits result;
    std::call_once(once, [] {
        std::unique_ptr<GlContext> ctx;
        std::string error;
        if (!anyContextCurrent() && (!(ctx = createHeadlessContext("", &error)) || !ctx->makeCurrent(&error))) return;
        if (loadGLFunctions().empty()) {
            GLint samples = 0, rb = 0, dims[2] = {0, 0};
            glGetIntegerv(GL_MAX_SAMPLES, &samples);
            glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &rb);
            glGetIntegerv(GL_MAX_VIEWPORT_DIMS, dims);
            result.maxSamples = samples;
            result.maxSize = std::min({rb, dims[0], dims[1]});
        }
        if (ctx) ctx->release();
    });
    return result;
}

HeadlessGl probeHeadlessGl() {
    static std::once_flag once;
    static HeadlessGl result;
    std::call_once(once, [] { result = probeUncached(); });
    return result;
}

}   // namespace rnd::gl
