// raycast_renderer.cpp - the "raycast" backend: CPU ray casting (docs/math.md) with the
// shared Phong shading (renderers/shading.h), shadow rays, optional mirror reflections and
// stratified supersampling, and the display transform (renderers/tone_map.h) on each pixel's
// mean colour; tile-parallel (oneTBB), progressive and cancellable.
//
// Sections: a frame's tiles (camera and shadow packets, shading each pixel's rays), then
// RaycastRenderer::render (tiles, AA, progress, cancellation). What one ray does: tracer.h.
//
// Primary rays come from CameraRays (unprojecting pixel centres, so images line up with the
// rasterizers); depth is window z, as the rasterizers write it.
#include "raycast/raycast_renderer.h"
#include "renderers/debug_switches.h"

#include "common/line_overlay.h"
#include "raycast/camera_rays.h"
#include "raycast/scene_accel.h"
#include "raycast/tracer.h"
#include "renderers/draw_list.h"
#include "renderers/environment.h"
#include "renderers/pbr.h"
#include "renderers/sampling.h"
#include "renderers/shading.h"
#include "renderers/shadow_map.h"
#include "renderers/srgb_encoder.h"
#include "renderers/texture_sampler.h"
#include "renderers/tone_map.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>

namespace rnd {

using namespace sg;

namespace {

using raycast::anyTranslucent;
using raycast::PixelFootprint;
using raycast::SurfaceRecord;
using raycast::Tracer;

float rand01(uint32_t& s) {
    s = hash32(s + 0x9e3779b9u);
    return unitFloat(s);
}

// --- a frame's tiles ----------------------------------------------------------------------------

// What every tile of a frame shares (RaycastRenderer::doRender sets it up).
struct FrameJob {
    const FrameInput& f;
    const RenderConfig& cfg;
    const rt::CameraRays& cam;
    int w, h;
    int sx, sy;                 // strata per pixel (see RaycastRenderer::capabilities)
    bool packets;               // the tile's camera rays are traced first, in packets
    bool shadowPackets;         // and then their hits' shadow rays (Tracer::presetShadows)
    bool countCost;             // the cost view: one centre ray per pixel, counted
    DisplayTransform display;   // exposure and tone mapping of each pixel's mean colour
    // Where a packet's camera ray met nothing and what it sees there is the plain background
    // (no environment map behind the scene): the pixel's bytes, made once (setConstantMiss, fillMisses).
    bool constantMiss = false;
    uint8_t missRgba[4] = {0, 0, 0, 255};
    // With constantMiss, a packet none of whose pixel centres lies in one of these window
    // rectangles (CameraRays::windowBounds of SceneAccel::hitBoxes) is not traced: its rays would
    // meet nothing, and such pixels need no ray (fillMisses). Empty: every packet is traced.
    std::vector<std::array<float, 4>> hitRects;
    // Per f.meshes entry, whether its packet hits are shaded eight at a time (lane_shading.h;
    // RaycastRenderer::laneMeshes: 0 no, 1 yes, 2 yes with a colour texture); empty: every hit
    // through Tracer::trace.
    std::vector<uint8_t> laneMesh;
    const SrgbEncoder& srgb = srgbEncoder();
    static constexpr int kTile = 32;    // pixels per tile side
    static constexpr int kPacket = 4;   // pixels per packet side (4x4: the benchmark's best, docs/benchmarks.md)
    static_assert(kPacket * kPacket <= rt::kMaxPacket);
};

// The strata per pixel of cfg: MSAA n as n jittered rays (2 -> 2x1, 4 -> 2x2, 8 -> 4x2), SSAA f
// as f x f.
void strataOf(const RenderConfig& cfg, int& sx, int& sy) {
    sx = cfg.ssaaFactor;
    sy = cfg.ssaaFactor;
    if (cfg.msaaSamples > 1) {
        sx = cfg.msaaSamples >= 4 ? (cfg.msaaSamples >= 8 ? 4 : 2) : cfg.msaaSamples;
        sy = cfg.msaaSamples / sx;
    }
}

// One sample per pixel: the camera rays of tile [x0, x1) x [y0, y1) (rows top-down; colShares[x -
// x0]: CameraRays::column at pixel column x) traced
// kPacket x kPacket pixels at a time (SceneAccel::intersectPacket: the same hits as one by one),
// into tileRays and tileHits (kTile per row); bit x - x0 of rowFound[row - y0] tells whether
// pixel (x, row)'s ray met something (tileHits' `found`, kept compact: the loops over the tile
// read it for every pixel), the same bit of rowTraced[row - y0] whether its packet was traced
// (tileRays holds its ray; packets that no hit rectangle overlaps are not).
void traceCameraPackets(const FrameJob& job, const rt::SceneAccel& accel, int x0, int y0, int x1, int y1, const glm::dvec4* colShares,
                        std::vector<rt::Ray>& tileRays, std::vector<Tracer::FirstHit>& tileHits, uint32_t* rowFound, uint32_t* rowTraced) {
    constexpr int kPacket = FrameJob::kPacket, tile = FrameJob::kTile;
    static_assert(tile <= 32, "one 32-bit mask per tile row");
    std::fill(rowFound, rowFound + (y1 - y0), 0u);
    std::fill(rowTraced, rowTraced + (y1 - y0), 0u);
    rt::PacketScratch<glm::dvec4, tile> rowShares;   // CameraRays::row of each row, made once for all the packets
    for (int row = y0; row < y1; ++row) rowShares[row - y0] = job.cam.row(float(job.h - 1 - row) + 0.5f);
    rt::Ray* const rays = tileRays.data();
    Tracer::FirstHit* const hits = tileHits.data();
    // Whether window rectangle r overlaps the pixel centres [xLo, xHi] x [yLo, yHi].
    auto overlaps = [](const std::array<float, 4>& r, float xLo, float xHi, float yLo, float yHi) {
        return xHi >= r[0] && xLo <= r[2] && yHi >= r[1] && yLo <= r[3];
    };
    // The rectangles that overlap these rows' pixel centres: a packet lies inside the rows, so a
    // rectangle that misses them misses each of its packets too (the same comparisons).
    // SceneAccel::hitBoxes holds at most 32 boxes; were there more, every packet is traced.
    constexpr int kNear = 32;
    const bool cull = !job.hitRects.empty() && job.hitRects.size() <= size_t(kNear);
    const std::array<float, 4>* nearRects[kNear];
    int nNear = 0;
    if (cull)
        for (const std::array<float, 4>& r : job.hitRects)
            if (overlaps(r, float(x0) + 0.5f, float(x1 - 1) + 0.5f, float(job.h - 1 - (y1 - 1)) + 0.5f, float(job.h - 1 - y0) + 0.5f))
                nearRects[nNear++] = &r;
    for (int py = y0; py < y1; py += kPacket)
        for (int px = x0; px < x1; px += kPacket) {
            rt::PacketScratch<rt::Ray, kPacket * kPacket> pr;
            rt::PacketScratch<rt::SceneHit, kPacket * kPacket> ph;
            const int nx = std::min(px + kPacket, x1) - px, ny = std::min(py + kPacket, y1) - py;
            float wx[kPacket], wy[kPacket];
            for (int i = 0; i < nx; ++i) wx[i] = float(px + i) + 0.5f;
            for (int j = 0; j < ny; ++j) wy[j] = float(job.h - 1 - (py + j)) + 0.5f;
            if (cull) {   // rowFound keeps 0 for the packet's pixels: misses, as traced
                bool any = false;
                for (int k = 0; k < nNear && !any; ++k)
                    any = overlaps(*nearRects[k], wx[0], wx[nx - 1], wy[ny - 1], wy[0]);   // (wy falls row by row)
                if (!any) continue;
            }
            job.cam.gridOf(colShares + (px - x0), nx, rowShares.data() + (py - y0), ny, pr.data());   // (at wx, wy)
            int n = nx * ny;
            const uint64_t found = accel.intersectPacket(pr.data(), n, ~uint64_t(0), ph.data(), job.f.settings.culling);
            // The hit triangles' vertex indices, fetched now for the frames (Tracer::frameMeshHits) a
            // few packets later.
            for (uint64_t m = found; m; m &= m - 1) {
                const rt::SceneHit& h = ph[__builtin_ctzll(m)];
                if (h.kind == rt::SceneHit::Kind::Mesh) __builtin_prefetch(&job.f.meshes[h.instance].mesh->indices[3 * size_t(h.prim)]);
            }
            for (int j = 0; j < ny; ++j) {
                const size_t at = size_t(py + j - y0) * tile + size_t(px - x0);
                for (int i = 0; i < nx; ++i) {
                    n = j * nx + i;
                    rays[at + size_t(i)] = pr[n];
                    Tracer::FirstHit& fh = hits[at + size_t(i)];
                    fh.found = (found >> n) & 1;
                    fh.framed = false;
                    if (fh.found) fh.hit = ph[n];
                }
                rowFound[py + j - y0] |= uint32_t((found >> (j * nx)) & ((1u << nx) - 1)) << (px - x0);
                rowTraced[py + j - y0] |= ((1u << nx) - 1) << (px - x0);
            }
        }
}

// The shadow rays of the tile's primary hits (traceCameraPackets), kPacket x kPacket pixels at a
// time (Tracer::presetShadows), into tilePresets (kTile per row). Packets without a hit are left
// out: only a hit's shading reads its preset.
void presetTileShadows(Tracer& tr, int x0, int y0, int x1, int y1, const std::vector<rt::Ray>& tileRays,
                       const std::vector<Tracer::FirstHit>& tileHits, const uint32_t* rowFound, std::vector<Tracer::PresetVisibility>& tilePresets) {
    constexpr int kPacket = FrameJob::kPacket, tile = FrameJob::kTile;
    for (int py = y0; py < y1; py += kPacket)
        for (int px = x0; px < x1; px += kPacket) {
            uint32_t any = 0;
            for (int row = py; row < std::min(py + kPacket, y1); ++row) any |= rowFound[row - y0] >> (px - x0);
            if (!(any & ((1u << kPacket) - 1))) continue;
            const rt::Ray* pr[kPacket * kPacket];
            const Tracer::FirstHit* ph[kPacket * kPacket];
            Tracer::PresetVisibility* pv[kPacket * kPacket];
            int n = 0;
            for (int row = py; row < std::min(py + kPacket, y1); ++row)
                for (int x = px; x < std::min(px + kPacket, x1); ++x, ++n) {
                    const size_t at = size_t(row - y0) * tile + size_t(x - x0);
                    pr[n] = &tileRays[at];
                    ph[n] = &tileHits[at];
                    pv[n] = &tilePresets[at];
                }
            tr.presetShadows(pr, ph, n, pv);
        }
}

// A pixel's bytes from its mean linear colour: the display transform after the resolve, as every
// backend (tone_map.h), then the sRGB bytes (toByteSRGB's, with one table lookup each); NaN is
// never fed to the byte conversion.
void encodePixel(const FrameJob& job, vec3 mean, uint8_t* px) {
    mean = job.display(mean);
    if (!isFinite(mean)) mean = vec3(1, 0, 1);
    px[0] = job.srgb(mean.x);
    px[1] = job.srgb(mean.y);
    px[2] = job.srgb(mean.z);
    px[3] = 255;
}

// The bytes shadePixel gives a pixel whose one camera ray meets nothing when Tracer::missed
// returns the settings' background: that colour summed as shadePixel sums it, then encodePixel.
void setConstantMiss(FrameJob& job) {
    vec3 sum(0.0f);
    sum += job.f.settings.background;
    encodePixel(job, sum, job.missRgba);
    job.constantMiss = true;
}

// The pixels x0 + i of `row` in [x0, x1) whose bit i of `found` is clear (their packet ray met
// nothing), when that gives the plain background (job.constantMiss): what shadePixel gives them
// (one ray, the bytes of setConstantMiss, depth 1, no surface) without the per-pixel work.
void fillMisses(const FrameJob& job, Tracer& tr, int row, int x0, int x1, uint32_t found, Framebuffer& target) {
    const size_t at = size_t(row) * size_t(job.w);
    const bool visibility = job.cfg.aovs.has(Aov::Visibility);
    for (int x = x0; x < x1; ++x) {
        if ((found >> (x - x0)) & 1) continue;
        ++tr.rays;
        std::memcpy(target.pixel(x, row), job.missRgba, 4);
        target.depth[at + size_t(x)] = 1.0f;
        if (visibility) {
            target.drawable[at + size_t(x)] = 0;
            target.primitive[at + size_t(x)] = kNoPrimitive;
        }
    }
}

// What a pixel keeps of its surface hp (one of its rays'): the nearest depth into `depth` (windowZ:
// job.cam.depth(hp.p), read only where hp.p is a point), and its drawable and primitive when the
// visibility is asked (one centre ray per pixel, RenderConfig::aovs).
void keepSurface(const FrameJob& job, const SurfaceRecord& hp, float windowZ, int x, int row, float& depth, Framebuffer& target) {
    if (!std::isnan(hp.p.x)) depth = std::min(depth, std::clamp(windowZ, 0.0f, 1.0f));
    if (job.cfg.aovs.has(Aov::Visibility)) {
        target.drawable[size_t(row) * size_t(job.w) + size_t(x)] = hp.drawable;
        target.primitive[size_t(row) * size_t(job.w) + size_t(x)] = hp.primitive;
    }
}

// The camera rays of a strip of packets (rows [y0, y0 + kPacket) of a tile from column x0),
// which are also its pixels' neighbouring rays for texture footprints: CameraRays::neighbours
// gives ray(wx + 1, wy) and ray(wx, wy + 1), the grid's rays of the pixels to the right and
// above bit for bit. The strip's own rays (kTile per row) where bit x - x0 of traced[row - y0]
// is set, and the row above the strip (the strip before's last) in above[x - x0] where bit
// x - x0 of aboveTraced is.
struct StripRays {
    const rt::Ray* rays = nullptr;
    const uint32_t* traced = nullptr;
    const rt::Ray* above = nullptr;
    uint32_t aboveTraced = 0;
    int x0 = 0, y0 = 0;
    // Pixel (x, row)'s footprint (its centre ray's), with the neighbours' rays where made.
    void footprint(const FrameJob& job, int x, int row, PixelFootprint& fp) const {
        constexpr int tile = FrameJob::kTile;
        fp.cam = &job.cam;
        fp.wx = float(x) + 0.5f;
        fp.wy = float(job.h - 1 - row) + 0.5f;
        fp.carried = false;
        const int i = x - x0, j = row - y0;
        fp.madeX = i + 1 < tile && ((traced[j] >> (i + 1)) & 1) ? &rays[size_t(j) * tile + size_t(i + 1)] : nullptr;
        fp.madeY = nullptr;
        if (j > 0 && ((traced[j - 1] >> i) & 1))   // (window y + 1 is the row above: rows run top-down)
            fp.madeY = &rays[size_t(j - 1) * tile + size_t(i)];
        else if (j == 0 && ((aboveTraced >> i) & 1))
            fp.madeY = &above[i];
    }
};

// Pixel (x, row) of the tile with corner (x0, y0): its sx x sy stratified rays traced and
// shaded, the mean colour through the display transform as sRGB bytes, the nearest depth, and (centre ray) the visibility and
// the traversal cost when asked. made: the strip's rays (with packets; null without).
void shadePixel(const FrameJob& job, Tracer& tr, int x, int row, int x0, int y0, const std::vector<rt::Ray>& tileRays,
                const std::vector<Tracer::FirstHit>& tileHits, const std::vector<Tracer::PresetVisibility>& tilePresets, const StripRays* made,
                Framebuffer& target) {
    constexpr int tile = FrameJob::kTile;
    const int w = job.w, h = job.h, sx = job.sx, sy = job.sy;
    const int wy = h - 1 - row;   // GL window y of this row
    vec3 sum(0.0f);
    float depth = 1.0f;
    uint32_t seed = sx * sy > 1 ? hash32(uint32_t(x) * 73856093u ^ uint32_t(wy) * 19349663u) : 0u;   // (jitter only)
    for (int j = 0; j < sy; ++j)
        for (int i = 0; i < sx; ++i) {
            float ox = 0.5f, oy = 0.5f;
            if (sx * sy > 1) {
                ox = (float(i) + rand01(seed)) / float(sx);
                oy = (float(j) + rand01(seed)) / float(sy);
            }
            // (the packet's ray: the same call with ox = oy = 0.5)
            rt::Ray own;
            const rt::Ray& r = job.packets ? tileRays[size_t(row - y0) * tile + size_t(x - x0)] : (own = job.cam.ray(float(x) + ox, float(wy) + oy));
            SurfaceRecord hp;
            PixelFootprint fp{&job.cam, float(x) + ox, float(wy) + oy};
            if (made) made->footprint(job, x, row, fp);   // (the same window position: one centre ray)
            rt::TraversalCount count;
            if (job.countCost) tr.cost = &count;
            if (job.packets) tr.firstHit = &tileHits[size_t(row - y0) * tile + size_t(x - x0)];
            if (job.shadowPackets) tr.preset = &tilePresets[size_t(row - y0) * tile + size_t(x - x0)];
            vec3 c = tr.trace(r, job.f.camera.eye, 0, &hp, &fp);
            tr.preset = nullptr;
            if (job.countCost) {   // one centre ray per pixel, like the visibility
                target.costNodes[size_t(row) * w + x] = count.nodes;
                target.costPrims[size_t(row) * w + x] = count.prims;
            }
            keepSurface(job, hp, std::isnan(hp.p.x) ? 1.0f : job.cam.depth(hp.p), x, row, depth, target);
            sum += c;
        }
    if (sx * sy > 1) sum /= float(sx * sy);   // (x / 1 is x: one sample skips three divisions)
    encodePixel(job, sum, target.pixel(x, row));
    target.depth[size_t(row) * w + x] = depth;
}

// The pixels x0 + i of `row` (tile corner (x0, y0)) whose bit i of `pixels` is set, when the
// tile's camera rays went in packets: hits of the meshes in job.laneMesh eight at a time
// (raycast::shadeLanes, then what Tracer::trace and shadePixel do after the shading: fog, depth,
// visibility, bytes), every other pixel and every lane shadeLanes leaves through shadePixel.
void shadePixels(const FrameJob& job, Tracer& tr, int row, int x0, int y0, uint32_t pixels, const std::vector<rt::Ray>& tileRays,
                 const std::vector<Tracer::FirstHit>& tileHits, const std::vector<Tracer::PresetVisibility>& tilePresets, const StripRays& made,
                 Framebuffer& target) {
    constexpr int tile = FrameJob::kTile;
    if (job.laneMesh.empty()) {
        for (uint32_t m = pixels; m; m &= m - 1)
            shadePixel(job, tr, x0 + __builtin_ctz(m), row, x0, y0, tileRays, tileHits, tilePresets, &made, target);
        return;
    }
    raycast::LaneBatch b;
    size_t at[raycast::LaneBatch::kLanes];
    PixelFootprint fp;   // a textured lane's
    auto flush = [&] {
        float rgb[3][raycast::LaneBatch::kLanes], windowZ[raycast::LaneBatch::kLanes];
        const unsigned shaded = raycast::shadeLanes(b, job.f, rgb);
        for (int q = 0; q < b.count; q += 4)   // (b.p: the hit points; shadeLanes filled every lane)
            job.cam.depth4(b.p[0] + q, b.p[1] + q, b.p[2] + q, windowZ + q);
        // With an identity display transform the bytes of all lanes are made at once (encodeLanes).
        const bool plainBytes = job.display.identity;
        alignas(32) float sums[3][raycast::LaneBatch::kLanes] = {};
        for (int l = 0; l < b.count; ++l) {
            const int x = x0 + int(at[l] % tile);
            if (!((shaded >> l) & 1)) {
                shadePixel(job, tr, x, row, x0, y0, tileRays, tileHits, tilePresets, &made, target);
                continue;
            }
            // What trace() and shadePixel do after the shading: count the ray, keep the surface
            // (keepSurface: depth, visibility), fog, bytes.
            const rt::SceneHit& h = tileHits[at[l]].hit;
            SurfaceRecord hp;
            hp.p = vec3(b.p[0][l], b.p[1][l], b.p[2][l]);
            hp.drawable = h.instance + 1;
            hp.primitive = h.prim;
            ++tr.rays;
            float depth = 1.0f;
            keepSurface(job, hp, windowZ[l], x, row, depth, target);
            vec3 sum(0.0f);
            sum += tr.fogged(vec3(rgb[0][l], rgb[1][l], rgb[2][l]), hp.p);
            if (plainBytes)
                for (int a = 0; a < 3; ++a) sums[a][l] = sum[a];
            else
                encodePixel(job, sum, target.pixel(x, row));
            target.depth[size_t(row) * size_t(job.w) + size_t(x)] = depth;
        }
        if (plainBytes) {
            uint32_t words[raycast::LaneBatch::kLanes];
            raycast::encodeLanes(sums, b.count, words);
            for (unsigned m = shaded; m; m &= m - 1) {
                const int l = __builtin_ctz(m);
                std::memcpy(target.pixel(x0 + int(at[l] % tile), row), &words[l], 4);
            }
        }
        b.count = 0;
    };
    for (uint32_t m = pixels; m; m &= m - 1) {
        const int x = x0 + __builtin_ctz(m);
        const size_t i = size_t(row - y0) * tile + size_t(x - x0);
        const Tracer::FirstHit& fh = tileHits[i];
        const uint8_t lane = fh.found && fh.hit.kind == rt::SceneHit::Kind::Mesh ? job.laneMesh[fh.hit.instance] : uint8_t(0);
        if (!lane) {
            shadePixel(job, tr, x, row, x0, y0, tileRays, tileHits, tilePresets, &made, target);
            continue;
        }
        if (lane == 2) made.footprint(job, x, row, fp);   // (shadePixel's)
        tr.laneInputs(fh, tileRays[i], job.shadowPackets ? &tilePresets[i] : nullptr, lane == 2 ? &fp : nullptr, b, b.count);
        at[b.count++] = i;
        if (b.count == raycast::LaneBatch::kLanes) flush();
    }
    if (b.count) flush();
}

// --- RaycastRenderer --------------------------------------------------------------------------------

class RaycastRenderer final : public Renderer {
public:
    std::string_view name() const override { return "raycast"; }
    Capabilities capabilities() const override {
        Capabilities c;
        c.progressive = true;
        c.exactImplicits = true;
        c.shadows = true;
        c.shadowRays = true;   // soft ones: settings.shadowRays rays to a light with a size
        c.reflections = true;
        c.wireframe = true;               // the CPU backends' overlay (common/line_overlay.h), after the rays
        c.pointsAndLines = true;          // the same pixel footprint as the rasterizers
        c.aovs.add(Aov::Visibility);      // what each primary ray keeps
        c.aovs.add(Aov::TraversalCost);   // counted per primary ray when asked (Tracer::cost)
        // MSAA n and SSAA f are both taken as stratified jittered rays per pixel: n rays
        // (2 -> 2x1, 4 -> 2x2, 8 -> 4x2 strata) and f x f rays; each ray is shaded.
        c.msaaSamples = {2, 4, 8};
        c.ssaaFactors = {2, 3, 4};
        c.maxImageSize = 16384;
        return c;
    }

protected:
    RenderStats doRender(const FrameInput& f, const RenderConfig& cfg, Framebuffer& target, RenderControl* control) override {
        RenderStats stats;
        const int w = cfg.width, h = cfg.height;
        target.resizeForOverwrite(w, h);   // (clear() below fills colour and depth)
        const DisplayTransform display(f.settings);
        const vec3 background = display(f.settings.background);
        const uint8_t bg[4] = {toByteSRGB(background.x), toByteSRGB(background.y), toByteSRGB(background.z), 255};
        target.clear(bg, 1.0f);
        if (cfg.aovs.has(Aov::Visibility)) target.allocate(Aov::Visibility);
        const bool countCost = cfg.aovs.has(Aov::TraversalCost) && cfg.samplesPerPixel == 1;   // render() asks only for one-sample frames
        if (countCost) target.allocate(Aov::TraversalCost);
        rt::CameraRays cam(f.camera, w, h);
        if (!cam.valid() || !isFinite(f.camera.eye)) {
            stats.error = "camera matrices are not invertible";
            return stats;
        }

        // FTZ/DAZ: denormals in the traversal cost a lot and change nothing visible.
        const unsigned csr = _mm_getcsr();
        m_accel.update(f);
        m_world = debugSwitches().raycastWorldVertices ? &m_worldVertices.update(f) : nullptr;
        stats.triangles = f.triangleCount();
        prepareSamplers(f);
        std::string envError;
        m_environment = environmentFor(f.settings, &envError);
        if (!envError.empty()) stats.config.notes.push_back("environment " + envError + " (lit without it)");

        int sx = 1, sy = 1;
        strataOf(cfg, sx, sy);
        // Camera rays in packets where each pixel has one (the cost view counts rays one by one);
        // VIEWER_RAYCAST_PACKETS=0 traces them one by one (timing comparisons: the same image).
        const bool packets = debugSwitches().raycastPackets && sx * sy == 1 && !countCost;
        // Their shadow rays in packets too where every shadow ray is a plain any-hit ray (no
        // cut-outs or blended layers to pass through).
        const bool shadowPackets = packets && debugSwitches().raycastShadowPackets && f.settings.shadows && !f.lights.empty() && !anyTranslucent(f);
        FrameJob job{f, cfg, cam, w, h, sx, sy, packets, shadowPackets, countCost, display};
        if (packets && !(m_environment.map && m_environment.background)) setConstantMiss(job);   // as Tracer::missed
        if (job.constantMiss && debugSwitches().raycastPacketCull) {
            for (const rt::SceneAccel::Box& b : m_accel.hitBoxes()) {
                std::array<float, 4> r;
                if (!cam.windowBounds(b.lo, b.hi, b.spread, r.data())) {   // no bound for this box: trace every packet
                    job.hitRects.clear();
                    break;
                }
                job.hitRects.push_back(r);
            }
        }
        if (packets && debugSwitches().raycastLanes && raycast::laneShadingApplies(f, shadowPackets)) job.laneMesh = laneMeshes(f);
        uint64_t rays = 0;
        stats.cancelled = !renderTiles(job, target, control, rays);
        _mm_setcsr(csr);

        stats.rays = rays;
        if (!stats.cancelled) drawOverlay(f, cfg, target);
        stats.ok = !stats.cancelled;
        if (stats.cancelled) stats.error = "cancelled";
        return stats;
    }

public:
    std::vector<float> lightVisibility(const FrameInput& f, const vec3& p, const vec3& ng) override {
        if (!f.settings.shadows || m_textures.size() != f.meshes.size()) return {};
        Tracer tr{f, m_accel, m_textures, m_maps, nullptr, 0, anyTranslucent(f)};
        std::vector<float> v(f.lights.size(), 1.0f);
        if (!v.empty()) tr.lightVisibility(p, ng, v.data());
        return v;
    }
    std::vector<float> lightVisibilityMany(const FrameInput& f, int light, const std::vector<vec3>& p, const std::vector<vec3>& ng) override {
        if (!f.settings.shadows || m_textures.size() != f.meshes.size() || light < 0 || size_t(light) >= f.lights.size() || p.size() != ng.size())
            return {};
        std::vector<float> out(p.size(), 1.0f);
        const bool translucent = anyTranslucent(f);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, p.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
            Tracer tr{f, m_accel, m_textures, m_maps, nullptr, 0, translucent};
            std::vector<float> v(f.lights.size(), 1.0f);
            for (size_t i = r.begin(); i < r.end(); ++i) {
                tr.lightVisibility(p[i], ng[i], v.data());
                out[i] = v[size_t(light)];
            }
        });
        return out;
    }

private:
    // Samplers (mip chains) per texture, cached by id + version; one pointer per mesh (m_textures,
    // m_maps: the material maps); and each mesh's material coefficients (m_coefficients).
    void prepareSamplers(const FrameInput& f) {
        m_samplers.beginFrame();
        m_textures.assign(f.meshes.size(), nullptr);
        m_maps.assign(f.meshes.size(), {});
        m_coefficients.resize(f.meshes.size());
        for (size_t i = 0; i < f.meshes.size(); ++i) {
            m_textures[i] = m_samplers.get(f.meshes[i].texture);
            m_coefficients[i] = coefficientsOf(f.meshes[i].material);
            const sg::DrawMesh& dm = f.meshes[i];
            const sg::MaterialMaps& fm = dm.maps;
            const bool hasUv1 = dm.mesh && dm.mesh->uv1.size() == dm.mesh->positions.size();
            m_maps[i] = {m_samplers.get(fm.emissive), m_samplers.get(fm.occlusion), m_samplers.get(fm.metallicRoughness), m_samplers.get(fm.normal),
                         hasUv1 ? dm.material.uv1Maps : uint8_t(0)};
        }
        m_samplers.endFrame();
    }

