// gl_internal.h - what the files of the OpenGL 3.3+ core backend ("gl") share (private to
// renderers/gl/): the shader programs' switches and uniform locations, the GPU cache's records,
// the render targets, the draw items and the GlRenderer class itself. By file:
//   gl_programs.cpp   shader programs: embedded GLSL (shaders/) specialised per frame setup
//                     and per draw's switches, compiled on first use; frame and material
//                     uniforms; the display pass's programs (one per tone-mapping operator)
//   gl_resources.cpp  GPU cache (meshes, tessellations and textures keyed by id + version, evicted
//                     when unused), render targets (multisampled / single-sample FBOs, the
//                     overdraw count target), the frame's draw list, read-back
//   gl_passes.cpp     the draw passes: opaque (with the visibility attachment), blended,
//                     wireframe, the overdraw view; frame state, MSAA resolve, the display pass
//   gl_shadows.cpp    shadow maps (renderers/shadow_map.h, the CPU rasterizer's plan): the
//                     depth pass into one texture array, the plan's uniform block for
//                     shaders/shadow.glsl, the maps read back for the pixel inspector
//   gl_environment.cpp pbr's environment light: its textures and the background pass
//   gl_renderer.cpp   GlRenderer: context, capabilities, state guard, doRender
//
// Conventions (shared with the CPU backends, see renderers/shading.h): lighting in linear
// space in world coordinates, sRGB8_ALPHA8 targets with GL_FRAMEBUFFER_SRGB, sRGB textures
// decoded on sampling, two-sided lighting by gl_FrontFacing (glFrontFace(GL_CW) for mirrored
// instances), fog on the eye-space distance. Gouraud lights the vertices with the albedo
// factored out (colour = rho * mul + add, see lighting.glsl), so textures still apply per
// fragment. Lines and points are drawn unlit (base colour x vertex colour + emissive).
// Exposure and tone mapping (renderers/tone_map.h), when they are not the identity: the frame
// is drawn into linear RGBA16F targets instead (not clamped at 1, blended in float), resolved,
// and the display pass (shaders/display.frag, tone_map.glsl) box-filters SSAA, applies the
// transform and writes an sRGB8 target of the output size, which is read back.
// Texture filters: nearest = GL_NEAREST, bilinear = GL_LINEAR without mipmaps, trilinear =
// GL_LINEAR_MIPMAP_LINEAR. Draws are sorted nearest first (early depth test on llvmpipe).
#pragma once

#include "gl/gl_context.h"
#include "gl/gl_renderer.h"
#include "renderers/debug_switches.h"
#include "renderers/environment.h"
#include "renderers/framebuffer.h"
#include "renderers/renderer.h"
#include "renderers/shadow_map.h"
#include "renderers/tessellate.h"
#include "scenegraph/frame.h"

#include <glad/gl.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace rnd::gl {

extern const char* const kShader_lighting_glsl;
extern const char* const kShader_shadow_glsl;
extern const char* const kShader_pbr_glsl;
extern const char* const kShader_mesh_vert;
extern const char* const kShader_mesh_frag;
extern const char* const kShader_tone_map_glsl;
extern const char* const kShader_display_vert;
extern const char* const kShader_display_frag;

constexpr int kMaxLights = 32;          // lights beyond this are ignored (uniform arrays)
constexpr int kMaxUnrolledLights = 8;   // more lights: one generic program with a loop
constexpr uint64_t kEvictAfterFrames = 120;
constexpr size_t kMaxPrograms = 64;    // beyond this, programs not used by the last frame are deleted
constexpr int kShadowUnit = 7;         // texture unit of the shadow maps (shadow.glsl's uShadowMaps)
constexpr GLuint kShadowBinding = 0;   // uniform buffer binding point of shadow.glsl's ShadowPlan

