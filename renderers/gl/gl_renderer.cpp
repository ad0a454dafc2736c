// gl_renderer.cpp - the OpenGL 3.3+ core rasterization backend ("gl"): the GlRenderer class
// (gl_internal.h) with its context handling, capabilities, the frame (doRender) and the pixel
// inspector's shadows (lightVisibility), and the state guard that restores the caller's GL
// state when we borrow its context. The programs, GPU objects, draw passes and shadow maps a
// frame uses are in gl_programs.cpp, gl_resources.cpp, gl_passes.cpp and gl_shadows.cpp;
// gl_internal.h has the overview and the conventions.
#include "gl/gl_renderer.h"

#include "gl/gl_context.h"
#include "gl/gl_internal.h"

#include <algorithm>
#include <cstdio>

namespace rnd {

namespace gl {

using namespace sg;

namespace {

// --- state guard -----------------------------------------------------------------------------
// Saves what a caller drawing its own UI relies on, and puts it back on scope exit.
class StateGuard {
public:
    StateGuard() {
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &m_drawFbo);
        glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &m_readFbo);
        glGetIntegerv(GL_VIEWPORT, m_viewport);
        glGetIntegerv(GL_CURRENT_PROGRAM, &m_program);
        glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &m_vao);
        glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &m_arrayBuffer);
        glGetIntegerv(GL_RENDERBUFFER_BINDING, &m_renderbuffer);
        glGetIntegerv(GL_ACTIVE_TEXTURE, &m_activeTexture);
        glActiveTexture(GL_TEXTURE0);
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &m_texture0);
        glGetIntegerv(GL_PACK_ALIGNMENT, &m_pack);
        glGetIntegerv(GL_UNPACK_ALIGNMENT, &m_unpack);
        glGetIntegerv(GL_POLYGON_MODE, m_polygonMode);
        glGetIntegerv(GL_FRONT_FACE, &m_frontFace);
        glGetIntegerv(GL_CULL_FACE_MODE, &m_cullMode);
        glGetIntegerv(GL_DEPTH_FUNC, &m_depthFunc);
        glGetBooleanv(GL_DEPTH_WRITEMASK, &m_depthMask);
        glGetBooleanv(GL_COLOR_WRITEMASK, m_colorMask);
        glGetFloatv(GL_COLOR_CLEAR_VALUE, m_clearColor);
        glGetIntegerv(GL_PROVOKING_VERTEX, &m_provoking);
        for (size_t i = 0; i < std::size(kCaps); ++i) m_enabled[i] = glIsEnabled(kCaps[i]);
    }
    ~StateGuard() {
        for (size_t i = 0; i < std::size(kCaps); ++i) (m_enabled[i] ? glEnable : glDisable)(kCaps[i]);
        glClearColor(m_clearColor[0], m_clearColor[1], m_clearColor[2], m_clearColor[3]);
        glColorMask(m_colorMask[0], m_colorMask[1], m_colorMask[2], m_colorMask[3]);
        glDepthMask(m_depthMask);
        glDepthFunc(GLenum(m_depthFunc));
        glCullFace(GLenum(m_cullMode));
        glFrontFace(GLenum(m_frontFace));
        glProvokingVertex(GLenum(m_provoking));
        glPolygonMode(GL_FRONT_AND_BACK, GLenum(m_polygonMode[0]));
        glPixelStorei(GL_PACK_ALIGNMENT, m_pack);
        glPixelStorei(GL_UNPACK_ALIGNMENT, m_unpack);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, GLuint(m_texture0));
        glActiveTexture(GLenum(m_activeTexture));
        glBindRenderbuffer(GL_RENDERBUFFER, GLuint(m_renderbuffer));
        glBindVertexArray(GLuint(m_vao));
        glBindBuffer(GL_ARRAY_BUFFER, GLuint(m_arrayBuffer));
        glUseProgram(GLuint(m_program));
        glViewport(m_viewport[0], m_viewport[1], m_viewport[2], m_viewport[3]);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(m_drawFbo));
        glBindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(m_readFbo));
    }

