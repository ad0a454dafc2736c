// gl_renderer.cpp - the OpenGL 3.3+ core rasterization backend ("gl").
//
// Sections:
//   1. Shader programs (embedded GLSL from shaders/, one program per shading model,
//      reflection model, fog mode, light setup and the draw's feature switches, compiled on
//      first use)
//   2. GPU cache: meshes (incl. tessellations) and textures keyed by id + version
//   3. Render targets: multisampled / single-sample FBOs, read-back
//   4. State guard: restores the caller's GL state when we borrow its context
//   5. GlRenderer::render: context, frame uniforms, draws, wireframe, resolve, SSAA
//
// Conventions (shared with the CPU backends, see renderers/shading.h): lighting in linear
// space in world coordinates, sRGB8_ALPHA8 targets with GL_FRAMEBUFFER_SRGB, sRGB textures
// decoded on sampling, two-sided lighting by gl_FrontFacing (glFrontFace(GL_CW) for mirrored
// instances), fog on the eye-space distance. Gouraud lights the vertices with the albedo
// factored out (colour = rho * mul + add, see lighting.glsl), so textures still apply per
// fragment. Lines and points are drawn unlit (base colour x vertex colour + emissive).
// Texture filters: nearest = GL_NEAREST, bilinear = GL_LINEAR without mipmaps, trilinear =
// GL_LINEAR_MIPMAP_LINEAR. Draws are sorted nearest first (early depth test on llvmpipe).
#include "gl/gl_renderer.h"

#include "gl/gl_context.h"
#include "renderers/draw_list.h"
#include "renderers/tessellate.h"
#include "scenegraph/setting_names.h"

#include <glad/gl.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <numeric>
#include <unordered_map>

namespace rnd::gl {
extern const char* const kShader_lighting_glsl;
extern const char* const kShader_mesh_vert;
extern const char* const kShader_mesh_frag;
}   // namespace rnd::gl

namespace rnd {

namespace {

using namespace sg;

constexpr int kMaxLights = 32;          // lights beyond this are ignored (uniform arrays)
constexpr int kMaxUnrolledLights = 8;   // more lights: one generic program with a loop
constexpr uint64_t kEvictAfterFrames = 120;
constexpr size_t kMaxPrograms = 64;   // beyond this, programs not used by the last frame are deleted

// --- 1. Shader programs ----------------------------------------------------------------------

// The compile-time switches of a draw (the list at the top of mesh.frag). A program is compiled
// per frame setup (programKey) and combination of these, on first use.
struct Features {
    bool texture = false;                                                                       // base colour texture
    bool emissiveMap = false, occlusionMap = false, metalRoughMap = false, normalMap = false;   // units 1..4
    bool specGloss = false;                                                                     // the metal-rough slot holds specular-glossiness
    bool uv1 = false;                                                                           // some map samples the mesh's uv1
    bool vertexColors = false;
    bool unlit = false;
    sg::AlphaMode alphaMode = sg::AlphaMode::Opaque;
    bool solid = false;        // the wireframe overlay
    bool overdraw = false;     // the overdraw view's pass
    bool visibility = false;   // writes the visibility attachment

