// raster_frame.h - what the stages of the CPU rasterizer's frame share (private to
// renderers/raster/): the draw items with their vertex-stage outputs, the scan-converted
// triangles and the chunks that bin them into tiles, the frame's context, the tile stage's
// buffers, and the entry point of each stage. The scan-conversion core itself (fixed-point setup,
// coverage, clipping) is raster_core.h, the vector kernels tile_kernels.h and raster_shading.h,
// the per-fragment attributes raster_fragment.h.
//
// Pipeline of one frame (tbb-parallel stages), by file:
//   1. gather     raster_renderer.cpp  meshes + tessellated analytics -> DrawItems; textures ->
//                                      SampledTextures
//   2. vertices   raster_vertex.cpp    object -> world -> eye -> clip, outcodes, window
//                                      coordinates; Gouraud: front + back vertex colours
//   3. triangles  raster_setup.cpp     chunks of triangles in submission order: clip in
//                                      homogeneous space, perspective divide, viewport, fixed-
//                                      point setup, culling, binning into 64x64 tiles
//   4. tiles      raster_tile.cpp      per tile, in parallel: rasterize the tile's triangles in
//                                      order into a visibility buffer (depth LESS + an index
//                                      into the tile's triangle list per pixel or MSAA sample)
//                 raster_shade.cpp     group the visible fragments by triangle, shade each once
//                                      (deferred), write sRGB bytes (one sample per pixel)
//                 raster_msaa.cpp      the same with 4 samples per pixel, and the resolve
//                 raster_blend.cpp     blended surfaces, sorted per pixel, composited "over"
//   5. lines      raster_renderer.cpp  Lines/Points meshes and the wireframe overlay
//   6. display    raster_shade.cpp     only when the display transform is not the identity
//                                      (exposure, tone mapping: renderers/tone_map.h): steps 4
//                                      and 5 write linear colour into the linear frame instead
//                                      of bytes (FrameContext::linear), and this step resolves
//                                      SSAA, applies the transform and encodes the bytes
#pragma once

#include "raster/raster_core.h"
#include "raster/raster_shading.h"
#include "raster/tile_kernels.h"
#include "renderers/environment.h"
#include "renderers/framebuffer.h"
#include "renderers/shading.h"
#include "renderers/shadow_map.h"
#include "renderers/srgb_encoder.h"
#include "renderers/texture_sampler.h"
#include "renderers/tone_map.h"
#include "scenegraph/frame.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>
#include <vector>

namespace rnd::raster {

constexpr uint32_t kNoTri = 0xFFFFFFFFu;
constexpr int kChunkBits = 20;   // triangle id = chunk << 20 | index in chunk

// ---------------------------------------------------------------------------------------
// Draw items (step 1) and their vertex-stage outputs (step 2)
// ---------------------------------------------------------------------------------------

struct DrawItem {
    DrawItem() = default;
    DrawItem(DrawItem&&) noexcept = default;
    DrawItem& operator=(DrawItem&&) noexcept = default;
    std::shared_ptr<const sg::Mesh> mesh;
    sg::mat4 world{1.0f};
    sg::mat3 normal{1.0f};
    sg::Material material;
    std::shared_ptr<const std::vector<uint16_t>> triMat;   // per-triangle material (CSG)
    std::shared_ptr<const std::vector<sg::Material>> materials;
    const SampledTexture* texture = nullptr;
    MapSamplers maps;   // maps.uv1 is cleared when the mesh has no uv1
    bool hasMaps() const { return maps.any(); }
    bool hasTangents = false;   // normal map with mesh tangents: wtan filled
    bool mirrored = false;
    bool perCorner = false;   // Gouraud with per-triangle materials: one vertex per corner
    bool hasNormals = false;
    bool hasUV = false;
    bool hasColors = false;
    uint64_t firstTri = 0;   // global index of its first triangle
    uint32_t drawable = 0;   // Framebuffer::drawable (PreparedDraw::drawable)
    bool analytic = false;   // tessellated analytic shape: no primitive in the visibility
    uint32_t triCount = 0;

    // Vertex stage outputs (one per vertex, or per corner when perCorner).
    std::vector<sg::vec4> clip;
    std::vector<uint8_t> code;
    std::vector<sg::vec4> win;   // window x, y, z, 1/w (valid when code == 0)
    // World position, world normal (0 without normals) and eye-space position (fog; 0 when
    // fog is off) of a vertex, side by side: the fragment stage fetches all three per triangle.
    struct VertexOut {
        sg::vec3 pos{0.0f}, nrm{0.0f}, eye{0.0f};
    };
    std::vector<VertexOut> wv;
    std::vector<sg::vec4> wtan;                       // world tangent (xyz, handedness; mirrored draws flip it), when hasTangents
    std::vector<sg::vec3> gouraudA[2], gouraudB[2];   // front/back: colour = A * albedo + B
    // Gouraud with shadow maps: A and B above leave out the lights of FrameContext::gouraudShadowed,
    // whose own terms are here, vertex v's of light j at v * count + j (empty: none).
    std::vector<sg::vec3> shadowedA[2], shadowedB[2];

