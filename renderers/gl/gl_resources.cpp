// gl_resources.cpp - the GL backend's GPU objects (gl_internal.h): the cache of meshes
// (tessellations included) and textures, uploaded once per (id, version), reused by every
// instance and frame and evicted after kEvictAfterFrames unused frames; the render targets
// (multisampled or single-sample colour + depth FBOs, sRGB8 or linear float, with an optional
// visibility attachment, the overdraw view's count target); the frame's draw list, sorted nearest first; texture
// binding; and reading images back.
#include "gl/gl_internal.h"

#include "renderers/draw_list.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <numeric>

namespace rnd::gl {

using namespace sg;

// --- GPU cache: meshes and textures ------------------------------------------------------------

namespace {

// Interleaved vertex: position, normal, uv0, colour (missing attributes get defaults).
struct Vertex {
    float p[3], n[3], uv[2], c[4];
};

GLint glWrap(WrapMode w) {
    switch (w) {
    case WrapMode::Repeat: return GL_REPEAT;
    case WrapMode::ClampToEdge: return GL_CLAMP_TO_EDGE;
    case WrapMode::MirroredRepeat: return GL_MIRRORED_REPEAT;
    }
    return GL_REPEAT;
}

}   // namespace

void releaseMesh(GpuMesh& m) {
    if (m.vao) glDeleteVertexArrays(1, &m.vao);
    if (m.vbo) glDeleteBuffers(1, &m.vbo);
    if (m.ebo) glDeleteBuffers(1, &m.ebo);
    if (m.tbo) glDeleteBuffers(1, &m.tbo);
    if (m.u1bo) glDeleteBuffers(1, &m.u1bo);
    m.vao = m.vbo = m.ebo = m.tbo = m.u1bo = 0;
}

void uploadMesh(GpuMesh& g, const Mesh& mesh, const std::vector<uint16_t>* triangleMaterial) {
    releaseMesh(g);
    g.version = mesh.version;
    g.ranges.clear();
    g.triangles = 0;
    g.valid = mesh.validate().empty() && !mesh.positions.empty();
    if (!g.valid) return;
    g.colors = !mesh.colors.empty();

    // Triangle meshes without normals get smooth ones (flat shading ignores them anyway).
    const std::vector<vec3>* normals = &mesh.normals;
    std::vector<vec3> computed;
    if (mesh.normals.size() != mesh.positions.size() && mesh.mode == PrimitiveMode::Triangles) {
        Mesh tmp;
        tmp.positions = mesh.positions;
        tmp.indices = mesh.indices;
        if (tmp.indices.empty()) {
            tmp.indices.resize(tmp.positions.size() / 3 * 3);
            std::iota(tmp.indices.begin(), tmp.indices.end(), 0u);
        }
        tmp.computeNormals();
        computed = std::move(tmp.normals);
        normals = &computed;
    }
    Aabb box = mesh.bounds();
    g.centre = box.empty() ? vec3(0.0f) : 0.5f * (box.min + box.max);
    std::vector<Vertex> verts(mesh.positions.size());
    for (size_t i = 0; i < verts.size(); ++i) {
        Vertex& v = verts[i];
        const vec3& p = mesh.positions[i];
        vec3 n = i < normals->size() ? (*normals)[i] : vec3(0, 0, 1);
        vec2 uv = i < mesh.uv0.size() ? mesh.uv0[i] : vec2(0.0f);
        vec4 c = i < mesh.colors.size() ? mesh.colors[i] : vec4(1.0f);
        v = {{p.x, p.y, p.z}, {n.x, n.y, n.z}, {uv.x, uv.y}, {c.r, c.g, c.b, c.a}};
    }

    std::vector<uint32_t> indices = mesh.indices;
    int per = mesh.mode == PrimitiveMode::Triangles ? 3 : mesh.mode == PrimitiveMode::Lines ? 2 : 1;
    if (indices.empty()) {
        indices.resize(mesh.positions.size() / per * per);
        std::iota(indices.begin(), indices.end(), 0u);
    }
    indices.resize(indices.size() / per * per);
    g.primitive = per == 3 ? GL_TRIANGLES : per == 2 ? GL_LINES : GL_POINTS;
    size_t prims = indices.size() / per;
    if (per == 3) g.triangles = prims;

    if (triangleMaterial && per == 3 && triangleMaterial->size() == prims) {
        // Stable sort of the triangles by material, one draw range per material.
        std::vector<uint32_t> order(prims);
        std::iota(order.begin(), order.end(), 0u);
        std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return (*triangleMaterial)[a] < (*triangleMaterial)[b]; });
        std::vector<uint32_t> sorted(indices.size());
        for (size_t t = 0; t < prims; ++t) {
            std::copy_n(&indices[size_t(order[t]) * 3], 3, &sorted[t * 3]);
            int m = (*triangleMaterial)[order[t]];
            if (g.ranges.empty() || g.ranges.back().material != m) g.ranges.push_back({GLsizei(t * 3), 0, m});
            g.ranges.back().count += 3;
        }
        indices = std::move(sorted);
    } else {
        g.ranges.push_back({0, GLsizei(indices.size()), -1});
    }

    glGenVertexArrays(1, &g.vao);
    glBindVertexArray(g.vao);
    glGenBuffers(1, &g.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(verts.size() * sizeof(Vertex)), verts.data(), GL_STATIC_DRAW);
    glGenBuffers(1, &g.ebo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(uint32_t)), indices.data(), GL_STATIC_DRAW);
    auto attrib = [](GLuint loc, GLint n, size_t offset) {
        glEnableVertexAttribArray(loc);
        glVertexAttribPointer(loc, n, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<const void*>(offset));
    };
    attrib(0, 3, offsetof(Vertex, p));
    attrib(1, 3, offsetof(Vertex, n));
    attrib(2, 2, offsetof(Vertex, uv));
    attrib(3, 4, offsetof(Vertex, c));
    if (per == 3 && mesh.tangents.size() == mesh.positions.size()) {   // normal maps: own buffer, other meshes pay nothing
        glGenBuffers(1, &g.tbo);
        glBindBuffer(GL_ARRAY_BUFFER, g.tbo);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.tangents.size() * sizeof(vec4)), mesh.tangents.data(), GL_STATIC_DRAW);
        glEnableVertexAttribArray(4);
        glVertexAttribPointer(4, 4, GL_FLOAT, GL_FALSE, sizeof(vec4), nullptr);
    }
    if (per == 3 && mesh.uv1.size() == mesh.positions.size()) {   // maps on a second UV set: own buffer too
        glGenBuffers(1, &g.u1bo);
        glBindBuffer(GL_ARRAY_BUFFER, g.u1bo);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.uv1.size() * sizeof(vec2)), mesh.uv1.data(), GL_STATIC_DRAW);
        glEnableVertexAttribArray(5);
        glVertexAttribPointer(5, 2, GL_FLOAT, GL_FALSE, sizeof(vec2), nullptr);
    }
    glBindVertexArray(0);
}

