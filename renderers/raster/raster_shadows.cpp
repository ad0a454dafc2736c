// raster_shadows.cpp - the CPU rasterizer's shadow maps (renderers/shadow_map.h): the depth pass
// over the vertex stage's world positions, and each fragment's visibility of each light for the
// lighting kernels (ShadeBatch::vis).
#include "raster/raster_frame.h"
#include "raster/raster_shading.h"
#include "renderers/shading.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cstring>

namespace rnd::raster {

namespace {

// Whether the casters are the ones src holds, bit for bit.
bool sameCasters(const std::vector<ShadowCaster>& casters, const ShadowMapsSource& src) {
    size_t vertices = 0, indices = 0;
    for (const ShadowCaster& c : casters) {
        vertices += c.vertices;
        indices += c.idx ? 3 * c.triangles : 0;
    }
    if (src.shape.size() != 3 * casters.size() || src.positions.size() != 3 * vertices || src.indices.size() != indices) return false;
    for (size_t i = 0; i < casters.size(); ++i)
        if (src.shape[3 * i] != casters[i].vertices || src.shape[3 * i + 1] != casters[i].triangles ||
            src.shape[3 * i + 2] != (casters[i].idx != nullptr))
            return false;
    std::atomic<bool> differ{false};
    size_t vBase = 0, iBase = 0;
    for (const ShadowCaster& c : casters) {   // the positions in parallel blocks
        const auto* base = static_cast<const unsigned char*>(c.positions);
        const float* copy = src.positions.data() + 3 * vBase;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, c.vertices, 16384), [&](const tbb::blocked_range<size_t>& r) {
            if (differ.load(std::memory_order_relaxed)) return;
            for (size_t v = r.begin(); v < r.end(); ++v)
                if (std::memcmp(base + v * c.stride, copy + 3 * v, 3 * sizeof(float)) != 0) {
                    differ = true;
                    return;
                }
        });
        if (differ || (c.idx && std::memcmp(c.idx, src.indices.data() + iBase, 3 * c.triangles * sizeof(uint32_t)) != 0)) return false;
        vBase += c.vertices;
        iBase += c.idx ? 3 * c.triangles : 0;
    }
    return true;
}

// src's copy of the casters.
void copyCasters(const std::vector<ShadowCaster>& casters, ShadowMapsSource& src) {
    size_t vertices = 0, indices = 0;
    for (const ShadowCaster& c : casters) {
        vertices += c.vertices;
        indices += c.idx ? 3 * c.triangles : 0;
    }
    src.shape.clear();
    src.positions.resize(3 * vertices);
    src.indices.resize(indices);
    size_t vBase = 0, iBase = 0;
    for (const ShadowCaster& c : casters) {
        src.shape.insert(src.shape.end(), {uint64_t(c.vertices), uint64_t(c.triangles), uint64_t(c.idx != nullptr)});
        const auto* base = static_cast<const unsigned char*>(c.positions);
        float* copy = src.positions.data() + 3 * vBase;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, c.vertices, 16384), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t v = r.begin(); v < r.end(); ++v) std::memcpy(copy + 3 * v, base + v * c.stride, 3 * sizeof(float));
        });
        if (c.idx) std::memcpy(src.indices.data() + iBase, c.idx, 3 * c.triangles * sizeof(uint32_t));
        vBase += c.vertices;
        iBase += c.idx ? 3 * c.triangles : 0;
    }
}

}   // namespace

