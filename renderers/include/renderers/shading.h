// shading.h - the one Phong evaluation shared by the CPU rasterizer and the ray caster (the
// GL shaders mirror it line by line; tests hold the three to each other).
//
// docs/math.md, illumination (with m = shininess):
//   L_cam = ka * rho (x) L_ambient
//         + sum_i  att_i * L_i * max(n.l_i, 0) (x) (kd * rho + ks * rho_spec * max(r_i.v, 0)^m)
// Phong:  r_i = 2 (n.l_i) n - l_i ;  Blinn-Phong: (r_i.v) replaced by (n.h_i), h = (l+v)/|l+v|.
// att_i = 1/d^2 for inverse-square lights, times the spot cone factor; plus emissive. Fog
// then blends toward the fog colour: L = f(d) L_cam + (1 - f(d)) C_fog. Colours are linear;
// the framebuffer stores sRGB (encodeSRGB), as GL does with an sRGB framebuffer.
#pragma once

#include "scenegraph/frame.h"

#include <memory>

#include <cstdint>

namespace rnd {

struct EnvironmentLight;   // renderers/environment.h

struct SurfacePoint {
    sg::vec3 position;   // world
    sg::vec3 normal;     // world, unit, facing the viewer for two-sided surfaces
    sg::vec3 albedo;     // rho: base colour (x) texture (x) vertex colour
};

// Direction from surface toward the light (unit), the light's radiance reaching the point
// (attenuation and spot cone applied) and the distance to the light (infinity for directional).
struct LightSample {
    sg::vec3 toLight;
    sg::vec3 radiance;
    float distance;
};
LightSample sampleLight(const sg::DrawLight& light, const sg::vec3& position);

// The model is linear in the albedo rho, so it is computed as two terms that do not depend on
// it: colour = rho (x) mul + add, with
//   mul = ka L_ambient + sum_i att_i L_i max(n.l_i,0) (kd + [tinted] ks spec_i)
//   add = emissive     + sum_i att_i L_i max(n.l_i,0) [untinted] ks spec_i specularColor
// Every shading model uses these: Phong and flat evaluate them per pixel; Gouraud evaluates
// them at the vertices and interpolates mul and add, so textures and vertex colours (rho)
// still apply per pixel. The GL shaders mirror these functions name for name
// (renderers/gl/shaders/lighting.glsl: sampleLight, lightTerms, shadeTerms).
struct ShadeTerms {
    sg::vec3 mul{0.0f};
    sg::vec3 add{0.0f};
    sg::vec3 apply(const sg::vec3& albedo) const { return albedo * mul + add; }
};

// The coefficients the reflection models use at one surface point: the material's, changed per
// texel by its occlusion, emissive and metallic-roughness textures (docs/math.md, "Material
// textures"). Field names as in sg::Material. Phong and Blinn-Phong read ka ... specularColor;
// pbr reads metallic ... occlusion (renderers/pbr.h).
struct SurfaceCoefficients {
    float ka = 0.2f, kd = 0.8f, ks = 0.3f, shininess = 32.0f;
    bool specularTinted = false;
    bool unlit = false;
    sg::vec3 specularColor{1.0f};
    sg::vec3 emissive{0.0f};
    // pbr: metallic-roughness with the dielectric's F0/F90 (KHR_materials_ior, _specular), or
    // specular-glossiness (specularF0 and roughness = 1 - glossiness); occlusion scales the
    // environment light.
    float metallic = 0.0f, roughness = 1.0f;
    sg::vec3 f0Dielectric{0.04f};
    float f90Dielectric = 1.0f;
    bool specularGlossiness = false;
    sg::vec3 specularF0{0.04f};
    float occlusion = 1.0f;
};
SurfaceCoefficients coefficientsOf(const sg::Material& m);

// What a material's maps hold at one point, linear: occlusion (R), emissive colour (RGB),
// roughness (G) and metallic (B); a missing map leaves its neutral value.
struct MapSample {
    float occlusion = 1.0f;
    sg::vec3 emissive{1.0f};
    bool hasMetallicRoughness = false;
    float roughness = 1.0f, metallic = 1.0f;
    sg::vec4 pbrTexel{1.0f};   // the parameter texture's RGBA (specular-glossiness: RGB linear-decoded, A glossiness)
    bool hasNormal = false;
    sg::vec3 normalTexel{0.5f, 0.5f, 1.0f};   // RGB as stored (0.5 n + 0.5)
};
// A texture coordinate and its screen-space derivatives (the change over one pixel in x and y;
// zero derivatives sample the finest level).
struct UvFootprint {
    sg::vec2 uv{0.0f}, ddx{0.0f}, ddy{0.0f};
};
// A draw's material maps (null = absent) and the UV set each samples.
class SampledTexture;
struct MapSamplers {
    const SampledTexture *emissive = nullptr, *occlusion = nullptr, *metallicRoughness = nullptr, *normal = nullptr;
    uint8_t uv1 = 0;   // sg::Material::MapBit set: that map reads the second UV set (uvs[1] below)
    bool any() const { return emissive || occlusion || metallicRoughness || normal; }
};
// Samples the maps, each at uvs[0] (Mesh::uv0) or uvs[1] (Mesh::uv1) as `maps.uv1` says.
MapSample sampleMaps(const MapSamplers& maps, const UvFootprint uvs[2]);
// The normal map's normal at a point (glTF 3.9.3): with the unit interpolated normal n (world,
// the surface's outward side), tangent t (world xyz, w = handedness) and the texel c,
//   m = 2c - 1, m.xy *= scale;  T = normalize(t - n (n.t));  B = w cross(n, T)
//   n' = normalize(m.x T + m.y B + m.z n)
// (n when the frame degenerates). Used by Phong shading; flat and Gouraud keep their normals.
sg::vec3 perturbNormal(const sg::vec3& n, const sg::vec4& t, const sg::vec3& texel, float scale);
// The coefficients at a point with these map samples:
//   ka_eff = ka (1 + strength (occlusion - 1)),  emissive_eff = emissive (x) emissive texel,
//   metallic-roughness texture: (kd, ks, n, tint) = phongFromMetallicRoughness(metallic x B, roughness x G);
//   specular-glossiness texture: spec = ks specularColor (x) RGB, gloss = glossiness x A:
//   kd = 1, ks = max(spec), specularColor = spec / ks, n = phongFromMetallicRoughness(0, 1 - gloss).n.
SurfaceCoefficients coefficientsAt(const sg::Material& m, const MapSample& s);
// Gouraud shading lights the vertices with the material's own coefficients; the occlusion and
// emissive maps still apply per pixel, exactly, because both terms are additive:
//   mul -= ka (1 - ao_eff) L_ambient,  add += emissive (x) (emissive texel - 1).
// (The metallic-roughness map needs per-pixel lighting: flat and Phong shading.)
// pbr: only the emissive map (the occlusion scales the environment's terms, which Gouraud has
// summed at the vertices).
void applyMapsToTerms(ShadeTerms& t, const sg::Material& m, const MapSample& s, const sg::vec3& ambient,
                      sg::ReflectionModel model = sg::ReflectionModel::Phong);

// One light's terms at world position p with unit normal n (facing the viewer), seen from
// direction toEye (unit). No ambient, no emissive.
ShadeTerms lightTerms(const SurfaceCoefficients& m, const sg::vec3& n, const sg::vec3& toEye, const LightSample& l, sg::ReflectionModel model);

// Whether the light can add anything at p with unit normal n: lightTerms() is exactly zero
// when n.l <= 0 or no radiance arrives (outside a spot's cone or range), and then the light's
// visibility changes nothing (the ray caster skips its shadow ray).
bool lightReaches(const sg::DrawLight& light, const sg::vec3& p, const sg::vec3& n, sg::ReflectionModel model = sg::ReflectionModel::Phong);
// The same test on a sample already made (sampleLight for Phong and Blinn-Phong,
// samplePunctualLight for pbr).
inline bool sampleReaches(const LightSample& l, const sg::vec3& n) { return glm::dot(n, l.toLight) > 0.0f && l.radiance != sg::vec3(0.0f); }

// What the pbr model needs beyond Phong's inputs: the albedo rho (F0 of metals depends on it;
// Gouraud passes the vertex's) and the environment light (null or empty: none).
struct ShadeExtras {
    sg::vec3 albedo{1.0f};
    const EnvironmentLight* environment = nullptr;
};

// All of the reflection model's terms at p with normal n seen from `eye`: ambient (Phong) or the
// environment (pbr) + emissive + every light. `lightVisible` (optional) scales light i by a
// visibility in [0,1] (the ray caster's shadow rays). Unlit materials: mul = 1, add = emissive.
ShadeTerms shadeTerms(const SurfaceCoefficients& m, const sg::vec3& p, const sg::vec3& n, const sg::vec3& eye, const sg::FrameInput& f,
                      const float* lightVisible = nullptr, const ShadeExtras& extras = {});
inline ShadeTerms shadeTerms(const sg::Material& m, const sg::vec3& p, const sg::vec3& n, const sg::vec3& eye, const sg::FrameInput& f,
                             const float* lightVisible = nullptr, const ShadeExtras& extras = {}) {
    return shadeTerms(coefficientsOf(m), p, n, eye, f, lightVisible, extras);
}

// Light `light`'s own share of shadeTerms (what it adds there with visibility 1; zero for unlit
// surfaces): Gouraud and flat shading keep the shadowed lights apart from the rest.
ShadeTerms lightShareTerms(const SurfaceCoefficients& m, const sg::vec3& p, const sg::vec3& n, const sg::vec3& eye, const sg::FrameInput& f,
                           size_t light, const ShadeExtras& extras = {});

// The full model: shadeTerms(..., {s.albedo, environment}).apply(s.albedo).
sg::vec3 shade(const SurfaceCoefficients& m, const SurfacePoint& s, const sg::vec3& eye, const sg::FrameInput& f, const float* lightVisible = nullptr,
               const EnvironmentLight* environment = nullptr);
inline sg::vec3 shade(const sg::Material& m, const SurfacePoint& s, const sg::vec3& eye, const sg::FrameInput& f, const float* lightVisible = nullptr,
                      const EnvironmentLight* environment = nullptr) {
    return shade(coefficientsOf(m), s, eye, f, lightVisible, environment);
}

// Fog on eye-space distance d, then clamp.
sg::vec3 applyFog(const sg::RenderSettings& s, const sg::vec3& color, float eyeDistance);

float encodeSRGB(float linear);   // [0,1] -> [0,1]
float decodeSRGB(float encoded);
// Clamp, encode, round: the byte round(255 encodeSRGB(clamp(x, 0, 1))), found without pow
// through a table made from that formula (exactly its value for every float; NaN gives 0).
uint8_t toByteSRGB(float linear);
// The smallest float whose toByteSRGB is >= b, for b in 1..255 (the thresholds its table uses);
// 0 for b <= 0, 2 for b >= 256.
float srgbByteThreshold(int b);
sg::vec3 srgbBytesToLinear(const uint8_t* rgb);

}   // namespace rnd