// --- shader programs (gl_programs.cpp) -------------------------------------------------------

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
    bool solid = false;          // the wireframe overlay
    bool overdraw = false;       // the overdraw view's pass
    bool visibility = false;     // writes the visibility attachment
    bool environment = false;    // pbr's environment light is bound (units 5 and 6)
    bool linearTarget = false;   // draws into the linear float target: colour not clamped at 1

    // One character per switch (part of the program's key).
    bool operator==(const Features&) const = default;
    std::string key() const {
        std::string k;
        for (bool b : {texture, emissiveMap, occlusionMap, metalRoughMap, normalMap, specGloss, uv1, vertexColors, unlit, solid, overdraw, visibility,
                       environment, linearTarget})
            k += b ? '1' : '0';
        return k + char('0' + int(alphaMode));
    }
};

struct Program {
    GLuint id = 0;
    uint64_t frameUniforms = 0;   // the frame whose uniforms (camera, lights, fog) it holds
    uint64_t lastUsed = 0;        // the frame that last drew with it
    bool hasMaterial = false;     // lastMaterial's values are in its uniforms
    sg::Material lastMaterial;
    // Uniform locations (-1 where this program's switches leave a uniform out).
    GLint model = -1, normalMatrix = -1, viewProj = -1, view = -1, pointSize = -1;
    GLint numLights = -1, lightPos = -1, lightDir = -1, lightRad = -1, lightCone = -1;
    GLint eye = -1, ambient = -1;
    GLint baseColor = -1, ka = -1, kd = -1, ks = -1, shininess = -1, specTinted = -1, specColor = -1, emissive = -1;
    // pbr (pbr.glsl): the dielectric's parameters and the environment (units 5 and 6).
    GLint ior = -1, specularFactor = -1, specularColorFactor = -1, specularGlossiness = -1;
    GLint envMap = -1, splitSum = -1, envSH = -1, envIntensity = -1, envRotation = -1, envLevels = -1;
    GLint texture = -1, solidColor = -1;
    // Material maps (texture units 1..4: emissive, occlusion, metallic-roughness, normal) and their factors.
    GLint maps[4] = {-1, -1, -1, -1}, occlusionStrength = -1, metallic = -1, roughness = -1, normalScale = -1;
    GLint glossiness = -1, uv1Maps = -1;
    GLint alpha = -1, alphaCutoff = -1;
    GLint fogColor = -1, fogParams = -1;
    GLint drawable = -1, primitiveBase = -1;   // visibility output (location 1)
};

// The frame setup part of a program's key: shading model, reflection model, fog mode, the
// shadow maps' filter (none when `shadows` is empty) and one letter per light (see gl_programs.cpp).
std::string programKey(const sg::FrameInput& f, const ShadowPlan& shadows);
// Builds the program of frame setup `key` (programKey) with the draw's switches `ft` for frame
// `f` into p (id and uniform locations). Returns "" or the compiler's or linker's message.
std::string buildProgram(const std::string& key, const Features& ft, const sg::FrameInput& f, Program& p);

// The display pass's program (shaders/display.vert, display.frag with tone_map.glsl) for one
// tone-mapping operator, and its uniform locations.
struct DisplayProgram {
    GLuint id = 0;
    GLint frame = -1, ssaa = -1, exposureScale = -1;
};
// Builds the display program of operator `op` into p. Returns "" or the compiler's or linker's message.
std::string buildDisplayProgram(sg::ToneMapping op, DisplayProgram& p);
// Compiles and links a program from its two sources: "" and `id`, or the reason (naming `what`)
// and id 0.
std::string linkProgram(const std::string& vertex, const std::string& fragment, const char* what, GLuint& id);

// --- GPU cache and render targets (gl_resources.cpp) -----------------------------------------

// A run of indices drawn with one material (tessellations with per-triangle materials).
struct IndexRange {
    GLsizei first = 0, count = 0;
    int material = -1;   // index into Tessellation::materials, -1 = the drawable's material
};

struct GpuMesh {
    uint64_t id = 0;   // sg::Mesh::id
    uint64_t version = 0;
    GLuint vao = 0, vbo = 0, ebo = 0;
    GLuint tbo = 0;    // tangents (attribute 4), only for meshes that have them
    GLuint u1bo = 0;   // the second UV set (attribute 5), only for meshes that have one
    GLenum primitive = GL_TRIANGLES;
    std::vector<IndexRange> ranges;
    size_t triangles = 0;
    bool colors = false;     // has vertex colours (else the buffer holds 1s, which no shader reads)
    sg::vec3 centre{0.0f};   // centre of the local bounding box (front-to-back sorting)
    bool valid = false;      // false: the mesh failed validation and is skipped
    uint64_t lastUsed = 0;
};

