// gl_context_test.cpp - headless context creation, its failure paths, and rendering inside a
// caller's context (state the caller relies on is restored).
#include "gl/gl_context.h"
#include "gl/gl_renderer.h"
#include "test_scenes.h"
#include "test_support.h"

#include <glad/gl.h>

#include <cstdlib>

using namespace sg;

namespace {

// Sets an environment variable for the scope of one test.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : m_name(name) {
        if (const char* old = std::getenv(name)) m_old = old, m_had = true;
        if (value)
            setenv(name, value, 1);
        else
            unsetenv(name);
    }
    ~ScopedEnv() {
        if (m_had)
            setenv(m_name.c_str(), m_old.c_str(), 1);
        else
            unsetenv(m_name.c_str());
    }

private:
    std::string m_name, m_old;
    bool m_had = false;
};

FrameInput simpleFrame() {
    FrameInput f = test_scenes::makeFrame(64, 48, Projection{}, vec3(0, 0, 5), vec3(0));
    f.lights.push_back(test_scenes::directional(vec3(0, 0, -1), vec3(1.0f)));
    test_scenes::addMesh(f, primitives::uvSphere(1.0f, 16, 8), Material{});
    return f;
}

}   // namespace

TEST(GlContextGLTest, EglSurfacelessGivesCore33OrNewer) {
    ASSERT_FALSE(rnd::gl::anyContextCurrent());
    std::string err;
    auto ctx = rnd::gl::createHeadlessContext("egl", &err);
    ASSERT_TRUE(ctx) << err;
    EXPECT_EQ(ctx->platform(), "egl-surfaceless");
    EXPECT_FALSE(ctx->isCurrent());
    ASSERT_TRUE(ctx->makeCurrent(&err)) << err;
    EXPECT_TRUE(rnd::gl::anyContextCurrent());
    EXPECT_EQ(rnd::gl::loadGLFunctions(), "");
    std::string desc = rnd::gl::describeCurrentContext();
    std::printf("[gl] %s\n", desc.c_str());
    EXPECT_NE(desc.find("OpenGL"), std::string::npos);
    ctx->release();
    EXPECT_FALSE(rnd::gl::anyContextCurrent());
}

// An unknown platform name is an error message, not a crash; so is a render that cannot get
// a context.
TEST(GlContextGLTest, UnknownPlatformIsReported) {
    std::string err;
    EXPECT_FALSE(rnd::gl::createHeadlessContext("vulkan-please", &err));
    EXPECT_NE(err.find("unknown GL platform 'vulkan-please'"), std::string::npos) << err;

    ScopedEnv env("VIEWER_GL_PLATFORM", "nonsense");
    auto r = rnd::makeGlRenderer();
    rnd::Framebuffer fb;
    rnd::RenderStats st = r->render(simpleFrame(), 64, 48, fb);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.error.find("unknown GL platform"), std::string::npos) << st.error;
    EXPECT_EQ(st.error.find('\n'), std::string::npos) << "one line";
    EXPECT_EQ(st.error.rfind("gl: ", 0), 0u) << "names the backend: " << st.error;
}

// Without an X display the GLFW fallback fails cleanly with a one-line reason.
TEST(GlContextGLTest, GlfwWithoutDisplayIsReported) {
    if (std::getenv("DISPLAY")) GTEST_SKIP() << "DISPLAY is set: the hidden GLFW window may work here";
    std::string err;
    EXPECT_FALSE(rnd::gl::createHeadlessContext("glfw", &err));
    EXPECT_NE(err.find("GLFW"), std::string::npos) << err;
    EXPECT_EQ(err.find('\n'), std::string::npos) << err;
}

TEST(GlContextGLTest, EmptySizeIsReported) {
    auto r = rnd::makeGlRenderer();
    rnd::Framebuffer fb;
    rnd::RenderStats st = r->render(simpleFrame(), 0, 10, fb);
    EXPECT_FALSE(st.ok);
    EXPECT_FALSE(st.error.empty());
}

