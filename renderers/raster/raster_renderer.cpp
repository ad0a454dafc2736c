// raster_renderer.cpp - the "raster" backend: our own CPU implementation of the pipeline of
// docs/math.md (modelling, lighting, viewing, projection, clipping, scan conversion).
//
// Pipeline of one frame (tbb-parallel stages):
//   1. gather     meshes + tessellated analytics -> DrawItems; textures -> SampledTextures
//   2. vertices   object -> world -> eye -> clip (DrawMesh::world, normal, camera view/proj),
//                 outcodes, window coordinates; Gouraud: front + back vertex colours
//   3. triangles  chunks of triangles in submission order: clip in homogeneous space (near and
//                 far exactly, x/y outside a guard band), perspective divide, viewport, fixed-
//                 point setup, culling, binning into 64x64 tiles
//   4. tiles      per tile, in parallel: rasterize the tile's triangles in order into a
//                 visibility buffer (depth LESS + an index into the tile's triangle list per
//                 pixel or per MSAA sample), group the visible fragments by triangle, then
//                 shade each once (deferred): perspective-correct barycentrics -> attributes
//                 -> rnd::shade / applyFog -> sRGB bytes. The hot loops (coverage, plain
//                 fragments' attributes, lighting, output) are vector kernels, AVX2 or SSE2
//                 (tile_kernels.h, raster_shading.h), equal bit for bit to the scalar code.
//   5. lines      Lines/Points meshes and the wireframe overlay with the DDA line rasterizer
// SSAA renders at aaRate x the size and box-filters down; MSAA 4x keeps 4 samples per pixel
// (coverage + depth per sample) and shades once per pixel and triangle at the pixel centre.
//
// Sections: [helpers] [draw items] [vertex stage] [triangle stage] [tile stage] [lines]
//           [renderer]
#include "raster/raster_renderer.h"
#include "renderers/debug_switches.h"

#include "common/line_overlay.h"
#include "raster/raster_core.h"
#include "raster/raster_shading.h"
#include "raster/simd.h"
#include "raster/srgb_encoder.h"
#include "raster/tile_kernels.h"
#include "renderers/draw_list.h"
#include "renderers/shading.h"
#include "renderers/tessellate.h"
#include "renderers/texture_sampler.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <type_traits>
#include <unordered_map>

namespace rnd {
namespace {

using namespace raster;
using sg::mat3;
using sg::mat4;
using sg::vec2;
using sg::vec3;
using sg::vec4;

// ---------------------------------------------------------------------------------------
// [helpers]
// ---------------------------------------------------------------------------------------

constexpr uint32_t kNoTri = 0xFFFFFFFFu;
constexpr int kChunkBits = 20;   // triangle id = chunk << 20 | index in chunk

// ---------------------------------------------------------------------------------------
// [draw items]
// ---------------------------------------------------------------------------------------

struct DrawItem {
    DrawItem() = default;
    DrawItem(DrawItem&&) noexcept = default;
    DrawItem& operator=(DrawItem&&) noexcept = default;
    std::shared_ptr<const sg::Mesh> mesh;
    mat4 world{1.0f};
    mat3 normal{1.0f};
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
    std::vector<vec4> clip;
    std::vector<uint8_t> code;
    std::vector<vec4> win;   // window x, y, z, 1/w (valid when code == 0)
    // World position, world normal (0 without normals) and eye-space position (fog; 0 when
    // fog is off) of a vertex, side by side: the fragment stage fetches all three per triangle.
    struct VertexOut {
        vec3 pos{0.0f}, nrm{0.0f}, eye{0.0f};
    };
    std::vector<VertexOut> wv;
    std::vector<vec4> wtan;                       // world tangent (xyz, handedness; mirrored draws flip it), when hasTangents
    std::vector<vec3> gouraudA[2], gouraudB[2];   // front/back: colour = A * albedo + B

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
// [vertex stage]
// ---------------------------------------------------------------------------------------

void runVertexStage(DrawItem& d, const sg::FrameInput& f, int width, int height, bool gouraud) {
    const sg::Mesh& m = *d.mesh;
    size_t n = d.perCorner ? m.indices.size() : m.positions.size();
    d.clip.resize(n);
    d.code.resize(n);
    d.win.resize(n);
    d.wv.resize(n);
    const bool fog = f.settings.fog != sg::FogMode::Off;
    d.wtan.resize(d.hasTangents ? n : 0);
    const float handedness = d.mirrored ? -1.0f : 1.0f;   // a mirroring transform flips cross(n, t)
    if (gouraud)
        for (int s = 0; s < 2; ++s) {
            d.gouraudA[s].resize(n);
            d.gouraudB[s].resize(n);
        }
    const mat4 viewProj = f.camera.proj * f.camera.view;
    const GuardBand g = guardBand(width, height);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            uint32_t mi = d.meshIndex(uint32_t(v));
            DrawItem::VertexOut& o = d.wv[v];
            if (mi >= m.positions.size()) {   // zeros, as in a new buffer
                d.code[v] = kClipNear;
                d.clip[v] = vec4(0.0f);
                o = DrawItem::VertexOut{};
                if (d.hasTangents) d.wtan[v] = vec4(0.0f);
                if (gouraud)
                    for (int s = 0; s < 2; ++s) d.gouraudA[s][v] = d.gouraudB[s][v] = vec3(0.0f);
                continue;
            }
            vec4 w = d.world * vec4(m.positions[mi], 1.0f);   // modelling: object -> world
            vec4 c = viewProj * w;                            // viewing + projection -> clip
            o.pos = vec3(w);
            o.eye = fog ? vec3(f.camera.view * vec4(o.pos, 1.0f)) : vec3(0.0f);
            d.clip[v] = c;
            d.code[v] = outcode(c, g);
            if (d.code[v] == 0) d.win[v] = toWindow(c, width, height);
            if (d.hasNormals) {
                vec3 nn = d.normal * m.normals[mi];   // normal matrix (inverse transpose)
                float len = glm::length(nn);
                o.nrm = len > 0 ? nn / len : vec3(0, 0, 1);
            } else {
                o.nrm = vec3(0.0f);
            }
            if (d.hasTangents) d.wtan[v] = vec4(mat3(d.world) * vec3(m.tangents[mi]), m.tangents[mi].w * handedness);
            if (gouraud) {
                const sg::Material& mat = d.perCorner ? d.materialOf(uint32_t(v / 3)) : d.material;
                // Gouraud: the model's two albedo-linear terms at the vertex, front and back side.
                ShadeTerms front = shadeTerms(mat, o.pos, o.nrm, f.camera.eye, f);
                ShadeTerms back = shadeTerms(mat, o.pos, -o.nrm, f.camera.eye, f);
                d.gouraudA[0][v] = front.mul;
                d.gouraudB[0][v] = front.add;
                d.gouraudA[1][v] = back.mul;
                d.gouraudB[1][v] = back.add;
            }
        }
    });
}

// ---------------------------------------------------------------------------------------
// [triangle stage]
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
    std::vector<std::array<vec3, 3>> clipBary;
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
    bool timing = false;       // VIEWER_RASTER_TIMING=1: print stage times to stderr
    bool visibility = false;   // fill target.drawable/primitive (one sample per pixel)
    bool overdraw = false;     // count fragments per pixel into target.overdraw (one sample per pixel)
    std::vector<DrawItem>* draws = nullptr;
    std::vector<Chunk>* chunks = nullptr;
};

// Stores setup `s` into t (coverage, z and 1/w planes).
bool finishTri(Tri& t, const TriSetup& s, const float z[3], const float iw[3]) {
    t.s.set(s);
    for (int k = 0; k < 3; ++k) t.order[k] = s.order[k];
    t.pl = makeTriPlanes(s, z, iw);
    return true;
}