// Texture rows are stored top to bottom with row 0 at v = 1: upload them bottom row first so
// that GL's t = v.
bool uploadTexture(GpuTexture& g, const Texture& t) {
    if (g.id) glDeleteTextures(1, &g.id);
    g.id = 0;
    g.version = t.version;
    g.srgb = t.srgb;
    if (t.width <= 0 || t.height <= 0 || t.rgba.size() < size_t(t.width) * t.height * 4) return false;
    std::vector<uint8_t> flipped(size_t(t.width) * t.height * 4);
    size_t row = size_t(t.width) * 4;
    for (int y = 0; y < t.height; ++y) std::memcpy(&flipped[size_t(y) * row], &t.rgba[size_t(t.height - 1 - y) * row], row);
    glGenTextures(1, &g.id);
    glBindTexture(GL_TEXTURE_2D, g.id);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    // Colour textures decode sRGB when sampled; data textures (normal, metallic-roughness,
    // occlusion) are linear, stored as RGBA16 (the 8-bit values exactly): llvmpipe filters RGBA8
    // with 8-bit weights, which sharp highlights on normal maps turn into visible differences
    // (SheenCloth: 99.3% of pixels within 3/255 of the CPU backends with RGBA8, 99.99% with RGBA16).
    glTexImage2D(GL_TEXTURE_2D, 0, t.srgb ? GL_SRGB8_ALPHA8 : GL_RGBA16, t.width, t.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, flipped.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    GLint minF = t.filter == FilterMode::Nearest ? GL_NEAREST : t.filter == FilterMode::Bilinear ? GL_LINEAR : GL_LINEAR_MIPMAP_LINEAR;
    GLint magF = t.filter == FilterMode::Nearest ? GL_NEAREST : GL_LINEAR;
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, minF);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, magF);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, glWrap(t.wrapS));
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, glWrap(t.wrapT));
    return true;
}

// --- render targets ---------------------------------------------------------------------------

void RenderTarget::release() {
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (color) glDeleteRenderbuffers(1, &color);
    if (colorTexture) glDeleteTextures(1, &colorTexture);
    if (depth) glDeleteRenderbuffers(1, &depth);
    if (ids) glDeleteRenderbuffers(1, &ids);
    fbo = color = colorTexture = depth = ids = 0;
    width = height = samples = 0;
    hdr = false;
}

