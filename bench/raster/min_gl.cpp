// min_gl.cpp - the minimal GL reference of bench_raster (see min_gl.h): the shader, the two
// submissions (the scene's order unindexed; the fair one indexed, nearest first, culled as ours)
// and the frame (clear, draw, glReadPixels).
#include "min_gl.h"

#include "gl/gl_context.h"

#include <glad/gl.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace bench {

namespace {

const char* kVert = R"(#version 330 core
layout(location = 0) in vec3 aPos;      // world
layout(location = 1) in vec3 aNormal;   // world, unit
layout(location = 2) in vec4 aColor;    // rgb: base colour, a: ks
uniform mat4 uViewProj;
uniform mat4 uView;
out vec3 vPos;
out vec3 vNormal;
out vec3 vEye;
out vec4 vColor;
void main() {
    vPos = aPos;
    vNormal = aNormal;
    vEye = (uView * vec4(aPos, 1.0)).xyz;
    vColor = aColor;
    gl_Position = uViewProj * vec4(aPos, 1.0);
}
)";

// Phong (rnd::shade with REFLECTION_PHONG, untinted specular), two-sided, linear fog on the
// eye-space distance.
const char* kFrag = R"(
in vec3 vPos;
in vec3 vNormal;
in vec3 vEye;
in vec4 vColor;
out vec4 oColor;
uniform vec4 uLightPos[NUM_LIGHTS];   // xyz: position (w = 1, point) or direction toward the light (w = 0)
uniform vec3 uLightRad[NUM_LIGHTS];
uniform vec3 uEyePos;
uniform vec3 uAmbient;
uniform float uKa;
uniform float uKd;
uniform float uShininess;
uniform vec3 uFogColor;
uniform vec2 uFog;   // start, end
void main() {
    vec3 n = normalize(vNormal);
    if (!gl_FrontFacing) n = -n;
    vec3 v = normalize(uEyePos - vPos);
    vec3 mul = uKa * uAmbient, add = vec3(0.0);
    for (int i = 0; i < NUM_LIGHTS; ++i) {
        vec3 l = uLightPos[i].w > 0.0 ? normalize(uLightPos[i].xyz - vPos) : uLightPos[i].xyz;
        float nl = dot(n, l);
        if (nl <= 0.0) continue;
        vec3 r = 2.0 * nl * n - l;
        float spec = max(dot(r, v), 0.0);
        spec = spec > 0.0 ? pow(spec, uShininess) : 0.0;
        vec3 ln = uLightRad[i] * nl;
        mul += ln * uKd;
        add += ln * (vColor.a * spec);
    }
    vec3 c = vColor.rgb * mul + add;
    float f = clamp((uFog.y - length(vEye)) / (uFog.y - uFog.x), 0.0, 1.0);
    oColor = vec4(f * c + (1.0 - f) * uFogColor, 1.0);
}
)";

GLuint compile(GLenum type, const std::string& src, std::string& err) {
    GLuint s = glCreateShader(type);
    const char* p = src.c_str();
    glShaderSource(s, 1, &p, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        err = log;
    }
    return s;
}

// Order::Fair sorts clusters of this many consecutive triangles of one mesh (not single
// triangles: neighbours share vertices, which llvmpipe's vertex cache reuses within a draw);
// BENCH_GL_CLUSTER overrides it.
size_t clusterSize() {
    const char* e = std::getenv("BENCH_GL_CLUSTER");
    return e ? std::max<size_t>(1, size_t(std::atol(e))) : 64;
}

// Appends vertex v of draw d (world position, world normal, base colour, ks) to `data`.
void pushVertex(std::vector<float>& data, const sg::DrawMesh& d, uint32_t v) {
    const sg::Mesh& mesh = *d.mesh;
    const sg::vec3 p = sg::vec3(d.world * sg::vec4(mesh.positions[v], 1.0f));
    const sg::vec3 n = mesh.normals.size() == mesh.positions.size() ? glm::normalize(d.normal * mesh.normals[v]) : sg::vec3(0, 1, 0);
    data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z, d.material.baseColor.x, d.material.baseColor.y, d.material.baseColor.z, d.material.ks});
}

}   // namespace

// One glDrawElements of the fair submission: `count` indices from `first`, culling back faces or not.
struct DrawRun {
    size_t first = 0, count = 0;
    bool cull = false;
};

