// raster_shading.h - the rasterizer's batched (SoA) evaluation of rnd::shade() for many
// fragments at once. It is the same formula as renderers/common/shading.cpp (Phong or
// Blinn-Phong, specular times max(n.l, 0), 1/d^2 attenuation, smoothstep spot cones, ambient
// and emissive) computed 4 fragments per instruction with SSE2, or 8 with AVX2 where the CPU
// has it (chosen at run time; VIEWER_RASTER_SSE=1 forces SSE2; both give the same bits), with
// pow(s, m) as exp2(m log2 s) from polynomials (relative error < 1e-5). tests/renderers/raster checks it
// against rnd::shade.
//
// With the pbr reflection model the same batch carries glTF's BRDF parameters instead (setPbr,
// pbr_kernel.inl: renderers/pbr.h's pbrLightTerms and pbrEnvironmentTerms per lane, the
// environment's lookups included), in the same arrays under other names:
//   ar ag ab = c_diff (albedo x (1 - metallic), or spec-gloss's factor)
//   sr sg sb = F0          kd = F90          ks = roughness (>= 1e-3: the lane is lit)
//   shin     = occlusion   cr cg cb = emissive in, the colour out
#pragma once

#include "renderers/pbr.h"
#include "renderers/shadow_map.h"
#include "scenegraph/frame.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rnd::raster {

// Structure of arrays for n fragments (n padded to a multiple of 8 by resize()).
struct ShadeBatch {
    // inputs
    std::vector<float> px, py, pz;     // world position
    std::vector<float> nx, ny, nz;     // unit normal facing the viewer
    std::vector<float> ar, ag, ab;     // albedo (kd term multiplies it)
    std::vector<float> sr, sg, sb;     // specular colour (albedo when tinted)
    std::vector<float> kd, ks, shin;   // coefficients; kd = ks = 0 for unlit
    // in: ambient + emissive (ka * albedo * L_ambient + emissive); out: the shaded colour
    std::vector<float> cr, cg, cb;
    // Per-batch constants: fragment i with mat[i] >= 0 takes ar..shin and the input cr/cg/cb
    // from mats[mat[i]] (the arrays above are not filled for it); mat[i] = -1: from the arrays.
    // A plain-material fragment then writes 7 values instead of 18 (position, normal, index).
    struct Constants {
        float ar, ag, ab, sr, sg, sb, kd, ks, shin, cr, cg, cb;
    };
    std::vector<int32_t> mat;
    std::vector<Constants> mats;
    size_t size = 0;
    // Shadows: the fraction of light l reaching fragment i is vis[l * visStride + i] (the
    // kernels scale the light's radiance by it); no shadows when visLights is 0.
    std::vector<float> vis;
    size_t visStride = 0, visLights = 0;
    // Sets visLights and visStride for the current size, every entry 1 (lit).
    void resetVisibility(size_t lights) {
        visLights = lights;
        visStride = lights ? ((size + 7) & ~size_t(7)) + kSlack : 0;
        vis.assign(visStride * lights, 1.0f);
    }