void runTriangleStage(Chunk& ch, const FrameContext& fc) {
    const std::vector<DrawItem>& draws = *fc.draws;
    const auto& st = fc.frame->settings;
    const GuardBand g = guardBand(fc.width, fc.height);
    // Triangles are counted per tile as they are made (binning's first pass); `rects` keeps
    // their tile ranges for the second.
    const int nt = fc.tilesX * fc.tilesY;
    ch.tileStart.assign(size_t(nt) + 1, 0);
    ch.rects.clear();
    // One Tri per input triangle unless clipped: sized once, so a first frame does not grow
    // (and copy) the vectors step by step.
    ch.tris.reserve(size_t(ch.end - ch.begin));
    ch.rects.reserve(size_t(ch.end - ch.begin));
    auto bin = [&](const Tri& tri) {   // counts ch.tris.back()
        const Chunk::TileRect r{uint16_t(tri.s.minX / kTileSize), uint16_t(tri.s.minY / kTileSize), uint16_t(tri.s.maxX / kTileSize),
                                uint16_t(tri.s.maxY / kTileSize)};
        ch.rects.push_back(r);
        for (int ty = r.y0; ty <= r.y1; ++ty)
            for (int tx = r.x0; tx <= r.x1; ++tx) ++ch.tileStart[size_t(ty) * fc.tilesX + tx + 1];
    };
    // First draw containing ch.begin.
    size_t di =
        size_t(std::upper_bound(draws.begin(), draws.end(), ch.begin, [](uint64_t v, const DrawItem& d) { return v < d.firstTri; }) - draws.begin()) -
        1;
    for (uint64_t gi = ch.begin; gi < ch.end; ++gi) {
        while (gi >= draws[di].firstTri + draws[di].triCount) ++di;
        const DrawItem& d = draws[di];
        uint32_t t = uint32_t(gi - d.firstTri);
        uint32_t v[3];
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
            v[k] = d.vertexOf(t, k);
            ok = ok && v[k] < d.clip.size();
        }
        if (!ok) continue;
        uint8_t c0 = d.code[v[0]], c1 = d.code[v[1]], c2 = d.code[v[2]];
        if (c0 & c1 & c2) continue;                // all outside one plane
        if ((c0 | c1 | c2) & kInvalid) continue;   // non-finite vertex
        if ((c0 | c1 | c2) == 0) {
            const vec4 &w0 = d.win[v[0]], &w1 = d.win[v[1]], &w2 = d.win[v[2]];
            float wx[3] = {w0.x, w1.x, w2.x};
            float wy[3] = {w0.y, w1.y, w2.y};
            TriSetup s;   // full setup on the stack; the record keeps its compact part
            if (!setupTriangle(wx, wy, fc.width, fc.height, s, fc.msaa)) continue;
            const bool front = s.flipped == d.mirrored;   // CCW is front; mirrored instances: CW
            if (!front && d.cullsBack(t, st.culling)) continue;
            Tri& tri = ch.tris.emplace_back();   // made in place
            tri.front = front;
            tri.alpha = d.materialOf(t).alphaMode;
            float z[3] = {w0.z, w1.z, w2.z};
            float iw[3] = {w0.w, w1.w, w2.w};
            finishTri(tri, s, z, iw);
            tri.draw = uint32_t(di);
            tri.prim = t;
            bin(tri);
            continue;
        }
        // Clip in homogeneous space, then fan-triangulate the polygon.
        vec4 c[3] = {d.clip[v[0]], d.clip[v[1]], d.clip[v[2]]};
        ClipVertex poly[9];
        int n = clipTriangle(c, uint8_t(c0 | c1 | c2), g, poly);
        if (n < 3) continue;
        vec4 w[9];
        for (int k = 0; k < n; ++k) w[k] = toWindow(poly[k].clip, fc.width, fc.height);
        for (int k = 1; k + 1 < n; ++k) {
            int idx[3] = {0, k, k + 1};
            Tri tri;
            float wx[3], wy[3], z[3], iw[3];
            for (int q = 0; q < 3; ++q) {
                wx[q] = w[idx[q]].x;
                wy[q] = w[idx[q]].y;
                z[q] = w[idx[q]].z;
                iw[q] = w[idx[q]].w;
            }
            TriSetup s;
            if (!setupTriangle(wx, wy, fc.width, fc.height, s, fc.msaa)) continue;
            tri.front = s.flipped == d.mirrored;
            if (!tri.front && d.cullsBack(t, st.culling)) continue;
            tri.alpha = d.materialOf(t).alphaMode;
            finishTri(tri, s, z, iw);
            tri.draw = uint32_t(di);
            tri.prim = t;
            tri.clip = int32_t(ch.clipBary.size());
            ch.clipBary.push_back({poly[idx[tri.order[0]]].bary, poly[idx[tri.order[1]]].bary, poly[idx[tri.order[2]]].bary});
            bin(ch.tris.emplace_back(tri));
        }
    }
    // Bin into tiles (counting sort keeps submission order within each tile).
    for (int i = 0; i < nt; ++i) ch.tileStart[i + 1] += ch.tileStart[i];
    ch.items.resize(ch.tileStart[nt]);
    ch.fill.assign(ch.tileStart.begin(), ch.tileStart.end() - 1);
    std::vector<uint32_t>& fill = ch.fill;
    for (uint32_t i = 0; i < ch.rects.size(); ++i) {
        const Chunk::TileRect r = ch.rects[i];
        for (int ty = r.y0; ty <= r.y1; ++ty)
            for (int tx = r.x0; tx <= r.x1; ++tx) ch.items[fill[size_t(ty) * fc.tilesX + tx]++] = i;
    }
}

// ---------------------------------------------------------------------------------------
// [tile stage]
// ---------------------------------------------------------------------------------------

// Rasterizes one triangle into the tile's visibility buffer (depth LESS). `samples` is 1 or 4
// (MSAA: sample s of pixel p at index p*4 + s).
// keep(i, j): whether the fragment of pixel (i, j) survives (alpha mask), asked only for
// samples that pass the depth test.
template <class Keep>
inline void rasterizeTri(const Tri& t, uint32_t id, int tx0, int ty0, int tx1, int ty1, int samples, float* depth, uint32_t* ids, Keep&& keep) {
    int x0 = std::max(tx0, int(t.s.minX)), x1 = std::min(tx1, int(t.s.maxX));
    int y0 = std::max(ty0, int(t.s.minY)), y1 = std::min(ty1, int(t.s.maxY));
    if (x0 > x1 || y0 > y1) return;
    const int tw = kTileSize;
    const PackedEdge& e0 = t.s.e[0];
    const PackedEdge& e1 = t.s.e[1];
    const PackedEdge& e2 = t.s.e[2];
    if (samples == 1) {
        auto pixel = [&](int i, int j) {
            float z = t.pl.zRef + t.pl.zdx * float(i - t.s.minX) + t.pl.zdy * float(j - t.s.minY);
            z = std::clamp(z, 0.0f, 1.0f);
            size_t p = size_t(j - ty0) * tw + (i - tx0);
            if (z < depth[p] && keep(i, j)) {
                depth[p] = z;
                ids[p] = id;
            }
        };
        if (x1 - x0 <= 1 && y1 - y0 <= 1) {
            // At most 2x2 pixels (most triangles of a big mesh): the edge functions at each pixel
            // centre directly, as forEachCoveredPixelSimple; the same pixels in the same order
            // as the block walk, without its setup.
            for (int j = y0; j <= y1; ++j)
                for (int i = x0; i <= x1; ++i) {
                    const int64_t px = int64_t(i) * kSub + kHalf, py = int64_t(j) * kSub + kHalf;
                    if (e0.at(px, py) >= e0.bias && e1.at(px, py) >= e1.bias && e2.at(px, py) >= e2.bias) pixel(i, j);
                }
            return;
        }
        forEachCoveredPixel(t.s, x0, y0, x1, y1, pixel);
        return;
    }
    for (int j = y0; j <= y1; ++j)
        for (int i = x0; i <= x1; ++i) {
            int p = ((j - ty0) * tw + (i - tx0)) * 4;
            for (int s = 0; s < 4; ++s) {
                int64_t px = int64_t(i) * kSub + kMsaa4X[s], py = int64_t(j) * kSub + kMsaa4Y[s];
                if (e0.at(px, py) < e0.bias || e1.at(px, py) < e1.bias || e2.at(px, py) < e2.bias) continue;
                float z = t.pl.zRef + t.pl.zdx * (float(i - t.s.minX) + float(kMsaa4X[s] - kHalf) / kSub) +
                          t.pl.zdy * (float(j - t.s.minY) + float(kMsaa4Y[s] - kHalf) / kSub);
                z = std::clamp(z, 0.0f, 1.0f);
                if (z < depth[p + s] && keep(i, j)) {
                    depth[p + s] = z;
                    ids[p + s] = id;
                }
            }
        }
}