struct GpuTexture {
    uint64_t version = 0;
    bool srgb = true;
    GLuint id = 0;
    uint64_t lastUsed = 0;
};

void releaseMesh(GpuMesh& m);
// Builds (or rebuilds) the buffers of `mesh`; triangleMaterial (optional) groups the
// triangles into per-material index ranges.
void uploadMesh(GpuMesh& g, const sg::Mesh& mesh, const std::vector<uint16_t>* triangleMaterial);
// Builds (or rebuilds) texture g from t; false when t holds no image.
bool uploadTexture(GpuTexture& g, const sg::Texture& t);

struct RenderTarget {
    int width = 0, height = 0, samples = 0;
    bool hdr = false;   // linear RGBA16F colour (the display pass reads it), else sRGB8_ALPHA8
    GLuint fbo = 0, color = 0, depth = 0;
    GLuint colorTexture = 0;   // the colour as a texture instead of `color`: single-sampled linear targets
    GLuint ids = 0;            // RG32UI visibility (drawable, primitive) at attachment 1, when asked

    void release();
    // (Re)creates the FBO when the size, sample count, visibility or colour format changed.
    // Returns "" or the reason. Only attachment 0 is a draw buffer; the frame enables 1 when it
    // wants ids.
    std::string ensure(int w, int h, int s, bool withIds = false, bool linear = false);
};

// The overdraw view's target: one R32F colour buffer (no depth), where additive blending of
// 1.0 per fragment counts fragments exactly (up to 2^24 per pixel).
struct CountTarget {
    int width = 0, height = 0;
    GLuint fbo = 0, count = 0;

    void release();
    std::string ensure(int w, int h);
};

// Reads the visibility attachment (drawable, primitive) of `fbo` into `out` (already sized).
void readVisibility(GLuint fbo, int w, int h, Framebuffer& out);

// --- draws and passes (gl_passes.cpp) ---------------------------------------------------------

// One draw: a cached GPU mesh with a transform and a material (per range for tessellations).
// Opaque: opaque and masked surfaces, lines, points; Blended: alphaMode BLEND surfaces only;
// Wireframe: every triangle mesh again as lines (no material changes).
enum class DrawPass { Opaque, Blended, Wireframe };

struct DrawItem {
    GpuMesh* gpu = nullptr;
    const sg::mat4* world = nullptr;
    sg::mat3 normal{1.0f};
    bool mirrored = false;
    const sg::Material* material = nullptr;
    const std::vector<sg::Material>* rangeMaterials = nullptr;   // tessellation's per-range materials
    GpuTexture* texture = nullptr;
    GpuTexture* maps[4] = {nullptr, nullptr, nullptr, nullptr};   // emissive, occlusion, metallic-roughness, normal (units 1..4)
    uint32_t drawable = 0;                                        // Framebuffer::drawable (PreparedDraw::drawable)
    bool analytic = false;                                        // tessellated: no primitive index in the visibility
};

// Makes attachment 1 (visibility) a draw buffer and clears it to "nothing".
void beginVisibility();
// Sets the fixed-function state of a frame and clears the target (background is linear; the
// sRGB framebuffer encodes it).
void beginFrameState(const sg::RenderSettings& s, GLuint fbo, int w, int h, int samples);

// --- the renderer (gl_renderer.cpp; its members are spread over the files above) --------------

class GlRenderer final : public Renderer {
public:
    ~GlRenderer() override { releaseAll(); }