    // One character per switch (part of the program's key).
    bool operator==(const Features&) const = default;
    std::string key() const {
        std::string k;
        for (bool b :
             {texture, emissiveMap, occlusionMap, metalRoughMap, normalMap, specGloss, uv1, vertexColors, unlit, solid, overdraw, visibility})
            k += b ? '1' : '0';
        return k + char('0' + int(alphaMode));
    }
};

struct Program {
    GLuint id = 0;
    uint64_t frameUniforms = 0;   // the frame whose uniforms (camera, lights, fog) it holds
    uint64_t lastUsed = 0;        // the frame that last drew with it
    bool hasMaterial = false;     // lastMaterial's values are in its uniforms
    Material lastMaterial;
    // Uniform locations (-1 where this program's switches leave a uniform out).
    GLint model = -1, normalMatrix = -1, viewProj = -1, view = -1, pointSize = -1;
    GLint numLights = -1, lightPos = -1, lightDir = -1, lightRad = -1, lightCone = -1;
    GLint eye = -1, ambient = -1;
    GLint baseColor = -1, ka = -1, kd = -1, ks = -1, shininess = -1, specTinted = -1, specColor = -1, emissive = -1;
    GLint texture = -1, solidColor = -1;
    // Material maps (texture units 1..4: emissive, occlusion, metallic-roughness, normal) and their factors.
    GLint maps[4] = {-1, -1, -1, -1}, occlusionStrength = -1, metallic = -1, roughness = -1, normalScale = -1;
    GLint glossiness = -1, uv1Maps = -1;
    GLint alpha = -1, alphaCutoff = -1;
    GLint fogColor = -1, fogParams = -1;
    GLint drawable = -1, primitiveBase = -1;   // visibility output (location 1)
};

std::string compileShader(GLenum type, const std::string& src, GLuint& out) {
    out = glCreateShader(type);
    const char* p = src.c_str();
    glShaderSource(out, 1, &p, nullptr);
    glCompileShader(out);
    GLint ok = 0;
    glGetShaderiv(out, GL_COMPILE_STATUS, &ok);
    if (ok) return {};
    char log[2048] = {};
    glGetShaderInfoLog(out, sizeof log, nullptr, log);
    std::string msg = log;
    std::replace(msg.begin(), msg.end(), '\n', ' ');
    return std::string(type == GL_VERTEX_SHADER ? "vertex" : "fragment") + " shader: " + msg;
}

}   // namespace

// Every settings enum value the shaders see, as a named constant with the C++ enum's own value
// (SHADING_PHONG, FOG_EXP2, LIGHT_SPOT, ...): the shaders compare against these names only, so
// reordering an enum cannot silently change what GLSL does, and a test checks that the shaders
// handle every name. Names come from the settings' name tables (scenegraph/setting_names.h,
// whose test checks that every enum value has an entry).
std::string glslEnumDefines() {
    std::string d;
    auto upper = [](std::string_view v) {
        std::string u(v);
        for (char& c : u) c = (c >= 'a' && c <= 'z') ? char(c - 'a' + 'A') : (c == '-' ? '_' : c);
        return u;
    };
    auto add = [&](const char* prefix, std::string_view name, int value) {
        d += std::string("#define ") + prefix + upper(name) + " " + std::to_string(value) + "\n";
    };
    auto all = [&](const char* prefix, const auto& table) {
        for (const auto& e : table.entries) add(prefix, e.name, int(e.value));
    };
    all("SHADING_", sg::nameTable<sg::ShadingModel>());
    all("REFLECTION_", sg::nameTable<sg::ReflectionModel>());
    all("FOG_", sg::nameTable<sg::FogMode>());
    all("LIGHT_", sg::nameTable<sg::LightType>());
    all("ALPHA_", sg::nameTable<sg::AlphaMode>());
    // The map bits of sg::Material::uv1Maps (which maps sample the second UV set).
    add("MAP_", "emissive", sg::Material::EmissiveMap);
    add("MAP_", "occlusion", sg::Material::OcclusionMap);
    add("MAP_", "metallic_roughness", sg::Material::MetallicRoughnessMap);
    add("MAP_", "normal", sg::Material::NormalMap);
    return d;
}

// "#define NAME PREFIX_VALUE\n" for a settings enum value: the name glslEnumDefines() gives it.
template <class E>
std::string glslEnumDefine(const char* name, const char* prefix, E value) {
    const auto* e = sg::nameTable<E>().find(value);
    std::string v = e ? std::string(e->name) : std::to_string(int(value));   // an unnamed value reaches the shader's #error
    for (char& c : v) c = (c >= 'a' && c <= 'z') ? char(c - 'a' + 'A') : (c == '-' ? '_' : c);
    return std::string("#define ") + name + " " + (e ? prefix + v : v) + "\n";
}

std::string glslSources() { return std::string(gl::kShader_lighting_glsl) + "\n" + gl::kShader_mesh_vert + "\n" + gl::kShader_mesh_frag; }

namespace {

// Programs are specialised per frame setup (see lighting.glsl): the key is the shading model,
// the reflection model, the fog mode and one letter per light (p/P point, d directional, s/S
// spot; upper case = inverse square), or '*' for the generic loop when there are many lights (a
// 30-light unrolled program takes seconds to compile on llvmpipe).
std::string programKey(const FrameInput& f) {
    std::string key;
    key += char('0' + int(f.settings.shading));
    key += char('0' + int(f.settings.reflection));
    key += char('0' + int(f.settings.fog));
    size_t n = std::min<size_t>(f.lights.size(), kMaxLights);
    if (n > size_t(kMaxUnrolledLights)) return key + '*';
    for (size_t i = 0; i < n; ++i) {
        const DrawLight& l = f.lights[i];
        char c = l.type == LightType::Point ? 'p' : l.type == LightType::Directional ? 'd' : 's';
        if (l.inverseSquare && c != 'd') c = char(c - 'a' + 'A');
        key += c;
    }
    return key;
}

// Builds the program of frame setup `key` (programKey) with the draw's switches `ft` for frame `f`.
std::string buildProgram(const std::string& key, const Features& ft, const FrameInput& f, Program& p) {
    constexpr size_t kLights = 3;   // where the lights start in the key
    std::string calls;
    if (key.size() > kLights && key[kLights] == '*')
        calls = "for (int i = 0; i < uNumLights; ++i) lightTerms(i, int(uLightPos[i].w + 0.5), uLightDir[i].w > 0.5, n, p, v, mul, add);";
    for (size_t i = kLights; i < key.size() && key[kLights] != '*'; ++i) {
        char c = char(key[i] | 0x20);
        const char* type = c == 'p' ? "LIGHT_POINT" : c == 'd' ? "LIGHT_DIRECTIONAL" : "LIGHT_SPOT";
        bool invSq = key[i] >= 'A' && key[i] <= 'Z';
        calls += "lightTerms(" + std::to_string(i - kLights) + ", " + type + ", " + (invSq ? "true" : "false") + ", n, p, v, mul, add); ";
    }
    auto flag = [](const char* name, bool on) { return std::string("#define ") + name + (on ? " 1\n" : " 0\n"); };
    const bool uv = ft.texture || ft.emissiveMap || ft.occlusionMap || ft.metalRoughMap || ft.normalMap;
    std::string prefix = "#version 330 core\n" + glslEnumDefines() + "#define SHADING " + key[0] + "\n#define REFLECTION " + key[1] +
                         "\n#define MAX_LIGHTS " + std::to_string(kMaxLights) + "\n#define LIGHT_CALLS " + calls + "\n" +
                         glslEnumDefine("FOG", "FOG_", f.settings.fog) + glslEnumDefine("ALPHA_MODE", "ALPHA_", ft.alphaMode) +
                         flag("HAS_TEXTURE", ft.texture) + flag("HAS_EMISSIVE_MAP", ft.emissiveMap) + flag("HAS_OCCLUSION_MAP", ft.occlusionMap) +
                         flag("HAS_METAL_ROUGH_MAP", ft.metalRoughMap) + flag("HAS_NORMAL_MAP", ft.normalMap) + flag("SPEC_GLOSS", ft.specGloss) +
                         flag("USES_UV", uv) + flag("USES_UV1", uv && ft.uv1) + flag("VERTEX_COLORS", ft.vertexColors) + flag("UNLIT", ft.unlit) +
                         flag("SOLID", ft.solid) + flag("OVERDRAW", ft.overdraw) + flag("VISIBILITY", ft.visibility);
    std::string common = prefix + gl::kShader_lighting_glsl + "\n";
    GLuint vs = 0, fs = 0;
    std::string err = compileShader(GL_VERTEX_SHADER, common + gl::kShader_mesh_vert, vs);
    if (err.empty()) err = compileShader(GL_FRAGMENT_SHADER, common + gl::kShader_mesh_frag, fs);
    if (err.empty()) {
        p.id = glCreateProgram();
        glAttachShader(p.id, vs);
        glAttachShader(p.id, fs);
        glLinkProgram(p.id);
        GLint ok = 0;
        glGetProgramiv(p.id, GL_LINK_STATUS, &ok);
        if (!ok) {
            char log[2048] = {};
            glGetProgramInfoLog(p.id, sizeof log, nullptr, log);
            err = std::string("shader link: ") + log;
            std::replace(err.begin(), err.end(), '\n', ' ');
            glDeleteProgram(p.id);
            p.id = 0;
        }
    }
    if (vs) glDeleteShader(vs);
    if (fs) glDeleteShader(fs);
    if (!err.empty()) return err;
    auto loc = [&](const char* n) { return glGetUniformLocation(p.id, n); };
    p.model = loc("uModel");
    p.drawable = loc("uDrawable");
    p.primitiveBase = loc("uPrimitiveBase");
    p.normalMatrix = loc("uNormalMatrix");
    p.viewProj = loc("uViewProj");
    p.view = loc("uView");
    p.pointSize = loc("uPointSize");
    p.numLights = loc("uNumLights");
    p.lightPos = loc("uLightPos");
    p.lightDir = loc("uLightDir");
    p.lightRad = loc("uLightRad");
    p.lightCone = loc("uLightCone");
    p.eye = loc("uEye");
    p.ambient = loc("uAmbient");
    p.baseColor = loc("uBaseColor");
    p.ka = loc("uKa");
    p.kd = loc("uKd");
    p.ks = loc("uKs");
    p.shininess = loc("uShininess");
    p.specTinted = loc("uSpecTinted");
    p.specColor = loc("uSpecColor");
    p.emissive = loc("uEmissive");
    p.texture = loc("uTexture");
    const char* mapNames[4] = {"uEmissiveMap", "uOcclusionMap", "uMetalRoughMap", "uNormalMap"};
    for (int k = 0; k < 4; ++k) p.maps[k] = loc(mapNames[k]);
    p.occlusionStrength = loc("uOcclusionStrength");
    p.metallic = loc("uMetallic");
    p.roughness = loc("uRoughness");
    p.glossiness = loc("uGlossiness");
    p.normalScale = loc("uNormalScale");
    p.uv1Maps = loc("uUv1Maps");
    p.alpha = loc("uAlpha");
    p.alphaCutoff = loc("uAlphaCutoff");
    p.solidColor = loc("uSolidColor");
    p.fogColor = loc("uFogColor");
    p.fogParams = loc("uFogParams");
    // Samplers: fixed units.
    glUseProgram(p.id);
    glUniform1i(p.texture, 0);
    for (int k = 0; k < 4; ++k) glUniform1i(p.maps[k], 1 + k);
    return {};
}

// --- 2. GPU cache ----------------------------------------------------------------------------

// A run of indices drawn with one material (tessellations with per-triangle materials).
struct IndexRange {
    GLsizei first = 0, count = 0;
    int material = -1;   // index into Tessellation::materials, -1 = the drawable's material
};

struct GpuMesh {
    uint64_t version = 0;
    GLuint vao = 0, vbo = 0, ebo = 0;
    GLuint tbo = 0;    // tangents (attribute 4), only for meshes that have them
    GLuint u1bo = 0;   // the second UV set (attribute 5), only for meshes that have one
    GLenum primitive = GL_TRIANGLES;
    std::vector<IndexRange> ranges;
    size_t triangles = 0;
    bool colors = false;   // has vertex colours (else the buffer holds 1s, which no shader reads)
    vec3 centre{0.0f};     // centre of the local bounding box (front-to-back sorting)
    bool valid = false;    // false: the mesh failed validation and is skipped
    uint64_t lastUsed = 0;
};

struct GpuTexture {
    uint64_t version = 0;
    bool srgb = true;
    GLuint id = 0;
    uint64_t lastUsed = 0;
};

// Interleaved vertex: position, normal, uv0, colour (missing attributes get defaults).
struct Vertex {
    float p[3], n[3], uv[2], c[4];
};

void releaseMesh(GpuMesh& m) {
    if (m.vao) glDeleteVertexArrays(1, &m.vao);
    if (m.vbo) glDeleteBuffers(1, &m.vbo);
    if (m.ebo) glDeleteBuffers(1, &m.ebo);
    if (m.tbo) glDeleteBuffers(1, &m.tbo);
    if (m.u1bo) glDeleteBuffers(1, &m.u1bo);
    m.vao = m.vbo = m.ebo = m.tbo = m.u1bo = 0;
}

// Builds (or rebuilds) the buffers of `mesh`; triangleMaterial (optional) groups the
// triangles into per-material index ranges.
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

GLint glWrap(WrapMode w) {
    switch (w) {
    case WrapMode::Repeat: return GL_REPEAT;
    case WrapMode::ClampToEdge: return GL_CLAMP_TO_EDGE;
    case WrapMode::MirroredRepeat: return GL_MIRRORED_REPEAT;
    }
    return GL_REPEAT;
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

// --- 3. Render targets -----------------------------------------------------------------------

struct RenderTarget {
    int width = 0, height = 0, samples = 0;
    GLuint fbo = 0, color = 0, depth = 0;
    GLuint ids = 0;   // RG32UI visibility (drawable, primitive) at attachment 1, when asked

    void release() {
        if (fbo) glDeleteFramebuffers(1, &fbo);
        if (color) glDeleteRenderbuffers(1, &color);
        if (depth) glDeleteRenderbuffers(1, &depth);
        if (ids) glDeleteRenderbuffers(1, &ids);
        fbo = color = depth = ids = 0;
        width = height = samples = 0;
    }
    // (Re)creates the FBO when the size, sample count or visibility changed. Returns "" or the
    // reason. Only attachment 0 is a draw buffer; the frame enables 1 when it wants ids.
    std::string ensure(int w, int h, int s, bool withIds = false) {
        if (fbo && w == width && h == height && s == samples && withIds == (ids != 0)) return {};
        release();
        width = w;
        height = h;
        samples = s;
        if (withIds) {   // single-sampled only (RenderConfig::visibility)
            glGenRenderbuffers(1, &ids);
            glBindRenderbuffer(GL_RENDERBUFFER, ids);
            glRenderbufferStorage(GL_RENDERBUFFER, GL_RG32UI, w, h);
        }
        glGenRenderbuffers(1, &color);
        glBindRenderbuffer(GL_RENDERBUFFER, color);
        if (s > 1)
            glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, GL_SRGB8_ALPHA8, w, h);
        else
            glRenderbufferStorage(GL_RENDERBUFFER, GL_SRGB8_ALPHA8, w, h);
        glGenRenderbuffers(1, &depth);
        glBindRenderbuffer(GL_RENDERBUFFER, depth);
        if (s > 1)
            glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, GL_DEPTH_COMPONENT32F, w, h);
        else
            glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, w, h);
        glBindRenderbuffer(GL_RENDERBUFFER, 0);
        glGenFramebuffers(1, &fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
        if (ids) glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_RENDERBUFFER, ids);
        glDrawBuffer(GL_COLOR_ATTACHMENT0);
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE) {
            char buf[160];
            std::snprintf(buf, sizeof buf, "framebuffer %dx%d with %d samples is incomplete (status 0x%x)", w, h, s, status);
            release();
            return buf;
        }
        return {};
    }
};