struct MinimalGl::State {
    std::unique_ptr<rnd::gl::GlContext> ctx;
    GLuint prog = 0, vao = 0, vbo = 0, fbo = 0, rbColor = 0, rbDepth = 0;
    GLuint ibo = 0;
    int width = 0, height = 0;
    sg::vec3 background{0.0f};
    MinimalGl::Order order = MinimalGl::Order::Scene;
    std::vector<DrawRun> runs;   // Order::Fair
};

void MinimalGl::activate() {
    if (m && m->ctx && !m->ctx->isCurrent()) m->ctx->makeCurrent();
}

size_t MinimalGl::draws() const { return !m ? 0 : m->order == Order::Scene ? 1 : m->runs.size(); }

MinimalGl::MinimalGl() = default;

MinimalGl::~MinimalGl() {
    if (!m || !m->ctx || !m->ctx->makeCurrent()) return;
    glDeleteProgram(m->prog);
    glDeleteBuffers(1, &m->vbo);
    glDeleteBuffers(1, &m->ibo);
    glDeleteVertexArrays(1, &m->vao);
    glDeleteFramebuffers(1, &m->fbo);
    glDeleteRenderbuffers(1, &m->rbColor);
    glDeleteRenderbuffers(1, &m->rbDepth);
    m->ctx->release();
}