__attribute__((noinline)) void rasterizeIntoTile(const Tri& t, uint32_t id, int tx0, int ty0, int tx1, int ty1, int samples, float* depth,
                                                 uint32_t* ids) {
#if defined(RASTER_HAVE_SSE2)
    // One sample per pixel, bigger than 2x2 pixels (rasterizeTri's own short path): a row of an
    // 8x8 block per vector step, the same pixels and depths.
    if (samples == 1) {
        const int x0 = std::max(tx0, int(t.s.minX)), x1 = std::min(tx1, int(t.s.maxX));
        const int y0 = std::max(ty0, int(t.s.minY)), y1 = std::min(ty1, int(t.s.maxY));
        if (x0 > x1 || y0 > y1) return;
        if ((x1 - x0 > 1 || y1 - y0 > 1) && coverageFits32(t.s)) {
            rasterizeOpaque(t.s, t.pl, id, tx0, ty0, x0, y0, x1, y1, depth, ids);
            return;
        }
    }
#endif
    rasterizeTri(t, id, tx0, ty0, tx1, ty1, samples, depth, ids, [](int, int) { return true; });
}

// Per-triangle data of the fragment stage, fetched once per run of fragments of the same
// triangle (consecutive pixels of a tile mostly share one).
// PlainTri (tile_kernels.h) holds the planes, clip barycentrics (cb), world and eye positions
// (p, pe), normals (n: n[0] alone when faceNormal) and the material's constant block (slot).
struct TriCache : PlainTri {
    uint32_t id = kNoTri;
    const Tri* t = nullptr;
    const DrawItem* d = nullptr;
    const sg::Material* mat = nullptr;
    uint32_t v[3] = {0, 0, 0};
    bool gouraud = false;
    // Plain lit fragment (no vertex colours, textures or maps, not Gouraud, not reference
    // shading): prepareFragment takes the short path with the material's coefficients below.
    bool simple = false;
    PhongCoefficients coeff;
    vec3 simpleSpec, simpleBase;   // ShadeBatch::set's specular colour and ambient + emissive term (simple)
    // slot: the material's ShadeBatch constant block (simple; -1: not added yet)

    void load(uint32_t newId, const Tri& tri, const Chunk& ch, const FrameContext& fc) {
        id = newId;
        t = &tri;
        const sg::FrameInput& f = *fc.frame;
        // Per draw (and material): the same for every triangle of a draw without per-triangle
        // materials, so consecutive fragments of one mesh skip it.
        const DrawItem* nd = &(*fc.draws)[tri.draw];
        const sg::Material* nm = nd->triMat ? &nd->materialOf(tri.prim) : &nd->material;
        if (nd != d || nm != mat) {
            d = nd;
            mat = nm;
            slot = -1;
            gouraud = f.settings.shading == sg::ShadingModel::Gouraud && !d->gouraudA[0].empty();
            faceNormal = f.settings.shading == sg::ShadingModel::Flat || !d->hasNormals;
            simple = !gouraud && !fc.referenceShading && !d->hasColors && !(d->texture && d->hasUV) && !(d->hasUV && d->hasMaps());
            if (simple) {
                coeff = coefficientsOf(*mat);
                simple = !coeff.unlit;
                const vec3 albedo = mat->baseColor;   // ShadeBatch::set() with this albedo
                simpleSpec = coeff.specularTinted ? albedo : coeff.specularColor;
                simpleBase = coeff.ka * albedo * f.ambientLight + coeff.emissive;
            }
        }
        cb = tri.clip >= 0 ? &ch.clipBary[size_t(tri.clip)] : nullptr;
        pl = &tri.pl;
        minX = tri.s.minX;
        minY = tri.s.minY;
        swapped = tri.order[1] != 1;   // setupTriangle's two orders: {0, 1, 2} or {0, 2, 1}
        vec3 nv[3];
        for (int k = 0; k < 3; ++k) {
            v[k] = d->vertexOf(tri.prim, k);
            const DrawItem::VertexOut& o = d->wv[v[k]];
            p[k] = o.pos;
            pe[k] = o.eye;
            nv[k] = o.nrm;
        }
        if (faceNormal) {
            // Face normal of the world-space triangle; outward = CCW side (CW for mirrored),
            // flipped toward the viewer when seen from the back (two-sided).
            vec3 nn = glm::cross(p[1] - p[0], p[2] - p[0]);
            if (d->mirrored != !tri.front) nn = -nn;
            float len = glm::length(nn);
            n[0] = len > 0 ? nn / len : vec3(0, 0, 1);
        } else {
            for (int k = 0; k < 3; ++k) n[k] = tri.front ? nv[k] : -nv[k];
        }
    }
};

// Perspective-correct barycentrics at the centre of pixel (i, j): b for the setup vertices,
// bo for the input triangle's corners; invSum = 1 / sum(lambda_k / w_k).
struct FragBary {
    float b[3];
    vec3 bo;
    float invSum;
};

inline FragBary baryAt(const TriCache& tc, int i, int j) {
    const Tri& t = *tc.t;
    FragBary fb;
    const float di = float(i - t.s.minX), dj = float(j - t.s.minY);
    // Perspective correction: lambda/w is linear in screen space; divide by the sum (1/w).
    float u[3], sum = 0;
    for (int q = 0; q < 3; ++q) {
        u[q] = t.pl.uRef[q] + t.pl.udx[q] * di + t.pl.udy[q] * dj;
        sum += u[q];
    }
    fb.invSum = sum != 0 ? 1.0f / sum : 0.0f;
    for (int q = 0; q < 3; ++q) fb.b[q] = u[q] * fb.invSum;
    // Weights of the input triangle's corners.
    const std::array<vec3, 3>* cb = tc.cb;
    if (cb)
        fb.bo = fb.b[0] * (*cb)[0] + fb.b[1] * (*cb)[1] + fb.b[2] * (*cb)[2];
    else {
        fb.bo[t.order[0]] = fb.b[0];
        fb.bo[t.order[1]] = fb.b[1];
        fb.bo[t.order[2]] = fb.b[2];
    }
    return fb;
}

// Texture coordinate at the fragment and its screen derivatives for the mip level, taken as GL
// implementations take them: finite differences over the fragment's 2x2 pixel quad (quads at
// even window x and y), d/dx = uv(x0 + 1, y0) - uv(x0, y0) and d/dy = uv(x0, y0 + 1) - uv(x0, y0)
// at pixel centres, the same for the four pixels (points outside the triangle extrapolate its
// plane, like GL's helper invocations). `set` is the mesh's uv0 (needs d.hasUV) or uv1.
inline void uvAt(const TriCache& tc, const FragBary& fb, const uint32_t mi[3], int i, int j, const std::vector<vec2>& set, vec2& uv, vec2& ddx,
                 vec2& ddy) {
    const Tri& t = *tc.t;
    const std::array<vec3, 3>* cb = tc.cb;
    vec2 uvc[3] = {set[mi[0]], set[mi[1]], set[mi[2]]};
    vec2 uvk[3];   // uv at the setup vertices
    for (int q = 0; q < 3; ++q) {
        vec3 w = cb ? (*cb)[q] : vec3(t.order[q] == 0, t.order[q] == 1, t.order[q] == 2);
        uvk[q] = w[0] * uvc[0] + w[1] * uvc[1] + w[2] * uvc[2];
    }
    uv = fb.b[0] * uvk[0] + fb.b[1] * uvk[1] + fb.b[2] * uvk[2];
    // uv at the centre of pixel (pi, pj): perspective-correct barycentrics from the setup planes.
    auto uvAtPixel = [&](int pi, int pj) {
        const float di = float(pi - t.s.minX), dj = float(pj - t.s.minY);
        float u[3], sum = 0;
        for (int q = 0; q < 3; ++q) {
            u[q] = t.pl.uRef[q] + t.pl.udx[q] * di + t.pl.udy[q] * dj;
            sum += u[q];
        }
        const float inv = sum != 0 ? 1.0f / sum : 0.0f;
        return (u[0] * inv) * uvk[0] + (u[1] * inv) * uvk[1] + (u[2] * inv) * uvk[2];
    };
    const int i0 = i & ~1, j0 = j & ~1;
    const vec2 base = (i0 == i && j0 == j) ? uv : uvAtPixel(i0, j0);
    ddx = uvAtPixel(i0 + 1, j0) - base;
    ddy = uvAtPixel(i0, j0 + 1) - base;
}