// The overdraw view's target: one R32F colour buffer (no depth), where additive blending of
// 1.0 per fragment counts fragments exactly (up to 2^24 per pixel).
struct CountTarget {
    int width = 0, height = 0;
    GLuint fbo = 0, count = 0;

    void release() {
        if (fbo) glDeleteFramebuffers(1, &fbo);
        if (count) glDeleteRenderbuffers(1, &count);
        fbo = count = 0;
        width = height = 0;
    }
    std::string ensure(int w, int h) {
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
};

// --- 4. State guard --------------------------------------------------------------------------
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
    GLint m_polygonMode[2] = {GL_FILL, GL_FILL}, m_frontFace = GL_CCW, m_cullMode = GL_BACK, m_depthFunc = GL_LESS;
    GLboolean m_depthMask = GL_TRUE, m_colorMask[4] = {GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
    GLfloat m_clearColor[4] = {};
    GLboolean m_enabled[std::size(kCaps)] = {};
};

// --- 5. GlRenderer ---------------------------------------------------------------------------

// One draw: a cached GPU mesh with a transform and a material (per range for tessellations).
// Opaque: opaque and masked surfaces, lines, points; Blended: alphaMode BLEND surfaces only;
// Wireframe: every triangle mesh again as lines (no material changes).
enum class DrawPass { Opaque, Blended, Wireframe };

struct DrawItem {
    GpuMesh* gpu = nullptr;
    const mat4* world = nullptr;
    mat3 normal{1.0f};
    bool mirrored = false;
    const Material* material = nullptr;
    const std::vector<Material>* rangeMaterials = nullptr;   // tessellation's per-range materials
    GpuTexture* texture = nullptr;
    GpuTexture* maps[4] = {nullptr, nullptr, nullptr, nullptr};   // emissive, occlusion, metallic-roughness, normal (units 1..4)
    uint32_t drawable = 0;                                        // Framebuffer::drawable (PreparedDraw::drawable)
    bool analytic = false;                                        // tessellated: no primitive index in the visibility
};

class GlRenderer final : public Renderer {
public:
    ~GlRenderer() override { releaseAll(); }