private:
    static constexpr GLenum kCaps[] = {GL_DEPTH_TEST,          GL_CULL_FACE,         GL_BLEND,       GL_SCISSOR_TEST,
                                       GL_STENCIL_TEST,        GL_FRAMEBUFFER_SRGB,  GL_MULTISAMPLE, GL_POLYGON_OFFSET_FILL,
                                       GL_POLYGON_OFFSET_LINE, GL_PROGRAM_POINT_SIZE};
    GLint m_drawFbo = 0, m_readFbo = 0, m_viewport[4] = {}, m_program = 0, m_vao = 0, m_arrayBuffer = 0;
    GLint m_renderbuffer = 0, m_activeTexture = GL_TEXTURE0, m_texture0 = 0, m_pack = 4, m_unpack = 4;
    GLint m_provoking = GL_LAST_VERTEX_CONVENTION;
    GLint m_polygonMode[2] = {GL_FILL, GL_FILL}, m_frontFace = GL_CCW, m_cullMode = GL_BACK, m_depthFunc = GL_LESS;
    GLboolean m_depthMask = GL_TRUE, m_colorMask[4] = {GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
    GLfloat m_clearColor[4] = {};
    GLboolean m_enabled[std::size(kCaps)] = {};
};

// The MSAA samples a frame can have: `asked` (render_config.h's resolution), or the driver's
// maximum when it allows fewer (a note in stats says so).
int usableSamples(int asked, int maxSamples, RenderStats& stats) {
    if (asked <= 1 || asked <= maxSamples) return asked;
    const int used = std::max(maxSamples, 1);
    stats.config.notes.push_back("msaa" + std::to_string(asked) + " -> " + (used > 1 ? "msaa" + std::to_string(used) : std::string("none")) +
                                 ": the driver allows " + std::to_string(maxSamples) + " samples");
    return used;
}

}   // namespace

Capabilities GlRenderer::capabilities() const {
    Capabilities c;
    c.affinity = ContextAffinity::CurrentGLContext;
    c.wireframe = true;
    c.pointsAndLines = true;
    c.shadows = true;   // shadow maps (renderers/shadow_map.h, gl_shadows.cpp), as the CPU rasterizer's
    c.shadowMaps = true;
    c.aovs.add(Aov::Visibility);   // a second colour attachment, RG32UI (mesh.frag's fragId)
    c.aovs.add(Aov::Overdraw);     // a second pass into an R32F target, additive (countOverdraw)
    // Constant for the life of the backend (callers may cache them): the driver's limits,
    // read once per process (gl::glLimits), whether or not this instance has rendered.
    const gl::GlLimits limits = gl::glLimits();
    for (int n : {2, 4, 8})
        if (limits.maxSamples == 0 || n <= limits.maxSamples) c.msaaSamples.push_back(n);
    c.ssaaFactors = {2, 3, 4};
    c.ssaaRendersLarger = true;
    c.maxImageSize = limits.maxSize > 0 ? std::min(limits.maxSize, 16384) : 16384;
    return c;
}

Device GlRenderer::device() const {
    const gl::HeadlessGl g = gl::probeHeadlessGl();
    return {g.usable, g.software, g.usable ? g.renderer : g.error};
}

std::string GlRenderer::prepareContext(bool& madeCurrent) {
    madeCurrent = false;
    if (!(m_own && m_own->isCurrent()) && !gl::anyContextCurrent()) {
        if (!m_own) {
            std::string err;
            m_own = gl::createHeadlessContext("", &err);
            if (!m_own) return err;
        }
        std::string err;
        if (!m_own->makeCurrent(&err)) return err;
        madeCurrent = true;
    }
    const void* handle = gl::currentContextHandle();
    if (handle != m_objectsContext || !m_loaded) {
        // A different context than last time: our objects are not valid in it.
        forgetGLObjects();
        std::string err = gl::loadGLFunctions();
        if (!err.empty()) return err;
        m_loaded = true;
        m_objectsContext = handle;
        m_contextDescription = gl::describeCurrentContext();
        glGetIntegerv(GL_MAX_SAMPLES, &m_maxSamples);
        GLint rb = 0, dims[2] = {0, 0};
        glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &rb);
        glGetIntegerv(GL_MAX_VIEWPORT_DIMS, dims);
        m_maxSize = std::min({rb, dims[0], dims[1]});
        glGetIntegerv(GL_MAX_TEXTURE_SIZE, &m_maxTextureSize);
        glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &m_maxTextureLayers);
    }
    m_platform = (m_own && m_own->isCurrent()) ? m_own->platform() : "caller";
    return {};
}