// Alpha of the fragment at the centre of pixel (i, j): material alpha x vertex colour alpha x
// texture alpha (filtered like the colour), as GL's fragment shader computes it.
float fragmentAlpha(const TriCache& tc, int i, int j) {
    const DrawItem& d = *tc.d;
    float a = tc.mat->alpha;
    const bool texAlpha = d.texture && d.hasUV && d.texture->hasAlpha();
    if (!d.hasColors && !texAlpha) return a;
    const FragBary fb = baryAt(tc, i, j);
    const uint32_t mi[3] = {d.meshIndex(tc.v[0]), d.meshIndex(tc.v[1]), d.meshIndex(tc.v[2])};
    if (d.hasColors) {
        const sg::Mesh& m = *d.mesh;
        a *= fb.bo[0] * m.colors[mi[0]].a + fb.bo[1] * m.colors[mi[1]].a + fb.bo[2] * m.colors[mi[2]].a;
    }
    if (texAlpha) {
        vec2 uv, ddx, ddy;
        uvAt(tc, fb, mi, i, j, d.mesh->uv0, uv, ddx, ddy);
        a *= d.texture->sampleAlpha(uv, ddx, ddy);
    }
    return a;
}

// prepareFragment() for a TriCache::simple triangle, inlined into the fragment loop: the same
// operations in the same order (so the same bits), with the per-material values precomputed.
inline __attribute__((always_inline)) float prepareSimple(const TriCache& tc, bool fog, int i, int j, const BatchOut& o, size_t k) {
    const FragBary fb = baryAt(tc, i, j);
    const vec3& bo = fb.bo;
    const vec3 pos = bo[0] * tc.p[0] + bo[1] * tc.p[1] + bo[2] * tc.p[2];
    vec3 n;
    if (tc.faceNormal) {
        n = tc.n[0];
    } else {
        n = bo[0] * tc.n[0] + bo[1] * tc.n[1] + bo[2] * tc.n[2];
        float len = glm::length(n);
        n = len > 0 ? n / len : vec3(0, 0, 1);
    }
    o.px[k] = pos.x;
    o.py[k] = pos.y;
    o.pz[k] = pos.z;
    o.nx[k] = n.x;
    o.ny[k] = n.y;
    o.nz[k] = n.z;
    o.mat[k] = tc.slot;   // albedo, coefficients and ambient + emissive: the material's constant block
    if (!fog) return 0.0f;
    return glm::length(bo[0] * tc.pe[0] + bo[1] * tc.pe[1] + bo[2] * tc.pe[2]);
}

// Interpolates the attributes of the cached triangle at the centre of pixel (i, j) and fills
// slot k of the shading batch (Gouraud: the final colour, with no lights left to add). Returns
// the eye-space distance for fog.
__attribute__((noinline)) float prepareFragment(const TriCache& tc, const FrameContext& fc, int i, int j, ShadeBatch& sb, size_t k) {
    const Tri& t = *tc.t;
    const DrawItem& d = *tc.d;
    const sg::FrameInput& f = *fc.frame;
    const FragBary fb = baryAt(tc, i, j);
    const vec3& bo = fb.bo;
    const uint32_t* v = tc.v;
    vec3 pos = bo[0] * tc.p[0] + bo[1] * tc.p[1] + bo[2] * tc.p[2];
    const sg::Material& mat = *tc.mat;
    vec3 albedo = mat.baseColor;
    const bool maps = d.hasUV && d.hasMaps();
    MapSample ms;
    if (d.hasColors || (d.texture && d.hasUV) || maps) {
        const sg::Mesh& m = *d.mesh;
        uint32_t mi[3] = {d.meshIndex(v[0]), d.meshIndex(v[1]), d.meshIndex(v[2])};
        if (d.hasColors) albedo *= vec3(bo[0] * m.colors[mi[0]] + bo[1] * m.colors[mi[1]] + bo[2] * m.colors[mi[2]]);
        if ((d.texture && d.hasUV) || maps) {
            UvFootprint uvs[2];
            uvAt(tc, fb, mi, i, j, m.uv0, uvs[0].uv, uvs[0].ddx, uvs[0].ddy);
            if (d.texture) albedo *= d.texture->sample(uvs[0].uv, uvs[0].ddx, uvs[0].ddy);
            if (maps) {
                if (d.maps.uv1) uvAt(tc, fb, mi, i, j, m.uv1, uvs[1].uv, uvs[1].ddx, uvs[1].ddy);
                ms = sampleMaps(d.maps, uvs);
            }
        }
    }

    if (tc.gouraud) {
        int side = t.front ? 0 : 1;
        ShadeTerms terms;
        terms.mul = bo[0] * d.gouraudA[side][v[0]] + bo[1] * d.gouraudA[side][v[1]] + bo[2] * d.gouraudA[side][v[2]];
        terms.add = bo[0] * d.gouraudB[side][v[0]] + bo[1] * d.gouraudB[side][v[1]] + bo[2] * d.gouraudB[side][v[2]];
        if (maps) applyMapsToTerms(terms, mat, ms, f.ambientLight);
        sb.setColor(k, terms.apply(albedo));
    } else {
        vec3 n;
        if (tc.faceNormal) {
            n = tc.n[0];
        } else {
            n = bo[0] * tc.n[0] + bo[1] * tc.n[1] + bo[2] * tc.n[2];
            float len = glm::length(n);
            n = len > 0 ? n / len : vec3(0, 0, 1);
            if (ms.hasNormal && d.hasTangents) {   // the map's normal, on the outward side, then flipped back
                const vec4 tan = bo[0] * d.wtan[v[0]] + bo[1] * d.wtan[v[1]] + bo[2] * d.wtan[v[2]];
                const vec4 tw(vec3(tan), d.wtan[v[0]].w);
                n = t.front ? perturbNormal(n, tw, ms.normalTexel, mat.normalScale) : -perturbNormal(-n, tw, ms.normalTexel, mat.normalScale);
            }
        }
        const PhongCoefficients coeff = maps ? coefficientsAt(mat, ms) : coefficientsOf(mat);
        if (fc.referenceShading)
            sb.setColor(k, shade(coeff, SurfacePoint{pos, n, albedo}, f.camera.eye, f));   // rnd::shade itself
        else
            sb.set(k, coeff, pos, n, albedo, f.ambientLight);
    }
    if (f.settings.fog == sg::FogMode::Off) return 0.0f;
    return glm::length(bo[0] * tc.pe[0] + bo[1] * tc.pe[1] + bo[2] * tc.pe[2]);   // eye-space distance
}

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
    std::vector<vec3> accum;   // MSAA: linear colour sum per pixel
    ShadeBatch batch;
};

const Tri& triById(const std::vector<Chunk>& chunks, uint32_t id) { return chunks[id >> kChunkBits].tris[id & ((1u << kChunkBits) - 1)]; }