    // Sets n fragments and empties mats. The arrays hold n rounded up to 8 (the padding lanes set
    // to harmless values, mat = -1) plus kSlack values that a vector store may write past the end.
    static constexpr size_t kSlack = 8;
    void resize(size_t n);   // also drops the shadow visibility (resetVisibility)
    // Sets the padding lanes again (after stores that ran past `size`).
    void pad();
    // Adds a constant block (albedo, specular colour, kd, ks, shininess, ambient + emissive; or
    // pbrConstants).
    int32_t addConstants(const Constants& c) {
        mats.push_back(c);
        return int32_t(mats.size() - 1);
    }
    // Copies fragment i's constant block (mat[i] >= 0) into the per-fragment arrays.
    void expand(size_t i) { store(i, mats[size_t(mat[i])]); }
    // Writes a constant block's values into fragment i's arrays.
    void store(size_t i, const Constants& c) {
        ar[i] = c.ar;
        ag[i] = c.ag;
        ab[i] = c.ab;
        sr[i] = c.sr;
        sg[i] = c.sg;
        sb[i] = c.sb;
        kd[i] = c.kd;
        ks[i] = c.ks;
        shin[i] = c.shin;
        cr[i] = c.cr;
        cg[i] = c.cg;
        cb[i] = c.cb;
    }
    // Fills fragment i from a material's coefficients (rnd::SurfaceCoefficients, or an
    // sg::Material: the same field names), position, normal, albedo (as rnd::shade sees them).
    template <class Coefficients>
    void set(size_t i, const Coefficients& m, const sg::vec3& p, const sg::vec3& n, const sg::vec3& albedo, const sg::vec3& ambient) {
        px[i] = p.x;
        py[i] = p.y;
        pz[i] = p.z;
        nx[i] = n.x;
        ny[i] = n.y;
        nz[i] = n.z;
        ar[i] = albedo.x;
        ag[i] = albedo.y;
        ab[i] = albedo.z;
        mat[i] = -1;
        if (m.unlit) {   // shade(): albedo + emissive, no lights
            setColor(i, albedo + m.emissive);
            return;
        }
        sg::vec3 s = m.specularTinted ? albedo : m.specularColor;
        sr[i] = s.x;
        sg[i] = s.y;
        sb[i] = s.z;
        kd[i] = m.kd;
        ks[i] = m.ks;
        shin[i] = m.shininess;
        sg::vec3 c = m.ka * albedo * ambient + m.emissive;
        cr[i] = c.x;
        cg[i] = c.y;
        cb[i] = c.z;
    }
    // A pbr fragment (the layout above): the BRDF's parameters at the point, its occlusion and emission.
    void setPbr(size_t i, const sg::vec3& p, const sg::vec3& n, const PbrPoint& q, const sg::vec3& albedo, float occlusion,
                const sg::vec3& emissive) {
        px[i] = p.x;
        py[i] = p.y;
        pz[i] = p.z;
        nx[i] = n.x;
        ny[i] = n.y;
        nz[i] = n.z;
        mat[i] = -1;
        store(i, pbrConstants(q, albedo, occlusion, emissive));
    }
    static Constants pbrConstants(const PbrPoint& q, const sg::vec3& albedo, float occlusion, const sg::vec3& emissive) {
        const sg::vec3 cdiff = albedo * q.cdiffFactor;
        return {cdiff.x, cdiff.y, cdiff.z, q.f0.x, q.f0.y, q.f0.z, q.f90, q.roughness, occlusion, emissive.x, emissive.y, emissive.z};
    }
    // A fragment whose colour is already final (unlit, Gouraud, reference shading).
    void setColor(size_t i, const sg::vec3& c) {
        px[i] = py[i] = pz[i] = 0;
        nx[i] = nz[i] = 0;
        ny[i] = 1;
        ar[i] = ag[i] = ab[i] = sr[i] = sg[i] = sb[i] = 0;
        kd[i] = ks[i] = 0;
        shin[i] = 1;
        mat[i] = -1;
        cr[i] = c.x;
        cg[i] = c.y;
        cb[i] = c.z;
    }
};

// rnd::shadowVisibility for fragments [i, i + shadowLookupWidth()) of b, all reading map `v`
// of the plan (lightVec: the light's direction, or its position when positional), into out[i...]
// (shadow_kernel.inl). Width 0: no vector kernel here (the caller uses the scalar function).
size_t shadowLookupWidth();
void shadowLookupVector(const ShadowPlan& plan, const ShadowView& v, const float* map, const sg::vec3& lightVec, bool positional, const ShadeBatch& b,
                        size_t i, float* out);

// Adds the contribution of every light in f to cr/cg/cb for fragments [0, n); with the pbr
// reflection model also the environment's (env: none when null or without a map).
void shadeBatch(ShadeBatch& b, size_t n, const sg::FrameInput& f, const EnvironmentLight* env = nullptr);

}   // namespace rnd::raster
