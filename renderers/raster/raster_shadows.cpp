// raster_shadows.cpp - the CPU rasterizer's shadow maps (renderers/shadow_map.h): the depth pass
// over the vertex stage's world positions, and each fragment's visibility of each light for the
// lighting kernels (ShadeBatch::vis).
#include "raster/raster_frame.h"
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
        // Blended surfaces let light through (the ray caster: 1 - alpha); they cast nothing here.
        if (d.material.alphaMode == sg::AlphaMode::Blend || d.wv.empty() || d.triCount == 0) continue;
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
    for (size_t l = 0; l < lights.size(); ++l) {
        if (l >= plan.viewCount.size() || plan.viewCount[l] == 0) continue;
        float* out = &b.vis[l * b.visStride];
        for (size_t k = 0; k < n; ++k) {
            if (b.mat[k] < 0 && b.kd[k] == 0.0f && b.ks[k] == 0.0f) continue;   // a final colour: no lights
            const sg::vec3 p(b.px[k], b.py[k], b.pz[k]), nrm(b.nx[k], b.ny[k], b.nz[k]);
            // Where the light adds nothing (facing away, outside a spot's cone) its visibility
            // changes nothing: no lookup (as the ray caster traces no shadow ray there).
            if (!lightReaches(lights[l], p, nrm, fc.frame->settings.reflection)) continue;
            out[k] = shadowVisibility(plan, *fc.shadowMaps, lights[l], int(l), p, nrm);
        }
    }
}

}   // namespace rnd::raster
