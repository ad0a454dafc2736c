// pbr.h - glTF 2.0's physically based BRDF (specification, Appendix B) with KHR_materials_ior,
// KHR_materials_specular and KHR_materials_pbrSpecularGlossiness, the punctual lights of
// KHR_lights_punctual and the environment light; one source for the CPU rasterizer and the ray
// caster, mirrored name for name by renderers/gl/shaders/pbr.glsl. docs/math.md, "PBR":
//
//   c_diff = mix(rho, 0, metallic)           F0  = mix(F0_dielectric, rho, metallic)
//   alpha  = roughness^2                     F90 = mix(F90_dielectric, 1, metallic)
//   F = F0 + (F90 - F0) (1 - |v.h|)^5
//   D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)
//   V = 0.5 / (n.l sqrt((n.v)^2 (1 - alpha^2) + alpha^2) + n.v sqrt((n.l)^2 (1 - alpha^2) + alpha^2))
//   f = (1 - F) c_diff / pi + F D V (1 + F0 (1/E(n.v) - 1))      (the last factor: energy kept, below)
//   L_out = sum_i f L_i (n.l_i)   with L_i the light's intensity at the point (lux, or candela / d^2)
//
// Specular-glossiness: c_diff = rho (1 - max(F0)), F0 = specular, F90 = 1, roughness = 1 - glossiness.
// The environment (split sum, Karis 2013; multiple scattering, Fdez-Aguera 2019):
//   (A, B) = splitSum(n.v, roughness),  E = A + B,  FssEss = F0 A + F90 B
//   F_avg = F0 + (1 - F0)/21,  FmsEms = (1 - E) FssEss F_avg / (1 - (1 - E) F_avg)
//   L_env = ao [ (1 - FssEss - FmsEms) c_diff I(n) + FssEss R(r, roughness) + FmsEms I(n) ]
// with I the diffuse (E(n)/pi) and R the prefiltered specular lookup of the environment.
// A white surface of any roughness, metal or not, in a constant environment of radiance 1 then
// reflects 1 (the white furnace).
//
// As for Phong the result is split into terms that the albedo rho multiplies and terms it does
// not (ShadeTerms: colour = rho mul + add) so Gouraud shading can interpolate them; with pbr they
// depend on rho themselves (F0 of metals), which per-pixel shading passes exactly and Gouraud at
// the vertices.
#pragma once

#include "renderers/environment.h"
#include "renderers/shading.h"

namespace rnd {

// The split-sum table: (A, B) with  integral f_spec cos = F0 A + F90 B  for a GGX surface of this
// roughness seen at n.v (Schlick's Fresnel integrated in). 32 x 32 entries at the texel centres
// ((i + 0.5)/32 in n.v and roughness), read bilinearly with clamped edges (the GL backend uploads
// the same table as a texture). Computed once, with 1024 GGX samples per entry.
constexpr int kSplitSumSize = 32;
const std::vector<sg::vec2>& splitSumTable();   // row = roughness, column = n.v
sg::vec2 splitSum(float nv, float roughness);
// The exact integral (by importance sampling with `samples` directions), for tests.
sg::vec2 splitSumIntegral(float nv, float roughness, int samples);

// Half vector i of n for GGX importance sampling (alpha^2 = a2), in the frame where n = +z:
// stratified in the polar angle, Hammersley's radical inverse in the azimuth (Karis 2013).
sg::vec3 ggxHalfVector(int i, int n, float a2);

// The BRDF's parameters at one point, from the coefficients (the material with its maps) and rho.
struct PbrPoint {
    sg::vec3 cdiffFactor{1.0f};   // c_diff = rho * cdiffFactor
    sg::vec3 f0{0.04f};
    float f90 = 1.0f;
    float alpha = 1.0f;   // roughness^2
    float roughness = 1.0f;
};
PbrPoint pbrPoint(const SurfaceCoefficients& c, const sg::vec3& albedo);

// The light sample of KHR_lights_punctual: directional (lux) as is; point and spot (candela)
// over d^2 with the range window (clamp(1 - (d/range)^4, 0, 1))^2 when range > 0, spots by
// (clamp((cos - cos_outer) / max(cos_inner - cos_outer, 1e-3), 0, 1))^2.
LightSample samplePunctualLight(const sg::DrawLight& light, const sg::vec3& position);

// One light's terms: rho-linear diffuse in mul, specular in add.
ShadeTerms pbrLightTerms(const PbrPoint& p, const sg::vec3& n, const sg::vec3& toEye, const LightSample& l);
// The environment's terms, occlusion included.
ShadeTerms pbrEnvironmentTerms(const PbrPoint& p, const sg::vec3& n, const sg::vec3& toEye, const EnvironmentLight& env, float occlusion);

}   // namespace rnd
