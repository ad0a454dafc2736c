// raster_renderer.cpp - the "raster" backend: our own CPU implementation of the pipeline of
// docs/math.md (modelling, lighting, viewing, projection, clipping, scan conversion). This file
// holds the renderer class and the orchestration of a frame; the stages live in their own files
// (raster_frame.h lists them):
//   1. gather     meshes + tessellated analytics -> DrawItems; textures -> SampledTextures (here)
//   2. vertices   raster_vertex.cpp
//   3. triangles  raster_setup.cpp (clipping, setup, culling, binning into 64x64 tiles)
//   4. tiles      raster_tile.cpp (coverage), raster_shade.cpp (deferred shading and output),
//                 raster_msaa.cpp (MSAA gather and resolve), raster_blend.cpp (blended surfaces);
//                 the hot loops are vector kernels, AVX2 or SSE2 (tile_kernels.h,
//                 raster_shading.h), equal bit for bit to the scalar code
//   5. lines      Lines/Points meshes and the wireframe overlay with the DDA line rasterizer (here)
//   6. display    exposure and tone mapping (renderers/tone_map.h), only when they are not the
//                 identity: steps 4 and 5 then write linear colour into a linear frame, which
//                 raster_shade.cpp's encodeLinearFrame resolves (SSAA), maps and encodes
// SSAA renders at aaRate x the size and box-filters down; MSAA 4x keeps 4 samples per pixel
// (coverage + depth per sample) and shades once per pixel and triangle at the pixel centre.
#include "raster/raster_renderer.h"
#include "renderers/debug_switches.h"

#include "common/line_overlay.h"
#include "raster/raster_frame.h"
#include "renderers/draw_list.h"
#include "renderers/tessellate.h"
#include "renderers/texture_sampler.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>

namespace rnd {
namespace {

using namespace raster;

class RasterRenderer final : public Renderer {
public:
    std::string_view name() const override { return "raster"; }
    Capabilities capabilities() const override {
        Capabilities c;
        c.progressive = true;
        c.wireframe = true;
        c.pointsAndLines = true;
        c.shadows = true;   // shadow maps (renderers/shadow_map.h)
        c.shadowMaps = true;
        c.aovs.add(Aov::Visibility);   // the visibility buffer the tiles shade from
        c.aovs.add(Aov::Overdraw);     // counted per tile when asked (countOverdraw)
        c.msaaSamples = {4};           // one fixed 4-sample pattern (raster_core.h)
        c.ssaaFactors = {2, 3, 4};
        c.ssaaRendersLarger = true;
        c.maxImageSize = 32768;
        return c;
    }

    // The pixel inspector's shadows: the last frame's maps at p.
    std::vector<float> lightVisibility(const sg::FrameInput& f, const sg::vec3& p, const sg::vec3& ng) override {
        if (m_shadowPlan.empty() || m_shadowPlan.viewCount.size() != f.lights.size()) return {};
        std::vector<float> v(f.lights.size(), 1.0f);
        for (size_t l = 0; l < v.size(); ++l) v[l] = shadowVisibility(m_shadowPlan, m_shadowMaps, f.lights[l], int(l), p, ng);
        return v;
    }
    std::vector<float> lightVisibilityMany(const sg::FrameInput& f, int light, const std::vector<sg::vec3>& p,
                                           const std::vector<sg::vec3>& ng) override {
        if (m_shadowPlan.empty() || m_shadowPlan.viewCount.size() != f.lights.size() || light < 0 || size_t(light) >= f.lights.size() ||
            p.size() != ng.size())
            return {};
        std::vector<float> out(p.size(), 1.0f);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, p.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i)
                out[i] = shadowVisibility(m_shadowPlan, m_shadowMaps, f.lights[size_t(light)], light, p[i], ng[i]);
        });
        return out;
    }

