// raster_shading.h - the rasterizer's batched (SoA, SSE2) evaluation of rnd::shade() for many
// fragments at once. It is the same formula as renderers/common/shading.cpp (Phong or
// Blinn-Phong, specular times max(n.l, 0), 1/d^2 attenuation, smoothstep spot cones, ambient
// and emissive) computed 4 fragments per instruction, with pow(s, m) as exp2(m log2 s) from
// polynomials (relative error < 1e-5). tests/raster checks it against rnd::shade.
#pragma once

#include "scenegraph/frame.h"

#include <cstddef>
#include <vector>

namespace rnd::raster {

// Structure of arrays for n fragments (n padded to a multiple of 4 by resize()).
struct ShadeBatch {
    // inputs
    std::vector<float> px, py, pz;      // world position
    std::vector<float> nx, ny, nz;      // unit normal facing the viewer
    std::vector<float> ar, ag, ab;      // albedo (kd term multiplies it)
    std::vector<float> sr, sg, sb;      // specular colour (albedo when tinted)
    std::vector<float> kd, ks, shin;    // coefficients; kd = ks = 0 for unlit
    // in: ambient + emissive (ka * albedo * L_ambient + emissive); out: the shaded colour
    std::vector<float> cr, cg, cb;
    size_t size = 0;

    void resize(size_t n);
    // Fills fragment i from a material, position, normal, albedo (as rnd::shade sees them).
    void set(size_t i, const sg::Material& m, const sg::vec3& p, const sg::vec3& n, const sg::vec3& albedo, const sg::vec3& ambient);
};

// Adds the contribution of every light in f to cr/cg/cb for fragments [0, n).
void shadeBatch(ShadeBatch& b, size_t n, const sg::FrameInput& f);

}  // namespace rnd::raster
