// gl_passes.cpp - the GL backend's draw passes (gl_internal.h) and the frame state around
// them: the opaque pass (opaque and masked surfaces, lines and points; it alone writes the
// visibility attachment), the blended pass ("over" in linear light, far to near, depth tested
// but not written), the wireframe overlay, the overdraw view's counting pass, the MSAA
// resolve with the read-back of colour, depth and visibility, and the display pass of linear
// frames (exposure and tone mapping).
#include "gl/gl_internal.h"

#include "renderers/tone_map.h"

#include <algorithm>
#include <cmath>

namespace rnd::gl {

using namespace sg;

// Sets the fixed-function state of a frame and clears the target (background is linear; the
// sRGB framebuffer encodes it).
void beginFrameState(const RenderSettings& s, GLuint fbo, int w, int h, int samples) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, w, h);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_STENCIL_TEST);
    glEnable(GL_FRAMEBUFFER_SRGB);
    if (samples > 1)
        glEnable(GL_MULTISAMPLE);
    else
        glDisable(GL_MULTISAMPLE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glClearColor(s.background.r, s.background.g, s.background.b, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glCullFace(GL_BACK);                             // enabled per material in drawAll (RenderSettings::culling)
    glProvokingVertex(GL_FIRST_VERTEX_CONVENTION);   // flat shading's vertex: a triangle's first, as in the CPU backends
    glDisable(GL_CULL_FACE);
    glActiveTexture(GL_TEXTURE0);
}

// Makes attachment 1 (visibility) a draw buffer and clears it to "nothing".
void beginVisibility() {
    const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, bufs);
    const GLuint none[4] = {0u, kNoPrimitive, 0u, 0u};
    glClearBufferuiv(GL_COLOR, 1, none);
}

// Draws every item (wireframe: the triangle meshes again as lines, no material changes), each
// range with the program of its switches (featuresOf). Returns the triangles submitted; on a
// program that does not build, sets `error` and stops.
uint64_t GlRenderer::drawAll(const std::vector<DrawItem>& items, DrawPass pass, sg::CullMode culling, std::string& error) {
    const bool wireframe = pass == DrawPass::Wireframe;
    uint64_t triangles = 0;
    bool cullOn = false;
    glDisable(GL_CULL_FACE);
    auto setCull = [&](bool on) {
        if (on == cullOn) return;
        cullOn = on;
        if (on)
            glEnable(GL_CULL_FACE);
        else
            glDisable(GL_CULL_FACE);
    };
    std::fill(std::begin(m_boundTexture), std::end(m_boundTexture), kUnknownTexture);
    // Blended surfaces after everything else, farthest first (items come nearest first).
    for (size_t k = 0; k < items.size(); ++k) {
        const DrawItem& it = items[pass == DrawPass::Blended ? items.size() - 1 - k : k];
        if (wireframe && it.gpu->primitive != GL_TRIANGLES) continue;
        bool bound = false;
        const Program* itemProgram = nullptr;   // the program holding this item's transform
        const bool unlit = it.gpu->primitive != GL_TRIANGLES;
        for (const IndexRange& r : it.gpu->ranges) {
            const Material* m = it.material;
            if (it.rangeMaterials && r.material >= 0 && size_t(r.material) < it.rangeMaterials->size()) m = &(*it.rangeMaterials)[r.material];
            const bool blended = m->alphaMode == sg::AlphaMode::Blend && !unlit;
            if (!wireframe && blended != (pass == DrawPass::Blended)) continue;
            if (!useProgram(featuresOf(it, *m, pass), error)) return triangles;
            Program& prog = *m_current;
            if (itemProgram != &prog) {
                glUniformMatrix4fv(prog.model, 1, GL_FALSE, &(*it.world)[0][0]);
                glUniformMatrix3fv(prog.normalMatrix, 1, GL_FALSE, &it.normal[0][0]);
                glUniform1ui(prog.drawable, it.drawable);
                itemProgram = &prog;
            }
            if (!bound) {
                glFrontFace(it.mirrored ? GL_CW : GL_CCW);
                if (!wireframe) bindTextures(it);
                glBindVertexArray(it.gpu->vao);
                bound = true;
            }
            if (!wireframe) {
                setMaterial(prog, *m);
                if (!unlit) triangles += uint64_t(r.count / 3);
            }
            setCull(!unlit && sg::cullsBackFaces(culling, m->doubleSided));
            // gl_PrimitiveID counts from 0 in every draw call: the range's first primitive.
            const GLuint perPrim = it.gpu->primitive == GL_TRIANGLES ? 3 : it.gpu->primitive == GL_LINES ? 2 : 1;
            glUniform1ui(prog.primitiveBase, it.analytic ? kNoPrimitive : GLuint(r.first) / perPrim);
            glDrawElements(it.gpu->primitive, r.count, GL_UNSIGNED_INT, reinterpret_cast<const void*>(size_t(r.first) * sizeof(uint32_t)));
        }
    }
    setCull(false);
    return triangles;
}

// The frame's passes into the current target: opaque, blended, then the wireframe overlay when
// the settings ask. Returns the triangles submitted; on a program that does not build, sets
// `error` and stops.
uint64_t GlRenderer::drawFramePasses(const std::vector<DrawItem>& items, const RenderSettings& s, std::string& error) {
    uint64_t triangles = drawAll(items, DrawPass::Opaque, s.culling, error);
    if (error.empty() && m_environment.map && m_environment.background && m_frameInput) drawEnvironmentBackground(*m_frameInput, error);
    triangles += drawBlendedPass(items, s, error);
    if (s.wireframe && error.empty()) drawWireframePass(items, s, error);
    glBindVertexArray(0);
    glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    return triangles;
}

