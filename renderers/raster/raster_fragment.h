// raster_fragment.h - the attributes of the CPU rasterizer's fragments (private to
// renderers/raster/), shared by the tile stage (alpha of masked surfaces), the opaque shading
// and the blended surfaces: the per-triangle cache a run of fragments reads (TriCache),
// perspective-correct barycentrics at a pixel centre, texture coordinates with their screen
// derivatives, the fragment's alpha, and prepareFragment (raster_fragment.cpp), which fills one
// slot of a ShadeBatch. The plain-material fast path is prepareSimple (raster_shade.cpp) and its
// vector form preparePlainRun (tile_kernels.h).
#pragma once

#include "raster/raster_frame.h"

namespace rnd::raster {

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
    // Flat shading: the model evaluated once per triangle, at its first vertex with the face
    // normal (faceTerms); the albedo (texture, vertex colours) still applies per pixel.
    bool flat = false;
    ShadeTerms faceTerms;
    // With shadow maps (FrameContext::mappedLights): flat's faceTerms leave out the lights with
    // maps, whose own terms at the first vertex are here (those that reach it), and Gouraud's
    // draw keeps its shadowed lights apart (DrawItem::shadowedA/B); the fragments scale them by
    // their visibility, looked up with the face normal ng.
    std::vector<std::pair<int, ShadeTerms>> faceLights;
    bool gouraudShadowed = false;
    sg::vec3 ng{0.0f};
    // Plain lit fragment (no vertex colours, textures or maps, not Gouraud, not reference
    // shading): prepareFragment takes the short path with the material's constant block below.
    bool simple = false;
    SurfaceCoefficients coeff;
    ShadeBatch::Constants block{};   // what ShadeBatch::set (or setPbr) would store (simple)
    // slot: the material's ShadeBatch constant block (simple; -1: not added yet)

    // The unit shading normal at barycentrics bo: the face normal (flat, or a mesh without
    // normals), else the vertex normals mixed and normalised (+z where they cancel).
    __attribute__((always_inline)) sg::vec3 normalAt(const sg::vec3& bo) const {
        if (faceNormal) return n[0];
        const sg::vec3 m = bo[0] * n[0] + bo[1] * n[1] + bo[2] * n[2];
        const float len = glm::length(m);
        return len > 0 ? m / len : sg::vec3(0, 0, 1);
    }

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
            gouraudShadowed = gouraud && !fc.gouraudShadowed.empty() && !d->shadowedA[0].empty();
            faceNormal = f.settings.shading == sg::ShadingModel::Flat || !d->hasNormals;
            flat = f.settings.shading == sg::ShadingModel::Flat && !mat->unlit;
            simple = !gouraud && !flat && !fc.referenceShading && !d->hasColors && !(d->texture && d->hasUV) && !(d->hasUV && d->hasMaps());
            if (simple) {
                coeff = coefficientsOf(*mat);
                simple = !coeff.unlit;
                const sg::vec3 albedo = mat->baseColor;   // ShadeBatch::set() or setPbr() with this albedo
                if (fc.pbr) {
                    block = ShadeBatch::pbrConstants(pbrPoint(coeff, albedo), albedo, coeff.occlusion, coeff.emissive);
                } else {
                    const sg::vec3 spec = coeff.specularTinted ? albedo : coeff.specularColor;
                    const sg::vec3 base = coeff.ka * albedo * f.ambientLight + coeff.emissive;
                    block = {albedo.x, albedo.y, albedo.z, spec.x, spec.y, spec.z, coeff.kd, coeff.ks, coeff.shininess, base.x, base.y, base.z};
                }
            }
        }
        cb = tri.clip >= 0 ? &ch.clipBary[size_t(tri.clip)] : nullptr;
        pl = &tri.pl;
        minX = tri.s.minX;
        minY = tri.s.minY;
        swapped = tri.order[1] != 1;   // setupTriangle's two orders: {0, 1, 2} or {0, 2, 1}
        sg::vec3 nv[3];
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
            sg::vec3 nn = glm::cross(p[1] - p[0], p[2] - p[0]);
            if (d->mirrored != !tri.front) nn = -nn;
            float len = glm::length(nn);
            n[0] = len > 0 ? nn / len : sg::vec3(0, 0, 1);
        } else {
            for (int k = 0; k < 3; ++k) n[k] = tri.front ? nv[k] : -nv[k];
        }
        if (flat) {   // the first vertex: GL's provoking vertex (glProvokingVertex(GL_FIRST_VERTEX_CONVENTION))
            const sg::vec3 albedo0 = d->hasColors ? mat->baseColor * sg::vec3(d->mesh->colors[d->meshIndex(v[0])]) : mat->baseColor;
            if (fc.mappedLights.empty())
                faceTerms = shadeTerms(*mat, p[0], n[0], f.camera.eye, f, nullptr, {albedo0, fc.environment});
            else
                loadFlatShadowed(fc, albedo0);
        }
        if (gouraudShadowed) {   // the face normal, either side (the lookup turns it toward the light)
            const sg::vec3 nn = glm::cross(p[1] - p[0], p[2] - p[0]);
            const float len = glm::length(nn);
            ng = len > 0 ? nn / len : sg::vec3(0, 0, 1);
        }
    }

    // Flat shading with shadow maps: faceTerms without the lights with maps, and their own terms.
    void loadFlatShadowed(const FrameContext& fc, const sg::vec3& albedo0) {
        const sg::FrameInput& f = *fc.frame;
        const SurfaceCoefficients c = coefficientsOf(*mat);
        const ShadeExtras x{albedo0, fc.environment};
        faceTerms = shadeTerms(c, p[0], n[0], f.camera.eye, f, fc.unmapped.data(), x);
        faceLights.clear();
        for (int l : fc.mappedLights) {
            const ShadeTerms t = lightShareTerms(c, p[0], n[0], f.camera.eye, f, size_t(l), x);
            if (t.mul != sg::vec3(0.0f) || t.add != sg::vec3(0.0f)) faceLights.emplace_back(l, t);
        }
        ng = n[0];
    }
};