int renderShadowMaps(const ShadowPlan& plan, const std::vector<DrawItem>& draws, ShadowMaps& maps, ShadowMapsSource* source) {
    maps.size = plan.size;
    if (plan.empty()) {
        maps.depth.clear();
        if (source) source->clear();
        return 0;
    }
    std::vector<ShadowCaster> casters;
    for (const DrawItem& d : draws) {
        if (!castsShadow(d.material) || d.wv.empty() || d.triCount == 0) continue;   // blended surfaces cast nothing (masked ones whole)
        ShadowCaster c;
        c.positions = &d.wv[0].pos;
        c.stride = sizeof(DrawItem::VertexOut);
        c.idx = d.perCorner ? nullptr : d.mesh->indices.data();
        c.triangles = d.triCount;
        c.vertices = d.wv.size();
        casters.push_back(c);
    }
    const size_t texels = size_t(plan.size) * size_t(plan.size);
    // A map as it is when it was drawn from this very view and these casters.
    std::vector<bool> draw(plan.views.size(), true);
    if (source) {
        const bool same = source->valid && source->size == plan.size && source->views.size() == plan.views.size() &&
                          maps.depth.size() == texels * plan.views.size() && sameCasters(casters, *source);
        int drawn = 0;
        for (size_t v = 0; v < plan.views.size(); ++v) {
            draw[v] = !(same && sameShadowView(source->views[v], plan.views[v]));
            drawn += draw[v];
        }
        if (drawn == 0) return 0;
        source->valid = false;   // (until the maps below are whole)
    }
    maps.depth.resize(texels * plan.views.size());
    int drawn = 0;
    for (size_t v = 0; v < plan.views.size(); ++v)
        if (draw[v]) {
            renderShadowDepth(plan.views[v], plan.size, casters, maps.map(int(v)));
            ++drawn;
        }
    if (source) {
        source->size = plan.size;
        source->views = plan.views;
        copyCasters(casters, *source);
        source->valid = true;
    }
    return drawn;
}

void fillShadowVisibility(const FrameContext& fc, ShadeBatch& b, size_t n) {
    if (!fc.shadowPlan || fc.shadowPlan->empty() || !fc.shadowMaps) return;
    const ShadowPlan& plan = *fc.shadowPlan;
    const auto& lights = fc.frame->lights;
    b.resetVisibility(lights.size());
    const size_t W = plan.filter == sg::ShadowFilter::Pcss ? 0 : shadowLookupWidth();   // PCSS: the scalar lookup
    for (size_t l = 0; l < lights.size(); ++l) {
        if (l >= plan.viewCount.size() || plan.viewCount[l] == 0) continue;
        const sg::DrawLight& L = lights[l];
        float* out = &b.vis[l * b.visStride];
        // One fragment the scalar way: where the light adds nothing (facing away, outside a
        // spot's cone) its visibility changes nothing, and no lookup is made (as the ray caster
        // traces no shadow ray there).
        auto scalar = [&](size_t k) {
            if (b.mat[k] < 0 && b.kd[k] == 0.0f && b.ks[k] == 0.0f) return;   // a final colour: no lights
            const sg::vec3 p(b.px[k], b.py[k], b.pz[k]), nrm(b.nx[k], b.ny[k], b.nz[k]);
            if (!lightReaches(L, p, nrm, fc.frame->settings.reflection)) return;
            out[k] = shadowVisibility(plan, *fc.shadowMaps, L, int(l), p, nrm);
        };
        const int first = plan.firstView[l];
        const bool point = L.type == sg::LightType::Point;
        const sg::vec3 lightVec = L.type == sg::LightType::Directional ? L.direction : L.position;
        size_t k = 0;
        if (W)   // a vector of fragments at a time where they read one map (the batch is padded to 8)
            for (; k + W <= ((n + W - 1) / W) * W; k += W) {
                int face = 0;
                bool same = true;
                if (point) {
                    face = pointLightFace(sg::vec3(b.px[k], b.py[k], b.pz[k]) - L.position);
                    for (size_t q = 1; q < W && same; ++q)
                        same = pointLightFace(sg::vec3(b.px[k + q], b.py[k + q], b.pz[k + q]) - L.position) == face;
                }
                if (!same) {
                    for (size_t q = k; q < std::min(n, k + W); ++q) scalar(q);
                    continue;
                }
                shadowLookupVector(plan, plan.views[size_t(first + face)], fc.shadowMaps->map(first + face), lightVec,
                                   L.type != sg::LightType::Directional, b, k, out);
            }
        for (; k < n; ++k) scalar(k);
    }
}

}   // namespace rnd::raster