    std::string_view name() const override { return "gl"; }

    Capabilities capabilities() const override {
        Capabilities c;
        c.affinity = ContextAffinity::CurrentGLContext;
        c.wireframe = true;
        c.pointsAndLines = true;
        c.visibility = true;   // a second colour attachment, RG32UI (mesh.frag's fragId)
        c.overdraw = true;     // a second pass into an R32F target, additive (countOverdraw)
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

    Device device() const override {
        const gl::HeadlessGl g = gl::probeHeadlessGl();
        return {g.usable, g.software, g.usable ? g.renderer : g.error};
    }

protected:
    RenderStats doRender(const FrameInput& frame, const RenderConfig& cfg, Framebuffer& target, RenderControl* control) override;

public:
    GlCacheCounters counters() const {
        GlCacheCounters c;
        c.meshUploads = m_meshUploads;
        c.textureUploads = m_textureUploads;
        c.meshesCached = m_meshes.size();
        c.texturesCached = m_textures.size();
        c.context = m_contextDescription;
        c.platform = m_platform;
        return c;
    }

private:
    std::string prepareContext(bool& madeCurrent);
    Program* programFor(const Features& ft, std::string& error);   // for this frame; compiles on first use
    bool useProgram(const Features& ft, std::string& error);       // makes it m_current, frame uniforms set
    void forgetGLObjects();                                        // drops names without deleting (their context is gone or not current)
    void releaseAll();
    GpuMesh* meshFor(const Mesh& mesh, const std::vector<uint16_t>* triangleMaterial);
    GpuTexture* textureFor(const TexturePtr& t);
    void setFrameUniforms(const Program& p, const FrameInput& f, int ssaa);
    Features featuresOf(const DrawItem& it, const Material& m, DrawPass pass) const;
    std::vector<DrawItem> collectDraws(const FrameInput& frame, int tessellation);   // uploads what is new
    uint64_t drawAll(const std::vector<DrawItem>& items, DrawPass pass, sg::CullMode culling, std::string& error);
    std::string countOverdraw(const std::vector<DrawItem>& items, const RenderSettings& s, int w, int h, Framebuffer& target);
    void readBack(GLuint fbo, int w, int h, Framebuffer& out);
    void setMaterial(Program& p, const Material& m);
    void bindTextures(const DrawItem& it);
    void evict();

    std::unique_ptr<gl::GlContext> m_own;     // our headless context, made on first need
    const void* m_objectsContext = nullptr;   // the context our GL objects live in
    bool m_loaded = false;
    std::string m_contextDescription, m_platform;
    int m_maxSamples = 0, m_maxSize = 0;

    std::unordered_map<std::string, Program> m_programs;   // by programKey() + Features::key()
    // The frame being drawn: its input, setup key, SSAA factor and what the passes draw.
    const FrameInput* m_frameInput = nullptr;
    std::string m_frameKey;
    int m_ssaa = 1;
    bool m_visibility = false;      // the target has the visibility attachment
    bool m_countPass = false;       // drawing the overdraw view's pass
    Program* m_current = nullptr;   // the program in use and its switches
    Features m_currentFeatures;
    static constexpr GLuint kUnknownTexture = ~0u;
    GLuint m_boundTexture[5] = {kUnknownTexture, kUnknownTexture, kUnknownTexture, kUnknownTexture, kUnknownTexture};   // units 0..4
    RenderTarget m_target, m_resolve;
    CountTarget m_overdraw;
    std::unordered_map<uint64_t, GpuMesh> m_meshes;        // by Mesh::id
    std::unordered_map<uint64_t, GpuTexture> m_textures;   // by Texture::id
    TessellationCache m_tess;
    std::vector<uint8_t> m_readRows;   // read-back rows to flip (without GL_MESA_pack_invert)
    uint64_t m_frame = 0, m_meshUploads = 0, m_textureUploads = 0;
};

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
    }
    m_platform = (m_own && m_own->isCurrent()) ? m_own->platform() : "caller";
    return {};
}