    std::string_view name() const override { return "gl"; }
    Capabilities capabilities() const override;
    Device device() const override;
    // The pixel inspector's shadows: the last frame's maps at p (read back from the GPU, the
    // layers asked for, once per frame).
    std::vector<float> lightVisibility(const sg::FrameInput& f, const sg::vec3& p, const sg::vec3& ng) override;
    std::vector<float> lightVisibilityMany(const sg::FrameInput& f, int light, const std::vector<sg::vec3>& p,
                                           const std::vector<sg::vec3>& ng) override;

protected:
    RenderStats doRender(const sg::FrameInput& frame, const RenderConfig& cfg, Framebuffer& target, RenderControl* control) override;

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
    // gl_renderer.cpp
    std::string prepareContext(bool& madeCurrent);
    void forgetGLObjects();   // drops names without deleting (their context is gone or not current)
    void releaseAll();
    // gl_programs.cpp
    void beginFramePrograms(const sg::FrameInput& frame, int ssaa, bool visibility);   // the frame useProgram serves
    Program* programFor(const Features& ft, std::string& error);                       // for this frame; compiles on first use
    bool useProgram(const Features& ft, std::string& error);                           // makes it m_current, frame uniforms set
    void setFrameUniforms(const Program& p, const sg::FrameInput& f, int ssaa);
    void setMaterial(Program& p, const sg::Material& m);
    Features featuresOf(const DrawItem& it, const sg::Material& m, DrawPass pass) const;
    // gl_resources.cpp
    GpuMesh* meshFor(const sg::Mesh& mesh, const std::vector<uint16_t>* triangleMaterial);
    GpuTexture* textureFor(const sg::TexturePtr& t);
    // Uploads what is new; tessellates new shapes as control's Shapes stage (empty when cancelled).
    std::vector<DrawItem> collectDraws(const sg::FrameInput& frame, int tessellation, RenderControl* control);
    void bindTextures(const DrawItem& it);
    void readBack(GLuint fbo, int w, int h, Framebuffer& out, bool withDepth = true);
    void evict();
    // gl_passes.cpp
    uint64_t drawAll(const std::vector<DrawItem>& items, DrawPass pass, sg::CullMode culling, std::string& error);
    uint64_t drawFramePasses(const std::vector<DrawItem>& items, const sg::RenderSettings& s, std::string& error);
    uint64_t drawBlendedPass(const std::vector<DrawItem>& items, const sg::RenderSettings& s, std::string& error);
    void drawWireframePass(const std::vector<DrawItem>& items, const sg::RenderSettings& s, std::string& error);
    std::string countOverdraw(const std::vector<DrawItem>& items, const sg::RenderSettings& s, int w, int h, Framebuffer& target);
    std::string resolveAndRead(int w, int h, int samples, int ssaa, bool visibility, Framebuffer& target);
    std::string displayPass(const sg::RenderSettings& s, GLuint frameTexture, int ssaa, int w, int h);   // linear frames only

    std::unique_ptr<GlContext> m_own;         // our headless context, made on first need
    const void* m_objectsContext = nullptr;   // the context our GL objects live in
    bool m_loaded = false;
    std::string m_contextDescription, m_platform;
    int m_maxSamples = 0, m_maxSize = 0;

