// shadow_map.cpp - the rasterizers' shadow maps (shadow_map.h has the formulas): which maps a
// frame's lights get, the CPU depth pass, and the lookup.
#include "renderers/shadow_map.h"
#include "renderers/huge_pages.h"

#include "renderers/sampling.h"

#include "raster/simd.h"
#include "renderers/debug_switches.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>

namespace rnd {

using sg::Aabb;
using sg::mat4;
using sg::vec3;
using sg::vec4;

namespace {

// An up vector not parallel to d.
vec3 upFor(const vec3& d) { return std::abs(d.y) < 0.99f ? vec3(0, 1, 0) : vec3(1, 0, 0); }

// The part of the casters the camera sees, in the light's eye space: the camera frustum between
// the casters' nearest and farthest depths (clamped to the frustum), its 8 corners' bounds.
Aabb visibleSliceInLight(const sg::FrameCamera& cam, const Aabb& casters, const mat4& lightView) {
    Aabb out;
    const Aabb ce = casters.transformed(cam.view);
    if (ce.empty() || (ce.min.z >= 0.0f && cam.projection.type == sg::ProjectionType::Perspective)) return out;
    auto ndcZ = [&](float dist) {
        const vec4 c = cam.proj * vec4(0.0f, 0.0f, -dist, 1.0f);
        return std::clamp(c.w != 0.0f ? c.z / c.w : 0.0f, -1.0f, 1.0f);
    };
    const float dNear = std::max(-ce.max.z, 0.0f), dFar = std::max(-ce.min.z, dNear);
    const float zs[2] = {ndcZ(std::max(dNear, 1e-6f)), ndcZ(std::max(dFar, 1e-6f))};
    const mat4 toLight = lightView * glm::inverse(cam.viewProj);
    for (float z : zs)
        for (float y : {-1.0f, 1.0f})
            for (float x : {-1.0f, 1.0f}) {
                const vec4 q = toLight * vec4(x, y, z, 1.0f);
                if (q.w != 0.0f) out.extend(vec3(q) / q.w);
            }
    return out;
}

// The near and far distances of the casters from a perspective view's eye along its axis.
void perspectiveRange(const Aabb& casters, const mat4& view, float& nearZ, float& farZ) {
    const Aabb le = casters.transformed(view);
    farZ = std::max(-le.min.z, 1e-4f) * 1.01f;
    nearZ = std::clamp(-le.max.z * 0.99f, farZ * 1e-4f, farZ * 0.5f);
}

}   // namespace

PageBuffer::~PageBuffer() { pageFree(data_, capacity_ * sizeof(float)); }

void PageBuffer::resize(size_t n) {
    if (n > capacity_) {
        pageFree(data_, capacity_ * sizeof(float));
        data_ = nullptr;
        size_ = capacity_ = 0;
        data_ = static_cast<float*>(pageAlloc(n * sizeof(float)));
        capacity_ = n;
    }
    size_ = n;
}

Aabb shadowCasterBounds(const sg::FrameInput& f) {
    Aabb b;
    for (const sg::DrawMesh& d : f.meshes)
        if (d.mesh && d.mesh->mode == sg::PrimitiveMode::Triangles && !d.mesh->positions.empty()) b.extend(d.mesh->bounds().transformed(d.world));
    for (const sg::DrawAnalytic& a : f.analytics)
        if (!a.worldBounds.empty() && std::isfinite(a.worldBounds.min.x) && std::isfinite(a.worldBounds.max.x)) b.extend(a.worldBounds);
    return b;
}

ShadowPlan planShadows(const sg::FrameInput& f, const Aabb& casters) {
    ShadowPlan plan;
    const sg::RenderSettings& s = f.settings;
    if (!s.shadows || casters.empty() || f.lights.empty()) return plan;
    plan.size = std::clamp(s.shadowMapSize, 1, 8192);
    plan.filter = s.shadowFilter;
    plan.pcf = s.shadowFilter != sg::ShadowFilter::None ? std::clamp(s.shadowPcfSize, 1, 15) : 1;
    plan.depthBias = s.shadowDepthBias;
    plan.normalBias = s.shadowNormalBias;
    const float N = float(plan.size);
    // Texels kept beyond an edge so that the filter's taps there still read the map (PCSS's
    // reach up to kPcssMaxRadius texels on each side).
    const float margin = float((plan.filter == sg::ShadowFilter::Pcss ? 2 * kPcssMaxRadius : plan.pcf) + 2) / N;
    const vec3 centre = casters.center();
    const float radius = std::max(0.5f * glm::length(casters.extent()), 1e-6f);
    for (const sg::DrawLight& L : f.lights) {
        plan.firstView.push_back(int(plan.views.size()));
        if (int(plan.views.size()) + (L.type == sg::LightType::Point ? 6 : 1) > kMaxShadowViews) {
            plan.viewCount.push_back(0);
            continue;
        }
        if (L.type == sg::LightType::Directional) {
            const vec3 d = glm::normalize(L.direction);
            const vec3 from = centre - 2.0f * radius * d;
            ShadowView v;
            v.view = glm::lookAt(from, from + d, upFor(d));
            const Aabb all = casters.transformed(v.view);
            Aabb fit = all;
            const Aabb seen = visibleSliceInLight(f.camera, casters, v.view);
            if (!seen.empty()) {   // x and y: the part in view, never more than the casters
                fit.min.x = std::max(all.min.x, seen.min.x);
                fit.max.x = std::min(all.max.x, seen.max.x);
                fit.min.y = std::max(all.min.y, seen.min.y);
                fit.max.y = std::min(all.max.y, seen.max.y);
                if (fit.min.x > fit.max.x || fit.min.y > fit.max.y) fit = all;
            }
            // Square texels, the margin around, and the depth range of every caster.
            const float half = 0.5f * std::max({fit.max.x - fit.min.x, fit.max.y - fit.min.y, 1e-6f * radius}) * (1.0f + 2.0f * margin);
            const float cx = 0.5f * (fit.min.x + fit.max.x), cy = 0.5f * (fit.min.y + fit.max.y);
            // (At least a thousandth of the scene and clear of float rounding at this distance: a
            // flat scene would otherwise get near == far.)
            const float depth = std::max({all.max.z - all.min.z, 1e-3f * radius, 1e-4f * std::max(std::abs(all.min.z), std::abs(all.max.z))});
            v.nearZ = -all.max.z - 0.01f * depth;
            v.farZ = -all.min.z + 0.01f * depth;
            v.viewProj = glm::ortho(cx - half, cx + half, cy - half, cy + half, v.nearZ, v.farZ) * v.view;
            v.texelAtUnit = 2.0f * half / N;
            plan.views.push_back(v);
        } else if (L.type == sg::LightType::Spot) {
            const vec3 d = glm::normalize(L.direction);
            ShadowView v;
            v.perspective = true;
            v.view = glm::lookAt(L.position, L.position + d, upFor(d));
            const float halfAngle = std::acos(std::clamp(L.cosOuter, -1.0f, 1.0f));
            const float tanHalf = std::min(std::tan(std::min(halfAngle, sg::radians(85.0f))) * (1.0f + 2.0f * margin), std::tan(sg::radians(87.0f)));
            perspectiveRange(casters, v.view, v.nearZ, v.farZ);
            v.viewProj = glm::perspective(2.0f * std::atan(tanHalf), 1.0f, v.nearZ, v.farZ) * v.view;
            v.texelAtUnit = 2.0f * tanHalf / N;
            plan.views.push_back(v);
        } else {   // point: six faces of 90 degrees plus the margin
            static const vec3 dirs[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
            static const vec3 ups[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
            const float tanHalf = 1.0f + 2.0f * margin;
            for (int k = 0; k < 6; ++k) {
                ShadowView v;
                v.perspective = true;
                v.view = glm::lookAt(L.position, L.position + dirs[k], ups[k]);
                perspectiveRange(casters, v.view, v.nearZ, v.farZ);
                v.viewProj = glm::perspective(2.0f * std::atan(tanHalf), 1.0f, v.nearZ, v.farZ) * v.view;
                v.texelAtUnit = 2.0f * tanHalf / N;
                plan.views.push_back(v);
            }
        }
        plan.viewCount.push_back(int(plan.views.size()) - plan.firstView.back());
    }
    return plan;
}

int pointLightFace(const vec3& d) {
    const float ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    if (ax >= ay && ax >= az) return d.x > 0.0f ? 0 : 1;
    if (ay >= az) return d.y > 0.0f ? 2 : 3;
    return d.z > 0.0f ? 4 : 5;
}

namespace {

// A triangle in the map's window coordinates: x, y in texels, z = 1/w and w_ = d/w with d the
// normalized linear depth (perspective-correct: d = w_ / z at a pixel; orthographic: w = 1).
struct WinTri {
    vec4 a, b, c;
    int y0, y1;   // rows it may cover
};

constexpr int kBand = 64;   // rows per band of the parallel depth pass

// Clips a clip-space polygon against the near plane (z >= -w) and writes its fan of window
// triangles (at most two) to out; returns how many.
int emitClipped(const vec4 (&in)[3], const ShadowView& v, int size, WinTri* out) {
    vec4 poly[4];
    int n = 0;
    for (int k = 0; k < 3; ++k) {
        const vec4& p = in[k];
        const vec4& q = in[(k + 1) % 3];
        const float dp = p.z + p.w, dq = q.z + q.w;
        if (dp >= 0.0f) poly[n++] = p;
        if ((dp >= 0.0f) != (dq >= 0.0f)) {
            const float t = dp / (dp - dq);
            poly[n++] = p + t * (q - p);
        }
    }
    if (n < 3) return 0;
    const float s = float(size), range = v.farZ - v.nearZ;
    vec4 w[4];
    for (int k = 0; k < n; ++k) {
        if (!(poly[k].w > 0.0f)) return 0;
        const float iw = 1.0f / poly[k].w;
        const vec3 ndc = vec3(poly[k]) * iw;
        // The stored depth: linear along the axis, 0 at near, 1 at far (perspective: w is the
        // eye depth; orthographic: the window depth is already linear).
        const float d = v.perspective ? (poly[k].w - v.nearZ) / range : ndc.z * 0.5f + 0.5f;
        w[k] = v.perspective ? vec4((ndc.x * 0.5f + 0.5f) * s, (ndc.y * 0.5f + 0.5f) * s, iw, d * iw)
                             : vec4((ndc.x * 0.5f + 0.5f) * s, (ndc.y * 0.5f + 0.5f) * s, 1.0f, d);
    }
    int emitted = 0;
    for (int k = 1; k + 1 < n; ++k) {
        WinTri t{w[0], w[k], w[k + 1], 0, 0};
        const float ymin = std::min({t.a.y, t.b.y, t.c.y}), ymax = std::max({t.a.y, t.b.y, t.c.y});
        const float xmin = std::min({t.a.x, t.b.x, t.c.x}), xmax = std::max({t.a.x, t.b.x, t.c.x});
        if (!(ymax >= 0.0f && ymin < s && xmax >= 0.0f && xmin < s)) continue;   // off the map (or NaN)
        // (Clamped as floats first: a vertex far off the map would overflow the conversion.)
        t.y0 = std::max(0, int(std::floor(std::max(ymin, -1.0f) - 0.5f)));
        t.y1 = std::min(size - 1, int(std::ceil(std::min(ymax, s + 1.0f) - 0.5f)));
        if (t.y0 <= t.y1) out[emitted++] = t;
    }
    return emitted;
}

// A window triangle's rasterizer constants, worked out once (not per band): edge k is the one
// opposite vertex k (counter-clockwise, so w_k(x, y) = ex x + ey y + e0 >= 0 inside); 1/w and d/w
// are affine in the pixel centre (sums of the edge functions' multiples); x0..x1, y0..y1 the
// texels it may cover.
struct TriSetup {
    float ex[3], ey[3], e0[3];
    float iwX, iwY, iw0, dwX, dwY, dw0;
    int x0, x1, y0, y1;
    bool inclusive[3];   // the top-left rule: a pixel centre on a top or a left edge is inside
    bool ortho;          // 1/w constant (orthographic): no division per texel
};

// t's constants; false when it has no area (or NaN corners) or covers no column.
bool setupTri(const WinTri& t, int size, TriSetup& s) {
    vec4 a = t.a, b = t.b, c = t.c;
    float area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (!(area != 0.0f)) return false;
    if (area < 0.0f) {   // both faces: counter-clockwise from here on
        std::swap(b, c);
        area = -area;
    }
    const vec4 v[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
        const vec4& p = v[(k + 1) % 3];
        const vec4& q = v[(k + 2) % 3];
        s.ex[k] = p.y - q.y;   // d w / d x
        s.ey[k] = q.x - p.x;   // d w / d y
        s.e0[k] = p.x * q.y - p.y * q.x;
        const bool top = s.ex[k] == 0.0f && s.ey[k]<0.0f, left = s.ex[k]> 0.0f;
        s.inclusive[k] = top || left;
    }
    const float xmin = std::min({a.x, b.x, c.x}), xmax = std::max({a.x, b.x, c.x});
    s.x0 = std::max(0, int(std::floor(std::max(xmin, -1.0f) - 0.5f)));
    s.x1 = std::min(size - 1, int(std::ceil(std::min(xmax, float(size) + 1.0f) - 0.5f)));
    s.y0 = t.y0;
    s.y1 = t.y1;
    s.iwX = s.iwY = s.iw0 = s.dwX = s.dwY = s.dw0 = 0.0f;
    for (int k = 0; k < 3; ++k) {
        s.iwX += s.ex[k] * v[k].z;
        s.iwY += s.ey[k] * v[k].z;
        s.iw0 += s.e0[k] * v[k].z;
        s.dwX += s.ex[k] * v[k].w;
        s.dwY += s.ey[k] * v[k].w;
        s.dw0 += s.e0[k] * v[k].w;
    }
    s.ortho = s.iwX == 0.0f && s.iwY == 0.0f;
    return s.x0 <= s.x1;
}

// Row y's candidate span [xs, xe] (pixel centre py): each edge bounds x from one side, a texel
// beyond its crossing; the exact test then decides each texel of it (the texels inside form one
// run: every edge function, rounding included, is monotonic along the row).
inline void rowSpan(const TriSetup& s, float py, int& xs, int& xe) {
    float lo = float(s.x0), hi = float(s.x1);
    for (int k = 0; k < 3; ++k) {
        const float c0 = s.ey[k] * py + s.e0[k];
        if (s.ex[k] > 0.0f)
            lo = std::max(lo, -c0 / s.ex[k] - 0.5f - 1.0f);
        else if (s.ex[k] < 0.0f)
            hi = std::min(hi, -c0 / s.ex[k] - 0.5f + 1.0f);
    }
    xs = std::max(s.x0, int(std::floor(lo)));
    xe = std::min(s.x1, int(std::ceil(hi)));
}

// The scalar reference: rasterizes s into rows [r0, r1] of the map (pixel centres, the top-left
// rule, depth less, depths outside [0, 1] dropped).
void rasterizeRows(const TriSetup& s, int size, int r0, int r1, float* map) {
    auto inside = [&](float px, float py) {
        for (int k = 0; k < 3; ++k) {
            const float w = s.ex[k] * px + s.ey[k] * py + s.e0[k];
            if (!(w > 0.0f || (w == 0.0f && s.inclusive[k]))) return false;
        }
        return true;
    };
    const int y0 = std::max(r0, s.y0), y1 = std::min(r1, s.y1);
    for (int y = y0; y <= y1; ++y) {
        const float py = float(y) + 0.5f;
        int xs, xe;
        rowSpan(s, py, xs, xe);
        // The run's ends by the exact test; every texel between them is inside (convex).
        while (xs <= xe && !inside(float(xs) + 0.5f, py)) ++xs;
        while (xe >= xs && !inside(float(xe) + 0.5f, py)) --xe;
        float* row = map + size_t(y) * size_t(size);
        const float iwRow = s.iwY * py + s.iw0, dwRow = s.dwY * py + s.dw0;
        if (s.ortho) {
            const float inv = iwRow != 0.0f ? 1.0f / iwRow : 0.0f;
            for (int x = xs; x <= xe; ++x) {
                const float z = (s.dwX * (float(x) + 0.5f) + dwRow) * inv;
                const bool ok = z >= 0.0f && z <= 1.0f;
                row[x] = ok ? std::min(row[x], z) : row[x];
            }
            continue;
        }
        for (int x = xs; x <= xe; ++x) {
            const float px = float(x) + 0.5f;
            const float iw = s.iwX * px + iwRow, dw = s.dwX * px + dwRow;
            const float z = iw != 0.0f ? dw / iw : 1.0f;   // (the barycentric normalisation cancels)
            const bool ok = z >= 0.0f && z <= 1.0f;
            row[x] = ok ? std::min(row[x], z) : row[x];
        }
    }
}

}   // namespace

// The same rows a vector of texels at a time (shadow_depth_kernel.inl), once per instruction set.
#if defined(RASTER_HAVE_SSE2)
namespace depth_sse {
using namespace raster::simd_sse;
#include "common/shadow_depth_kernel.inl"
}   // namespace depth_sse
#if defined(RASTER_HAVE_AVX2)
VIEWER_ISA_REGION_BEGIN("avx2")
namespace depth_avx2 {
using namespace raster::simd_avx2;
#include "common/shadow_depth_kernel.inl"
}   // namespace depth_avx2
VIEWER_ISA_REGION_END
#endif
#endif

namespace {

using RowsFn = void (*)(const TriSetup&, int, int, int, float*);

// The kernel the CPU runs: AVX2 where it has it (and VIEWER_RASTER_SSE is not 1), else SSE2.
RowsFn vectorRows(const char** name) {
#if defined(RASTER_HAVE_SSE2)
#if defined(RASTER_HAVE_AVX2)
    static const bool avx2 = [] {
        if (debugSwitches().rasterForceSse) return false;
        __builtin_cpu_init();
        return bool(__builtin_cpu_supports("avx2"));
    }();
    if (avx2) {
        if (name) *name = "avx2";
        return depth_avx2::rasterizeRowsV;
    }
#endif
    if (name) *name = "sse2";
    return depth_sse::rasterizeRowsV;
#else
    if (name) *name = "scalar";
    return rasterizeRows;
#endif
}

}   // namespace

const char* shadowDepthKernelName(ShadowDepthKernel kernel) {
    const char* name = "scalar";
    if (kernel == ShadowDepthKernel::Auto) vectorRows(&name);
    return name;
}

void renderShadowDepth(const ShadowView& v, int size, const std::vector<ShadowCaster>& casters, float* map, ShadowDepthKernel kernel) {
    const RowsFn rows = kernel == ShadowDepthKernel::Scalar ? rasterizeRows : vectorRows(nullptr);
    // Window triangles and their rasterizer constants, built in parallel blocks of each caster,
    // each block into its own stretch of one buffer, twice its triangles long (a clipped triangle
    // makes at most two). The buffers are the calling thread's, kept from call to call:
    // allocating them per map, in the workers, fragmented the heap of a long session (resident
    // memory kept growing).
    constexpr size_t kBlock = 4096;
    struct Block {
        const ShadowCaster* c;
        size_t begin, end;
        size_t out;   // where its stretch of `built` starts
    };
    struct Scratch {
        std::vector<Block> blocks;
        // (every entry read was written first: huge pages, no zero fill)
        HugeVector<TriSetup> built;
        std::vector<uint32_t> builtCount;
        std::vector<std::vector<uint32_t>> perBand;
    };
    thread_local Scratch scratch;
    // (Named here: inside the workers' lambdas a thread_local would be the worker's own.)
    Scratch& sc = scratch;
    auto& blocks = sc.blocks;
    auto& built = sc.built;
    auto& builtCount = sc.builtCount;
    auto& perBand = sc.perBand;
    blocks.clear();
    size_t stretches = 0;   // (a fixed 2 x kBlock per block made the scene of 1024 small instances hold 740 MB)
    for (const ShadowCaster& c : casters)
        for (size_t b = 0; b < c.triangles; b += kBlock) {
            blocks.push_back({&c, b, std::min(c.triangles, b + kBlock), stretches});
            stretches += 2 * (blocks.back().end - b);
        }
    if (built.size() < stretches) built.resize(stretches);
    builtCount.assign(blocks.size(), 0);
    tbb::parallel_for(size_t(0), blocks.size(), [&](size_t bi) {
        const Block& blk = blocks[bi];
        const auto* base = static_cast<const unsigned char*>(blk.c->positions);
        TriSetup* out = &built[blk.out];
        uint32_t count = 0;
        for (size_t t = blk.begin; t < blk.end; ++t) {
            vec4 clip[3];
            bool valid = true;
            for (int k = 0; k < 3 && valid; ++k) {
                const size_t i = blk.c->idx ? blk.c->idx[3 * t + size_t(k)] : 3 * t + size_t(k);
                valid = i < blk.c->vertices;
                if (!valid) break;
                float xyz[3];
                std::memcpy(xyz, base + i * blk.c->stride, sizeof(xyz));
                clip[k] = v.viewProj * vec4(xyz[0], xyz[1], xyz[2], 1.0f);
            }
            if (!valid) continue;
            WinTri w[2];
            const int n = emitClipped(clip, v, size, w);
            for (int q = 0; q < n; ++q) count += setupTri(w[q], size, out[count]) ? 1u : 0u;
        }
        builtCount[bi] = count;
    });
    // Bands of rows, each with the triangles that reach it, cleared to 1 and rasterized in
    // parallel (a band's rows stay in the cache between the two).
    const int bands = (size + kBand - 1) / kBand;
    if (perBand.size() < size_t(bands)) perBand.resize(size_t(bands));
    for (auto& list : perBand) list.clear();
    for (size_t bi = 0; bi < blocks.size(); ++bi)
        for (uint32_t q = 0; q < builtCount[bi]; ++q) {
            const uint32_t id = uint32_t(blocks[bi].out + q);
            const TriSetup& t = built[id];
            for (int b = t.y0 / kBand; b <= t.y1 / kBand; ++b) perBand[size_t(b)].push_back(id);
        }
    tbb::parallel_for(0, bands, [&](int b) {
        const int r0 = b * kBand, r1 = std::min(size - 1, r0 + kBand - 1);
        std::fill(map + size_t(r0) * size_t(size), map + size_t(r1 + 1) * size_t(size), 1.0f);
        for (uint32_t id : perBand[size_t(b)]) rows(built[id], size, r0, r1, map);
    });
}

float pcssJitter(int i, int j, int view, int axis) {
    uint32_t h = hash32(uint32_t(i) * 73856093u ^ uint32_t(j) * 19349663u ^ uint32_t(view) * 83492791u);
    if (axis) h = hash32(h);
    return unitFloat(h);
}

std::vector<int> gouraudShadowedLights(const ShadowPlan& plan, size_t maxLights) {
    std::vector<int> out;
    for (size_t l = 0; l < plan.viewCount.size() && l < maxLights && out.size() < size_t(kGouraudShadowedLights); ++l)
        if (plan.viewCount[l] > 0) out.push_back(int(l));
    return out;
}

float shadowVisibility(const ShadowPlan& plan, const ShadowMaps& maps, const sg::DrawLight& L, int light, const vec3& p, const vec3& ng) {
    if (light < 0 || size_t(light) >= plan.viewCount.size() || plan.viewCount[size_t(light)] == 0 || maps.size != plan.size) return 1.0f;
    int vi = plan.firstView[size_t(light)];
    if (L.type == sg::LightType::Point) vi += pointLightFace(p - L.position);
    const ShadowView& v = plan.views[size_t(vi)];
    const vec3 toLight = L.type == sg::LightType::Directional ? -L.direction : L.position - p;
    const vec3 n = glm::dot(ng, toLight) < 0.0f ? -ng : ng;   // the side the light is on
    // The texel's size at p, the normal offset, then the receiver's depth less the depth bias.
    const float depthP = -(v.view[0][2] * p.x + v.view[1][2] * p.y + v.view[2][2] * p.z + v.view[3][2]);
    const float t = v.perspective ? v.texelAtUnit * depthP : v.texelAtUnit;
    const vec3 q = p + plan.normalBias * t * n;
    const vec4 c = v.viewProj * vec4(q, 1.0f);
    if (!(c.w > 0.0f)) return 1.0f;
    const float u = (c.x / c.w) * 0.5f + 0.5f, w = (c.y / c.w) * 0.5f + 0.5f;
    const float zq = -(v.view[0][2] * q.x + v.view[1][2] * q.y + v.view[2][2] * q.z + v.view[3][2]);
    const float zb = zq - plan.depthBias * t;
    // The biased depth as the maps store depth (linear, 0 at near, 1 at far); each tap compares
    // the receiver's plane at the tap's texel centre (receiver-plane depth bias: a tilted receiver
    // is deeper or shallower there than at q, by its slope in the light's frame, clamped at 4).
    const float range = v.farZ - v.nearZ;
    if (!(range > 0.0f)) return 1.0f;
    const float dRecv = (zb - v.nearZ) / range;
    const vec3 nl(v.view[0][0] * n.x + v.view[1][0] * n.y + v.view[2][0] * n.z, v.view[0][1] * n.x + v.view[1][1] * n.y + v.view[2][1] * n.z,
                  v.view[0][2] * n.x + v.view[1][2] * n.y + v.view[2][2] * n.z);
    // The receiver's tilt against the ray to the light (a perspective map's rays leave its axis
    // by up to 45 degrees at a cube face's edge), clamped at a slope of 4.
    const float cosRay = v.perspective ? glm::dot(n, glm::normalize(toLight)) : nl.z;
    const float nz = std::max(cosRay, 0.25f * std::sqrt(nl.x * nl.x + nl.y * nl.y));                                    // the light's side: > 0
    const float slopeX = nz > 0.0f ? nl.x / nz * t / range : 0.0f, slopeY = nz > 0.0f ? nl.y / nz * t / range : 0.0f;   // per texel
    const int N = plan.size, k = plan.pcf;
    const float su = u * float(N), sv = w * float(N);
    if (!(std::abs(su) < 1e8f && std::abs(sv) < 1e8f)) return 1.0f;   // far outside the map (or NaN): lit
    const float* map = maps.map(vi);
    // The receiver's depth at texel (i, j)'s centre, and that texel's depth (outside the map:
    // infinite, lit).
    auto receiver = [&](int i, int j) { return dRecv + slopeX * (float(i) + 0.5f - su) + slopeY * (float(j) + 0.5f - sv); };
    auto stored = [&](int i, int j) {
        return i < 0 || j < 0 || i >= N || j >= N ? std::numeric_limits<float>::infinity() : map[size_t(j) * size_t(N) + size_t(i)];
    };
    if (plan.filter == sg::ShadowFilter::Pcss) {
        // PCSS (docs/math.md, "Soft shadows"): the source's size in the map's terms, lambda (a
        // directional light: tan of its angular radius; a point or spot: its radius, over the
        // blocker's depth for the penumbra and over the near plane's for the search), gives the
        // blocker search's radius in texels, then the penumbra's from the blockers' mean depth.
        const float zR = zq;
        const float size = L.type == sg::LightType::Directional ? L.tanAngularRadius : L.radius;
        auto reach = [&](float zB) {   // the penumbra's radius in texels for a blocker at depth zB
            const float world = v.perspective ? size * (zR - zB) / std::max(zB, 1e-6f) : size * (zR - zB);
            return world / t;
        };
        const float kf = float(k);
        // The taps' grid shifted inside its cells by a hash of p's texel: a thin caster between
        // taps turns into noise instead of streaks.
        const float jx = pcssJitter(int(std::floor(su)), int(std::floor(sv)), vi, 0),
                    jy = pcssJitter(int(std::floor(su)), int(std::floor(sv)), vi, 1);
        const float rs = std::clamp(reach(v.nearZ), 0.5f * kf, float(kPcssMaxRadius));
        float blockers = 0.0f, depthSum = 0.0f;
        for (int b = 0; b < kPcssSearch * kPcssSearch; ++b) {
            const float ox = ((float(b % kPcssSearch) + jx) / float(kPcssSearch) * 2.0f - 1.0f) * rs;
            const float oy = ((float(b / kPcssSearch) + jy) / float(kPcssSearch) * 2.0f - 1.0f) * rs;
            const int i = int(std::floor(su + ox)), j = int(std::floor(sv + oy));
            const float d = stored(i, j);
            if (d < receiver(i, j)) {
                blockers += 1.0f;
                depthSum += d;
            }
        }
        if (blockers == 0.0f) return 1.0f;
        const float zB = v.linearDepth(depthSum / blockers);
        const float rf = std::clamp(reach(zB), 0.5f * kf, float(kPcssMaxRadius));
        int lit = 0;
        for (int b = 0; b < k * k; ++b) {
            const float ox = ((float(b % k) + jx) / kf * 2.0f - 1.0f) * rf, oy = ((float(b / k) + jy) / kf * 2.0f - 1.0f) * rf;
            const int i = int(std::floor(su + ox)), j = int(std::floor(sv + oy));
            lit += receiver(i, j) <= stored(i, j) ? 1 : 0;
        }
        return float(lit) / float(k * k);
    }
    const int i0 = int(std::floor(su - 0.5f * float(k) + 0.5f)), j0 = int(std::floor(sv - 0.5f * float(k) + 0.5f));
    int lit = 0;
    for (int j = j0; j < j0 + k; ++j)
        for (int i = i0; i < i0 + k; ++i) lit += receiver(i, j) <= stored(i, j) ? 1 : 0;
    return float(lit) / float(k * k);
}

bool sameShadowView(const ShadowView& a, const ShadowView& b) {
    return std::memcmp(&a.view, &b.view, sizeof(a.view)) == 0 && std::memcmp(&a.viewProj, &b.viewProj, sizeof(a.viewProj)) == 0 &&
           a.perspective == b.perspective && std::memcmp(&a.nearZ, &b.nearZ, sizeof(float)) == 0 && std::memcmp(&a.farZ, &b.farZ, sizeof(float)) == 0;
}

}   // namespace rnd