void GlRenderer::forgetGLObjects() {
    m_programs.clear();
    m_target = RenderTarget{};
    m_resolve = RenderTarget{};
    m_display = RenderTarget{};
    for (DisplayProgram& p : m_displayPrograms) p = DisplayProgram{};
    m_emptyVao = 0;
    m_overdraw = CountTarget{};
    m_meshes.clear();
    m_textures.clear();
    forgetEnvironment();
    forgetShadows();
    m_loaded = false;
}

void GlRenderer::releaseAll() {
    // Delete our objects when their context can be made (or is) current; otherwise they die
    // with their context.
    bool madeCurrent = false;
    if (m_own && m_objectsContext && !gl::anyContextCurrent()) madeCurrent = m_own->makeCurrent(nullptr);
    if (m_loaded && gl::currentContextHandle() == m_objectsContext) {
        for (auto& [key, p] : m_programs) glDeleteProgram(p.id);
        m_target.release();
        m_resolve.release();
        m_display.release();
        for (DisplayProgram& p : m_displayPrograms)
            if (p.id) glDeleteProgram(p.id);
        if (m_emptyVao) glDeleteVertexArrays(1, &m_emptyVao);
        m_overdraw.release();
        for (auto& [id, m] : m_meshes) releaseMesh(m);
        for (auto& [id, t] : m_textures)
            if (t.id) glDeleteTextures(1, &t.id);
        releaseEnvironment();
        releaseShadows();
    }
    forgetGLObjects();
    if (madeCurrent) m_own->release();
    m_own.reset();
}

RenderStats GlRenderer::doRender(const FrameInput& frame, const RenderConfig& cfg, Framebuffer& target, RenderControl* control) {
    RenderStats stats;
    bool madeCurrent = false;
    std::string err = prepareContext(madeCurrent);
    if (!err.empty()) {
        stats.error = err;
        if (madeCurrent) m_own->release();
        return stats;
    }
    struct ReleaseOnExit {
        gl::GlContext* ctx;
        ~ReleaseOnExit() {
            if (ctx) ctx->release();
        }
    } releaseOnExit{madeCurrent ? m_own.get() : nullptr};

    StateGuard guard;
    ++m_frame;

    // Anti-aliasing as resolved (render_config.h); the driver's limits are known only now.
    const RenderSettings& s = frame.settings;
    const int samples = usableSamples(cfg.msaaSamples, m_maxSamples, stats);
    const int ssaa = cfg.ssaaFactor;
    const int rw = cfg.width * ssaa, rh = cfg.height * ssaa;
    if (rw > m_maxSize || rh > m_maxSize) {
        stats.error = "render size " + std::to_string(rw) + "x" + std::to_string(rh) + " exceeds the driver's limit of " + std::to_string(m_maxSize);
        return stats;
    }
    const bool visibility = cfg.aovs.has(Aov::Visibility) && samples <= 1 && ssaa == 1;   // render() asks only for one-sample frames
    // Exposure or tone mapping: linear float targets, and the display pass at the end.
    m_linear = !s.displayTransformIsIdentity();
    err = m_target.ensure(rw, rh, samples > 1 ? samples : 0, visibility, m_linear);
    if (err.empty() && samples > 1) err = m_resolve.ensure(rw, rh, 0, false, m_linear);
    if (!err.empty()) {
        stats.error = err;
        return stats;
    }

    // One GL frame is not progressive (render() checked cancellation before), but tessellating
    // new shapes can take seconds: that part reports its progress and stops when cancelled.
    const std::vector<DrawItem> items = collectDraws(frame, cfg.tessellation, control);
    if (control && control->cancel.load()) {
        stats.cancelled = true;
        stats.error = "cancelled";
        return stats;
    }
    // Shadow maps into their own target first (their texture then on unit 7, the plan in a
    // uniform buffer); the programs' key depends on the plan.
    err = renderShadowMaps(frame, items, stats);
    if (!err.empty()) {
        stats.error = err;
        return stats;
    }
    beginFrameState(s, m_target.fbo, rw, rh, samples);
    if (visibility) beginVisibility();
    prepareEnvironment(frame, stats);   // pbr: textures on units 5 and 6
    // The programs of this frame (useProgram): its setup, and uniforms set once per program.
    beginFramePrograms(frame, ssaa, visibility);
    struct EndOfFrame {
        GlRenderer& r;
        ~EndOfFrame() {
            r.m_frameInput = nullptr;
            r.m_current = nullptr;
        }
    } endOfFrame{*this};
    stats.triangles = drawFramePasses(items, s, err);
    if (!err.empty()) {
        if (visibility) glDrawBuffer(GL_COLOR_ATTACHMENT0);
        stats.error = err;
        return stats;
    }
    err = resolveAndRead(rw, rh, samples, ssaa, visibility, target);
    if (!err.empty()) {
        stats.error = err;
        return stats;
    }
    if (cfg.aovs.has(Aov::Overdraw) && samples <= 1 && ssaa == 1) {   // render() asks only for one-sample frames
        err = countOverdraw(items, s, rw, rh, target);
        if (!err.empty()) {
            stats.error = err;
            return stats;
        }
    }

    GLenum glErr = glGetError();
    evict();
    if (glErr != GL_NO_ERROR) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "OpenGL error 0x%x during the frame", glErr);
        stats.error = buf;
        return stats;
    }
    stats.ok = true;
    return stats;
}