// Blended surfaces (glTF alphaMode BLEND): "over" in linear light (the sRGB framebuffer
// blends decoded values), sorted per draw back to front, depth tested but not written
// (nor is the visibility, which belongs to the surface that wrote depth). Attachment 1 stays
// masked until drawFramePasses ends.
uint64_t GlRenderer::drawBlendedPass(const std::vector<DrawItem>& items, const RenderSettings& s, std::string& error) {
    uint64_t triangles = 0;
    glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glDepthMask(GL_FALSE);
    if (error.empty()) triangles = drawAll(items, DrawPass::Blended, s.culling, error);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    return triangles;
}

// Wireframe overlay: the same triangles as lines, pulled slightly toward the viewer.
void GlRenderer::drawWireframePass(const std::vector<DrawItem>& items, const RenderSettings& s, std::string& error) {
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    glEnable(GL_POLYGON_OFFSET_LINE);
    glPolygonOffset(-1.0f, -1.0f);
    glDepthFunc(GL_LEQUAL);
    drawAll(items, DrawPass::Wireframe, s.culling, error);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glDisable(GL_POLYGON_OFFSET_LINE);
}

// The overdraw view (Aov::Overdraw, one sample per pixel): the frame's draws again
// (surfaces of every alpha mode, lines, points, the wireframe; culled as in the frame) into
// m_overdraw with the depth test off and additive blending, with mesh.frag's OVERDRAW variant
// writing 1.0 for every fragment (it never discards), so each pixel holds the fragments
// rasterized in it; read into target.overdraw. Returns "" or the reason it failed.
std::string GlRenderer::countOverdraw(const std::vector<DrawItem>& items, const RenderSettings& s, int w, int h, Framebuffer& target) {
    std::string err = m_overdraw.ensure(w, h);
    if (!err.empty()) return err;
    glBindFramebuffer(GL_FRAMEBUFFER, m_overdraw.fbo);
    glViewport(0, 0, w, h);
    const GLfloat zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    glClearBufferfv(GL_COLOR, 0, zero);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    m_countPass = true;
    drawAll(items, DrawPass::Opaque, s.culling, err);
    if (err.empty()) drawAll(items, DrawPass::Blended, s.culling, err);
    if (err.empty() && s.wireframe) {
        glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
        drawAll(items, DrawPass::Wireframe, s.culling, err);
        glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    }
    m_countPass = false;
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glEnable(GL_DEPTH_TEST);
    if (!err.empty()) return err;
    std::vector<float> counts(size_t(w) * h);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, m_overdraw.fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, h, GL_RED, GL_FLOAT, counts.data());
    target.allocate(Aov::Overdraw);
    for (int y = 0; y < h; ++y) {
        const float* src = &counts[size_t(h - 1 - y) * w];
        for (int x = 0; x < w; ++x) target.overdraw[size_t(y) * w + x] = uint32_t(std::lround(std::max(src[x], 0.0f)));
    }
    return {};
}

// Resolves MSAA (reading a multisampled buffer directly would give an aliased image) and reads
// the frame into `target`: colour and depth, box-filtered down with SSAA, the visibility when
// the frame has it. A linear frame's colour comes from the display pass instead, its depth as
// above. Leaves attachment 0 the only draw buffer. Returns "" or the reason it failed.
std::string GlRenderer::resolveAndRead(int w, int h, int samples, int ssaa, bool visibility, Framebuffer& target) {
    GLuint readFbo = m_target.fbo;
    GLuint frameTexture = m_target.colorTexture;
    if (samples > 1) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, m_target.fbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, m_resolve.fbo);
        glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
        readFbo = m_resolve.fbo;
        frameTexture = m_resolve.colorTexture;
    }
    if (ssaa > 1) {
        Framebuffer full;
        readBack(readFbo, w, h, full);
        target = downsample(full, ssaa);
    } else {
        readBack(readFbo, w, h, target);
        if (visibility) readVisibility(readFbo, w, h, target);
    }
    if (visibility) glDrawBuffer(GL_COLOR_ATTACHMENT0);
    if (!m_linear) return {};
    // The colour read above is the linear frame's, clamped to bytes: replaced by the display pass's.
    const int ow = w / ssaa, oh = h / ssaa;
    std::string err = displayPass(m_frameInput->settings, frameTexture, ssaa, ow, oh);
    if (err.empty()) readBack(m_display.fbo, ow, oh, target, false);
    return err;
}

// The display pass (linear frames): the resolved linear frame `frameTexture` (ssaa x the output
// size w x h) box-filtered, through exposure and the tone-mapping operator (display.frag with
// tone_map.glsl), into m_display's sRGB8 colour. Returns "" or the reason it could not.
std::string GlRenderer::displayPass(const RenderSettings& s, GLuint frameTexture, int ssaa, int w, int h) {
    std::string err = m_display.ensure(w, h, 0);
    if (!err.empty()) return err;
    DisplayProgram& p = m_displayPrograms[std::clamp(int(s.toneMapping), 0, 2)];
    if (!p.id && !(err = buildDisplayProgram(s.toneMapping, p)).empty()) return err;
    if (!m_emptyVao) glGenVertexArrays(1, &m_emptyVao);
    glBindFramebuffer(GL_FRAMEBUFFER, m_display.fbo);
    glViewport(0, 0, w, h);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_MULTISAMPLE);
    glEnable(GL_FRAMEBUFFER_SRGB);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glUseProgram(p.id);
    m_current = nullptr;   // useProgram must bind a mesh program again
    glUniform1i(p.ssaa, ssaa);
    glUniform1f(p.exposureScale, exposureScale(s.exposure));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, frameTexture);
    m_boundTexture[0] = kUnknownTexture;
    glBindVertexArray(m_emptyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glEnable(GL_DEPTH_TEST);
    return {};
}

}   // namespace rnd::gl