// Per-stage time of the tile stage (ns, summed over threads), for VIEWER_RASTER_TIMING.
std::atomic<int64_t> g_rasterNs{0}, g_prepareNs{0}, g_lightNs{0};
inline int64_t nowNs() { return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

void shadeOpaque(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples);

// The pixel's visibility: the drawable and mesh triangle of its front-most kept surface.
inline void writeVisibility(const FrameContext& fc, Framebuffer& target, size_t pixel, const Tri& t) {
    const DrawItem& d = (*fc.draws)[t.draw];
    target.drawable[pixel] = d.drawable;
    target.primitive[pixel] = d.analytic ? kNoPrimitive : t.prim;
}
void renderBlended(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples);

// The overdraw view (RenderConfig::overdraw, one sample per pixel): every fragment the tile's
// triangles rasterize, whatever their alpha mode and before any depth or alpha test, adds one
// to its pixel's counter. A pass of its own, so that frames that do not ask pay nothing.
void countOverdraw(int tile, const FrameContext& fc, Framebuffer& target, int x0, int y0, int x1, int y1) {
    const auto& chunks = *fc.chunks;
    for (const Chunk& ch : chunks)
        for (uint32_t k = ch.tileStart[tile]; k < ch.tileStart[tile + 1]; ++k)
            forEachCoveredPixel(ch.tris[ch.items[k]].s, x0, y0, x1, y1,
                                [&](int i, int j) { ++target.overdraw[size_t(fc.height - 1 - j) * fc.width + i]; });
}

// The background colour as the tiles store it: sRGB bytes and alpha 255 in one RGBA8 word.
uint32_t backgroundWord(const sg::RenderSettings& st) {
    const SrgbEncoder& enc = srgbEncoder();
    const uint8_t px[4] = {enc(st.background.x), enc(st.background.y), enc(st.background.z), 255};
    uint32_t word;
    std::memcpy(&word, px, 4);
    return word;
}

// Rasterizes the tile's triangles into its visibility buffer (opaque and masked ones; blended
// ones are set aside), shades what is visible, then composites the blended surfaces.
void renderTile(int tile, const FrameContext& fc, Framebuffer& target, TileBuffers& buf) {
    int64_t tA = fc.timing ? nowNs() : 0;
    const int tx = tile % fc.tilesX, ty = tile / fc.tilesX;
    const int x0 = tx * kTileSize, y0 = ty * kTileSize;
    const int x1 = std::min(x0 + kTileSize, fc.width) - 1, y1 = std::min(y0 + kTileSize, fc.height) - 1;
    const int samples = fc.msaa ? 4 : 1;
    const auto& chunks = *fc.chunks;
    // No triangle touches the tile (sky, margins): background and far depth straight into the
    // framebuffer, without the tile's buffers.
    bool empty = true;
    for (const Chunk& ch : chunks) empty = empty && ch.tileStart[tile] == ch.tileStart[tile + 1];
    if (empty) {
        const uint32_t bgWord = backgroundWord(fc.frame->settings);
        for (int j = y0; j <= y1; ++j) {
            const int row = fc.height - 1 - j;
            uint8_t* out = target.pixel(x0, row);
            for (int i = x0; i <= x1; ++i, out += 4) std::memcpy(out, &bgWord, 4);
            std::fill_n(&target.depth[size_t(row) * fc.width + x0], x1 - x0 + 1, 1.0f);
        }
        if (fc.timing) g_rasterNs += nowNs() - tA;
        return;
    }
    const size_t n = size_t(kTileSize) * kTileSize * samples;
    buf.depth.assign(n + kTilePad, 1.0f);
    buf.ids.assign(n + kTilePad, kNoTri);
    buf.blendTris.clear();
    buf.tileTris.clear();
    TriCache masked;
    for (size_t c = 0; c < chunks.size(); ++c) {
        const Chunk& ch = chunks[c];
        const uint32_t kEnd = ch.tileStart[tile + 1];
        for (uint32_t k = ch.tileStart[tile]; k < kEnd; ++k) {
            // A tile reads its triangles' records scattered over the chunk (only those that touch
            // it): fetch them ahead, or each one is a miss (most of the coverage time of a mesh of
            // small triangles such as the bunny).
            if (k + 6 < kEnd) {
                const char* ahead = reinterpret_cast<const char*>(&ch.tris[ch.items[k + 6]]);
                __builtin_prefetch(ahead);
                __builtin_prefetch(ahead + sizeof(Tri) - 1);
            }
            uint32_t idx = ch.items[k];
            const Tri& t = ch.tris[idx];
            const uint32_t id = uint32_t(c << kChunkBits) | idx;
            const uint32_t local = uint32_t(buf.tileTris.size());   // what the visibility buffer stores
            if (t.alpha == sg::AlphaMode::Opaque) {
                buf.tileTris.push_back(id);
                rasterizeIntoTile(t, local, x0, y0, x1, y1, samples, buf.depth.data(), buf.ids.data());
            } else if (t.alpha == sg::AlphaMode::Blend) {
                buf.blendTris.push_back(id);   // after the opaque surfaces, in renderBlended
            } else {
                // Cut-out (MASK): a fragment below the cutoff is discarded before it writes depth,
                // as GL's discard; alpha at the pixel centre, shared by its MSAA samples.
                if (masked.id != id) masked.load(id, t, ch, fc);
                int li = -1, lj = -1;
                bool lastKeep = false;
                const float cutoff = masked.mat->alphaCutoff;
                buf.tileTris.push_back(id);
                rasterizeTri(t, local, x0, y0, x1, y1, samples, buf.depth.data(), buf.ids.data(), [&](int i, int j) {
                    if (i != li || j != lj) {
                        li = i;
                        lj = j;
                        lastKeep = fragmentAlpha(masked, i, j) >= cutoff;
                    }
                    return lastKeep;
                });
            }
        }
    }
    if (fc.overdraw) countOverdraw(tile, fc, target, x0, y0, x1, y1);
    if (fc.timing) g_rasterNs += nowNs() - tA;
    shadeOpaque(fc, target, buf, x0, y0, x1, y1, samples);
    if (!buf.blendTris.empty()) renderBlended(fc, target, buf, x0, y0, x1, y1, samples);
}

// Shades the visible opaque (and kept masked) fragments of the tile and writes its pixels.
void shadeOpaque(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples) {
    const auto& chunks = *fc.chunks;
    int64_t tB = fc.timing ? nowNs() : 0;
    const auto& st = fc.frame->settings;
    const SrgbEncoder& enc = srgbEncoder();
    const vec3 bg = st.background;
    const uint32_t bgWord = backgroundWord(st);
    // Fragments: one per covered pixel (MSAA: per distinct triangle in the pixel).
    // Sized for the worst case (every sample its own triangle); filled by index, no push_back.
    const size_t maxFrags = size_t(kTileSize) * kTileSize * samples;
    if (buf.fragPixel.size() < maxFrags + kTilePad) {   // slack: preparePlainRun reads whole vectors
        buf.fragPixel.resize(maxFrags + kTilePad);
        buf.fragTri.resize(maxFrags);
        buf.fragCount.resize(maxFrags);
    }
    size_t nf = 0;
    const int tw = x1 - x0 + 1, th = y1 - y0 + 1;
    const uint32_t* tileTris = buf.tileTris.data();
    std::vector<FragRun>& runs = buf.runs;
    runs.clear();
    if (samples == 1) {
        // Row by row: depth copied as a whole row, visibility, and the runs of equal ids (bit ii
        // of rowRuns[jj]: a run starts at pixel ii), each run's length added to its triangle's
        // count. Runs, not pixels: an increment per pixel of the same counter is a chain of
        // store-to-load forwards. Colours go to the tile's own buffer, background first.
        const uint32_t nt = uint32_t(buf.tileTris.size());
        buf.runStart.assign(size_t(nt) + 1, 0);   // [nt]: uncovered pixels
        uint32_t* start = buf.runStart.data();
        std::fill(buf.color.begin(), buf.color.end(), bgWord);
        const uint64_t rowMask = tw == 64 ? ~uint64_t(0) : (uint64_t(1) << tw) - 1;
        for (int jj = 0; jj < th; ++jj) {
            const int row = fc.height - 1 - (y0 + jj);
            std::memcpy(&target.depth[size_t(row) * fc.width + x0], &buf.depth[size_t(jj) * kTileSize], size_t(tw) * sizeof(float));
            const uint32_t* ids = &buf.ids[size_t(jj) * kTileSize];
            uint64_t starts = 1;   // pixel 0 starts a run
#if defined(RASTER_HAVE_SSE2)
            for (int ii = 1; ii < tw; ii += 4) {   // reads up to ids[64]: the next row or the buffer's slack
                const __m128i cur = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ids + ii));
                const __m128i prev = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ids + ii - 1));
                const int same = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(cur, prev)));
                starts |= uint64_t(~same & 0xF) << ii;
            }
#else
            for (int ii = 1; ii < tw; ++ii) starts |= uint64_t(ids[ii] != ids[ii - 1]) << ii;