bool GlRenderer::inMapsContext(const FrameInput& f, const std::function<bool()>& ask) {
    if (m_shadowPlan.empty() || m_shadowPlan.viewCount.size() != f.lights.size()) return false;
    // The maps live in the GPU, in the context that rendered them: current here already (the
    // caller's), or ours made current for the question. Never another one: prepareContext would
    // take it for a new context and forget (leak) every object of the old one.
    bool madeCurrent = false;
    if (!gl::anyContextCurrent()) {
        if (!m_own || !m_own->makeCurrent(nullptr)) return false;
        madeCurrent = true;
    }
    struct ReleaseOnExit {
        gl::GlContext* ctx;
        ~ReleaseOnExit() {
            if (ctx) ctx->release();
        }
    } releaseOnExit{madeCurrent ? m_own.get() : nullptr};
    if (!m_loaded || gl::currentContextHandle() != m_objectsContext) return false;
    StateGuard guard;
    return ask();
}

bool GlRenderer::visibilityAt(const FrameInput& f, size_t l, const vec3& p, const vec3& ng, float& out) {
    out = 1.0f;
    if (m_shadowPlan.viewCount[l] == 0) return true;
    // The light's map at p (a point light's face for p), as a plan of that one view: the same
    // lookup as shadowVisibility over the whole plan, with one layer read back.
    DrawLight L = f.lights[l];
    int view = m_shadowPlan.firstView[l];
    if (L.type == LightType::Point) {
        view += pointLightFace(p - L.position);
        L.type = LightType::Spot;   // one perspective view from the position, the face already chosen
    }
    const ShadowMaps* maps = shadowLayer(view);
    if (!maps) return false;
    ShadowPlan& one = m_onePlan;   // (kept: no allocation per point)
    one.size = m_shadowPlan.size;
    one.filter = m_shadowPlan.filter;
    one.pcf = m_shadowPlan.pcf;
    one.depthBias = m_shadowPlan.depthBias;
    one.normalBias = m_shadowPlan.normalBias;
    one.views.assign(1, m_shadowPlan.views[size_t(view)]);
    one.firstView.assign(1, 0);
    one.viewCount.assign(1, 1);
    out = shadowVisibility(one, *maps, L, 0, p, ng);
    return true;
}

std::vector<float> GlRenderer::lightVisibility(const FrameInput& f, const vec3& p, const vec3& ng) {
    std::vector<float> v(f.lights.size(), 1.0f);
    const bool ok = inMapsContext(f, [&] {
        for (size_t l = 0; l < v.size(); ++l)
            if (!visibilityAt(f, l, p, ng, v[l])) return false;
        return true;
    });
    return ok ? v : std::vector<float>{};
}

std::vector<float> GlRenderer::lightVisibilityMany(const FrameInput& f, int light, const std::vector<vec3>& p, const std::vector<vec3>& ng) {
    if (light < 0 || size_t(light) >= f.lights.size() || p.size() != ng.size()) return {};
    std::vector<float> v(p.size(), 1.0f);
    const bool ok = inMapsContext(f, [&] {
        for (size_t i = 0; i < p.size(); ++i)
            if (!visibilityAt(f, size_t(light), p[i], ng[i], v[i])) return false;
        return true;
    });
    return ok ? v : std::vector<float>{};
}

}   // namespace gl

std::unique_ptr<Renderer> makeGlRenderer() { return std::make_unique<gl::GlRenderer>(); }

GlCacheCounters glCacheCounters(const Renderer& r) {
    if (auto* g = dynamic_cast<const gl::GlRenderer*>(&r)) return g->counters();
    return {};
}

}   // namespace rnd
