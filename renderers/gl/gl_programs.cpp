// gl_programs.cpp - the GL backend's shader programs (gl_internal.h): the GLSL of shaders/
// (embedded at build time) specialised per frame setup - shading model, reflection model, fog
// mode, shadow maps, light setup - and per draw's feature switches (textures, maps, alpha
// mode, the wireframe, overdraw and visibility variants), compiled on first use and cached by
// key; the uniforms a frame sets once per program (camera, lights, fog) and those a material
// sets; the display pass's programs (exposure, tone mapping, SSAA box filter of linear frames).
#include "gl/gl_internal.h"

#include "scenegraph/setting_names.h"

#include <algorithm>

namespace rnd {

namespace gl {
namespace {

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

std::string linkProgram(const std::string& vertex, const std::string& fragment, const char* what, GLuint& id) {
    id = 0;
    GLuint vs = 0, fs = 0;
    std::string err = compileShader(GL_VERTEX_SHADER, vertex, vs);
    if (err.empty()) err = compileShader(GL_FRAGMENT_SHADER, fragment, fs);
    if (err.empty()) {
        id = glCreateProgram();
        glAttachShader(id, vs);
        glAttachShader(id, fs);
        glLinkProgram(id);
        GLint ok = 0;
        glGetProgramiv(id, GL_LINK_STATUS, &ok);
        if (!ok) {
            char log[2048] = {};
            glGetProgramInfoLog(id, sizeof log, nullptr, log);
            err = std::string(what) + " link: " + log;
            std::replace(err.begin(), err.end(), '\n', ' ');
            glDeleteProgram(id);
            id = 0;
        }
    } else {
        err = std::string(what) + ", " + err;
    }
    if (vs) glDeleteShader(vs);
    if (fs) glDeleteShader(fs);
    return err;
}
}   // namespace gl

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
    all("TONE_MAPPING_", sg::nameTable<sg::ToneMapping>());
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

std::string glslSources() {
    return std::string(gl::kShader_pbr_glsl) + "\n" + gl::kShader_shadow_glsl + "\n" + gl::kShader_lighting_glsl + "\n" + gl::kShader_mesh_vert +
           "\n" + gl::kShader_mesh_frag + "\n" + gl::kShader_tone_map_glsl + "\n" + gl::kShader_display_vert + "\n" + gl::kShader_display_frag;
}

namespace gl {

using namespace sg;

// Programs are specialised per frame setup (see lighting.glsl): the key is the shading model,
// the reflection model, the fog mode, the shadow maps ('-' none, else 'A' + k - 1 for k x k
// PCF, 'a' + k - 1 for PCSS with k x k taps; shadow.glsl), and one letter per light (p/P point, d directional, s/S spot; upper case =
// inverse square), or '*' for the generic loop when there are many lights (a 30-light unrolled
// program takes seconds to compile on llvmpipe); Gouraud shading with maps then adds '/' and
// one character per light it shadows ('0' + index: gouraudShadowedLights, their terms kept
// apart in the vertex outputs).
std::string programKey(const FrameInput& f, const ShadowPlan& shadows) {
    std::string key;
    key += char('0' + int(f.settings.shading));
    key += char('0' + int(f.settings.reflection));
    key += char('0' + int(f.settings.fog));
    key += !shadows.empty() ? char((shadows.filter == ShadowFilter::Pcss ? 'a' : 'A') + std::clamp(shadows.pcf, 1, 15) - 1) : '-';
    size_t n = std::min<size_t>(f.lights.size(), kMaxLights);
    if (n > size_t(kMaxUnrolledLights)) {
        key += '*';
    } else {
        for (size_t i = 0; i < n; ++i) {
            const DrawLight& l = f.lights[i];
            char c = l.type == LightType::Point ? 'p' : l.type == LightType::Directional ? 'd' : 's';
            if (l.inverseSquare && c != 'd') c = char(c - 'a' + 'A');
            key += c;
        }
    }
    if (f.settings.shading == ShadingModel::Gouraud && !shadows.empty()) {
        const std::vector<int> apart = gouraudShadowedLights(shadows, n);
        if (!apart.empty()) key += '/';
        for (int l : apart) key += char('0' + l);
    }
    return key;
}

// Builds the program of frame setup `key` (programKey) with the draw's switches `ft` for frame `f`.
std::string buildProgram(const std::string& key, const Features& ft, const FrameInput& f, Program& p) {
    constexpr size_t kLights = 4;   // where the lights start in the key
    const bool pcss = key.size() > 3 && key[3] >= 'a' && key[3] <= 'z';
    const int shadowPcf = key.size() > 3 && key[3] != '-' ? key[3] - (pcss ? 'a' : 'A') + 1 : 0;
    const size_t slash = std::min(key.find('/'), key.size());
    std::vector<int> apart;   // Gouraud's shadowed lights (programKey), whose terms lightTerms keeps in gLightMul/Add[j]
    for (size_t i = slash + 1; i < key.size(); ++i) apart.push_back(key[i] - '0');
    static_assert(kGouraudShadowedLights == 2, "mesh.vert and mesh.frag name two slots (SHADOW_SLOT_LIGHT0, SHADOW_SLOT_LIGHT1)");
    std::string calls;
    if (key.size() > kLights && key[kLights] == '*') {
        const std::string call = "lightTerms(i, int(uLightPos[i].w + 0.5), uLightDir[i].w > 0.5, n, p, v, ";
        if (apart.empty()) {
            calls = "for (int i = 0; i < uNumLights; ++i) " + call + "mul, add);";
        } else {   // a branch per kept light: an inout argument must be an l-value
            calls = "for (int i = 0; i < uNumLights; ++i) {";
            for (size_t j = 0; j < apart.size(); ++j)
                calls += " if (i == " + std::to_string(apart[j]) + ") " + call + "gLightMul[" + std::to_string(j) + "], gLightAdd[" +
                         std::to_string(j) + "]); else";
            calls += " " + call + "mul, add); }";
        }
    }
    for (size_t i = kLights; i < slash && key[kLights] != '*'; ++i) {
        char c = char(key[i] | 0x20);
        const char* type = c == 'p' ? "LIGHT_POINT" : c == 'd' ? "LIGHT_DIRECTIONAL" : "LIGHT_SPOT";
        bool invSq = key[i] >= 'A' && key[i] <= 'Z';
        const int light = int(i - kLights);
        std::string out = "mul, add";
        for (size_t j = 0; j < apart.size(); ++j)
            if (apart[j] == light) out = "gLightMul[" + std::to_string(j) + "], gLightAdd[" + std::to_string(j) + "]";
        calls += "lightTerms(" + std::to_string(light) + ", " + type + ", " + (invSq ? "true" : "false") + ", n, p, v, " + out + "); ";
    }
    auto flag = [](const char* name, bool on) { return std::string("#define ") + name + (on ? " 1\n" : " 0\n"); };
    const bool uv = ft.texture || ft.emissiveMap || ft.occlusionMap || ft.metalRoughMap || ft.normalMap;
    // Shadow maps (shadow.glsl): on or off for the frame, the filter's taps, PCSS or plain PCF, and
    // the bounds of the views and of PCSS.
    const std::string shadows = flag("SHADOWS", shadowPcf > 0) + "#define SHADOW_PCF " + std::to_string(std::max(shadowPcf, 1)) + "\n" +
                                flag("SHADOW_PCSS", pcss) + "#define MAX_SHADOW_VIEWS " + std::to_string(kMaxShadowViews) + "\n#define PCSS_SEARCH " +
                                std::to_string(kPcssSearch) + "\n#define PCSS_MAX_RADIUS " + std::to_string(kPcssMaxRadius) +
                                "\n#define SHADOW_SLOTS " + std::to_string(apart.size()) + "\n#define SHADOW_SLOT_LIGHT0 " +
                                std::to_string(apart.size() > 0 ? apart[0] : -1) + "\n#define SHADOW_SLOT_LIGHT1 " +
                                std::to_string(apart.size() > 1 ? apart[1] : -1) + "\n";
    std::string prefix = "#version 330 core\n" + glslEnumDefines() + "#define SHADING " + key[0] + "\n#define REFLECTION " + key[1] +
                         "\n#define MAX_LIGHTS " + std::to_string(kMaxLights) + "\n#define LIGHT_CALLS " + calls + "\n" +
                         glslEnumDefine("FOG", "FOG_", f.settings.fog) + glslEnumDefine("ALPHA_MODE", "ALPHA_", ft.alphaMode) +
                         flag("HAS_TEXTURE", ft.texture) + flag("HAS_EMISSIVE_MAP", ft.emissiveMap) + flag("HAS_OCCLUSION_MAP", ft.occlusionMap) +
                         flag("HAS_METAL_ROUGH_MAP", ft.metalRoughMap) + flag("HAS_NORMAL_MAP", ft.normalMap) + flag("SPEC_GLOSS", ft.specGloss) +
                         flag("USES_UV", uv) + flag("USES_UV1", uv && ft.uv1) + flag("VERTEX_COLORS", ft.vertexColors) + flag("UNLIT", ft.unlit) +
                         flag("SOLID", ft.solid) + flag("OVERDRAW", ft.overdraw) + flag("VISIBILITY", ft.visibility) +
                         flag("HAS_ENVIRONMENT", ft.environment) + flag("LINEAR_TARGET", ft.linearTarget) + shadows;
    std::string common = prefix + gl::kShader_pbr_glsl + "\n" + gl::kShader_shadow_glsl + "\n" + gl::kShader_lighting_glsl + "\n";
    if (std::string err = linkProgram(common + gl::kShader_mesh_vert, common + gl::kShader_mesh_frag, "shader", p.id); !err.empty()) return err;
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
    p.ior = loc("uIor");
    p.specularFactor = loc("uSpecularFactor");
    p.specularColorFactor = loc("uSpecularColorFactor");
    p.specularGlossiness = loc("uSpecularGlossiness");
    p.envMap = loc("uEnvMap");
    p.splitSum = loc("uSplitSum");
    p.envSH = loc("uEnvSH");
    p.envIntensity = loc("uEnvIntensity");
    p.envRotation = loc("uEnvRotation");
    p.envLevels = loc("uEnvLevels");
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
    glUniform1i(p.envMap, 5);
    glUniform1i(p.splitSum, 6);
    if (shadowPcf > 0) {   // shadow.glsl: the maps and the plan's uniform block (gl_shadows.cpp)
        glUniform1i(loc("uShadowMaps"), kShadowUnit);
        const GLuint block = glGetUniformBlockIndex(p.id, "ShadowPlan");
        if (block != GL_INVALID_INDEX) glUniformBlockBinding(p.id, block, kShadowBinding);
    }
    return {};
}

std::string buildDisplayProgram(sg::ToneMapping op, DisplayProgram& p) {
    const std::string prefix = "#version 330 core\n" + glslEnumDefines() + glslEnumDefine("TONE_MAPPING", "TONE_MAPPING_", op);
    if (std::string err =
            linkProgram(prefix + kShader_display_vert, prefix + kShader_tone_map_glsl + "\n" + kShader_display_frag, "display shader", p.id);
        !err.empty())
        return err;
    p.frame = glGetUniformLocation(p.id, "uFrame");
    p.ssaa = glGetUniformLocation(p.id, "uSsaa");
    p.exposureScale = glGetUniformLocation(p.id, "uExposureScale");
    glUseProgram(p.id);
    glUniform1i(p.frame, 0);
    return {};
}

// Starts the programs' frame: its input, setup key (with this frame's shadow plan, made
// before), SSAA factor and visibility output, for useProgram; no program in use yet.
void GlRenderer::beginFramePrograms(const FrameInput& frame, int ssaa, bool visibility) {
    m_frameInput = &frame;
    m_frameKey = programKey(frame, m_shadowPlan);
    m_ssaa = ssaa;
    m_visibility = visibility;
    m_current = nullptr;
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
    if (m_environment.map) {
        glUniform3fv(p.envSH, 9, &m_environment.map->sh()[0][0]);
        glUniform1f(p.envIntensity, m_environment.intensity);
        glUniform2f(p.envRotation, m_environment.cosRot, m_environment.sinRot);
        glUniform1f(p.envLevels, float(EnvironmentMap::kLevels));
    }

    int n = int(std::min<size_t>(f.lights.size(), kMaxLights));
    std::vector<vec4> pos(n), dir(n), rad(n), cone(n);
    for (int i = 0; i < n; ++i) {
        const DrawLight& l = f.lights[i];   // type and 1/r^2: compiled in, or read by the loop
        float type = float(int(l.type));    // LIGHT_POINT ... (glslEnumDefines)
        pos[i] = vec4(l.position, type);
        dir[i] = vec4(l.direction, l.inverseSquare ? 1.0f : 0.0f);
        rad[i] = vec4(l.radiance, 0.0f);
        cone[i] = vec4(l.cosInner, l.cosOuter, l.range, l.type == LightType::Directional ? l.tanAngularRadius : l.radius);
    }
    glUniform1i(p.numLights, n);
    if (n > 0) {
        glUniform4fv(p.lightPos, n, &pos[0][0]);
        glUniform4fv(p.lightDir, n, &dir[0][0]);
        glUniform4fv(p.lightRad, n, &rad[0][0]);
        glUniform4fv(p.lightCone, n, &cone[0][0]);
    }
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
    glUniform1f(p.ior, m.ior);
    glUniform1f(p.specularFactor, m.specularFactor);
    glUniform3fv(p.specularColorFactor, 1, &m.specularColorFactor[0]);
    glUniform1i(p.specularGlossiness, m.specularGlossiness ? 1 : 0);
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
    f.linearTarget = m_linear;
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
    f.environment = m_environment.map && !f.unlit && m_frameInput && m_frameInput->settings.reflection == sg::ReflectionModel::Pbr;
    return f;
}

}   // namespace gl
}   // namespace rnd