std::string MinimalGl::setup(const sg::FrameInput& f, int width, int height, Order order) {
    m = std::make_unique<State>();
    std::string err;
    m->ctx = rnd::gl::createHeadlessContext("", &err);
    if (!m->ctx) return err;
    if (!m->ctx->makeCurrent(&err)) return err;
    if (std::string e = rnd::gl::loadGLFunctions(); !e.empty()) return e;
    m->width = width;
    m->height = height;
    m->background = f.settings.background;
    m->order = order;

    // Interleaved world-space vertices: position, normal, colour (rgb base colour, a ks).
    std::vector<float> data;
    std::vector<uint32_t> indices;   // Order::Fair
    if (order == Order::Scene) {
        for (const sg::DrawMesh& d : f.meshes) {
            if (!d.mesh || d.mesh->mode != sg::PrimitiveMode::Triangles) continue;
            for (uint32_t i : d.mesh->indices) pushVertex(data, d, i);
        }
        m_triangles = data.size() / 30;
    } else {
        // Each mesh's vertices once; its triangles in clusters of kCluster, each cluster with
        // its distance from the eye (to the nearest point of its bounds) and whether our
        // rasterizer culls its back faces. Mirrored draws swap two corners, so that front
        // faces wind counter-clockwise in world space for every draw.
        struct Cluster {
            float distance;
            bool cull;
            size_t first, count;   // into `tris`
        };
        std::vector<uint32_t> tris;
        std::vector<Cluster> clusters;
        for (const sg::DrawMesh& d : f.meshes) {
            if (!d.mesh || d.mesh->mode != sg::PrimitiveMode::Triangles) continue;
            const sg::Mesh& mesh = *d.mesh;
            const uint32_t base = uint32_t(data.size() / 10);
            for (uint32_t v = 0; v < uint32_t(mesh.positions.size()); ++v) pushVertex(data, d, v);
            const bool cull = sg::cullsBackFaces(f.settings.culling, d.material.doubleSided);
            const size_t nt = mesh.indices.size() / 3;
            const size_t kCluster = clusterSize();
            for (size_t t0 = 0; t0 < nt; t0 += kCluster) {
                Cluster c{0.0f, cull, tris.size(), 0};
                sg::Aabb box;
                for (size_t t = t0; t < std::min(t0 + kCluster, nt); ++t) {
                    uint32_t v[3] = {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
                    if (d.mirrored) std::swap(v[1], v[2]);
                    for (uint32_t k : v) {
                        tris.push_back(base + k);
                        const float* p = &data[size_t(base + k) * 10];
                        box.extend(sg::vec3(p[0], p[1], p[2]));
                    }
                }
                c.count = tris.size() - c.first;
                c.distance = glm::length(f.camera.eye - glm::clamp(f.camera.eye, box.min, box.max));
                clusters.push_back(c);
            }
        }
        std::stable_sort(clusters.begin(), clusters.end(), [](const Cluster& a, const Cluster& b) { return a.distance < b.distance; });
        for (const Cluster& c : clusters) {
            if (m->runs.empty() || m->runs.back().cull != c.cull) m->runs.push_back({indices.size(), 0, c.cull});
            indices.insert(indices.end(), tris.begin() + std::ptrdiff_t(c.first), tris.begin() + std::ptrdiff_t(c.first + c.count));
            m->runs.back().count += c.count;
        }
        m_triangles = indices.size() / 3;
    }
    m_vertices = data.size() / 10;

    int nl = std::max<int>(1, int(f.lights.size()));
    std::string fragSrc = "#version 330 core\n#define NUM_LIGHTS " + std::to_string(nl) + "\n" + kFrag;
    GLuint vs = compile(GL_VERTEX_SHADER, kVert, err);
    if (!err.empty()) return "vertex shader: " + err;
    GLuint fs = compile(GL_FRAGMENT_SHADER, fragSrc, err);
    if (!err.empty()) return "fragment shader: " + err;
    m->prog = glCreateProgram();
    glAttachShader(m->prog, vs);
    glAttachShader(m->prog, fs);
    glLinkProgram(m->prog);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(m->prog, GL_LINK_STATUS, &ok);
    if (!ok) return "link failed";
    glUseProgram(m->prog);
    auto loc = [&](const char* n) { return glGetUniformLocation(m->prog, n); };
    glUniformMatrix4fv(loc("uViewProj"), 1, GL_FALSE, &f.camera.viewProj[0][0]);
    glUniformMatrix4fv(loc("uView"), 1, GL_FALSE, &f.camera.view[0][0]);
    std::vector<sg::vec4> lp(size_t(nl), sg::vec4(0, 1, 0, 0));
    std::vector<sg::vec3> lr(size_t(nl), sg::vec3(0.0f));
    for (size_t i = 0; i < f.lights.size(); ++i) {
        const sg::DrawLight& l = f.lights[i];
        lp[i] = l.type == sg::LightType::Directional ? sg::vec4(-l.direction, 0.0f) : sg::vec4(l.position, 1.0f);
        lr[i] = l.radiance;
    }
    glUniform4fv(loc("uLightPos"), nl, &lp[0].x);
    glUniform3fv(loc("uLightRad"), nl, &lr[0].x);
    glUniform3fv(loc("uEyePos"), 1, &f.camera.eye.x);
    glUniform3fv(loc("uAmbient"), 1, &f.ambientLight.x);
    const sg::Material mat = f.meshes.empty() ? sg::Material{} : f.meshes[0].material;
    glUniform1f(loc("uKa"), mat.ka);
    glUniform1f(loc("uKd"), mat.kd);
    glUniform1f(loc("uShininess"), mat.shininess);
    glUniform3fv(loc("uFogColor"), 1, &f.settings.fogColor.x);
    glUniform2f(loc("uFog"), f.settings.fogStart, f.settings.fogEnd);

    glGenVertexArrays(1, &m->vao);
    glBindVertexArray(m->vao);
    glGenBuffers(1, &m->vbo);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
    const GLsizei stride = 10 * sizeof(float);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, nullptr);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(3 * sizeof(float)));
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(6 * sizeof(float)));
    for (GLuint a = 0; a < 3; ++a) glEnableVertexAttribArray(a);
    if (order == Order::Fair) {
        glGenBuffers(1, &m->ibo);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->ibo);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(uint32_t)), indices.data(), GL_STATIC_DRAW);
    }

    glGenRenderbuffers(1, &m->rbColor);
    glBindRenderbuffer(GL_RENDERBUFFER, m->rbColor);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_SRGB8_ALPHA8, width, height);
    glGenRenderbuffers(1, &m->rbDepth);
    glBindRenderbuffer(GL_RENDERBUFFER, m->rbDepth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glGenFramebuffers(1, &m->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, m->fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, m->rbColor);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, m->rbDepth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) return "framebuffer incomplete";
    glEnable(GL_FRAMEBUFFER_SRGB);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glViewport(0, 0, width, height);
    glClearColor(m->background.x, m->background.y, m->background.z, 1.0f);
    if (glGetError() != GL_NO_ERROR) return "GL error during setup";
    return {};
}

void MinimalGl::render(std::vector<uint8_t>& rgba) {
    activate();
    rgba.resize(size_t(m->width) * m->height * 4);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (m->order == Order::Scene)
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(m_vertices));
    else
        for (const DrawRun& r : m->runs) {
            if (r.cull)
                glEnable(GL_CULL_FACE);
            else
                glDisable(GL_CULL_FACE);
            glDrawElements(GL_TRIANGLES, GLsizei(r.count), GL_UNSIGNED_INT, reinterpret_cast<const void*>(r.first * sizeof(uint32_t)));
        }
    glReadPixels(0, 0, m->width, m->height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
}

}   // namespace bench