#endif
            starts &= rowMask;
            buf.rowRuns[size_t(jj)] = starts;
            for (uint64_t m = starts; m;) {
                const int ib = __builtin_ctzll(m);
                m &= m - 1;
                const int ie = m ? __builtin_ctzll(m) : tw;
                start[std::min(ids[ib], nt)] += uint32_t(ie - ib);
            }
            if (fc.visibility)
                for (int ii = 0; ii < tw; ++ii)
                    if (ids[ii] != kNoTri) writeVisibility(fc, target, size_t(row) * fc.width + x0 + ii, triById(chunks, tileTris[ids[ii]]));
        }
        // Fragments grouped by triangle, in the tile's submission order, each triangle's pixels in
        // row order (a counting sort): the preparation below loads each triangle once and takes
        // its fragments a vector at a time.
        buf.runEnd.resize(nt);
        uint32_t* end = buf.runEnd.data();
        uint32_t pos = 0;
        for (uint32_t l = 0; l < nt; ++l) {
            const uint32_t count = start[l];
            start[l] = pos;
            if (count) runs.push_back(FragRun{tileTris[l], pos, count});
            pos += count;
            end[l] = pos;
        }
        nf = pos;
        uint16_t* fragPixel = buf.fragPixel.data();
#if defined(RASTER_HAVE_SSE2)
        const __m128i iota = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);
#endif
        for (int jj = 0; jj < th; ++jj) {
            const uint32_t* ids = &buf.ids[size_t(jj) * kTileSize];
            for (uint64_t m = buf.rowRuns[size_t(jj)]; m;) {
                const int ib = __builtin_ctzll(m);
                m &= m - 1;
                const int ie = m ? __builtin_ctzll(m) : tw;
                const uint32_t id = ids[ib];
                if (id == kNoTri) continue;
                const uint32_t slot = start[id], len = uint32_t(ie - ib);
                start[id] = slot + len;
                const int first = jj * kTileSize + ib;
#if defined(RASTER_HAVE_SSE2)
                // Whole vectors of 8 indices where they stay inside this triangle's slots: what
                // they write past the run is rewritten by its later runs (a loop per run
                // mispredicts its exit).
                if (slot + ((len + 7) & ~7u) <= end[id]) {
                    for (uint32_t q = 0; q < len; q += 8)
                        _mm_storeu_si128(reinterpret_cast<__m128i*>(fragPixel + slot + q),
                                         _mm_add_epi16(iota, _mm_set1_epi16(short(first + int(q)))));
                    continue;
                }
#endif
                for (uint32_t q = 0; q < len; ++q) fragPixel[slot + q] = uint16_t(first + int(q));
            }
        }
    } else {
        // MSAA: a fragment per pixel and distinct triangle among its samples, with the number of
        // samples it covers.
        for (int jj = 0; jj < th; ++jj)
            for (int ii = 0; ii < tw; ++ii) {
                int p = jj * kTileSize + ii;
                int row = fc.height - 1 - (y0 + jj);
                std::memcpy(target.pixel(x0 + ii, row), &bgWord, 4);
                float dmin = 1.0f;
                uint32_t seen[4];
                int nseen = 0;
                size_t first = nf;
                for (int s = 0; s < 4; ++s) {
                    dmin = std::min(dmin, buf.depth[p * 4 + s]);
                    uint32_t id = buf.ids[p * 4 + s];
                    if (id == kNoTri) continue;
                    id = tileTris[id];
                    int q = 0;
                    while (q < nseen && seen[q] != id) ++q;
                    if (q == nseen) {
                        seen[nseen++] = id;
                        buf.fragPixel[nf] = uint16_t(p);
                        buf.fragTri[nf] = id;
                        buf.fragCount[nf++] = 1;
                    } else {
                        ++buf.fragCount[first + q];
                    }
                }
                target.depth[size_t(row) * fc.width + x0 + ii] = dmin;
            }
        for (size_t k = 0; k < nf;) {   // runs of consecutive fragments of one triangle
            size_t e = k + 1;
            while (e < nf && buf.fragTri[e] == buf.fragTri[k]) ++e;
            runs.push_back(FragRun{buf.fragTri[k], uint32_t(k), uint32_t(e - k)});
            k = e;
        }
    }
    // The tile's colours to the framebuffer (one sample per pixel; MSAA writes its own).
    auto writeColorRows = [&] {
        if (samples != 1) return;
        for (int jj = 0; jj < th; ++jj) std::memcpy(target.pixel(x0, fc.height - 1 - (y0 + jj)), &buf.color[size_t(jj) * kTileSize], size_t(tw) * 4);
    };
    if (nf == 0) {
        writeColorRows();
        return;
    }
    buf.batch.resize(nf);
    buf.fogDist.resize(nf + ShadeBatch::kSlack);
    TriCache tc;
    const BatchOut out(buf.batch);
    const bool fogOn = st.fog != sg::FogMode::Off;
    const size_t nr = runs.size();
    for (size_t r = 0; r < nr; ++r) {
        // Tiny triangles (a big mesh) change every fragment and miss the cache on the triangle,
        // its indices and its vertices: prefetch the triangle 16 runs ahead, its indices 8 ahead
        // and its vertices 4 ahead.
        if (r + 16 < nr) __builtin_prefetch(&triById(chunks, runs[r + 16].tri));
        if (r + 8 < nr) {
            const Tri& tn = triById(chunks, runs[r + 8].tri);
            const DrawItem& dn = (*fc.draws)[tn.draw];
            if (!dn.perCorner && size_t(tn.prim) * 3 < dn.mesh->indices.size()) __builtin_prefetch(&dn.mesh->indices[size_t(tn.prim) * 3]);
        }
        if (r + 4 < nr) {
            const Tri& tn = triById(chunks, runs[r + 4].tri);
            const DrawItem& dn = (*fc.draws)[tn.draw];
            for (int q = 0; q < 3; ++q) {
                const uint32_t vq = dn.vertexOf(tn.prim, q);
                if (vq < dn.wv.size()) {
                    __builtin_prefetch(&dn.wv[vq]);
                    __builtin_prefetch(reinterpret_cast<const char*>(&dn.wv[vq]) + sizeof(DrawItem::VertexOut) - 1);
                }
            }
        }
        const FragRun run = runs[r];
        if (run.tri != tc.id) {
            tc.load(run.tri, triById(chunks, run.tri), chunks[run.tri >> kChunkBits], fc);
            if (tc.simple && tc.slot < 0)   // once per material run: its constants for the kernel
                tc.slot = buf.batch.addConstants(tc.mat->baseColor, tc.simpleSpec, tc.coeff.kd, tc.coeff.ks, tc.coeff.shininess, tc.simpleBase);
        }
#if defined(RASTER_HAVE_SSE2)
        if (tc.simple) {   // a vector of fragments per step (whole vectors: up to 7 slots past the run, rewritten later)
            preparePlainRun(tc, fogOn, buf.fragPixel.data(), x0, y0, run.begin, run.count, out, buf.fogDist.data());
            continue;
        }
#endif
        for (size_t k = run.begin; k < size_t(run.begin) + run.count; ++k) {
            const int p = buf.fragPixel[k];
            if (tc.simple)
                buf.fogDist[k] = prepareSimple(tc, fogOn, x0 + p % kTileSize, y0 + p / kTileSize, out, k);
            else
                buf.fogDist[k] = prepareFragment(tc, fc, x0 + p % kTileSize, y0 + p / kTileSize, buf.batch, k);
        }
    }
    buf.batch.pad();   // the vector stores may have run past nf
    int64_t tC = fc.timing ? nowNs() : 0;
    if (fc.timing) g_prepareNs += tC - tB;
    shadeBatch(buf.batch, nf, *fc.frame);
    if (fc.timing) g_lightNs += nowNs() - tC;
    const bool fog = st.fog != sg::FogMode::Off;
    const bool linearFog = st.fog == sg::FogMode::Linear;
    const ShadeBatch& b = buf.batch;
    if (samples == 1) {
        // Into the tile's colour buffer (contiguous: the framebuffer's rows of a tile, 5 KB apart
        // at 1280 pixels, share a few cache sets), then a copy per row.
        uint32_t* color = buf.color.data();
        auto packRgba = [](uint8_t r, uint8_t g, uint8_t b) {
            const uint8_t px[4] = {r, g, b, 255};
            uint32_t w;
            std::memcpy(&w, px, 4);
            return w;
        };
        size_t k = 0;
#if defined(RASTER_HAVE_SSE2)
        if (linearFog || !fog) {   // a vector of fragments at a time: the scalar loop's operations per lane
            const LinearFog lf{linearFog, st.fogEnd, st.fogEnd - st.fogStart, st.fogColor};
            writeFragments(b.cr.data(), b.cg.data(), b.cb.data(), buf.fogDist.data(), buf.fragPixel.data(), nf, lf, enc, color);
            k = nf;
        }
#endif
        for (; k < nf; ++k) {
            vec3 c(b.cr[k], b.cg[k], b.cb[k]);
            if (linearFog) {   // applyFog(), inlined: the same operations in the same order
                const float vis = std::clamp((st.fogEnd - buf.fogDist[k]) / (st.fogEnd - st.fogStart), 0.0f, 1.0f);
                c = vis * c + (1.0f - vis) * st.fogColor;
            } else if (fog) {
                c = applyFog(st, c, buf.fogDist[k]);
            }
            color[buf.fragPixel[k]] = packRgba(enc(c.x), enc(c.y), enc(c.z));
        }
        writeColorRows();
        return;
    }
    // MSAA resolve: average the samples in linear space (background where uncovered).
    buf.accum.assign(size_t(kTileSize) * kTileSize, vec3(0.0f));
    std::vector<uint8_t> covered(size_t(kTileSize) * kTileSize, 0);
    for (size_t k = 0; k < nf; ++k) {
        vec3 c(b.cr[k], b.cg[k], b.cb[k]);
        if (fog) c = applyFog(st, c, buf.fogDist[k]);
        c = glm::clamp(c, 0.0f, 1.0f);
        buf.accum[buf.fragPixel[k]] += float(buf.fragCount[k]) * c;
        covered[buf.fragPixel[k]] += buf.fragCount[k];
    }
    for (int jj = 0; jj < th; ++jj)
        for (int ii = 0; ii < tw; ++ii) {
            int p = jj * kTileSize + ii;
            if (!covered[p]) continue;
            vec3 c = (buf.accum[p] + float(4 - covered[p]) * bg) * 0.25f;
            uint8_t* out = target.pixel(x0 + ii, fc.height - 1 - (y0 + jj));
            out[0] = enc(c.x);
            out[1] = enc(c.y);
            out[2] = enc(c.z);
        }
}