    // Per f.meshes entry, whether Tracer::trace would shade its hits as raycast::shadeLanes does
    // (given laneShadingApplies): an opaque, lit material without maps other than the colour
    // texture, and no mirror reflection; 2 where that texture is sampled (texture and uvs), else 1.
    std::vector<uint8_t> laneMeshes(const FrameInput& f) const {
        std::vector<uint8_t> lanes(f.meshes.size(), 0);
        for (size_t i = 0; i < f.meshes.size(); ++i) {
            const sg::DrawMesh& dm = f.meshes[i];
            const sg::Material& m = dm.material;
            const bool hasUV = dm.mesh && dm.mesh->uv0.size() == dm.mesh->positions.size();
            const bool reflects = f.settings.reflections && m.reflectivity > 0.0f && f.settings.maxBounces > 0;
            if (dm.mesh && m.alphaMode == sg::AlphaMode::Opaque && !m.unlit && !reflects && !(hasUV && m_maps[i].any()))
                lanes[i] = hasUV && m_textures[i] ? 2 : 1;
        }
        return lanes;
    }

    // The frame's 32x32 tiles, in parallel (FTZ/DAZ in each worker), with progress and
    // cancellation; adds the rays traced to `rays`. Returns false when cancelled.
    bool renderTiles(const FrameJob& job, Framebuffer& target, RenderControl* control, uint64_t& rays) {
        const FrameInput& f = job.f;
        const bool anyAlpha = anyTranslucent(f);
        constexpr int tile = FrameJob::kTile;
        const int tx = (job.w + tile - 1) / tile, ty = (job.h + tile - 1) / tile, ntiles = tx * ty;
        std::atomic<int> done{0};
        std::atomic<uint64_t> rayCount{0};
        std::atomic<bool> cancelled{false};
        if (control) control->progress = 0.0f;

        tbb::parallel_for(tbb::blocked_range<int>(0, ntiles, 1), [&](const tbb::blocked_range<int>& range) {
            TileBuffers& buffers = m_tileBuffers.local();   // made once per thread (every entry is written before it is read)
            buffers.reserve(job);
            std::vector<Tracer::FirstHit>& tileHits = buffers.hits;
            std::vector<rt::Ray>& tileRays = buffers.rays;
            std::vector<Tracer::PresetVisibility>& tilePresets = buffers.presets;
            const unsigned old = _mm_getcsr();
            _mm_setcsr(old | 0x8040);   // FTZ | DAZ in this worker
            for (int ti = range.begin(); ti != range.end(); ++ti) {
                if (control && control->cancel.load(std::memory_order_relaxed)) {
                    cancelled = true;
                    break;
                }
                Tracer tr{f, m_accel, m_textures, m_maps, m_world, 0, anyAlpha};
                tr.env = &m_environment;
                tr.meshCoefficients = &m_coefficients;
                const int x0 = (ti % tx) * tile, y0 = (ti / tx) * tile;   // y0: framebuffer row (top-down)
                const int x1 = std::min(x0 + tile, job.w), y1 = std::min(y0 + tile, job.h);
                uint32_t* const rowFound = buffers.rowFound;
                const uint32_t allPixels = uint32_t((uint64_t(1) << (x1 - x0)) - 1);
                if (!job.packets) {
                    for (int row = y0; row < y1; ++row)
                        for (int x = x0; x < x1; ++x) shadePixel(job, tr, x, row, x0, y0, tileRays, tileHits, tilePresets, nullptr, target);
                }
                // With packets, one row of packets at a time through all three steps (camera rays,
                // their shadow rays, the shading): its hits (kTile x kPacket of them) stay in the
                // first level cache between the steps, where a whole tile's would not.
                if (job.packets)
                    for (int x = x0; x < x1; ++x) buffers.colShares[x - x0] = job.cam.column(float(x) + 0.5f);
                StripRays made{tileRays.data(), buffers.rowTraced, buffers.above, 0, x0, y0};
                for (int sy = y0; job.packets && sy < y1; sy += FrameJob::kPacket) {
                    const int sy1 = std::min(sy + FrameJob::kPacket, y1);
                    traceCameraPackets(job, m_accel, x0, sy, x1, sy1, buffers.colShares, tileRays, tileHits, rowFound, buffers.rowTraced);
                    if (job.shadowPackets) presetTileShadows(tr, x0, sy, x1, sy1, tileRays, tileHits, rowFound, tilePresets);
                    made.y0 = sy;
                    for (int row = sy; row < sy1; ++row) {
                        const uint32_t found = job.constantMiss ? rowFound[row - sy] : allPixels;
                        if (job.constantMiss) fillMisses(job, tr, row, x0, x1, found, target);
                        shadePixels(job, tr, row, x0, sy, found, tileRays, tileHits, tilePresets, made, target);
                    }
                    // The strip's last row is the next one's row above (the next strip overwrites tileRays).
                    const int last = sy1 - 1 - sy;
                    made.aboveTraced = buffers.rowTraced[last];
                    for (uint32_t m = made.aboveTraced; m; m &= m - 1) {
                        const int i = __builtin_ctz(m);
                        buffers.above[i] = tileRays[size_t(last) * tile + size_t(i)];
                    }
                }
                rayCount += tr.rays;
                int d = ++done;
                if (control) {
                    control->progress = float(d) / float(ntiles);
                    if (control->onTileDone) control->onTileDone();
                }
            }
            _mm_setcsr(old);
        });
        rays = rayCount.load();
        return !cancelled.load();
    }

