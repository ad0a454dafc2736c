// settings.h - RenderSettings: one plain struct read by all three backends, edited by the UI,
// set from the command line and saved with the scene.
#pragma once

#include "scenegraph/math.h"

#include <string>
#include <string_view>

namespace sg {

enum class ShadingModel { Flat, Gouraud, Phong };
// Phong and BlinnPhong: the seeds' local model with ka, kd, ks and the ambient light. Pbr: glTF
// 2.0's BRDF (Appendix B) on the material's metallic/roughness parameters, lit by the lights in
// KHR_lights_punctual's units and by the environment (image-based light); no ambient term.
enum class ReflectionModel { Phong, BlinnPhong, Pbr };
enum class FogMode { Off, Linear, Exp, Exp2 };
enum class AAMode { None, MSAA, SSAA };
// Back-face culling: Auto culls the back faces of single-sided materials (Material::doubleSided
// false, glTF's default) and draws double-sided ones from both sides; On culls every back face;
// Off draws every back face.
enum class CullMode { Auto, On, Off };
// The tone-mapping operator of the display transform (see RenderSettings::exposure).
enum class ToneMapping { None, Aces, KhrNeutral };
// How the rasterizers filter a shadow-map lookup (renderers/shadow_map.h): one texel's answer, or
// the mean answer of the k x k texels around the point (percentage-closer filtering).
enum class ShadowFilter { None, Pcf, Pcss };

// Whether a triangle of a material with this doubleSided flag loses its back face.
inline bool cullsBackFaces(CullMode m, bool doubleSided) { return m == CullMode::On || (m == CullMode::Auto && !doubleSided); }

struct RenderSettings {
    ShadingModel shading = ShadingModel::Phong;
    ReflectionModel reflection = ReflectionModel::Phong;

    // Fog blends toward fogColor by visibility f(d) of the eye-space distance d:
    // linear f = (end - d)/(end - start), exp f = e^(-density d), exp2 f = e^(-(density d)^2).
    FogMode fog = FogMode::Off;
    vec3 fogColor{0.6f, 0.65f, 0.7f};
    float fogStart = 5.0f;
    float fogEnd = 30.0f;
    float fogDensity = 0.05f;

    bool attenuation = true;   // honour Light::inverseSquare
    vec3 ambientLight{1.0f};   // L_ambient of docs/math.md (scaled per material by ka)

    // Environment light of the pbr model (image-based light): "none", "default" (a built-in
    // neutral studio) or the path of an equirectangular Radiance .hdr. Radiance is scaled by
    // environmentIntensity and turned about the world's +y axis by environmentRotationDeg;
    // environmentBackground draws it behind the scene instead of the background colour.
    std::string environment = "default";
    float environmentIntensity = 1.0f;
    float environmentRotationDeg = 0.0f;
    bool environmentBackground = false;

    // Anti-aliasing. MSAA: aaRate samples per pixel (2, 4, 8). SSAA: aaRate x aaRate samples
    // per pixel (2 -> 4 spp, 4 -> 16 spp); the ray caster uses aaRate x aaRate jittered rays.
    AAMode aa = AAMode::None;
    int aaRate = 4;

    CullMode culling = CullMode::Auto;
    bool wireframe = false;
    vec3 wireframeColor{0.05f, 0.05f, 0.05f};
    vec3 background{0.08f, 0.09f, 0.11f};

    // Display transform, the last step of every backend (docs/math.md, "Exposure and tone
    // mapping"; renderers/tone_map.h): a pixel's linear colour L - after fog, blending and the
    // anti-aliasing resolve - is shown as encodeSRGB(T(2^exposure L)), T the operator. With
    // exposure 0 and no operator the backends encode L as they always did.
    float exposure = 0.0f;   // EV: the linear colour is multiplied by 2^exposure
    ToneMapping toneMapping = ToneMapping::None;
    bool displayTransformIsIdentity() const { return exposure == 0.0f && toneMapping == ToneMapping::None; }

    // Shadows of every light: shadow rays in the ray caster, shadow maps in the rasterizers
    // (docs/math.md, "Shadow maps"): one map of shadowMapSize^2 texels per light (six for a
    // point light), biased by shadowDepthBias and shadowNormalBias texels, filtered by
    // shadowFilter over shadowPcfSize^2 texels (PCSS: spread over the penumbra that the light's
    // size gives, docs/math.md "Soft shadows"). The ray caster traces shadowRays rays to each
    // light that has a size (Light::radius, angularRadiusDeg), one to a point source.
    bool shadows = true;
    int shadowMapSize = 1024;
    ShadowFilter shadowFilter = ShadowFilter::Pcf;
    int shadowPcfSize = 3;
    float shadowDepthBias = 1.0f;
    float shadowNormalBias = 1.0f;
    int shadowRays = 16;

    // Ray caster only.
    bool reflections = false;
    int maxBounces = 3;

    // Tessellation of implicit shapes / CSG / parametric / grids for the rasterizers:
    // grid resolution of marching cubes and segments of analytic tessellations.
    int tessellation = 64;

    bool operator==(const RenderSettings&) const = default;

    // Returns an empty string when the settings are usable, else the reason: every value in its
    // range (the parameter table, params.h), then the rules that tie values together.
    std::string validate() const;
    // The name of aa/aaRate used by the command line and the JSON file (the AAChoice table in
    // setting_names.h); setAA accepts the table's names and aliases, false for anything else.
    std::string aaName() const;
    bool setAA(std::string_view name);
};

// Names from the tables in setting_names.h.
std::string_view toString(ShadingModel m);
std::string_view toString(ReflectionModel m);
std::string_view toString(FogMode m);
std::string_view toString(CullMode m);
std::string_view toString(ToneMapping m);
std::string_view toString(ShadowFilter m);
bool parse(std::string_view s, ShadingModel& out);
bool parse(std::string_view s, ReflectionModel& out);
bool parse(std::string_view s, FogMode& out);

// Fog visibility f(d) in [0,1] (1 = no fog) as described above.
float fogVisibility(const RenderSettings& s, float distance);

}   // namespace sg