// Perspective-correct barycentrics at the centre of pixel (i, j): b for the setup vertices,
// bo for the input triangle's corners; invSum = 1 / sum(lambda_k / w_k).
struct FragBary {
    float b[3];
    sg::vec3 bo;
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
    const std::array<sg::vec3, 3>* cb = tc.cb;
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
inline void uvAt(const TriCache& tc, const FragBary& fb, const uint32_t mi[3], int i, int j, const std::vector<sg::vec2>& set, sg::vec2& uv,
                 sg::vec2& ddx, sg::vec2& ddy) {
    const Tri& t = *tc.t;
    const std::array<sg::vec3, 3>* cb = tc.cb;
    sg::vec2 uvc[3] = {set[mi[0]], set[mi[1]], set[mi[2]]};
    sg::vec2 uvk[3];   // uv at the setup vertices
    for (int q = 0; q < 3; ++q) {
        sg::vec3 w = cb ? (*cb)[q] : sg::vec3(t.order[q] == 0, t.order[q] == 1, t.order[q] == 2);
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
    const sg::vec2 base = (i0 == i && j0 == j) ? uv : uvAtPixel(i0, j0);
    ddx = uvAtPixel(i0 + 1, j0) - base;
    ddy = uvAtPixel(i0, j0 + 1) - base;
}

// Alpha of the fragment at the centre of pixel (i, j): material alpha x vertex colour alpha x
// texture alpha (filtered like the colour), as GL's fragment shader computes it.
inline float fragmentAlpha(const TriCache& tc, int i, int j) {
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
        sg::vec2 uv, ddx, ddy;
        uvAt(tc, fb, mi, i, j, d.mesh->uv0, uv, ddx, ddy);
        a *= d.texture->sampleAlpha(uv, ddx, ddy);
    }
    return a;
}

// Interpolates the attributes of the cached triangle at the centre of pixel (i, j) and fills
// slot k of the shading batch (Gouraud: the final colour, with no lights left to add). Returns
// the eye-space distance for fog. (raster_fragment.cpp)
float prepareFragment(const TriCache& tc, const FrameContext& fc, int i, int j, ShadeBatch& sb, size_t k);

}   // namespace rnd::raster