Program* GlRenderer::programFor(const Features& ft, std::string& error) {
    std::string key = m_frameKey + ft.key();
    auto it = m_programs.find(key);
    if (it == m_programs.end()) {
        Program p;
        error = buildProgram(m_frameKey, ft, *m_frameInput, p);
        if (!error.empty()) return nullptr;
        it = m_programs.emplace(key, p).first;
    }
    it->second.lastUsed = m_frame;
    return &it->second;
}

bool GlRenderer::useProgram(const Features& ft, std::string& error) {
    if (m_current && ft == m_currentFeatures) return true;
    Program* p = programFor(ft, error);
    if (!p) return false;
    if (p != m_current) glUseProgram(p->id);
    if (p->frameUniforms != m_frame) {
        setFrameUniforms(*p, *m_frameInput, m_ssaa);
        p->frameUniforms = m_frame;
    }
    m_current = p;
    m_currentFeatures = ft;
    return true;
}

void GlRenderer::forgetGLObjects() {
    m_programs.clear();
    m_target = RenderTarget{};
    m_resolve = RenderTarget{};
    m_overdraw = CountTarget{};
    m_meshes.clear();
    m_textures.clear();
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
        m_overdraw.release();
        for (auto& [id, m] : m_meshes) releaseMesh(m);
        for (auto& [id, t] : m_textures)
            if (t.id) glDeleteTextures(1, &t.id);
    }
    forgetGLObjects();
    if (madeCurrent) m_own->release();
    m_own.reset();
}