std::string RenderTarget::ensure(int w, int h, int s, bool withIds, bool linear) {
    if (fbo && w == width && h == height && s == samples && withIds == (ids != 0) && linear == hdr) return {};
    release();
    width = w;
    height = h;
    samples = s;
    hdr = linear;
    if (withIds) {   // single-sampled only (RenderConfig::aovs' Visibility)
        glGenRenderbuffers(1, &ids);
        glBindRenderbuffer(GL_RENDERBUFFER, ids);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_RG32UI, w, h);
    }
    const GLenum format = linear ? GL_RGBA16F : GL_SRGB8_ALPHA8;
    if (linear && s <= 1) {   // a texture, for the display pass to read
        glGenTextures(1, &colorTexture);
        glBindTexture(GL_TEXTURE_2D, colorTexture);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, w, h, 0, GL_RGBA, GL_FLOAT, nullptr);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
        glBindTexture(GL_TEXTURE_2D, 0);
    } else {
        glGenRenderbuffers(1, &color);
        glBindRenderbuffer(GL_RENDERBUFFER, color);
        if (s > 1)
            glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, format, w, h);
        else
            glRenderbufferStorage(GL_RENDERBUFFER, format, w, h);
    }
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    if (s > 1)
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, GL_DEPTH_COMPONENT32F, w, h);
    else
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    if (colorTexture)
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colorTexture, 0);
    else
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    if (ids) glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_RENDERBUFFER, ids);
    glDrawBuffer(GL_COLOR_ATTACHMENT0);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "%sframebuffer %dx%d with %d samples is incomplete (status 0x%x)", linear ? "float " : "", w, h, s, status);
        release();
        return buf;
    }
    return {};
}

void CountTarget::release() {
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (count) glDeleteRenderbuffers(1, &count);
    fbo = count = 0;
    width = height = 0;
}

std::string CountTarget::ensure(int w, int h) {
    if (fbo && w == width && h == height) return {};
    release();
    width = w;
    height = h;
    glGenRenderbuffers(1, &count);
    glBindRenderbuffer(GL_RENDERBUFFER, count);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_R32F, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, count);
    glDrawBuffer(GL_COLOR_ATTACHMENT0);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "overdraw framebuffer %dx%d (R32F) is incomplete (status 0x%x)", w, h, status);
        release();
        return buf;
    }
    return {};
}

// --- the cache, the frame's draws, read-back -------------------------------------------------

GpuMesh* GlRenderer::meshFor(const Mesh& mesh, const std::vector<uint16_t>* triangleMaterial) {
    GpuMesh& g = m_meshes[mesh.id];
    g.id = mesh.id;
    if (g.version != mesh.version || (!g.vao && g.valid)) {
        uploadMesh(g, mesh, triangleMaterial);
        ++m_meshUploads;
    }
    g.lastUsed = m_frame;
    return g.valid ? &g : nullptr;
}

GpuTexture* GlRenderer::textureFor(const TexturePtr& t) {
    if (!t) return nullptr;
    GpuTexture& g = m_textures[t->id];
    if (g.version != t->version || g.srgb != t->srgb) {
        uploadTexture(g, *t);
        ++m_textureUploads;
    }
    g.lastUsed = m_frame;
    return g.id ? &g : nullptr;
}

void GlRenderer::evict() {
    for (auto it = m_meshes.begin(); it != m_meshes.end();) {
        if (m_frame - it->second.lastUsed > kEvictAfterFrames) {
            releaseMesh(it->second);
            it = m_meshes.erase(it);
        } else {
            ++it;
        }
    }
    for (auto it = m_textures.begin(); it != m_textures.end();) {
        if (m_frame - it->second.lastUsed > kEvictAfterFrames) {
            if (it->second.id) glDeleteTextures(1, &it->second.id);
            it = m_textures.erase(it);
        } else {
            ++it;
        }
    }
    m_tess.nextFrame(int(kEvictAfterFrames));
    // Light setups and materials come and go while editing: keep a bounded number of programs
    // (those this frame drew with stay).
    if (m_programs.size() > kMaxPrograms)
        for (auto it = m_programs.begin(); it != m_programs.end();) {
            if (it->second.lastUsed != m_frame) {
                glDeleteProgram(it->second.id);
                it = m_programs.erase(it);
            } else {
                ++it;
            }
        }
    m_current = nullptr;
}

// The draw's textures: the base colour on unit 0, its maps on units 1..4 (unit 0 left active).
// Units already holding the texture are left alone (each bind makes llvmpipe revalidate the
// samplers at the next draw).
void GlRenderer::bindTextures(const DrawItem& it) {
    const GpuTexture* want[5] = {it.texture, it.maps[0], it.maps[1], it.maps[2], it.maps[3]};
    for (int u = 4; u >= 0; --u) {
        const GLuint id = want[u] ? want[u]->id : 0;
        if (id == m_boundTexture[u]) continue;
        glActiveTexture(GLenum(GL_TEXTURE0 + u));
        glBindTexture(GL_TEXTURE_2D, id);
        m_boundTexture[u] = id;
    }
    glActiveTexture(GL_TEXTURE0);
}

