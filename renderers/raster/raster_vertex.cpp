// raster_vertex.cpp - step 2 of the CPU rasterizer's frame (raster_frame.h): the vertex stage.
// Per vertex of a draw (per corner for Gouraud with per-triangle materials), in parallel:
// object -> world -> eye -> clip, the clip outcode and, inside the guard band, window
// coordinates; the world normal and tangent; Gouraud: the lighting terms of the front and the
// back side (with shadow maps, the shadowed lights' terms apart from the others' sum).
#include "raster/raster_frame.h"

#include "renderers/shading.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace rnd::raster {

using sg::mat3;
using sg::mat4;
using sg::vec3;
using sg::vec4;

void runVertexStage(DrawItem& d, const sg::FrameInput& f, int width, int height, bool gouraud, const EnvironmentLight* env,
                    const std::vector<int>& shadowed) {
    const sg::Mesh& m = *d.mesh;
    size_t n = d.perCorner ? m.indices.size() : m.positions.size();
    d.clip.resize(n);
    d.code.resize(n);
    d.win.resize(n);
    d.wv.resize(n);
    const bool fog = f.settings.fog != sg::FogMode::Off;
    d.wtan.resize(d.hasTangents ? n : 0);
    const float handedness = d.mirrored ? -1.0f : 1.0f;   // a mirroring transform flips cross(n, t)
    const size_t ns = gouraud ? shadowed.size() : 0;      // lights kept apart per vertex
    if (gouraud)
        for (int s = 0; s < 2; ++s) {
            d.gouraudA[s].resize(n);
            d.gouraudB[s].resize(n);
            d.shadowedA[s].resize(n * ns);
            d.shadowedB[s].resize(n * ns);
        }
    const mat4 viewProj = f.camera.proj * f.camera.view;
    const GuardBand g = guardBand(width, height);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
        // Shadowed Gouraud: shadeTerms' visibility, 0 for the lights kept apart (their sum leaves them out).
        std::vector<float> apart;
        if (ns) {
            apart.assign(f.lights.size(), 1.0f);
            for (int l : shadowed) apart[size_t(l)] = 0.0f;
        }
        for (size_t v = r.begin(); v != r.end(); ++v) {
            uint32_t mi = d.meshIndex(uint32_t(v));
            DrawItem::VertexOut& o = d.wv[v];
            if (mi >= m.positions.size()) {   // zeros, as in a new buffer
                d.code[v] = kClipNear;
                d.clip[v] = vec4(0.0f);
                o = DrawItem::VertexOut{};
                if (d.hasTangents) d.wtan[v] = vec4(0.0f);
                if (gouraud)
                    for (int s = 0; s < 2; ++s) {
                        d.gouraudA[s][v] = d.gouraudB[s][v] = vec3(0.0f);
                        for (size_t j = 0; j < ns; ++j) d.shadowedA[s][v * ns + j] = d.shadowedB[s][v * ns + j] = vec3(0.0f);
                    }
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
                // pbr: with the vertex's albedo (base colour x vertex colour; F0 of metals needs it).
                const ShadeExtras x{d.hasColors ? mat.baseColor * vec3(m.colors[mi]) : mat.baseColor, env};
                if (ns == 0) {
                    ShadeTerms front = shadeTerms(mat, o.pos, o.nrm, f.camera.eye, f, nullptr, x);
                    ShadeTerms back = shadeTerms(mat, o.pos, -o.nrm, f.camera.eye, f, nullptr, x);
                    d.gouraudA[0][v] = front.mul;
                    d.gouraudB[0][v] = front.add;
                    d.gouraudA[1][v] = back.mul;
                    d.gouraudB[1][v] = back.add;
                    continue;
                }
                // With shadow maps: the other lights summed, each shadowed light's terms apart (the
                // fragments scale them by their visibility).
                const SurfaceCoefficients c = coefficientsOf(mat);
                for (int s = 0; s < 2; ++s) {
                    const vec3 nrm = s == 0 ? o.nrm : -o.nrm;
                    const ShadeTerms sum = shadeTerms(c, o.pos, nrm, f.camera.eye, f, apart.data(), x);
                    d.gouraudA[s][v] = sum.mul;
                    d.gouraudB[s][v] = sum.add;
                    for (size_t j = 0; j < ns; ++j) {
                        const ShadeTerms lt = lightShareTerms(c, o.pos, nrm, f.camera.eye, f, size_t(shadowed[j]), x);
                        d.shadowedA[s][v * ns + j] = lt.mul;
                        d.shadowedB[s][v * ns + j] = lt.add;
                    }
                }
            }
        }
    });
}

}   // namespace rnd::raster