    // Points, lines and the wireframe, rasterized over the ray-cast image against its depth
    // exactly as the CPU rasterizer draws them (rays cannot hit zero-width primitives). The
    // wireframe of analytic shapes is their tessellation's, as in the rasterizers. Drawn at the
    // output size: with SSAA the rasterizers' 1-pixel lines come out fainter after downsampling.
    void drawOverlay(const FrameInput& f, const RenderConfig& cfg, Framebuffer& target) {
        std::vector<PreparedDraw> draws;
        if (f.settings.wireframe) {
            draws = prepareDraws(f, cfg.tessellation, m_tess);
            m_tess.nextFrame();
        } else {
            for (const PreparedDraw& d : prepareMeshDraws(f))
                if (d.mesh->mode != sg::PrimitiveMode::Triangles) draws.push_back(d);
        }
        if (!draws.empty()) drawPointsLinesWireframe(draws, f, target, 2.0f);
    }

    // A tile's camera rays, their first hits and their shadow presets (traceCameraPackets,
    // presetTileShadows), per thread: kept between ranges and frames rather than made and
    // value-initialized for each range.
    struct TileBuffers {
        std::vector<Tracer::FirstHit> hits;
        std::vector<rt::Ray> rays;
        std::vector<Tracer::PresetVisibility> presets;
        uint32_t rowFound[FrameJob::kTile];      // per tile row, which pixels' rays met something
        uint32_t rowTraced[FrameJob::kTile];     // and which were traced (traceCameraPackets)
        rt::Ray above[FrameJob::kTile];          // the camera rays of the row above a strip (StripRays)
        glm::dvec4 colShares[FrameJob::kTile];   // CameraRays::column per tile column (traceCameraPackets)
        void reserve(const FrameJob& job) {
            constexpr size_t n = size_t(FrameJob::kTile) * FrameJob::kTile;
            if (job.packets && hits.size() < n) {
                hits.resize(n);
                rays.resize(n);
            }
            if (job.shadowPackets && presets.size() < n) presets.resize(n);
        }
    };
    tbb::enumerable_thread_specific<TileBuffers> m_tileBuffers;

    rt::SceneAccel m_accel;
    rt::WorldVertexCache m_worldVertices;
    const std::vector<const rt::WorldVertices*>* m_world = nullptr;   // this frame's (null: switched off)
    SamplerCache m_samplers;
    // The last frame's samplers per mesh (kept for lightVisibility).
    std::vector<const SampledTexture*> m_textures;
    std::vector<MapSamplers> m_maps;
    std::vector<SurfaceCoefficients> m_coefficients;   // this frame's coefficientsOf per mesh (Tracer::meshCoefficients)
    EnvironmentLight m_environment;                    // this frame's (environmentFor)
    TessellationCache m_tess;                          // wireframe of analytic shapes only
};

}   // namespace

std::unique_ptr<Renderer> makeRaycastRenderer() { return std::make_unique<RaycastRenderer>(); }

}   // namespace rnd