// Draws for the frame from the shared draw list (renderers/draw_list.h), nearest first so
// that llvmpipe's early depth test skips shading hidden fragments. Uploads happen here, only
// for new or edited meshes and textures.
std::vector<DrawItem> GlRenderer::collectDraws(const FrameInput& frame, int tessellation, RenderControl* control) {
    std::vector<DrawItem> items;
    const std::vector<PreparedDraw> prepared = prepareDraws(frame, tessellation, m_tess, control);
    if (control && control->cancel.load()) return items;   // the caller gives up
    for (const PreparedDraw& p : prepared) {
        DrawItem it;
        it.gpu = meshFor(*p.mesh, p.triangleMaterial);
        if (!it.gpu) continue;
        it.world = p.world;
        it.normal = p.normal;
        it.mirrored = p.mirrored;
        it.drawable = p.drawable;
        it.analytic = p.analytic;
        it.material = p.material;
        it.rangeMaterials = p.materials;
        it.texture = textureFor(p.texture);
        it.maps[0] = textureFor(p.maps.emissive);
        it.maps[1] = textureFor(p.maps.occlusion);
        it.maps[2] = textureFor(p.maps.metallicRoughness);
        it.maps[3] = it.gpu->tbo ? textureFor(p.maps.normal) : nullptr;   // a normal map needs the mesh's tangents
        items.push_back(it);
    }
    std::vector<float> distance(items.size());
    for (size_t i = 0; i < items.size(); ++i) distance[i] = glm::length(vec3(*items[i].world * vec4(items[i].gpu->centre, 1.0f)) - frame.camera.eye);
    std::vector<uint32_t> order(items.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return distance[a] < distance[b]; });
    std::vector<DrawItem> sorted(items.size());
    for (size_t i = 0; i < order.size(); ++i) sorted[i] = items[order[i]];
    return sorted;
}

// Reads colour and depth of `fbo` into `out` (GL rows are bottom-up, Framebuffer rows
// top-down). With GL_MESA_pack_invert (Mesa, llvmpipe included) the driver writes the rows
// top-down straight into `out`; otherwise they pass through m_readRows (kept between frames, so
// no allocation, zero-fill or page faults per frame) and are flipped. Alpha needs no pass: the
// target's alpha is 1 everywhere (cleared to 1; every pass writes 1 or, blending, keeps it).
// withDepth false: the colour only, into `out` as it is (already w x h; the display pass's
// target, whose depth means nothing).
void GlRenderer::readBack(GLuint fbo, int w, int h, Framebuffer& out, bool withDepth) {
    if (withDepth) out.resizeForOverwrite(w, h);   // every pixel is written below
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    if (GLAD_GL_MESA_pack_invert) {
        GLint invert = GL_FALSE;
        glGetIntegerv(GL_PACK_INVERT_MESA, &invert);
        glPixelStorei(GL_PACK_INVERT_MESA, GL_TRUE);
        glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, out.color.data());
        if (withDepth) glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, out.depth.data());
        glPixelStorei(GL_PACK_INVERT_MESA, invert);
        return;
    }
    const size_t rowBytes = size_t(w) * 4;   // RGBA8 and float depth alike
    m_readRows.resize(rowBytes * h);
    auto flipInto = [&](uint8_t* dst) {
        for (int y = 0; y < h; ++y) std::memcpy(dst + size_t(y) * rowBytes, &m_readRows[size_t(h - 1 - y) * rowBytes], rowBytes);
    };
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, m_readRows.data());
    flipInto(out.color.data());
    if (!withDepth) return;
    glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, m_readRows.data());
    flipInto(reinterpret_cast<uint8_t*>(out.depth.data()));
}

// Reads the visibility attachment (drawable, primitive) of `fbo` into `out` (already sized).
void readVisibility(GLuint fbo, int w, int h, Framebuffer& out) {
    out.allocate(Aov::Visibility);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT1);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    std::vector<uint32_t> rg(size_t(w) * h * 2);
    glReadPixels(0, 0, w, h, GL_RG_INTEGER, GL_UNSIGNED_INT, rg.data());
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    for (int y = 0; y < h; ++y) {
        const uint32_t* src = &rg[size_t(h - 1 - y) * w * 2];
        for (int x = 0; x < w; ++x) {
            out.drawable[size_t(y) * w + x] = src[2 * x];
            out.primitive[size_t(y) * w + x] = src[2 * x + 1];
        }
    }
}

}   // namespace rnd::gl