GpuMesh* GlRenderer::meshFor(const Mesh& mesh, const std::vector<uint16_t>* triangleMaterial) {
    GpuMesh& g = m_meshes[mesh.id];
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

void GlRenderer::setFrameUniforms(const Program& p, const FrameInput& f, int ssaa) {
    const RenderSettings& s = f.settings;
    glUniformMatrix4fv(p.viewProj, 1, GL_FALSE, &f.camera.viewProj[0][0]);
    glUniformMatrix4fv(p.view, 1, GL_FALSE, &f.camera.view[0][0]);
    glUniform3fv(p.eye, 1, &f.camera.eye[0]);
    glUniform3fv(p.ambient, 1, &f.ambientLight[0]);
    glUniform1f(p.pointSize, 2.0f * float(ssaa));
    glUniform3fv(p.fogColor, 1, &s.fogColor[0]);
    glUniform3f(p.fogParams, s.fogStart, s.fogEnd, s.fogDensity);
    glUniform3fv(p.solidColor, 1, &s.wireframeColor[0]);

    int n = int(std::min<size_t>(f.lights.size(), kMaxLights));
    std::vector<vec4> pos(n), dir(n), rad(n), cone(n);
    for (int i = 0; i < n; ++i) {
        const DrawLight& l = f.lights[i];   // type and 1/r^2: compiled in, or read by the loop
        float type = float(int(l.type));    // LIGHT_POINT ... (glslEnumDefines)
        pos[i] = vec4(l.position, type);
        dir[i] = vec4(l.direction, l.inverseSquare ? 1.0f : 0.0f);
        rad[i] = vec4(l.radiance, 0.0f);
        cone[i] = vec4(l.cosInner, l.cosOuter, 0.0f, 0.0f);
    }
    glUniform1i(p.numLights, n);
    if (n > 0) {
        glUniform4fv(p.lightPos, n, &pos[0][0]);
        glUniform4fv(p.lightDir, n, &dir[0][0]);
        glUniform4fv(p.lightRad, n, &rad[0][0]);
        glUniform4fv(p.lightCone, n, &cone[0][0]);
    }
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

// The material's uniforms, unless the program holds them already (instances of one material).
void GlRenderer::setMaterial(Program& p, const Material& m) {
    if (p.hasMaterial && p.lastMaterial == m) return;
    p.hasMaterial = true;
    p.lastMaterial = m;
    glUniform1f(p.normalScale, m.normalScale);
    glUniform1i(p.uv1Maps, int(m.uv1Maps));   // read only by USES_UV1 programs: meshes that have uv1
    glUniform1f(p.occlusionStrength, m.occlusionStrength);
    glUniform1f(p.metallic, m.metallic);
    glUniform1f(p.roughness, m.roughness);
    glUniform1f(p.glossiness, m.glossiness);
    glUniform3fv(p.baseColor, 1, &m.baseColor[0]);
    glUniform1f(p.ka, m.ka);
    glUniform1f(p.kd, m.kd);
    glUniform1f(p.ks, m.ks);
    glUniform1f(p.shininess, m.shininess);
    glUniform1i(p.specTinted, m.specularTinted ? 1 : 0);
    glUniform3fv(p.specColor, 1, &m.specularColor[0]);
    glUniform3fv(p.emissive, 1, &m.emissive[0]);
    glUniform1f(p.alpha, m.alpha);
    glUniform1f(p.alphaCutoff, m.alphaCutoff);
}

// The switches of range material `m` of `it` in `pass` (mesh.frag). Lines and points are unlit
// and opaque (as in the CPU backends) and use no maps; unlit surfaces use only the texture and
// the emissive map.
Features GlRenderer::featuresOf(const DrawItem& it, const Material& m, DrawPass pass) const {
    Features f;
    if (m_countPass) {
        f.overdraw = true;
        return f;
    }
    if (pass == DrawPass::Wireframe) {
        f.solid = true;
        return f;
    }
    const bool primitiveUnlit = it.gpu->primitive != GL_TRIANGLES;
    f.unlit = primitiveUnlit || m.unlit;
    f.texture = it.texture != nullptr;
    f.vertexColors = it.gpu->colors;
    f.alphaMode = primitiveUnlit ? sg::AlphaMode::Opaque : m.alphaMode;
    if (!primitiveUnlit) {
        f.emissiveMap = it.maps[0] != nullptr;
        f.occlusionMap = it.maps[1] && !f.unlit;
        f.metalRoughMap = it.maps[2] && !f.unlit;
        f.normalMap = it.maps[3] && !f.unlit;
        f.specGloss = f.metalRoughMap && m.specularGlossiness;
        const uint8_t used = (f.emissiveMap ? sg::Material::EmissiveMap : 0) | (f.occlusionMap ? sg::Material::OcclusionMap : 0) |
                             (f.metalRoughMap ? sg::Material::MetallicRoughnessMap : 0) | (f.normalMap ? sg::Material::NormalMap : 0);
        f.uv1 = it.gpu->u1bo != 0 && (m.uv1Maps & used) != 0;
    }
    f.visibility = m_visibility && pass == DrawPass::Opaque;   // the other passes mask attachment 1
    return f;
}

// Draws for the frame from the shared draw list (renderers/draw_list.h), nearest first so
// that llvmpipe's early depth test skips shading hidden fragments. Uploads happen here, only
// for new or edited meshes and textures.
std::vector<DrawItem> GlRenderer::collectDraws(const FrameInput& frame, int tessellation) {
    std::vector<DrawItem> items;
    for (const PreparedDraw& p : prepareDraws(frame, tessellation, m_tess)) {
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

// The overdraw view (RenderConfig::overdraw, one sample per pixel): the frame's draws again
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
    target.resizeOverdraw();
    for (int y = 0; y < h; ++y) {
        const float* src = &counts[size_t(h - 1 - y) * w];
        for (int x = 0; x < w; ++x) target.overdraw[size_t(y) * w + x] = uint32_t(std::lround(std::max(src[x], 0.0f)));
    }
    return {};
}

// Reads colour and depth of `fbo` into `out` (GL rows are bottom-up, Framebuffer rows
// top-down). With GL_MESA_pack_invert (Mesa, llvmpipe included) the driver writes the rows
// top-down straight into `out`; otherwise they pass through m_readRows (kept between frames, so
// no allocation, zero-fill or page faults per frame) and are flipped. Alpha needs no pass: the
// target's alpha is 1 everywhere (cleared to 1; every pass writes 1 or, blending, keeps it).
void GlRenderer::readBack(GLuint fbo, int w, int h, Framebuffer& out) {
    out.resizeForOverwrite(w, h);   // every pixel is written below
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    if (GLAD_GL_MESA_pack_invert) {
        GLint invert = GL_FALSE;
        glGetIntegerv(GL_PACK_INVERT_MESA, &invert);
        glPixelStorei(GL_PACK_INVERT_MESA, GL_TRUE);
        glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, out.color.data());
        glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, out.depth.data());
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
    glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, m_readRows.data());
    flipInto(reinterpret_cast<uint8_t*>(out.depth.data()));
}

// Reads the visibility attachment (drawable, primitive) of `fbo` into `out` (already sized).
void readVisibility(GLuint fbo, int w, int h, Framebuffer& out) {
    out.resizeVisibility();
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

// Makes attachment 1 (visibility) a draw buffer and clears it to "nothing".
void beginVisibility() {
    const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, bufs);
    const GLuint none[4] = {0u, kNoPrimitive, 0u, 0u};
    glClearBufferuiv(GL_COLOR, 1, none);
}

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
    glCullFace(GL_BACK);   // enabled per material in drawAll (RenderSettings::culling)
    glDisable(GL_CULL_FACE);
    glActiveTexture(GL_TEXTURE0);
}