// Blended surfaces (alphaMode BLEND), order-correct per pixel: every blended fragment in front
// of the opaque depth is kept (depth is not written), a pixel's fragments are sorted far to
// near and composited "over" in linear light onto the pixel, each step re-encoded to 8-bit sRGB
// as an SRGB8 framebuffer blends. With MSAA a fragment weighs by the samples it covers.
void renderBlended(const FrameContext& fc, Framebuffer& target, TileBuffers& buf, int x0, int y0, int x1, int y1, int samples) {
    const auto& chunks = *fc.chunks;
    std::vector<BlendFrag>& frags = buf.blendFrags;
    frags.clear();
    TriCache tc;
    const int tw = kTileSize;
    for (uint32_t order = 0; order < buf.blendTris.size(); ++order) {
        const uint32_t id = buf.blendTris[order];
        const Tri& t = triById(chunks, id);
        tc.load(id, t, chunks[id >> kChunkBits], fc);
        const int bx0 = std::max(x0, int(t.s.minX)), bx1 = std::min(x1, int(t.s.maxX));
        const int by0 = std::max(y0, int(t.s.minY)), by1 = std::min(y1, int(t.s.maxY));
        if (bx0 > bx1 || by0 > by1) continue;
        auto zAt = [&](float i, float j) {
            return std::clamp(t.pl.zRef + t.pl.zdx * (i - float(t.s.minX)) + t.pl.zdy * (j - float(t.s.minY)), 0.0f, 1.0f);
        };
        auto add = [&](int i, int j, int coverage) {
            const float a = fragmentAlpha(tc, i, j);
            if (!(a > 0.0f)) return;
            frags.push_back(BlendFrag{uint16_t((j - y0) * tw + (i - x0)), uint8_t(coverage), zAt(float(i), float(j)), std::min(a, 1.0f), id, order});
        };
        if (samples == 1) {
            forEachCoveredPixel(t.s, bx0, by0, bx1, by1, [&](int i, int j) {
                if (zAt(float(i), float(j)) < buf.depth[size_t(j - y0) * tw + (i - x0)]) add(i, j, 1);
            });
            continue;
        }
        const PackedEdge& e0 = t.s.e[0];
        const PackedEdge& e1 = t.s.e[1];
        const PackedEdge& e2 = t.s.e[2];
        for (int j = by0; j <= by1; ++j)
            for (int i = bx0; i <= bx1; ++i) {
                int covered = 0;
                const size_t p = (size_t(j - y0) * tw + (i - x0)) * 4;
                for (int s = 0; s < 4; ++s) {
                    int64_t px = int64_t(i) * kSub + kMsaa4X[s], py = int64_t(j) * kSub + kMsaa4Y[s];
                    if (e0.at(px, py) < e0.bias || e1.at(px, py) < e1.bias || e2.at(px, py) < e2.bias) continue;
                    const float z = zAt(float(i) + float(kMsaa4X[s] - kHalf) / kSub, float(j) + float(kMsaa4Y[s] - kHalf) / kSub);
                    if (z < buf.depth[p + s]) ++covered;
                }
                if (covered) add(i, j, covered);
            }
    }
    if (frags.empty()) return;
    std::sort(frags.begin(), frags.end(), [](const BlendFrag& a, const BlendFrag& b) {
        if (a.pixel != b.pixel) return a.pixel < b.pixel;
        if (a.z != b.z) return a.z > b.z;   // far first
        return a.order < b.order;
    });
    const size_t n = frags.size();
    buf.batch.resize(n);
    buf.fogDist.resize(n);
    tc = TriCache();
    for (size_t k = 0; k < n; ++k) {
        const uint32_t id = frags[k].tri;
        if (id != tc.id) tc.load(id, triById(chunks, id), chunks[id >> kChunkBits], fc);
        const int p = frags[k].pixel;
        buf.fogDist[k] = prepareFragment(tc, fc, x0 + p % tw, y0 + p / tw, buf.batch, k);
    }
    shadeBatch(buf.batch, n, *fc.frame);
    const auto& st = fc.frame->settings;
    const bool fog = st.fog != sg::FogMode::Off;
    const SrgbEncoder& enc = srgbEncoder();
    const ShadeBatch& b = buf.batch;
    for (size_t k = 0; k < n; ++k) {
        vec3 c(b.cr[k], b.cg[k], b.cb[k]);
        if (fog) c = applyFog(st, c, buf.fogDist[k]);
        c = glm::clamp(c, 0.0f, 1.0f);
        const int p = frags[k].pixel;
        uint8_t* out = target.pixel(x0 + p % tw, fc.height - 1 - (y0 + p / tw));
        const vec3 dst = srgbBytesToLinear(out);
        const float w = frags[k].alpha * float(frags[k].coverage) / float(samples);
        const vec3 r = dst + w * (c - dst);
        out[0] = enc(r.x);
        out[1] = enc(r.y);
        out[2] = enc(r.z);
    }
}

// ---------------------------------------------------------------------------------------
// [renderer]
// ---------------------------------------------------------------------------------------

