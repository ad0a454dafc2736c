// gl_shadows.cpp - the GL backend's shadow maps (renderers/shadow_map.h), so that its shadows
// agree with the CPU rasterizer's: the same plan (rnd::planShadows, every shading model),
// one depth map per plan view drawn by the GPU the way renderShadowDepth draws it on the CPU
// (every opaque or masked triangle mesh, both faces, depth test less, cleared to 1; blended
// surfaces, lines and points cast nothing), and the lookup in shaders/shadow.glsl, which
// mirrors rnd::shadowVisibility. The maps are the layers of one DEPTH_COMPONENT32F array texture
// on unit kShadowUnit (nearest, no compare mode: shadow.glsl compares the stored linear depths itself with
// texelFetch); the plan's numbers go to shadow.glsl's uniform block ShadowPlan (std140, binding
// point kShadowBinding), one buffer for every program of the frame. The pixel inspector's
// lightVisibility reads the layers it needs back and asks rnd::shadowVisibility.
#include "gl/gl_internal.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace rnd::gl {

using namespace sg;

namespace {

// The depth-only pass: world positions as mesh.vert makes them, no colour.
const char* const kDepthVert = R"GLSL(
layout(location = 0) in vec3 aPosition;
uniform mat4 uModel;
uniform mat4 uViewProj;   // the shadow view's
uniform vec3 uDepth;      // x: perspective (1) or orthographic (0), y: nearZ, z: farZ
out float vDepth;         // the depth the maps store: linear along the axis, 0 at near, 1 at far
void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);
    gl_Position = uViewProj * world;
    // Perspective: w is the eye depth (interpolated perspective-correctly, so exact at every
    // fragment); orthographic: the window depth, already linear.
    vDepth = uDepth.x > 0.5 ? (gl_Position.w - uDepth.y) / (uDepth.z - uDepth.y) : gl_Position.z / gl_Position.w * 0.5 + 0.5;
}
)GLSL";
const char* const kDepthFrag = R"GLSL(
in float vDepth;
void main() { gl_FragDepth = vDepth; }
)GLSL";

// shadow.glsl's uniform block ShadowPlan in std140 (every member a vec4, ivec4 or mat4 array:
// no padding between them).
struct ShadowBlock {
    float viewProj[kMaxShadowViews][16];   // column-major, as glm
    float axis[kMaxShadowViews][4];        // the view matrix's third row
    float rowX[kMaxShadowViews][4];        // its first and second rows (the receiver plane's slope)
    float rowY[kMaxShadowViews][4];
    float view[kMaxShadowViews][4];   // perspective, nearZ, farZ, texelAtUnit
    int32_t light[kMaxLights][4];     // first view, view count
    float params[4];                  // size, depthBias, normalBias
};
static_assert(sizeof(ShadowBlock) == size_t(kMaxShadowViews) * (64 + 16 + 16 + 16 + 16) + size_t(kMaxLights) * 16 + 16,
              "std140 layout of ShadowPlan");

}   // namespace

// Draws the layers of m_shadowPlan that `draw` marks into m_shadowTexture.
std::string GlRenderer::drawShadowLayers(const std::vector<DrawItem>& items, const std::vector<bool>& draw) {
    const int N = m_shadowPlan.size, layers = int(m_shadowPlan.views.size());
    if (!m_shadowFbo) glGenFramebuffers(1, &m_shadowFbo);
    glBindFramebuffer(GL_FRAMEBUFFER, m_shadowFbo);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);

    // renderShadowDepth's state: both faces, depth test less, cleared to 1, single sample.
    glViewport(0, 0, N, N);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glClearDepth(1.0);
    glUseProgram(m_shadowProgram);
    m_current = nullptr;   // useProgram must bind a mesh program again
    bool checked = false;
    for (int layer = 0; layer < layers; ++layer) {
        if (!draw[size_t(layer)]) continue;
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, m_shadowTexture, 0, layer);
        if (!checked) {
            checked = true;
            const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
            if (status != GL_FRAMEBUFFER_COMPLETE) {
                char buf[128];
                std::snprintf(buf, sizeof buf, "shadow map framebuffer %dx%d is incomplete (status 0x%x)", N, N, status);
                m_shadowPlan = ShadowPlan{};
                return buf;
            }
        }
        glClear(GL_DEPTH_BUFFER_BIT);
        const ShadowView& sv = m_shadowPlan.views[size_t(layer)];
        glUniformMatrix4fv(m_shadowViewProj, 1, GL_FALSE, &sv.viewProj[0][0]);
        glUniform3f(m_shadowDepth, sv.perspective ? 1.0f : 0.0f, sv.nearZ, sv.farZ);
        for (const DrawItem& it : items) {
            if (it.gpu->primitive != GL_TRIANGLES) continue;   // points and lines cast nothing
            bool bound = false;
            for (const IndexRange& r : it.gpu->ranges) {
                const Material* m = it.material;
                if (it.rangeMaterials && r.material >= 0 && size_t(r.material) < it.rangeMaterials->size()) m = &(*it.rangeMaterials)[r.material];
                if (!castsShadow(*m)) continue;   // blended surfaces cast nothing (masked ones whole)
                if (!bound) {
                    glUniformMatrix4fv(m_shadowModel, 1, GL_FALSE, &(*it.world)[0][0]);
                    glBindVertexArray(it.gpu->vao);
                    bound = true;
                }
                glDrawElements(GL_TRIANGLES, r.count, GL_UNSIGNED_INT, reinterpret_cast<const void*>(size_t(r.first) * sizeof(uint32_t)));
            }
        }
    }
    glBindVertexArray(0);
    return {};
}