    std::unordered_map<std::string, Program> m_programs;   // by programKey() + Features::key()
    // The frame being drawn: its input, setup key, SSAA factor and what the passes draw.
    const sg::FrameInput* m_frameInput = nullptr;
    std::string m_frameKey;
    int m_ssaa = 1;
    bool m_visibility = false;      // the target has the visibility attachment
    bool m_countPass = false;       // drawing the overdraw view's pass
    bool m_linear = false;          // this frame draws into linear targets (exposure or tone mapping)
    Program* m_current = nullptr;   // the program in use and its switches
    Features m_currentFeatures;
    static constexpr GLuint kUnknownTexture = ~0u;
    GLuint m_boundTexture[5] = {kUnknownTexture, kUnknownTexture, kUnknownTexture, kUnknownTexture, kUnknownTexture};   // units 0..4
    RenderTarget m_target, m_resolve;
    RenderTarget m_display;                // the display pass's sRGB8 output (linear frames)
    DisplayProgram m_displayPrograms[3];   // by sg::ToneMapping, built on first use
    GLuint m_emptyVao = 0;                 // the display pass's triangle needs no vertex data
    CountTarget m_overdraw;
    std::unordered_map<uint64_t, GpuMesh> m_meshes;        // by Mesh::id
    std::unordered_map<uint64_t, GpuTexture> m_textures;   // by Texture::id
    // pbr's environment light: this frame's (environmentFor), and its textures: the prefiltered
    // levels as one mipmapped texture (for the map uploaded last) and the split-sum table.
    EnvironmentLight m_environment;
    const EnvironmentMap* m_envUploaded = nullptr;
    GLuint m_envTexture = 0, m_splitSumTexture = 0, m_backgroundProgram = 0, m_backgroundVao = 0;
    void prepareEnvironment(const sg::FrameInput& frame, RenderStats& stats);
    void drawEnvironmentBackground(const sg::FrameInput& frame, std::string& error);
    void releaseEnvironment();   // deletes the objects above (their context current)
    void forgetEnvironment();    // forgets them (their context is gone)
    // Shadow maps (gl_shadows.cpp): this frame's plan (rnd::planShadows, every shading
    // model), its maps as the layers of one DEPTH_COMPONENT32F array texture (kept between
    // frames, reallocated when the size or the layer count changes), the FBO the depth pass
    // draws each layer through, the plan's uniform buffer and the depth-only program.
    ShadowPlan m_shadowPlan;
    GLuint m_shadowTexture = 0, m_shadowFbo = 0, m_shadowUbo = 0, m_shadowProgram = 0;
    GLint m_shadowModel = -1, m_shadowViewProj = -1, m_shadowDepth = -1;
    int m_shadowTextureSize = 0, m_shadowTextureLayers = 0;
    // What the maps in m_shadowTexture were drawn from: the plan's views and one key per drawn
    // range (sorted: the draw order changes with the camera, the depths do not). A frame with the
    // same views and keys keeps them (a still camera; a moving one where the maps do not follow
    // it); m_shadowDrawn false: nothing kept. VIEWER_GL_SHADOW_REUSE=0 draws them every frame.
    struct ShadowCasterKey {
        uint64_t mesh, version;
        sg::mat4 world;
        uint32_t first, count;
    };
    std::vector<ShadowView> m_shadowDrawnViews;
    std::vector<ShadowCasterKey> m_shadowDrawnCasters;
    bool m_shadowDrawn = false;
    bool m_shadowReuse = debugSwitches().glShadowReuse;   // VIEWER_GL_SHADOW_REUSE=0: draw the maps every frame
    std::string drawShadowLayers(const std::vector<DrawItem>& items, const std::vector<bool>& draw);
    int m_maxTextureSize = 0, m_maxTextureLayers = 0;   // the driver's limits
    // lightVisibility's: runs `ask` with the maps' context current (false: no maps to ask), and the
    // answer for light l at one point from the layer it needs.
    bool inMapsContext(const sg::FrameInput& f, const std::function<bool()>& ask);
    bool visibilityAt(const sg::FrameInput& f, size_t l, const sg::vec3& p, const sg::vec3& ng, float& out);
    ShadowPlan m_onePlan;                                   // visibilityAt's plan of one view
    std::unordered_map<int, ShadowMaps> m_shadowReadBack;   // layers read for lightVisibility this frame
    // Plans and draws this frame's maps (frame setup: before beginFrameState) and binds them
    // for the mesh programs; a map size the driver cannot make leaves the frame unshadowed,
    // with a note in stats. Returns "" or the reason the depth pass failed.
    std::string renderShadowMaps(const sg::FrameInput& frame, const std::vector<DrawItem>& items, RenderStats& stats);
    const ShadowMaps* shadowLayer(int view);   // one layer of the last frame's maps, read back on first use
    void releaseShadows();                     // deletes the objects above (their context current)
    void forgetShadows();                      // forgets them (their context is gone)
    TessellationCache m_tess;
    std::vector<uint8_t> m_readRows;   // read-back rows to flip (without GL_MESA_pack_invert)
    uint64_t m_frame = 0, m_meshUploads = 0, m_textureUploads = 0;
};

}   // namespace rnd::gl