class RasterRenderer final : public Renderer {
public:
    std::string_view name() const override { return "raster"; }
    Capabilities capabilities() const override {
        Capabilities c;
        c.progressive = true;
        c.wireframe = true;
        c.pointsAndLines = true;
        c.visibility = true;   // the visibility buffer the tiles shade from
        c.overdraw = true;     // counted per tile when asked (countOverdraw)
        c.msaaSamples = {4};   // one fixed 4-sample pattern (raster_core.h)
        c.ssaaFactors = {2, 3, 4};
        c.ssaaRendersLarger = true;
        c.maxImageSize = 32768;
        return c;
    }

protected:
    RenderStats doRender(const sg::FrameInput& frame, const RenderConfig& cfg, Framebuffer& target, RenderControl* control) override {
        RenderStats stats;
        const int r = cfg.ssaaFactor;
        if (r > 1) {
            Framebuffer hi;
            stats = renderSingle(frame, cfg.width * r, cfg.height * r, cfg.tessellation, hi, false, control, r);
            if (stats.ok) target = downsample(hi, r);
        } else {
            stats =
                renderSingle(frame, cfg.width, cfg.height, cfg.tessellation, target, cfg.msaaSamples > 1, control, 1, cfg.visibility, cfg.overdraw);
        }
        return stats;
    }

private:
    // pointScale: the SSAA factor (points are 2 pixels wide at the output resolution, like GL).
    // visibility: fill target.drawable/primitive; overdraw: count fragments per pixel into
    // target.overdraw (both one sample per pixel only).
    RenderStats renderSingle(const sg::FrameInput& frame, int width, int height, int tessRes, Framebuffer& target, bool msaa, RenderControl* control,
                             int pointScale = 1, bool visibility = false, bool overdraw = false) {
        RenderStats stats;
        auto t0frame = std::chrono::steady_clock::now();
        m_samplers.beginFrame();
        m_tess.nextFrame();
        // The tiles write every pixel's colour and depth (background where nothing is drawn), so
        // the buffers are not cleared first: a serial pass over ~7 MB at 1280x720.
        target.resizeForOverwrite(width, height);
        if (visibility) target.resizeVisibility();
        if (overdraw && !msaa) target.resizeOverdraw();
        const auto& st = frame.settings;
        const bool gouraud = st.shading == sg::ShadingModel::Gouraud;

        // 1. gather (the draw list shared with the GL backend)
        std::vector<DrawItem> draws;
        const std::vector<PreparedDraw> prepared = prepareDraws(frame, tessRes, m_tess);
        draws.reserve(prepared.size());
        for (const PreparedDraw& p : prepared) {
            DrawItem d;
            d.mesh = p.mesh;
            d.world = *p.world;
            d.normal = p.normal;
            d.material = *p.material;
            d.mirrored = p.mirrored;
            d.drawable = p.drawable;
            d.analytic = p.analytic;
            d.texture = m_samplers.get(p.texture);
            d.maps = {m_samplers.get(p.maps.emissive), m_samplers.get(p.maps.occlusion), m_samplers.get(p.maps.metallicRoughness),
                      m_samplers.get(p.maps.normal), p.mesh->uv1.size() == p.mesh->positions.size() ? p.material->uv1Maps : uint8_t(0)};
            d.hasTangents = d.maps.normal && p.mesh->tangents.size() == p.mesh->positions.size();
            d.hasNormals = p.mesh->normals.size() == p.mesh->positions.size();
            d.hasUV = p.mesh->uv0.size() == p.mesh->positions.size();
            d.hasColors = p.mesh->colors.size() == p.mesh->positions.size();
            if (p.triangleMaterial) {   // borrowed for this frame (the tessellation cache keeps them)
                d.triMat = std::shared_ptr<const std::vector<uint16_t>>(std::shared_ptr<void>(), p.triangleMaterial);
                d.materials = std::shared_ptr<const std::vector<sg::Material>>(std::shared_ptr<void>(), p.materials);
            }
            if (p.mesh->mode == sg::PrimitiveMode::Triangles) {
                d.triCount = uint32_t(p.mesh->indices.size() / 3);
                if (d.triCount == 0) continue;
                d.perCorner = gouraud && d.triMat;
                if (draws.size() < m_vertexBuffers.size()) d.swapBuffers(m_vertexBuffers[draws.size()]);
                draws.push_back(std::move(d));
            }   // points and lines: the overlay (step 5)
        }
        m_samplers.endFrame();
        // Whatever way this frame ends, the vertex buffers go back for the next one.
        struct GiveBack {
            std::vector<DrawItem>& draws;
            std::vector<DrawItem>& pool;
            ~GiveBack() {
                if (pool.size() < draws.size()) pool.resize(draws.size());
                for (size_t i = 0; i < draws.size(); ++i) draws[i].swapBuffers(pool[i]);
            }
        } giveBack{draws, m_vertexBuffers};

        auto tStart = std::chrono::steady_clock::now();
        auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
        // 2. vertices
        uint64_t total = 0;
        for (auto& d : draws) {
            d.firstTri = total;
            total += d.triCount;
        }
        stats.triangles = total;
        tbb::parallel_for(size_t(0), draws.size(), [&](size_t i) { runVertexStage(draws[i], frame, width, height, gouraud); });

        auto tVert = std::chrono::steady_clock::now();
        // 3. triangles
        FrameContext fc;
        fc.frame = &frame;
        fc.width = width;
        fc.height = height;
        fc.tilesX = (width + kTileSize - 1) / kTileSize;
        fc.tilesY = (height + kTileSize - 1) / kTileSize;
        fc.msaa = msaa;
        fc.referenceShading = m_referenceShading;
        fc.timing = m_timing;
        fc.visibility = visibility && !msaa;
        fc.overdraw = overdraw && !msaa;
        fc.draws = &draws;
        uint64_t chunkSize = std::max<uint64_t>(4096, (total + 4000) / 4000);
        if (chunkSize * 7 >= (1u << kChunkBits)) {
            target.resize(width, height);
            stats.error = "too many triangles (" + std::to_string(total) + ")";
            return stats;
        }
        // Chunks persist between frames so their buffers keep their capacity.
        std::vector<Chunk>& chunks = m_chunks;
        chunks.resize(size_t((total + chunkSize - 1) / chunkSize));
        for (size_t c = 0; c < chunks.size(); ++c) {
            chunks[c].begin = c * chunkSize;
            chunks[c].end = std::min(total, (c + 1) * chunkSize);
            chunks[c].tris.clear();
            chunks[c].clipBary.clear();
        }
        fc.chunks = &chunks;
        tbb::parallel_for(size_t(0), chunks.size(), [&](size_t c) { runTriangleStage(chunks[c], fc); });

        auto tTri = std::chrono::steady_clock::now();
        g_rasterNs = g_prepareNs = g_lightNs = 0;
        // 4. tiles
        const int tiles = fc.tilesX * fc.tilesY;
        std::atomic<int> done{0};
        std::atomic<bool> cancelled{false};
        tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& r) {
            thread_local TileBuffers buf;
            for (int tile = r.begin(); tile != r.end(); ++tile) {
                if (control && control->cancel.load(std::memory_order_relaxed)) {
                    cancelled = true;
                    continue;
                }
                renderTile(tile, fc, target, buf);
                int n = ++done;
                if (control) {
                    control->progress = float(n) / float(tiles);
                    if (control->onTileDone) control->onTileDone();
                }
            }
        });
        if (cancelled) {
            target.resize(width, height);   // tiles left unwritten: cleared, as before
            stats.cancelled = true;
            stats.error = "cancelled";
            return stats;
        }

        auto tTiles = std::chrono::steady_clock::now();
        // 5. lines, points, wireframe
        drawPointsLinesWireframe(prepared, frame, target, 2.0f * float(pointScale));
        if (m_timing) {
            size_t ntri = 0;
            for (const auto& c : chunks) ntri += c.tris.size();
            std::fprintf(stderr,
                         "raster timing: gather %.2f vertices %.2f triangles %.2f (%zu set up) tiles %.2f [raster %.2f prepare %.2f light %.2f "
                         "cpu-ms] lines %.2f ms\n",
                         ms(t0frame, tStart), ms(tStart, tVert), ms(tVert, tTri), ntri, ms(tTri, tTiles), g_rasterNs * 1e-6, g_prepareNs * 1e-6,
                         g_lightNs * 1e-6, ms(tTiles, std::chrono::steady_clock::now()));
        }
        stats.ok = true;
        return stats;
    }

    SamplerCache m_samplers;
    TessellationCache m_tess;
    std::vector<Chunk> m_chunks;
    std::vector<DrawItem> m_vertexBuffers;   // only their vertex-stage buffers (DrawItem::swapBuffers)
    // VIEWER_RASTER_REFERENCE_SHADING=1: shade every fragment with rnd::shade (slow; used to
    // check the batched path).
    bool m_timing = debugSwitches().rasterTiming;
    bool m_referenceShading = debugSwitches().rasterReferenceShading;
};

}   // namespace

std::unique_ptr<Renderer> makeRasterRenderer() { return std::make_unique<RasterRenderer>(); }

}   // namespace rnd
