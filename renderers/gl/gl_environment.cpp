// gl_environment.cpp - pbr's environment light in the GL backend: the textures (EnvironmentMap's
// prefiltered levels as the mip levels of one RGB32F texture on unit 5, the split-sum table as an
// RG32F texture on unit 6), bound for the frame, and the background pass that draws the
// environment where no surface is (pbr.glsl's envSpecular at roughness 0, as the CPU backends'
// EnvironmentLight::backgroundRadiance).
#include "gl/gl_internal.h"
#include "renderers/pbr.h"

namespace rnd::gl {

using namespace sg;

namespace {

const char* const kBackgroundVert = R"GLSL(
out vec2 vNdc;
void main() {
    // One triangle over the viewport, at the far plane.
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    vNdc = p;
    gl_Position = vec4(p, 1.0, 1.0);
}
)GLSL";

const char* const kBackgroundFrag = R"GLSL(
in vec2 vNdc;
uniform mat4 uInvViewProj;
layout(location = 0) out vec4 fragColor;
void main() {
    vec4 a = uInvViewProj * vec4(vNdc, -1.0, 1.0), b = uInvViewProj * vec4(vNdc, 1.0, 1.0);
    vec3 dir = normalize(b.xyz / b.w - a.xyz / a.w);
    fragColor = vec4(max(envSpecular(dir, 0.0), 0.0), 1.0);   // unclamped for the linear target (tone mapping)
}
)GLSL";

}   // namespace

void GlRenderer::prepareEnvironment(const FrameInput& frame, RenderStats& stats) {
    std::string envError;
    m_environment = environmentFor(frame.settings, &envError);
    if (!envError.empty()) stats.config.notes.push_back("environment " + envError + " (lit without it)");
    if (!m_environment.map) return;
    if (!m_splitSumTexture) {
        const std::vector<vec2>& t = splitSumTable();
        glGenTextures(1, &m_splitSumTexture);
        glBindTexture(GL_TEXTURE_2D, m_splitSumTexture);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RG32F, kSplitSumSize, kSplitSumSize, 0, GL_RG, GL_FLOAT, t.data());
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    if (m_envUploaded != m_environment.map.get()) {
        if (!m_envTexture) glGenTextures(1, &m_envTexture);
        glBindTexture(GL_TEXTURE_2D, m_envTexture);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        for (int k = 0; k < EnvironmentMap::kLevels; ++k) {
            const EnvironmentMap::Level& l = m_environment.map->level(k);
            glTexImage2D(GL_TEXTURE_2D, k, GL_RGB32F, l.width, l.height, 0, GL_RGB, GL_FLOAT, l.rgb.data());
        }
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, EnvironmentMap::kLevels - 1);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        m_envUploaded = m_environment.map.get();
    }
    glActiveTexture(GL_TEXTURE5);
    glBindTexture(GL_TEXTURE_2D, m_envTexture);
    glActiveTexture(GL_TEXTURE6);
    glBindTexture(GL_TEXTURE_2D, m_splitSumTexture);
    glActiveTexture(GL_TEXTURE0);
}

void GlRenderer::drawEnvironmentBackground(const FrameInput& frame, std::string& error) {
    if (!m_backgroundProgram) {
        const std::string head = "#version 330 core\n#define HAS_ENVIRONMENT 1\n";
        error = linkProgram(head + kBackgroundVert, head + kShader_pbr_glsl + "\n" + kBackgroundFrag, "environment background shader",
                            m_backgroundProgram);
        if (!error.empty()) return;
        glGenVertexArrays(1, &m_backgroundVao);
    }
    glUseProgram(m_backgroundProgram);
    m_current = nullptr;   // the mesh programs must be made current again
    auto loc = [&](const char* n) { return glGetUniformLocation(m_backgroundProgram, n); };
    const mat4 inv = glm::inverse(frame.camera.viewProj);
    glUniformMatrix4fv(loc("uInvViewProj"), 1, GL_FALSE, &inv[0][0]);
    glUniform1i(loc("uEnvMap"), 5);
    glUniform1f(loc("uEnvIntensity"), m_environment.intensity);
    glUniform2f(loc("uEnvRotation"), m_environment.cosRot, m_environment.sinRot);
    glUniform1f(loc("uEnvLevels"), float(EnvironmentMap::kLevels));
    // Where the depth is still the cleared far value: no surface.
    glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(m_backgroundVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

void GlRenderer::releaseEnvironment() {
    if (m_envTexture) glDeleteTextures(1, &m_envTexture);
    if (m_splitSumTexture) glDeleteTextures(1, &m_splitSumTexture);
    if (m_backgroundProgram) glDeleteProgram(m_backgroundProgram);
    if (m_backgroundVao) glDeleteVertexArrays(1, &m_backgroundVao);
    forgetEnvironment();
}

void GlRenderer::forgetEnvironment() {
    m_envTexture = m_splitSumTexture = m_backgroundProgram = m_backgroundVao = 0;
    m_envUploaded = nullptr;
}

}   // namespace rnd::gl
