// draw_list.cpp - prepareDraws(): meshes + tessellated analytic shapes as one draw list.
#include "renderers/draw_list.h"

#include <algorithm>

namespace rnd {

std::vector<PreparedDraw> prepareMeshDraws(const sg::FrameInput& frame) {
    std::vector<PreparedDraw> draws;
    draws.reserve(frame.meshes.size());
    for (size_t i = 0; i < frame.meshes.size(); ++i) {
        const sg::DrawMesh& d = frame.meshes[i];
        if (!d.mesh || d.mesh->positions.empty()) continue;
        PreparedDraw p;
        p.drawable = uint32_t(i + 1);
        p.mesh = d.mesh;
        p.world = &d.world;
        p.normal = d.normal;
        p.mirrored = d.mirrored;
        p.material = &d.material;
        p.texture = d.texture;
        p.maps = d.maps;
        p.node = d.node;
        draws.push_back(std::move(p));
    }
    return draws;
}

std::vector<PreparedDraw> prepareDraws(const sg::FrameInput& frame, int tessellation, TessellationCache& cache, RenderControl* control) {
    static const sg::mat4 kIdentity(1.0f);
    std::vector<PreparedDraw> draws = prepareMeshDraws(frame);
    draws.reserve(frame.meshes.size() + frame.analytics.size());
    // The shapes' work still to do: the Shapes stage of the render's progress.
    double total = 0, done = 0;
    float shown = 0;   // the progress reported last (it only increases)
    if (control)
        for (const sg::DrawAnalytic& a : frame.analytics)
            if (!cache.contains(a, tessellation)) total += tessellationWork(a, tessellation);
    if (total > 0) {
        control->progress = 0.0f;
        control->stage = RenderStage::Shapes;
    }
    for (size_t j = 0; j < frame.analytics.size(); ++j) {
        const sg::DrawAnalytic& a = frame.analytics[j];
        const Tessellation* tess = nullptr;
        if (total > 0 && !cache.contains(a, tessellation)) {
            const double work = tessellationWork(a, tessellation);
            TessellationProgress progress;
            progress.cancel = &control->cancel;
            progress.report = [&](float share) {
                const float p = float(std::min(1.0, (done + share * work) / total));
                if (p > shown) control->progress = shown = p;
            };
            tess = &cache.get(a, tessellation, &progress);
            done += work;
            if (control->cancel) break;   // incomplete: the caller gives up
        } else {
            tess = &cache.get(a, tessellation);
        }
        const Tessellation& t = *tess;
        if (!t.mesh || t.mesh->positions.empty()) continue;
        const bool perTriangle = !t.triangleMaterial.empty() && !t.materials.empty();
        PreparedDraw p;
        p.mesh = t.mesh;
        p.world = t.worldSpace ? &kIdentity : &a.world;
        p.normal = t.worldSpace ? sg::mat3(1.0f) : a.normal;
        p.mirrored = !t.worldSpace && glm::determinant(sg::mat3(a.world)) < 0.0f;
        p.material = &a.material;
        p.texture = perTriangle ? nullptr : a.texture;
        p.triangleMaterial = perTriangle ? &t.triangleMaterial : nullptr;
        p.materials = perTriangle ? &t.materials : nullptr;
        p.node = a.node;
        p.analytic = true;
        p.drawable = uint32_t(frame.meshes.size() + j + 1);
        draws.push_back(std::move(p));
    }
    if (total > 0) {
        control->stage = RenderStage::Image;
        control->progress = 0.0f;
    }
    return draws;
}

}   // namespace rnd
