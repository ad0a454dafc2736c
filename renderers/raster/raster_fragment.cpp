// raster_fragment.cpp - prepareFragment (raster_fragment.h): the general path of the CPU
// rasterizer's fragment preparation, for everything the plain-material kernel does not take
// (vertex colours, textures, material maps, Gouraud, reference shading) and for blended
// surfaces. Interpolates the attributes at the pixel centre and fills one ShadeBatch slot.
#include "raster/raster_fragment.h"

#include "renderers/shading.h"

namespace rnd::raster {

using sg::vec3;
using sg::vec4;

namespace {

// Gouraud with shadow maps: each shadowed light's terms interpolated from the vertices on their
// own, scaled by the fragment's visibility (no lookup where the light adds nothing).
void addShadowedGouraud(const TriCache& tc, const FrameContext& fc, const vec3& bo, const vec3& pos, int side, ShadeTerms& terms) {
    const DrawItem& d = *tc.d;
    const size_t ns = fc.gouraudShadowed.size();
    const size_t v0 = tc.v[0] * ns, v1 = tc.v[1] * ns, v2 = tc.v[2] * ns;
    const std::vector<vec3>& A = d.shadowedA[side];
    const std::vector<vec3>& B = d.shadowedB[side];
    for (size_t j = 0; j < ns; ++j) {
        const vec3 mul = bo[0] * A[v0 + j] + bo[1] * A[v1 + j] + bo[2] * A[v2 + j];
        const vec3 add = bo[0] * B[v0 + j] + bo[1] * B[v1 + j] + bo[2] * B[v2 + j];
        if (mul == vec3(0.0f) && add == vec3(0.0f)) continue;
        const int l = fc.gouraudShadowed[j];
        const float vis = shadowVisibility(*fc.shadowPlan, *fc.shadowMaps, fc.frame->lights[size_t(l)], l, pos, tc.ng);
        terms.mul += vis * mul;
        terms.add += vis * add;
    }
}

}   // namespace

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

    if (tc.flat) {   // one evaluation per triangle (TriCache::faceTerms); occlusion and emission per pixel
        ShadeTerms terms = tc.faceTerms;
        for (const auto& [l, lt] : tc.faceLights) {   // the lights with maps, scaled by the fragment's visibility
            const float vis = shadowVisibility(*fc.shadowPlan, *fc.shadowMaps, f.lights[size_t(l)], l, pos, tc.ng);
            terms.mul += vis * lt.mul;
            terms.add += vis * lt.add;
        }
        if (maps) applyMapsToTerms(terms, mat, ms, f.ambientLight, f.settings.reflection);
        sb.setColor(k, terms.apply(albedo));
    } else if (tc.gouraud) {
        int side = t.front ? 0 : 1;
        ShadeTerms terms;
        terms.mul = bo[0] * d.gouraudA[side][v[0]] + bo[1] * d.gouraudA[side][v[1]] + bo[2] * d.gouraudA[side][v[2]];
        terms.add = bo[0] * d.gouraudB[side][v[0]] + bo[1] * d.gouraudB[side][v[1]] + bo[2] * d.gouraudB[side][v[2]];
        if (tc.gouraudShadowed) addShadowedGouraud(tc, fc, bo, pos, side, terms);
        if (maps) applyMapsToTerms(terms, mat, ms, f.ambientLight, f.settings.reflection);
        sb.setColor(k, terms.apply(albedo));
    } else {
        vec3 n = tc.normalAt(bo);
        if (!tc.faceNormal && ms.hasNormal && d.hasTangents) {   // the map's normal, on the outward side, then flipped back
            const vec4 tan = bo[0] * d.wtan[v[0]] + bo[1] * d.wtan[v[1]] + bo[2] * d.wtan[v[2]];
            const vec4 tw(vec3(tan), d.wtan[v[0]].w);
            n = t.front ? perturbNormal(n, tw, ms.normalTexel, mat.normalScale) : -perturbNormal(-n, tw, ms.normalTexel, mat.normalScale);
        }
        const SurfaceCoefficients coeff = maps ? coefficientsAt(mat, ms) : coefficientsOf(mat);
        if (fc.referenceShading)
            sb.setColor(k, shade(coeff, SurfacePoint{pos, n, albedo}, f.camera.eye, f, nullptr, fc.environment));   // rnd::shade itself
        else if (fc.pbr && coeff.unlit)
            sb.setColor(k, albedo + coeff.emissive);
        else if (fc.pbr)
            sb.setPbr(k, pos, n, pbrPoint(coeff, albedo), albedo, coeff.occlusion, coeff.emissive);
        else
            sb.set(k, coeff, pos, n, albedo, f.ambientLight);
    }
    if (f.settings.fog == sg::FogMode::Off) return 0.0f;
    return glm::length(bo[0] * tc.pe[0] + bo[1] * tc.pe[1] + bo[2] * tc.pe[2]);   // eye-space distance
}

}   // namespace rnd::raster