RenderStats GlRenderer::doRender(const FrameInput& frame, const RenderConfig& cfg, Framebuffer& target, RenderControl* control) {
    (void)control;   // one GL frame: not progressive; render() checked cancellation before
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
    int samples = cfg.msaaSamples;
    if (samples > 1 && samples > m_maxSamples) {
        int used = std::max(m_maxSamples, 1);
        stats.config.notes.push_back("msaa" + std::to_string(samples) + " -> " + (used > 1 ? "msaa" + std::to_string(used) : std::string("none")) +
                                     ": the driver allows " + std::to_string(m_maxSamples) + " samples");
        samples = used;
    }
    const int ssaa = cfg.ssaaFactor;
    const int rw = cfg.width * ssaa, rh = cfg.height * ssaa;
    if (rw > m_maxSize || rh > m_maxSize) {
        stats.error = "render size " + std::to_string(rw) + "x" + std::to_string(rh) + " exceeds the driver's limit of " + std::to_string(m_maxSize);
        return stats;
    }
    const bool visibility = cfg.visibility && samples <= 1 && ssaa == 1;   // render() asks only for one-sample frames
    err = m_target.ensure(rw, rh, samples > 1 ? samples : 0, visibility);
    if (err.empty() && samples > 1) err = m_resolve.ensure(rw, rh, 0);
    if (!err.empty()) {
        stats.error = err;
        return stats;
    }

    beginFrameState(s, m_target.fbo, rw, rh, samples);
    if (visibility) beginVisibility();
    const std::vector<DrawItem> items = collectDraws(frame, cfg.tessellation);
    // The programs of this frame (useProgram): its setup, and uniforms set once per program.
    m_frameInput = &frame;
    m_frameKey = programKey(frame);
    m_ssaa = ssaa;
    m_visibility = visibility;
    m_current = nullptr;
    struct EndOfFrame {
        GlRenderer& r;
        ~EndOfFrame() {
            r.m_frameInput = nullptr;
            r.m_current = nullptr;
        }
    } endOfFrame{*this};
    stats.triangles = drawAll(items, DrawPass::Opaque, s.culling, err);
    // Blended surfaces (glTF alphaMode BLEND): "over" in linear light (the sRGB framebuffer
    // blends decoded values), sorted per draw back to front, depth tested but not written
    // (nor is the visibility, which belongs to the surface that wrote depth).
    glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glDepthMask(GL_FALSE);
    if (err.empty()) stats.triangles += drawAll(items, DrawPass::Blended, s.culling, err);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);

    // Wireframe overlay: the same triangles as lines, pulled slightly toward the viewer.
    if (s.wireframe && err.empty()) {
        glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
        glEnable(GL_POLYGON_OFFSET_LINE);
        glPolygonOffset(-1.0f, -1.0f);
        glDepthFunc(GL_LEQUAL);
        drawAll(items, DrawPass::Wireframe, s.culling, err);
        glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
        glDisable(GL_POLYGON_OFFSET_LINE);
    }
    glBindVertexArray(0);
    glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    if (!err.empty()) {
        if (visibility) glDrawBuffer(GL_COLOR_ATTACHMENT0);
        stats.error = err;
        return stats;
    }

    // Resolve MSAA (reading a multisampled buffer directly would give an aliased image).
    GLuint readFbo = m_target.fbo;
    if (samples > 1) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, m_target.fbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, m_resolve.fbo);
        glBlitFramebuffer(0, 0, rw, rh, 0, 0, rw, rh, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glBlitFramebuffer(0, 0, rw, rh, 0, 0, rw, rh, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
        readFbo = m_resolve.fbo;
    }
    if (ssaa > 1) {
        Framebuffer full;
        readBack(readFbo, rw, rh, full);
        target = downsample(full, ssaa);
    } else {
        readBack(readFbo, rw, rh, target);
        if (visibility) readVisibility(readFbo, rw, rh, target);
    }
    if (visibility) glDrawBuffer(GL_COLOR_ATTACHMENT0);
    if (cfg.overdraw && samples <= 1 && ssaa == 1) {   // render() asks only for one-sample frames
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

}   // namespace

std::unique_ptr<Renderer> makeGlRenderer() { return std::make_unique<GlRenderer>(); }

GlCacheCounters glCacheCounters(const Renderer& r) {
    if (auto* g = dynamic_cast<const GlRenderer*>(&r)) return g->counters();
    return {};
}

}   // namespace rnd