    // Exchanges the vertex stage's buffers with `o` (the renderer keeps them between frames,
    // so a frame neither allocates nor zero-fills them: large meshes page-faulted on them).
    void swapBuffers(DrawItem& o) {
        clip.swap(o.clip);
        code.swap(o.code);
        win.swap(o.win);
        wv.swap(o.wv);
        wtan.swap(o.wtan);
        for (int s = 0; s < 2; ++s) {
            gouraudA[s].swap(o.gouraudA[s]);
            gouraudB[s].swap(o.gouraudB[s]);
            shadowedA[s].swap(o.shadowedA[s]);
            shadowedB[s].swap(o.shadowedB[s]);
        }
    }

    // Whether back faces of triangle `tri` are culled (RenderSettings::culling, per material).
    bool cullsBack(uint32_t tri, sg::CullMode mode) const {
        if (mode != sg::CullMode::Auto) return mode == sg::CullMode::On;
        return !materialOf(tri).doubleSided;
    }
    const sg::Material& materialOf(uint32_t tri) const {
        if (triMat && materials && tri < triMat->size() && (*triMat)[tri] < materials->size()) return (*materials)[(*triMat)[tri]];
        return material;
    }
    uint32_t meshIndex(uint32_t v) const { return perCorner ? mesh->indices[v] : v; }
    uint32_t vertexOf(uint32_t tri, int k) const { return perCorner ? tri * 3 + k : mesh->indices[size_t(tri) * 3 + k]; }
};

// A vector of DrawItems that grows moves them only if the move cannot throw; otherwise it
// copies, vertex buffers included (glm's vectors do not declare noexcept).
static_assert(std::is_nothrow_move_constructible_v<DrawItem>, "DrawItem must move without copying its buffers");

// ---------------------------------------------------------------------------------------
// Triangles and chunks (step 3)
// ---------------------------------------------------------------------------------------

// One scan-converted triangle (a whole input triangle or a piece of a clipped one).
struct Tri {
    // User-provided, so emplace_back() does not zero the record before the member initializers
    // run (it did: 15% of the triangle stage); setup writes every other field.
    Tri() {}
    TriCoverage s;   // edges (top-left bias folded in) and pixel bbox; 128 bytes in all, not 192
    TriPlanes pl;    // window z and u_k = lambda_k / w_k at pixel centre (minX, minY) and per-pixel steps
    uint32_t draw = 0, prim = 0;
    int32_t clip = -1;   // index into Chunk::clipBary (bary of setup vertices), -1 = none
    bool front = true;
    sg::AlphaMode alpha = sg::AlphaMode::Opaque;   // of its material
    uint8_t order[3] = {0, 1, 2};                  // TriSetup::order
};
static_assert(sizeof(Tri) <= 128, "a Tri is two cache lines");

struct Chunk {
    uint64_t begin = 0, end = 0;   // global triangle range
    std::vector<Tri> tris;
    std::vector<std::array<sg::vec3, 3>> clipBary;
    std::vector<uint32_t> tileStart, items;   // CSR: tiles -> triangle indices in order
    struct TileRect {
        uint16_t x0, y0, x1, y1;   // tiles a triangle's bbox touches, inclusive
    };
    std::vector<TileRect> rects;   // one per triangle: binning reads these, not the triangles
    std::vector<uint32_t> fill;    // scratch for binning
};

struct FrameContext {
    const sg::FrameInput* frame = nullptr;
    int width = 0, height = 0;
    int tilesX = 0, tilesY = 0;
    bool msaa = false;
    bool referenceShading = false;
    bool pbr = false;                                // settings.reflection == pbr: ShadeBatch::setPbr and pbr_kernel.inl
    const EnvironmentLight* environment = nullptr;   // pbr's environment light (empty map: none)
    const ShadowPlan* shadowPlan = nullptr;          // the lights' shadow maps (empty plan: no shadows)
    const ShadowMaps* shadowMaps = nullptr;
    // Flat and Gouraud shading with shadow maps (docs/math.md, "Shadow maps"): the lights with a
    // map (flat: each scaled by the fragment's visibility), per light 0 for those and 1 for the
    // rest (shadeTerms' visibility for the unshadowed sum; empty without maps), and the lights
    // Gouraud shadows (gouraudShadowedLights; the vertex stage's DrawItem::shadowedA/B).
    std::vector<int> mappedLights;
    std::vector<float> unmapped;
    std::vector<int> gouraudShadowed;
    bool timing = false;       // VIEWER_RASTER_TIMING=1: print stage times to stderr
    bool visibility = false;   // fill target.drawable/primitive (one sample per pixel)
    bool overdraw = false;     // count fragments per pixel into target.overdraw (one sample per pixel)
    // The linear frame (width x height, rows top-down like the framebuffer) while the display
    // transform is not the identity: the tiles write each pixel's linear colour (after fog, the
    // MSAA resolve and blending) here and no colour bytes; nullptr: sRGB bytes as always.
    sg::vec3* linear = nullptr;
    std::vector<DrawItem>* draws = nullptr;
    std::vector<Chunk>* chunks = nullptr;
};

inline const Tri& triById(const std::vector<Chunk>& chunks, uint32_t id) { return chunks[id >> kChunkBits].tris[id & ((1u << kChunkBits) - 1)]; }

// The linear frame's storage, kept between frames and grown without being initialised: the
// tiles write every pixel, in parallel, so its pages are first touched by the workers instead of
// being zero-filled on one thread (~35 ms at 1280x720 here).
struct LinearFrame {
    std::unique_ptr<float[]> storage;
    size_t capacity = 0;   // pixels
    sg::vec3* pixels(size_t n) {
        static_assert(sizeof(sg::vec3) == 3 * sizeof(float), "a pixel is three packed floats");
        if (n > capacity) {
            storage = std::make_unique_for_overwrite<float[]>(3 * n);
            capacity = n;
        }
        return reinterpret_cast<sg::vec3*>(storage.get());
    }
};

// Pixel (i, j) of the linear frame (j: window row, 0 at the bottom, as the tiles count).
inline sg::vec3& linearAt(const FrameContext& fc, int i, int j) { return fc.linear[size_t(fc.height - 1 - j) * fc.width + i]; }
// The tile's pixels [x0, x1] x [y0, y1] of the linear frame set to the background.
inline void fillLinearBackground(const FrameContext& fc, int x0, int y0, int x1, int y1) {
    for (int j = y0; j <= y1; ++j) std::fill_n(&linearAt(fc, x0, j), x1 - x0 + 1, fc.frame->settings.background);
}

// ---------------------------------------------------------------------------------------
// The tile stage's buffers (step 4), one set per worker thread
// ---------------------------------------------------------------------------------------

// A fragment of a blended surface (alphaMode BLEND), kept for the per-pixel sorted composite.
struct BlendFrag {
    uint16_t pixel;     // in the tile
    uint8_t coverage;   // samples of the pixel it covers in front of the opaque depth (1, or 1..4 with MSAA)
    float z;            // window depth at the pixel centre
    float alpha;
    uint32_t tri;
    uint32_t order;   // submission order (ties in depth: the later one on top, as GL)
};

// A run of fragments of one triangle: slots [begin, begin + count) of the tile's fragments.
struct FragRun {
    uint32_t tri;   // global triangle id (chunk << kChunkBits | index)
    uint32_t begin, count;
};

struct TileBuffers {
    std::vector<float> depth;
    std::vector<uint32_t> blendTris;   // blended triangles of this tile, in submission order
    std::vector<BlendFrag> blendFrags;
    // The visibility buffer: per pixel (or MSAA sample) an index into tileTris, the global ids of
    // the tile's opaque and masked triangles in submission order (kNoTri: none).
    std::vector<uint32_t> ids;
    std::vector<uint32_t> tileTris;
    std::vector<uint32_t> runStart;                                                       // per entry of tileTris: its fragments' first slot
    std::vector<uint32_t> runEnd;                                                         // per entry of tileTris: one past its fragments' last slot
    std::vector<FragRun> runs;                                                            // the fragments, grouped by triangle
    std::vector<uint64_t> rowRuns = std::vector<uint64_t>(kTileSize);                     // per row: bit i = a run of equal ids starts at pixel i
    std::vector<uint32_t> color = std::vector<uint32_t>(size_t(kTileSize) * kTileSize);   // RGBA8 of the tile (one sample per pixel)
    std::vector<uint16_t> fragPixel;                                                      // pixel index in the tile
    std::vector<uint32_t> fragTri;                                                        // MSAA: global triangle id
    std::vector<uint8_t> fragCount;                                                       // MSAA samples covered
    std::vector<float> fogDist;
    std::vector<sg::vec3> accum;   // MSAA: linear colour sum per pixel
    ShadeBatch batch;
};

// The background colour as the tiles store it: sRGB bytes and alpha 255 in one RGBA8 word.
inline uint32_t backgroundWord(const sg::RenderSettings& st) {
    const SrgbEncoder& enc = srgbEncoder();
    const uint8_t px[4] = {enc(st.background.x), enc(st.background.y), enc(st.background.z), 255};
    uint32_t word;
    std::memcpy(&word, px, 4);
    return word;
}

// Per-stage time of the tile stage (ns, summed over threads), for VIEWER_RASTER_TIMING
// (raster_tile.cpp holds them).
extern std::atomic<int64_t> g_rasterNs, g_prepareNs, g_lightNs;
inline int64_t nowNs() { return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// ---------------------------------------------------------------------------------------
// The stages
// ---------------------------------------------------------------------------------------

// Step 2 (raster_vertex.cpp): transforms, outcodes and window coordinates of d's vertices
// (Gouraud: the lighting terms of both sides too).
// Shadows: the maps' answer (shadowVisibility) for the lit fragments [0, n) of a batch, per
// light, into ShadeBatch::vis (raster_shadows.cpp); nothing without a shadow plan.
void fillShadowVisibility(const FrameContext& fc, ShadeBatch& b, size_t n);
// What a renderer's shadow maps were last drawn from: the maps' views and size, and a copy of
// every caster's world positions and triangles. A frame whose casters equal it bit for bit
// keeps each map whose view is the same too (a still camera keeps them all; a moving one
// refits a directional light's maps and keeps the spot and point lights').
struct ShadowMapsSource {
    bool valid = false;
    int size = 0;
    std::vector<ShadowView> views;
    std::vector<float> positions;    // xyz per vertex, caster after caster
    std::vector<uint32_t> indices;   // per caster with indices, caster after caster
    std::vector<uint64_t> shape;     // per caster: vertices, triangles, whether indexed
    void clear() {                   // (the copies' memory too: they are as large as the casters' meshes)
        *this = ShadowMapsSource{};
    }
};

// The depth maps of the plan from the frame's opaque and masked triangles (world positions of
// the vertex stage). source (optional): what the maps were last drawn from; when this frame's
// casters and a map's view are the same that map is left as it is (and source is updated when
// any is drawn). Returns how many maps were drawn.
int renderShadowMaps(const ShadowPlan& plan, const std::vector<DrawItem>& draws, ShadowMaps& maps, ShadowMapsSource* source = nullptr);

// shadowed: Gouraud's lights with per-fragment visibility (FrameContext::gouraudShadowed), kept
// apart in DrawItem::shadowedA/B.
void runVertexStage(DrawItem& d, const sg::FrameInput& f, int width, int height, bool gouraud, const EnvironmentLight* env,
                    const std::vector<int>& shadowed);

// Step 3 (raster_setup.cpp): clips, sets up and culls the chunk's triangles and bins them into
// the tiles (ch.tileStart / ch.items, submission order within each tile).
void runTriangleStage(Chunk& ch, const FrameContext& fc);

// Step 4 (raster_tile.cpp): rasterizes the tile's triangles into its visibility buffer (opaque
// and masked ones; blended ones are set aside), shades what is visible, then composites the
// blended surfaces.
void renderTile(int tile, const FrameContext& fc, Framebuffer& target, TileBuffers& buf);

// Shades the visible opaque (and kept masked) fragments of the tile and writes its pixels: one
// sample per pixel (raster_shade.cpp), or, with samples = 4, through the MSAA path below.
void shadeOpaque(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples);

// MSAA (raster_msaa.cpp): the tile's fragments, one per pixel and distinct triangle among its
// samples with the number of samples it covers (buf.fragPixel/fragTri/fragCount, buf.runs);
// writes the background and the depth (nearest sample) of every pixel. Returns their count.
size_t gatherMsaaFragments(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1);
// MSAA resolve: the shaded fragments [0, nf) averaged per pixel in linear space, weighed by the
// samples they cover (background for the rest), into the framebuffer.
void resolveMsaa(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, size_t nf);

// Blended surfaces of the tile (raster_blend.cpp), after its opaque ones: see there.
void renderBlended(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples);

// Step 6 (raster_shade.cpp): the linear frame `linear` of `factor` x the target's size box-
// filtered down by `factor` (SSAA; 1: as it is), through the display transform, into the
// target's colour bytes (alpha 255). The target's depth is left as it is.
void encodeLinearFrame(const sg::vec3* linear, int factor, const DisplayTransform& display, Framebuffer& target);

}   // namespace rnd::raster
