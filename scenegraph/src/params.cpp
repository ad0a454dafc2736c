// params.cpp - the parameter tables (see params.h) and the text forms of their values. Every
// user-editable value's key, flag, label, help, range and UI section is written here once.
#include "scenegraph/params.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

namespace sg {

namespace {

template <class T>
std::vector<Param<T>> inSection(std::string_view section, std::initializer_list<Param<T>> rows) {
    std::vector<Param<T>> out(rows);
    for (Param<T>& p : out) p.section = section;
    return out;
}

template <class T>
std::vector<Param<T>> concat(std::initializer_list<std::vector<Param<T>>> groups) {
    std::vector<Param<T>> out;
    for (const auto& g : groups) out.insert(out.end(), g.begin(), g.end());
    return out;
}

// --- render settings ---------------------------------------------------------------------------

// The scene's anti-aliasing as one choice (mode and rate: "ssaa2"); none keeps the rate.
Param<RenderSettings> aaParam() {
    Param<RenderSettings> p;
    p.key = "aa";
    p.flag = "aa";
    p.label = "Scene AA";
    p.help = "Anti-aliasing saved with the scene (the ray caster uses jittered rays for either mode)";
    p.kind = ParamKind::Choice;
    p.choices = param_detail::choicesOf<AAChoice>();
    p.get = [](const RenderSettings& s) { return ParamValue(s.aaName()); };
    p.set = [](RenderSettings& s, const ParamValue& v) {
        const std::string* name = std::get_if<std::string>(&v);
        return name && s.setAA(*name);
    };
    return p;
}

bool fogOn(const RenderSettings& s) { return s.fog != FogMode::Off; }
bool pbr(const RenderSettings& s) { return s.reflection == ReflectionModel::Pbr; }
bool notPbr(const RenderSettings& s) { return s.reflection != ReflectionModel::Pbr; }
bool pbrEnvironment(const RenderSettings& s) { return pbr(s) && s.environment != "none"; }
bool fogLinear(const RenderSettings& s) { return s.fog == FogMode::Linear; }
bool fogExponential(const RenderSettings& s) { return s.fog == FogMode::Exp || s.fog == FogMode::Exp2; }
bool shadowsOn(const RenderSettings& s) { return s.shadows; }

std::vector<Param<RenderSettings>> renderTable() {
    using S = RenderSettings;
    return concat<S>({
        inSection<S>(
            "Shading",
            {
                field<&S::shading>("shading", "shading", "Shading", "Where lighting is computed: per face, per vertex or per pixel").asRadios(),
                field<&S::reflection>("reflection", "reflection", "Reflection", "The specular term of the reflection model").asRadios(),
                field<&S::attenuation>("attenuation", "attenuation", "Light attenuation (1/r^2)",
                                       "Honour the inverse-square falloff of lights that have it"),
                field<&S::ambientLight>("ambientLight", "ambient", "Ambient light",
                                        "L_ambient: light from everywhere, scaled per material by ka (linear RGB; Phong and Blinn-Phong)")
                    .range(0.0, 1000.0)
                    .when(notPbr),
            }),
        inSection<S>(
            "Environment",
            {
                field<&S::environment>("environment.map", "environment", "Environment",
                                       "Image-based light of the pbr model: none, default (a neutral studio) or an equirectangular .hdr file")
                    .when(pbr),
                field<&S::environmentIntensity>("environment.intensity", "environment-intensity", "Intensity", "Scales the environment's radiance")
                    .range(0.0, 1e5)
                    .log()
                    .fmt("%.3f")
                    .when(pbrEnvironment),
                field<&S::environmentRotationDeg>("environment.rotation", "environment-rotation", "Rotation",
                                                  "Turns the environment about the vertical (+y) axis, degrees")
                    .range(-360.0, 360.0)
                    .fmt("%.1f deg")
                    .when(pbrEnvironment),
                field<&S::environmentBackground>("environment.background", "environment-background", "Show as background",
                                                 "Draw the environment behind the scene instead of the background colour")
                    .when(pbrEnvironment),
            }),
        inSection<S>(
            "Fog",
            {
                field<&S::fog>("fog.mode", "fog", "Fog", "Fog: visibility falls with the eye-space distance"),
                field<&S::fogColor>("fog.color", "fog-color", "Fog colour", "The colour fog blends toward (linear RGB)").range(0.0, 1.0).when(fogOn),
                field<&S::fogStart>("fog.start", "fog-start", "Fog start", "Linear fog: distance where it begins")
                    .range(0.0, 1e9)
                    .dragged("%.3f")
                    .when(fogLinear),
                field<&S::fogEnd>("fog.end", "fog-end", "Fog end", "Linear fog: distance where nothing is left visible")
                    .range(0.0, 1e9)
                    .dragged("%.3f")
                    .when(fogLinear),
                field<&S::fogDensity>("fog.density", "fog-density", "Fog density", "Exponential fog: density per unit distance")
                    .range(0.0, 1e4)
                    .log()
                    .fmt("%.4f")
                    .when(fogExponential),
            }),
        inSection<S>("Exposure and tone mapping",
                     {
                         field<&S::exposure>("exposure", "exposure", "Exposure",
                                             "Exposure in EV: the linear colour is multiplied by 2^EV before the tone mapping")
                             .range(-10.0, 10.0)
                             .fmt("%.2f EV"),
                         field<&S::toneMapping>("toneMapping", "tone-mapping", "Tone mapping",
                                                "Maps the exposed linear colour to the display's range, before the sRGB encoding"),
                     }),
        inSection<S>("Anti-aliasing",
                     {
                         // The rate first, so a file's "aa" name wins over a stray rate.
                         field<&S::aaRate>("aaRate", "", "", "Samples of the anti-aliasing mode, kept while it is off").range(1, 8),
                         aaParam(),
                     }),
        inSection<S>("Rasterizers",
                     {
                         field<&S::wireframe>("wireframe", "wireframe", "Wireframe", "Draw the triangle edges over the shaded surfaces")
                             .needing(Feature::Wireframe),
                         field<&S::wireframeColor>("wireframeColor", "wireframe-color", "Wireframe colour", "Colour of the edges (linear RGB)")
                             .range(0.0, 1.0)
                             .when([](const S& s) { return s.wireframe; }),
                         field<&S::culling>("culling", "culling", "Back faces", "Which back faces are culled"),
                         field<&S::tessellation>("tessellation", "tessellation", "Tessellation",
                                                 "Segments / marching-cubes resolution for implicit shapes, CSG, parametric surfaces and grids")
                             .range(4, 512),
                     }),
        inSection<S>(
            "Shadows",
            {
                field<&S::shadows>("shadows", "shadows", "Shadows", "Shadows of every light: shadow rays (ray caster) or shadow maps (rasterizers)")
                    .needing(Feature::Shadows),
                field<&S::shadowMapSize>("shadow.mapSize", "shadow-map-size", "Map size", "Texels per side of each shadow map")
                    .range(64, 8192)
                    .needing(Feature::ShadowMaps)
                    .when(shadowsOn),
                field<&S::shadowFilter>("shadow.filter", "shadow-filter", "Filter", "How a shadow-map lookup is filtered")
                    .needing(Feature::ShadowMaps)
                    .when(shadowsOn),
                field<&S::shadowPcfSize>("shadow.pcfSize", "shadow-pcf-size", "Filter taps",
                                         "k: PCF averages the k x k texels around the point; PCSS spreads k x k taps over the penumbra")
                    .range(1, 15)
                    .needing(Feature::ShadowMaps)
                    .when([](const S& s) { return s.shadows && s.shadowFilter != ShadowFilter::None; }),
                field<&S::shadowDepthBias>("shadow.depthBias", "shadow-depth-bias", "Depth bias",
                                           "Texels a receiver's depth is moved toward the light before the comparison (against acne)")
                    .range(0.0, 64.0)
                    .fmt("%.2f texels")
                    .needing(Feature::ShadowMaps)
                    .when(shadowsOn),
                field<&S::shadowNormalBias>("shadow.normalBias", "shadow-normal-bias", "Normal bias",
                                            "Texels a receiver is moved along its normal before the lookup (against acne)")
                    .range(0.0, 64.0)
                    .fmt("%.2f texels")
                    .needing(Feature::ShadowMaps)
                    .when(shadowsOn),
                field<&S::shadowRays>("shadow.rays", "shadow-rays", "Shadow rays",
                                      "Rays to each light that has a size (soft shadows; a point source takes one)")
                    .range(1, 256)
                    .needing(Feature::ShadowRays)
                    .when(shadowsOn),
            }),
        inSection<S>("Ray caster",
                     {
                         field<&S::reflections>("reflections", "reflections", "Reflections", "Mirror reflections of reflective materials")
                             .needing(Feature::Reflections),
                         field<&S::maxBounces>("maxBounces", "bounces", "Max bounces", "Reflection depth limit")
                             .range(0, 16)
                             .needing(Feature::Reflections)
                             .when([](const S& s) { return s.reflections; }),
                     }),
        inSection<S>("Background",
                     {
                         field<&S::background>("background", "background", "Background", "Colour behind the scene (linear RGB)").range(0.0, 1.0),
                     }),
    });
}

// --- projection --------------------------------------------------------------------------------

// The projection type; also takes the oblique presets (cavalier, cabinet), which set the angle
// and factor too, and the axonometric one (isometric), which is orthographic here (the command
// line turns the camera as well).
Param<Projection> projectionTypeParam() {
    Param<Projection> p = field<&Projection::type>("type", "projection", "Type",
                                                   "Projection: perspective, orthographic or oblique (or a preset: cavalier, cabinet, isometric)");
    p.set = [](Projection& pr, const ParamValue& v) {
        const std::string* name = std::get_if<std::string>(&v);
        if (!name) return false;
        ObliquePreset preset;
        if (parseName(*name, preset)) {
            Projection q = obliquePreset(preset);
            pr.type = q.type;
            pr.obliqueAngleDeg = q.obliqueAngleDeg;
            pr.obliqueFactor = q.obliqueFactor;
            return true;
        }
        AxonometricPreset axonometric;
        if (parseName(*name, axonometric)) {
            pr.type = ProjectionType::Orthographic;
            return true;
        }
        return parseName(*name, pr.type);
    };
    for (const ParamChoice& c : param_detail::choicesOf<ObliquePreset>()) p.choices.push_back(c);
    for (const ParamChoice& c : param_detail::choicesOf<AxonometricPreset>()) p.choices.push_back(c);
    return p;
}

std::vector<Param<Projection>> projectionTable() {
    using P = Projection;
    auto perspective = [](const P& p) { return p.type == ProjectionType::Perspective && !p.useFrustum; };
    auto frustumOnly = [](const P& p) { return p.type == ProjectionType::Perspective; };
    auto parallel = [](const P& p) { return p.type != ProjectionType::Perspective; };
    auto oblique = [](const P& p) { return p.type == ProjectionType::Oblique; };
    return inSection<P>(
        "Projection",
        {
            projectionTypeParam(),
            field<&P::useFrustum>("useFrustum", "", "General frustum (l, r, b, t)",
                                  "Perspective from the frustum's sides at the near plane instead of the field of view")
                .when(frustumOnly),
            field<&P::fovyDeg>("fovy", "fovy", "Field of view y", "Perspective: vertical angle of view in degrees")
                .range(0.1, 179.0)
                .fmt("%.1f deg")
                .when(perspective),
            field<&P::aspectRatio>("aspectRatio", "", "Framed aspect",
                                   "Perspective: the width/height the author framed (0 = none); a narrower viewport widens "
                                   "the vertical field so nothing framed is cut")
                .range(0.0, 100.0)
                .fmt("%.3f")
                .when(perspective),
            field<&P::orthoHalfHeight>("orthoHalfHeight", "ortho-half-height", "Half height",
                                       "Orthographic and oblique: half the visible height in view units")
                .range(1e-6, 1e9)
                .dragged("%.4g")
                .when(parallel),
            field<&P::obliqueAngleDeg>("obliqueAngle", "oblique-angle", "Oblique angle", "Oblique: angle of the receding axis in degrees")
                .range(-90.0, 90.0)
                .fmt("%.1f deg")
                .when(oblique),
            field<&P::obliqueFactor>("obliqueFactor", "oblique-factor", "Oblique factor",
                                     "Oblique: foreshortening of the receding axis (1 cavalier, 0.5 cabinet)")
                .range(0.0, 4.0)
                .when(oblique),
            field<&P::zNear>("near", "near", "Near", "Near clipping distance").range(1e-6, 1e9).dragged("%.4g").log(),
            field<&P::zFar>("far", "far", "Far", "Far clipping distance").range(1e-6, 1e9).dragged("%.4g").log(),
        });
}

// --- material ----------------------------------------------------------------------------------

std::vector<Param<Material>> materialTable() {
    using M = Material;
    auto notOpaque = [](const M& m) { return m.alphaMode != AlphaMode::Opaque; };
    auto masked = [](const M& m) { return m.alphaMode == AlphaMode::Mask; };
    return concat<M>({
        inSection<M>(
            "Phong",
            {
                field<&M::baseColor>("baseColor", "", "Base colour", "rho: the surface colour (linear RGB; x the base colour texture)")
                    .range(0.0, 1.0),
                field<&M::ka>("ka", "", "ka (ambient)", "Ambient coefficient").range(0.0, 1.0),
                field<&M::kd>("kd", "", "kd (diffuse)", "Diffuse coefficient").range(0.0, 1.0),
                field<&M::ks>("ks", "", "ks (specular)", "Specular coefficient").range(0.0, 1.0),
                field<&M::shininess>("shininess", "", "Shininess n", "Phong exponent of the highlight").range(0.0, 1e5).log().fmt("%.1f"),
                field<&M::specularTinted>("specularTinted", "", "Specular tinted by base colour",
                                          "On: highlights take the base colour (metals); off: the specular colour"),
                field<&M::specularColor>("specularColor", "", "Specular colour", "Colour of the highlights when not tinted (linear RGB)")
                    .range(0.0, 1.0)
                    .when([](const M& m) { return !m.specularTinted; }),
                field<&M::emissive>("emissive", "", "Emissive", "Light the surface gives off (linear RGB; x the emissive texture)").range(0.0, 1e4),
                field<&M::reflectivity>("reflectivity", "", "Reflectivity", "Mirror reflection weight (ray caster)")
                    .range(0.0, 1.0)
                    .needing(Feature::Reflections),
                field<&M::unlit>("unlit", "", "Unlit", "Colour = base colour (x texture), no lighting"),
                field<&M::doubleSided>("doubleSided", "", "Double-sided",
                                       "Off: the back face is not drawn when back faces are culled per material (Back faces: auto)"),
            }),
        inSection<M>(
            "Alpha",
            {
                field<&M::alphaMode>("alphaMode", "", "Alpha mode", "How alpha is used"),
                field<&M::alpha>("alpha", "", "Alpha", "Base colour alpha (x texture and vertex alpha)").range(0.0, 1.0).when(notOpaque),
                field<&M::alphaCutoff>("alphaCutoff", "", "Alpha cutoff", "Mask: drawn where alpha >= the cutoff").range(0.0, 1.0).when(masked),
            }),
        // glTF's physically based parameters: what the pbr reflection model uses (the panel shows
        // this section under pbr), and per texel of a metallic-roughness map under Phong
        // (docs/math.md, "Material textures").
        inSection<M>(
            "Physically based",
            {
                field<&M::metallic>("metallic", "", "Metallic", "glTF metallic factor: 0 dielectric, 1 metal").range(0.0, 1.0),
                field<&M::roughness>("roughness", "", "Roughness", "glTF roughness factor (GGX alpha = roughness^2)").range(0.0, 1.0),
                field<&M::ior>("ior", "", "IOR", "KHR_materials_ior: index of refraction of the dielectric (1.5: F0 = 0.04)").range(1.0, 5.0),
                field<&M::specularFactor>("specularFactor", "", "Specular", "KHR_materials_specular: strength of the dielectric's specular")
                    .range(0.0, 1.0),
                field<&M::specularColorFactor>("specularColorFactor", "", "Specular colour",
                                               "KHR_materials_specular: tints the dielectric's F0 (linear RGB)")
                    .range(0.0, 1e4),
                field<&M::specularGlossiness>("specularGlossiness", "", "", "KHR_materials_pbrSpecularGlossiness material"),
                field<&M::glossiness>("glossiness", "", "", "Specular-glossiness: glossiness factor").range(0.0, 1.0),
            }),
        inSection<M>("Maps",
                     {
                         field<&M::occlusionStrength>("occlusionStrength", "", "", "Occlusion map strength").range(0.0, 1.0),
                         field<&M::normalScale>("normalScale", "", "", "Normal map x/y scale").range(-1000.0, 1000.0),
                     }),
    });
}

// --- light -------------------------------------------------------------------------------------

std::vector<Param<Light>> lightTable() {
    using L = Light;
    auto spot = [](const L& l) { return l.type == LightType::Spot; };
    return inSection<L>(
        "Light",
        {
            field<&L::type>("type", "", "Type", "Point, directional or spot"),
            field<&L::color>("color", "", "Colour", "Light colour (linear RGB)").range(0.0, 1.0),
            field<&L::intensity>("intensity", "", "Intensity", "Scales the colour").range(0.0, 1e6).dragged("%.3f"),
            field<&L::inverseSquare>("inverseSquare", "", "Inverse-square falloff", "Falls off as 1/r^2 (when the scene's attenuation is on)"),
            field<&L::spotInnerDeg>("spotInner", "", "Inner angle", "Spot: full intensity inside (degrees)").range(0.0, 90.0).when(spot),
            field<&L::spotOuterDeg>("spotOuter", "", "Outer angle", "Spot: nothing outside (degrees)").range(0.0, 90.0).when(spot),
            field<&L::range>("range", "", "Range", "KHR_lights_punctual range: the pbr model fades the light to 0 there (0 = none)")
                .range(0.0, 1e9)
                .dragged("%.3f")
                .when([](const L& l) { return l.type != LightType::Directional; }),
            field<&L::radius>("radius", "", "Radius", "Size of the source for soft shadows (world units; 0 = a point)")
                .range(0.0, 1e6)
                .dragged("%.3f")
                .when([](const L& l) { return l.type != LightType::Directional; }),
            field<&L::angularRadiusDeg>("angularRadius", "", "Angular radius",
                                        "Size of the source for soft shadows (degrees; the sun is about 0.27; 0 = a point)")
                .range(0.0, 45.0)
                .dragged("%.2f")
                .when([](const L& l) { return l.type == LightType::Directional; }),
        });
}

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

bool parseDouble(std::string_view s, double& out) {
    s = trim(s);
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size() && !s.empty();
}

}   // namespace

template <>
std::span<const Param<RenderSettings>> params<RenderSettings>() {
    static const std::vector<Param<RenderSettings>> t = renderTable();
    return t;
}
template <>
std::span<const Param<Projection>> params<Projection>() {
    static const std::vector<Param<Projection>> t = projectionTable();
    return t;
}
template <>
std::span<const Param<Material>> params<Material>() {
    static const std::vector<Param<Material>> t = materialTable();
    return t;
}
template <>
std::span<const Param<Light>> params<Light>() {
    static const std::vector<Param<Light>> t = lightTable();
    return t;
}

std::string checkValue(std::string_view key, ParamKind kind, double min, double max, const ParamValue& v) {
    const std::string k(key);
    auto outside = [&](double x) { return !std::isfinite(x) || x < min || x > max; };
    auto rangeText = [&] { return "[" + number(min) + ", " + number(max) + "]"; };
    switch (kind) {
    case ParamKind::Bool:
        if (!std::holds_alternative<bool>(v)) return k + ": expected on or off";
        return {};
    case ParamKind::Int:
        if (!std::holds_alternative<int>(v)) return k + ": expected a whole number";
        if (outside(std::get<int>(v))) return k + " must be in " + rangeText();
        return {};
    case ParamKind::Float:
        if (!std::holds_alternative<float>(v)) return k + ": expected a number";
        if (outside(std::get<float>(v))) return k + " must be in " + rangeText();
        return {};
    case ParamKind::Color:
        if (!std::holds_alternative<vec3>(v)) return k + ": expected a colour r,g,b";
        for (int c = 0; c < 3; ++c)
            if (outside(std::get<vec3>(v)[c])) return k + ": each component must be in " + rangeText();
        return {};
    case ParamKind::Choice:
        if (!std::holds_alternative<std::string>(v)) return k + ": expected a name";
        return {};
    case ParamKind::Text:
        if (!std::holds_alternative<std::string>(v)) return k + ": expected text";
        if (std::get<std::string>(v).size() > 4096) return k + ": longer than 4096 characters";
        return {};
    }
    return {};
}

std::optional<ParamValue> parseParamText(ParamKind kind, std::string_view text, std::string& error) {
    std::string_view s = trim(text);
    switch (kind) {
    case ParamKind::Bool:
        if (s == "on" || s == "true" || s == "yes" || s == "1") return ParamValue(true);
        if (s == "off" || s == "false" || s == "no" || s == "0") return ParamValue(false);
        error = "'" + std::string(text) + "': expected on or off";
        return std::nullopt;
    case ParamKind::Int: {
        double d = 0;
        if (!parseDouble(s, d) || d != std::floor(d) || std::abs(d) > 2e9) {
            error = "'" + std::string(text) + "': expected a whole number";
            return std::nullopt;
        }
        return ParamValue(int(d));
    }
    case ParamKind::Float: {
        double d = 0;
        if (!parseDouble(s, d) || !(std::abs(d) <= double(std::numeric_limits<float>::max()))) {
            error = "'" + std::string(text) + "': expected a finite number";
            return std::nullopt;
        }
        return ParamValue(float(d));
    }
    case ParamKind::Color: {
        std::string_view body = s;
        if (body.size() >= 2 && body.front() == '[' && body.back() == ']') body = body.substr(1, body.size() - 2);
        vec3 c(0.0f);
        for (int i = 0; i < 3; ++i) {
            size_t comma = body.find(',');
            std::string_view part = i < 2 ? body.substr(0, comma) : body;
            double d = 0;
            if ((i < 2 && comma == std::string_view::npos) || !parseDouble(part, d) || !(std::abs(d) <= double(std::numeric_limits<float>::max()))) {
                error = "'" + std::string(text) + "': expected a colour r,g,b (three finite numbers, linear)";
                return std::nullopt;
            }
            c[i] = float(d);
            if (i < 2) body.remove_prefix(comma + 1);
        }
        return ParamValue(c);
    }
    case ParamKind::Choice:
    case ParamKind::Text:
        if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
        if (s.empty()) {
            error = "expected a name";
            return std::nullopt;
        }
        return ParamValue(std::string(s));
    }
    return std::nullopt;
}

std::string formatParamValue(const ParamValue& v) {
    return std::visit(
        [](const auto& x) -> std::string {
            using V = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<V, bool>)
                return x ? "on" : "off";
            else if constexpr (std::is_same_v<V, int>)
                return std::to_string(x);
            else if constexpr (std::is_same_v<V, float>)
                return number(x);
            else if constexpr (std::is_same_v<V, vec3>)
                return number(x.x) + "," + number(x.y) + "," + number(x.z);
            else
                return x;
        },
        v);
}

}   // namespace sg