std::string GlRenderer::renderShadowMaps(const FrameInput& frame, const std::vector<DrawItem>& items, RenderStats& stats) {
    m_shadowReadBack.clear();
    // Shadow maps for every shading model (flat and Gouraud scale the lights with maps by each
    // fragment's visibility, as the CPU rasterizer).
    m_shadowPlan = planShadows(frame, shadowCasterBounds(frame));
    if (m_shadowPlan.empty()) return {};
    const int N = m_shadowPlan.size, layers = int(m_shadowPlan.views.size());
    if (N > m_maxTextureSize || N > m_maxSize || layers > m_maxTextureLayers) {
        stats.config.notes.push_back("shadow maps of " + std::to_string(N) + "x" + std::to_string(N) + " exceed the driver's limit of " +
                                     std::to_string(std::min(m_maxTextureSize, m_maxSize)) + ": no shadows");
        m_shadowPlan = ShadowPlan{};
        return {};
    }
    if (!m_shadowProgram) {
        std::string err = linkProgram(std::string("#version 330 core\n") + kDepthVert, std::string("#version 330 core\n") + kDepthFrag,
                                      "shadow depth shader", m_shadowProgram);
        if (!err.empty()) return err;
        m_shadowModel = glGetUniformLocation(m_shadowProgram, "uModel");
        m_shadowViewProj = glGetUniformLocation(m_shadowProgram, "uViewProj");
        m_shadowDepth = glGetUniformLocation(m_shadowProgram, "uDepth");
    }
    glActiveTexture(GLenum(GL_TEXTURE0 + kShadowUnit));
    if (!m_shadowTexture) glGenTextures(1, &m_shadowTexture);
    glBindTexture(GL_TEXTURE_2D_ARRAY, m_shadowTexture);
    if (N != m_shadowTextureSize || layers != m_shadowTextureLayers) {
        glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT32F, N, N, layers, 0, GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAX_LEVEL, 0);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_NONE);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        m_shadowTextureSize = N;
        m_shadowDrawn = false;   // new storage: nothing kept
        m_shadowTextureLayers = layers;
    }
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);   // not sampled while drawn into
    glActiveTexture(GL_TEXTURE0);
    // The casters as keys; the maps stay when they were drawn from these very views and keys.
    std::vector<ShadowCasterKey> casters;
    for (const DrawItem& it : items) {
        if (it.gpu->primitive != GL_TRIANGLES) continue;   // points and lines cast nothing
        for (const IndexRange& r : it.gpu->ranges) {
            const Material* m = it.material;
            if (it.rangeMaterials && r.material >= 0 && size_t(r.material) < it.rangeMaterials->size()) m = &(*it.rangeMaterials)[r.material];
            if (castsShadow(*m)) casters.push_back({it.gpu->id, it.gpu->version, *it.world, uint32_t(r.first), uint32_t(r.count)});
        }
    }
    static_assert(sizeof(ShadowCasterKey) == 8 + 8 + 64 + 4 + 4, "no padding: keys compare as bytes");
    auto less = [](const ShadowCasterKey& a, const ShadowCasterKey& b) { return std::memcmp(&a, &b, sizeof a) < 0; };
    std::sort(casters.begin(), casters.end(), less);
    // Each layer stays when the casters and its own view are the ones it was drawn from (a
    // moving camera refits a sun's map; a point light's faces and a spot's map stay).
    const bool sameCasters =
        m_shadowReuse && m_shadowDrawn && m_shadowDrawnViews.size() == m_shadowPlan.views.size() && m_shadowDrawnCasters.size() == casters.size() &&
        (casters.empty() || std::memcmp(casters.data(), m_shadowDrawnCasters.data(), casters.size() * sizeof(ShadowCasterKey)) == 0);
    std::vector<bool> draw(size_t(layers), true);
    int drawn = 0;
    for (int v = 0; v < layers; ++v) {
        draw[size_t(v)] = !(sameCasters && sameShadowView(m_shadowDrawnViews[size_t(v)], m_shadowPlan.views[size_t(v)]));
        drawn += draw[size_t(v)];
    }
    if (drawn > 0) {
        m_shadowDrawn = false;   // (until the layers are whole)
        const std::string err = drawShadowLayers(items, draw);
        if (!err.empty()) return err;
        m_shadowDrawnViews = m_shadowPlan.views;
        m_shadowDrawnCasters = std::move(casters);
        m_shadowDrawn = true;
    }
    stats.shadowMapsDrawn = drawn;

    // The plan for shadow.glsl, and the maps on their unit for the frame's draws.
    ShadowBlock b{};
    for (int v = 0; v < layers; ++v) {
        const ShadowView& sv = m_shadowPlan.views[size_t(v)];
        std::memcpy(b.viewProj[v], &sv.viewProj[0][0], sizeof b.viewProj[v]);
        for (int c = 0; c < 4; ++c) {
            b.axis[v][c] = sv.view[c][2];
            b.rowX[v][c] = sv.view[c][0];
            b.rowY[v][c] = sv.view[c][1];
        }
        b.view[v][0] = sv.perspective ? 1.0f : 0.0f;
        b.view[v][1] = sv.nearZ;
        b.view[v][2] = sv.farZ;
        b.view[v][3] = sv.texelAtUnit;
    }
    const size_t lights = std::min(m_shadowPlan.viewCount.size(), size_t(kMaxLights));
    for (size_t l = 0; l < lights; ++l) {
        b.light[l][0] = m_shadowPlan.firstView[l];
        b.light[l][1] = m_shadowPlan.viewCount[l];
    }
    b.params[0] = float(N);
    b.params[1] = m_shadowPlan.depthBias;
    b.params[2] = m_shadowPlan.normalBias;
    if (!m_shadowUbo) glGenBuffers(1, &m_shadowUbo);
    glBindBuffer(GL_UNIFORM_BUFFER, m_shadowUbo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof b, &b, GL_DYNAMIC_DRAW);
    glBindBufferBase(GL_UNIFORM_BUFFER, kShadowBinding, m_shadowUbo);
    glBindBuffer(GL_UNIFORM_BUFFER, 0);
    glActiveTexture(GLenum(GL_TEXTURE0 + kShadowUnit));
    glBindTexture(GL_TEXTURE_2D_ARRAY, m_shadowTexture);
    glActiveTexture(GL_TEXTURE0);
    return {};
}

