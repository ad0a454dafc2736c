// raster_shadows.cpp - the CPU rasterizer's shadow maps (renderers/shadow_map.h): the depth pass
// over the vertex stage's world positions, and each fragment's visibility of each light for the
// lighting kernels (ShadeBatch::vis).
#include "raster/raster_frame.h"
#include "raster/raster_shading.h"
#include "renderers/shading.h"

#include <tbb/parallel_for.h>

namespace rnd::raster {

void renderShadowMaps(const ShadowPlan& plan, const std::vector<DrawItem>& draws, ShadowMaps& maps) {
    maps.size = plan.size;
    if (plan.empty()) {
        maps.depth.clear();
        return;
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
    maps.depth.resize(texels * plan.views.size());
    for (size_t v = 0; v < plan.views.size(); ++v) renderShadowDepth(plan.views[v], plan.size, casters, maps.map(int(v)));
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