protected:
    RenderStats doRender(const sg::FrameInput& frame, const RenderConfig& cfg, Framebuffer& target, RenderControl* control) override {
        RenderStats stats;
        const int r = cfg.ssaaFactor;
        // Exposure or tone mapping: the frame in linear colour first, bytes at the end (step 6).
        const DisplayTransform display(frame.settings);
        LinearFrame* linear = display.identity ? nullptr : &m_linear;
        if (r > 1) {
            Framebuffer hi;
            stats = renderSingle(frame, cfg.width * r, cfg.height * r, cfg.tessellation, hi, false, control, r, false, false, linear);
            if (stats.ok) target = downsample(hi, r);   // depth (and the colour, unless the linear frame replaces it)
        } else {
            stats = renderSingle(frame, cfg.width, cfg.height, cfg.tessellation, target, cfg.msaaSamples > 1, control, 1,
                                 cfg.aovs.has(Aov::Visibility), cfg.aovs.has(Aov::Overdraw), linear);
        }
        if (stats.ok && linear) encodeLinearFrame(linear->pixels(0), r, display, target);
        return stats;
    }

private:
    // Step 1: a DrawItem per triangle mesh of the shared draw list (points and lines are drawn
    // by step 5), with its samplers and, from the pool, the vertex buffers of an earlier frame.
    std::vector<DrawItem> gatherDraws(const std::vector<PreparedDraw>& prepared, bool gouraud) {
        std::vector<DrawItem> draws;
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
        return draws;
    }

    // Step 3's chunks of chunkSize triangles (of `total`), kept between frames so their buffers
    // keep their capacity.
    std::vector<Chunk>& prepareChunks(uint64_t total, uint64_t chunkSize) {
        std::vector<Chunk>& chunks = m_chunks;
        chunks.resize(size_t((total + chunkSize - 1) / chunkSize));
        for (size_t c = 0; c < chunks.size(); ++c) {
            chunks[c].begin = c * chunkSize;
            chunks[c].end = std::min(total, (c + 1) * chunkSize);
            chunks[c].tris.clear();
            chunks[c].clipBary.clear();
        }
        return chunks;
    }

    // Step 4: every tile, in parallel, with progress and cancellation. Returns false when cancelled.
    static bool renderTiles(const FrameContext& fc, Framebuffer& target, RenderControl* control) {
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
        return !cancelled;
    }

    // pointScale: the SSAA factor (points are 2 pixels wide at the output resolution, like GL).
    // visibility: fill target.drawable/primitive; overdraw: count fragments per pixel into
    // target.overdraw (both one sample per pixel only). linear: the linear frame to write
    // colour into instead of target's bytes (FrameContext::linear), sized here.
    RenderStats renderSingle(const sg::FrameInput& frame, int width, int height, int tessRes, Framebuffer& target, bool msaa, RenderControl* control,
                             int pointScale = 1, bool visibility = false, bool overdraw = false, LinearFrame* linear = nullptr) {
        RenderStats stats;
        auto t0frame = std::chrono::steady_clock::now();
        m_samplers.beginFrame();
        m_tess.nextFrame();
        // The tiles write every pixel's colour and depth (background where nothing is drawn), so
        // the buffers are not cleared first: a serial pass over ~7 MB at 1280x720.
        target.resizeForOverwrite(width, height);
        if (visibility) target.allocate(Aov::Visibility);
        if (overdraw && !msaa) target.allocate(Aov::Overdraw);
        const bool gouraud = frame.settings.shading == sg::ShadingModel::Gouraud;

        // 1. gather (the draw list shared with the GL backend)
        const std::vector<PreparedDraw> prepared = prepareDraws(frame, tessRes, m_tess, control);
        if (control && control->cancel.load()) {   // while tessellating shapes anew
            m_samplers.endFrame();
            target.resize(width, height);
            stats.cancelled = true;
            stats.error = "cancelled";
            return stats;
        }
        std::vector<DrawItem> draws = gatherDraws(prepared, gouraud);
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
        // 2. vertices
        uint64_t total = 0;
        for (auto& d : draws) {
            d.firstTri = total;
            total += d.triCount;
        }
        stats.triangles = total;
        std::string envError;
        const EnvironmentLight environment = environmentFor(frame.settings, &envError);
        if (!envError.empty()) stats.config.notes.push_back("environment " + envError + " (lit without it)");
        // Shadow maps (every shading model: flat and Gouraud scale the lights with maps by each
        // fragment's visibility, Gouraud keeping its shadowed lights apart at the vertices).
        m_shadowPlan = planShadows(frame, shadowCasterBounds(frame));
        const std::vector<int> gouraudShadowed = gouraud ? gouraudShadowedLights(m_shadowPlan) : std::vector<int>{};
        tbb::parallel_for(size_t(0), draws.size(),
                          [&](size_t i) { runVertexStage(draws[i], frame, width, height, gouraud, &environment, gouraudShadowed); });
        const auto tShadow0 = std::chrono::steady_clock::now();
        const int drawn = renderShadowMaps(m_shadowPlan, draws, m_shadowMaps, m_shadowReuse ? &m_shadowSource : nullptr);
        stats.shadowMapsDrawn = drawn;
        if (m_timing && !m_shadowPlan.empty())
            std::fprintf(stderr, "raster timing: shadow maps %d of %zu x %d^2 drawn %.2f ms\n", drawn, m_shadowPlan.views.size(), m_shadowPlan.size,
                         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tShadow0).count());

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
        fc.pbr = frame.settings.reflection == sg::ReflectionModel::Pbr;
        fc.environment = &environment;
        fc.shadowPlan = &m_shadowPlan;
        fc.shadowMaps = &m_shadowMaps;
        if (!m_shadowPlan.empty() && frame.settings.shading != sg::ShadingModel::Phong) {
            fc.unmapped.assign(frame.lights.size(), 1.0f);
            for (size_t l = 0; l < m_shadowPlan.viewCount.size() && l < frame.lights.size(); ++l)
                if (m_shadowPlan.viewCount[l] > 0) {
                    fc.mappedLights.push_back(int(l));
                    fc.unmapped[l] = 0.0f;
                }
            fc.gouraudShadowed = gouraudShadowed;
        }
        fc.timing = m_timing;
        fc.visibility = visibility && !msaa;
        fc.overdraw = overdraw && !msaa;
        if (linear) fc.linear = linear->pixels(size_t(width) * height);   // every pixel is written by its tile
        fc.draws = &draws;
        uint64_t chunkSize = std::max<uint64_t>(4096, (total + 4000) / 4000);
        if (chunkSize * 7 >= (1u << kChunkBits)) {
            target.resize(width, height);
            stats.error = "too many triangles (" + std::to_string(total) + ")";
            return stats;
        }
        std::vector<Chunk>& chunks = prepareChunks(total, chunkSize);
        fc.chunks = &chunks;
        tbb::parallel_for(size_t(0), chunks.size(), [&](size_t c) { runTriangleStage(chunks[c], fc); });

        auto tTri = std::chrono::steady_clock::now();
        g_rasterNs = g_prepareNs = g_lightNs = 0;
        // 4. tiles
        if (!renderTiles(fc, target, control)) {
            target.resize(width, height);   // tiles left unwritten: cleared, as before
            stats.cancelled = true;
            stats.error = "cancelled";
            return stats;
        }

        if (environment.map && environment.background) {   // pbr: the environment where nothing was drawn
            const uint8_t bg[3] = {toByteSRGB(frame.settings.background.x), toByteSRGB(frame.settings.background.y),
                                   toByteSRGB(frame.settings.background.z)};
            drawEnvironmentBackground(target, frame.camera, environment, bg, fc.linear, frame.settings.background);
        }
        auto tTiles = std::chrono::steady_clock::now();
        // 5. lines, points, wireframe
        drawPointsLinesWireframe(prepared, frame, target, 2.0f * float(pointScale), fc.linear);
        if (m_timing) {
            auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
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
    LinearFrame m_linear;                    // the linear frame of step 6, kept between frames
    ShadowPlan m_shadowPlan;                 // this frame's shadow maps (their memory kept between frames)
    ShadowMaps m_shadowMaps;
    ShadowMapsSource m_shadowSource;   // what they were drawn from (kept when a frame's are the same)
    // VIEWER_RASTER_REFERENCE_SHADING=1: shade every fragment with rnd::shade (slow; used to
    // check the batched path).
    bool m_timing = debugSwitches().rasterTiming;
    bool m_referenceShading = debugSwitches().rasterReferenceShading;
    bool m_shadowReuse = debugSwitches().rasterShadowReuse;   // VIEWER_RASTER_SHADOW_REUSE=0: draw the maps every frame
};

}   // namespace

std::unique_ptr<Renderer> makeRasterRenderer() { return std::make_unique<RasterRenderer>(); }

}   // namespace rnd
