// material.h - the Phong material (docs/math.md, illumination):
//   L_cam = ka * rho (x) L_ambient
//         + sum_i L_i (n.l_i) (x) (kd * rho + ks * rho_spec * (r_i.v)^n)
// rho is the base colour (times the diffuse texture), rho_spec white or tinted by rho.
#pragma once

#include "scenegraph/math.h"

#include <cstdint>
#include <string>

namespace sg {

// glTF alphaMode: Opaque ignores alpha; Mask keeps a fragment when its alpha >= alphaCutoff and
// drops it otherwise (a cut-out); Blend composites the surface over what lies behind it with
// its alpha ("over"). alpha = Material::alpha x texture alpha x vertex colour alpha.
enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

struct Material {
    std::string name = "default";
    vec3 baseColor{0.8f, 0.8f, 0.8f};   // rho, linear RGB
    float ka = 0.2f;                    // ambient coefficient
    float kd = 0.8f;                    // diffuse coefficient
    float ks = 0.3f;                    // specular coefficient
    float shininess = 32.0f;            // Phong exponent n
    bool specularTinted = false;        // false: white highlights; true: tinted by base colour
    vec3 specularColor{1.0f};           // used when not tinted
    int diffuseTexture = -1;            // index into Scene::textures, -1 = none (base colour, sRGB)
    vec3 emissive{0.0f};                // emission factor, linear RGB (x emissiveTexture)
    // glTF's other textures (indices into Scene::textures, -1 = none). Each samples Mesh::uv0,
    // as the diffuse texture does, or Mesh::uv1 where its bit is set in `uv1Maps`.
    // docs/math.md, "Material textures", has the formulas.
    int emissiveTexture = -1;    // sRGB colour, multiplies `emissive`
    int occlusionTexture = -1;   // R: ambient occlusion; ka_eff = ka (1 + strength (R - 1))
    float occlusionStrength = 1.0f;
    int normalTexture = -1;              // tangent-space normal (linear, RGB = 0.5 n + 0.5), needs tangents
    float normalScale = 1.0f;            // scales the map's x and y
    int metallicRoughnessTexture = -1;   // B: metallic, G: roughness (x the factors below), mapped
    float metallic = 0.0f;               // per texel to kd, ks, shininess, tint by phongFromMetallicRoughness()
    float roughness = 1.0f;
    // KHR_materials_ior and KHR_materials_specular (the pbr model's dielectric reflectance):
    //   F0_dielectric = min(((ior - 1)/(ior + 1))^2 specularColorFactor, 1) specularFactor,
    //   F90_dielectric = specularFactor. ior 1.5 and factors 1 give glTF's core 0.04.
    float ior = 1.5f;
    float specularFactor = 1.0f;
    vec3 specularColorFactor{1.0f};
    // KHR_materials_pbrSpecularGlossiness: metallicRoughnessTexture then holds the
    // specular-glossiness texture (sRGB specular RGB x ks specularColor, linear A x glossiness).
    bool specularGlossiness = false;
    float glossiness = 1.0f;
    // Which of the textures above sample Mesh::uv1 (a MapBit each; clear: Mesh::uv0). A mesh
    // without uv1 samples uv0 for all. The glTF importer fills uv0 and uv1 with the material's
    // two UV channels (each a TEXCOORD set with its KHR_texture_transform applied).
    enum MapBit : uint8_t { EmissiveMap = 1, OcclusionMap = 2, MetallicRoughnessMap = 4, NormalMap = 8 };
    uint8_t uv1Maps = 0;
    float alpha = 1.0f;   // base colour alpha (glTF baseColorFactor.a)
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;    // Mask only
    bool unlit = false;          // colour = base colour (times texture), no lighting
    bool doubleSided = true;     // false: the back face is culled (RenderSettings::culling auto)
    float reflectivity = 0.0f;   // mirror reflection weight (ray caster)

    bool operator==(const Material&) const = default;
};

// The documented mapping of glTF's metallic-roughness parameters to Phong coefficients (the
// importer uses it for the factors, the renderers per texel of a metallicRoughnessTexture):
//   kd = 1 - 0.75 m
//   ks = clamp(mix(0.04, 1, m) + 0.25 (1 - r)(1 - m), 0, 1)
//   n  = clamp(2 / a^2 - 2, 1, 2048) with a = r^2 (Blinn-Phong exponent of GGX width a; 2048 when a < 1e-3)
//   specular tinted by the base colour when m >= 0.5 (a metal), white otherwise
struct PhongFromPbr {
    float kd, ks, shininess;
    bool tinted;
};
PhongFromPbr phongFromMetallicRoughness(float metallic, float roughness);

}   // namespace sg