// Layer `view` of the last frame's maps as a one-map ShadowMaps (N x N, row 0 at v = 0, as
// glReadPixels gives it), read back on first use in a frame; null without one. The caller
// makes the maps' context current and restores the read state.
const ShadowMaps* GlRenderer::shadowLayer(int view) {
    if (m_shadowPlan.empty() || view < 0 || view >= m_shadowTextureLayers || !m_shadowTexture || !m_shadowFbo ||
        m_shadowTextureSize != m_shadowPlan.size)
        return nullptr;
    auto it = m_shadowReadBack.find(view);
    if (it != m_shadowReadBack.end()) return &it->second;
    const int N = m_shadowPlan.size;
    ShadowMaps maps;
    maps.size = N;
    maps.depth.resize(size_t(N) * size_t(N));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, m_shadowFbo);
    glFramebufferTextureLayer(GL_READ_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, m_shadowTexture, 0, view);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, N, N, GL_DEPTH_COMPONENT, GL_FLOAT, maps.depth.data());
    if (glGetError() != GL_NO_ERROR) return nullptr;
    return &m_shadowReadBack.emplace(view, std::move(maps)).first->second;
}

void GlRenderer::releaseShadows() {
    if (m_shadowTexture) glDeleteTextures(1, &m_shadowTexture);
    if (m_shadowFbo) glDeleteFramebuffers(1, &m_shadowFbo);
    if (m_shadowUbo) glDeleteBuffers(1, &m_shadowUbo);
    if (m_shadowProgram) glDeleteProgram(m_shadowProgram);
    forgetShadows();
}

void GlRenderer::forgetShadows() {
    m_shadowTexture = m_shadowFbo = m_shadowUbo = m_shadowProgram = 0;
    m_shadowModel = m_shadowViewProj = -1;
    m_shadowTextureSize = m_shadowTextureLayers = 0;
    m_shadowPlan = ShadowPlan{};
    m_shadowReadBack.clear();
    m_shadowDrawn = false;
    m_shadowDrawnViews.clear();
    m_shadowDrawnCasters.clear();
}

}   // namespace rnd::gl