// With a context current (the viewer's window), the renderer uses it, renders into its own
// FBO and restores the bound framebuffer, viewport and program; images match the headless ones.
TEST(GlContextGLTest, CallerContextIsUsedAndStateRestored) {
    auto headless = rnd::makeGlRenderer();
    rnd::Framebuffer reference;
    ASSERT_TRUE(headless->render(simpleFrame(), 64, 48, reference).ok);
    EXPECT_EQ(rnd::glCacheCounters(*headless).platform, "egl-surfaceless");
    EXPECT_FALSE(rnd::gl::anyContextCurrent()) << "the renderer releases its own context";

    std::string err;
    auto ctx = rnd::gl::createHeadlessContext("", &err);
    ASSERT_TRUE(ctx) << err;
    ASSERT_TRUE(ctx->makeCurrent(&err)) << err;
    ASSERT_EQ(rnd::gl::loadGLFunctions(), "");
    GLuint fbo = 0, rb = 0;
    glGenRenderbuffers(1, &rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 32, 32);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
    glViewport(3, 4, 20, 21);
    glClearColor(0.1f, 0.2f, 0.3f, 0.4f);

    {
        auto r = rnd::makeGlRenderer();
        rnd::Framebuffer fb;
        rnd::RenderStats st = r->render(simpleFrame(), 64, 48, fb);
        ASSERT_TRUE(st.ok) << st.error;
        EXPECT_EQ(rnd::glCacheCounters(*r).platform, "caller");
        EXPECT_TRUE(ctx->isCurrent());
        GLint bound = -1, vp[4] = {};
        GLfloat clear[4] = {};
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
        glGetIntegerv(GL_VIEWPORT, vp);
        glGetFloatv(GL_COLOR_CLEAR_VALUE, clear);
        EXPECT_EQ(GLuint(bound), fbo);
        EXPECT_EQ(vp[0], 3);
        EXPECT_EQ(vp[1], 4);
        EXPECT_EQ(vp[2], 20);
        EXPECT_EQ(vp[3], 21);
        EXPECT_FLOAT_EQ(clear[2], 0.3f);
        EXPECT_FALSE(glIsEnabled(GL_FRAMEBUFFER_SRGB));
        EXPECT_FALSE(glIsEnabled(GL_DEPTH_TEST));
        EXPECT_LE(rnd::compareImages(fb, reference, 1).maxAbs, 1);
    }   // the renderer deletes its objects in the caller's context
    EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &rb);
    ctx->release();
}

TEST(GlContextTest, SoftwareRenderersAreRecognised) {
    for (const char* r : {"llvmpipe (LLVM 15.0.6, 256 bits)", "softpipe", "Software Rasterizer", "zink (llvmpipe (LLVM 15.0.6))", "SWR (LLVM 11)"})
        EXPECT_TRUE(rnd::isSoftwareGLRenderer(r)) << r;
    for (const char* r : {"NVIDIA H100 80GB HBM3/PCIe/SSE2", "AMD Radeon RX 6800 (navi21, LLVM 15.0.6, DRM 3.49)",
                          "Mesa Intel(R) UHD Graphics 620 (KBL GT2)", "virgl", ""})
        EXPECT_FALSE(rnd::isSoftwareGLRenderer(r)) << r;
}

// What probeHeadlessGl says without rendering (here: from EGL's device list when Mesa has no
// GPU device) agrees with the GL_RENDERER of the context a real render gets; the gl backend's
// device() and the registry's default backend follow from it.
TEST(GlContextGLTest, ProbeAgreesWithTheContextARenderGets) {
    const rnd::gl::HeadlessGl probe = rnd::gl::probeHeadlessGl();
    ASSERT_TRUE(probe.usable) << probe.error;
    EXPECT_FALSE(rnd::gl::anyContextCurrent()) << "the probe leaves no context current";
    auto r = rnd::makeGlRenderer();
    rnd::Framebuffer fb;
    ASSERT_TRUE(r->render(simpleFrame(), 64, 48, fb).ok);
    const std::string context = rnd::glCacheCounters(*r).context;
    std::printf("[gl] probe: %s (%s); a render's context: %s\n", probe.software ? "software" : "hardware", probe.renderer.c_str(), context.c_str());
    EXPECT_EQ(probe.software, rnd::isSoftwareGLRenderer(context)) << probe.renderer << " vs " << context;

    const rnd::Device d = r->device();
    EXPECT_TRUE(d.usable);
    EXPECT_EQ(d.softwareEmulated, probe.software);
    const rnd::BackendChoice choice = rnd::defaultRenderBackend();
    EXPECT_EQ(choice.name, probe.software ? "raster" : "gl");
    EXPECT_EQ(choice.note.empty(), !probe.software) << choice.note;
    EXPECT_FALSE(rnd::makeRenderer("raster")->device().softwareEmulated);
}
