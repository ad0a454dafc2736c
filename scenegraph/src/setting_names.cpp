// setting_names.cpp - the name tables (see setting_names.h): every settings name is spelled here.
#include "scenegraph/setting_names.h"

namespace sg {

namespace {

constexpr NamedValue<ShadingModel> kShading[] = {
    {ShadingModel::Flat, "flat", "Flat", "one colour per face, lit at the face normal"},
    {ShadingModel::Gouraud, "gouraud", "Gouraud", "lit at the vertices, colours interpolated across the face"},
    {ShadingModel::Phong, "phong", "Phong", "normals interpolated, lit at every pixel"},
};

constexpr NamedValue<ReflectionModel> kReflection[] = {
    {ReflectionModel::Phong, "phong", "Phong", "specular from the mirrored light and the view vector: (r.v)^s"},
    {ReflectionModel::BlinnPhong, "blinn", "Blinn-Phong", "specular from the half vector: (n.h)^s"},
    {ReflectionModel::Pbr, "pbr", "PBR (glTF)",
     "glTF 2.0's metal/roughness BRDF (Lambert + GGX, Smith, Schlick), lit by the lights and the environment"},
};
constexpr NameAlias<ReflectionModel> kReflectionAliases[] = {{"blinn-phong", ReflectionModel::BlinnPhong}};

constexpr NamedValue<FogMode> kFog[] = {
    {FogMode::Off, "off", "Off", "no fog"},
    {FogMode::Linear, "linear", "Linear", "visibility falls linearly from fog start to fog end"},
    {FogMode::Exp, "exp", "Exponential", "visibility e^(-density d)"},
    {FogMode::Exp2, "exp2", "Exponential squared", "visibility e^(-(density d)^2)"},
};

constexpr NamedValue<AAChoice> kAA[] = {
    {{AAMode::None, 0}, "none", "None", "one sample per pixel"},
    {{AAMode::MSAA, 2}, "msaa2", "MSAA 2x", "multisampling, 2 samples per pixel"},
    {{AAMode::MSAA, 4}, "msaa4", "MSAA 4x", "multisampling, 4 samples per pixel"},
    {{AAMode::MSAA, 8}, "msaa8", "MSAA 8x", "multisampling, 8 samples per pixel"},
    {{AAMode::SSAA, 2}, "ssaa2", "SSAA 2x2", "supersampling, 2x2 samples per pixel"},
    {{AAMode::SSAA, 3}, "ssaa3", "SSAA 3x3", "supersampling, 3x3 samples per pixel"},
    {{AAMode::SSAA, 4}, "ssaa4", "SSAA 4x4", "supersampling, 4x4 samples per pixel"},
};
constexpr NameAlias<AAChoice> kAAAliases[] = {{"off", {AAMode::None, 0}}};

constexpr NamedValue<ProjectionType> kProjection[] = {
    {ProjectionType::Perspective, "perspective", "Perspective", "pinhole camera: vertical field of view and aspect, or a general frustum"},
    {ProjectionType::Orthographic, "orthographic", "Orthographic", "parallel rays along the view axis"},
    {ProjectionType::Oblique, "oblique", "Oblique", "parallel rays at an angle to the picture plane"},
};

constexpr NamedValue<ObliquePreset> kObliquePreset[] = {
    {ObliquePreset::Cavalier, "cavalier", "Cavalier", "oblique at 45 degrees, receding axis at full length (factor 1)"},
    {ObliquePreset::Cabinet, "cabinet", "Cabinet", "oblique at 45 degrees, receding axis at half length (factor 0.5)"},
};

constexpr NamedValue<AxonometricPreset> kAxonometricPreset[] = {
    {AxonometricPreset::Isometric, "isometric", "Isometric",
     "orthographic, seen along (-1,-1,-1) so the three axes are equally foreshortened (the camera turns there too)"},
};

constexpr NamedValue<LightType> kLight[] = {
    {LightType::Point, "point", "Point", "shines from the node's position in every direction"},
    {LightType::Directional, "directional", "Directional", "parallel light along the node's -z axis"},
    {LightType::Spot, "spot", "Spot", "a cone along the node's -z axis, soft between the inner and outer angles"},
};

constexpr NamedValue<CullMode> kCull[] = {
    {CullMode::Auto, "auto", "Auto (per material)", "cull the back faces of single-sided materials, draw double-sided ones from both sides"},
    {CullMode::On, "on", "On", "cull every back face"},
    {CullMode::Off, "off", "Off", "draw every back face"},
};

constexpr NamedValue<ToneMapping> kToneMapping[] = {
    {ToneMapping::None, "none", "None", "the exposed linear colour as it is, clipped at 1 by the sRGB encoding"},
    {ToneMapping::Aces, "aces", "ACES filmic",
     "Stephen Hill's fit of the ACES RRT + sRGB ODT, as the Khronos glTF Sample Viewer applies it (input / 0.6)"},
    {ToneMapping::KhrNeutral, "khr-neutral", "Khronos PBR Neutral",
     "Khronos PBR Neutral: base colours 0.08..0.8 kept (less 0.04), highlights compressed toward white without hue shifts"},
};

constexpr NamedValue<ShadowFilter> kShadowFilter[] = {
    {ShadowFilter::None, "none", "None", "one texel's answer: hard, stair-stepped edges"},
    {ShadowFilter::Pcf, "pcf", "PCF", "percentage-closer filtering: the mean answer of the k x k texels around the point"},
    {ShadowFilter::Pcss, "pcss", "PCSS",
     "percentage-closer soft shadows: PCF over the penumbra the light's size gives (blocker search, then k x k taps)"},
};

constexpr NamedValue<AlphaMode> kAlphaMode[] = {
    {AlphaMode::Opaque, "opaque", "Opaque", "alpha is ignored: the surface is fully opaque"},
    {AlphaMode::Mask, "mask", "Mask", "cut-out: drawn where alpha >= the cutoff, not drawn elsewhere"},
    {AlphaMode::Blend, "blend", "Blend", "transparent: blended over what lies behind it with its alpha"},
};

constexpr NamedValue<WrapMode> kWrap[] = {
    {WrapMode::Repeat, "repeat", "Repeat", "the texture tiles"},
    {WrapMode::ClampToEdge, "clamp", "Clamp to edge", "coordinates outside [0,1] take the edge texel"},
    {WrapMode::MirroredRepeat, "mirror", "Mirrored repeat", "the texture tiles, every other copy mirrored"},
};

constexpr NamedValue<FilterMode> kFilter[] = {
    {FilterMode::Nearest, "nearest", "Nearest", "the nearest texel"},
    {FilterMode::Bilinear, "bilinear", "Bilinear", "blend of the four nearest texels"},
    {FilterMode::Trilinear, "trilinear", "Trilinear", "bilinear on the two nearest mipmap levels, blended"},
};

constexpr NamedValue<ImplicitType> kImplicit[] = {
    {ImplicitType::Sphere, "sphere", "Sphere", "all points at the radius from the centre"},
    {ImplicitType::Box, "box", "Box", "an axis-aligned box of the given half extents"},
    {ImplicitType::Cylinder, "cylinder", "Cylinder", "a capped cylinder along y"},
    {ImplicitType::Cone, "cone", "Cone", "a capped cone along y"},
    {ImplicitType::Torus, "torus", "Torus", "a ring around y: major and minor radius"},
    {ImplicitType::Plane, "plane", "Plane", "the infinite plane y = 0"},
    {ImplicitType::Quadric, "quadric", "Quadric (hyperboloid)", "x^T Q x = 0 for a symmetric 4x4 Q, clipped to its bounds"},
};

constexpr NamedValue<CsgOp> kCsg[] = {
    {CsgOp::Union, "union", "Union", "inside either operand"},
    {CsgOp::Intersection, "intersection", "Intersection", "inside both operands"},
    {CsgOp::Difference, "difference", "Difference", "inside the first operand and outside the second"},
};

constexpr NamedValue<ParametricType> kParametric[] = {
    {ParametricType::Torus, "torus", "Torus", "a torus parametrised by two angles"},
    {ParametricType::BezierPatch, "bezier", "Bezier patch", "a bicubic Bezier patch of 4x4 control points"},
};

}   // namespace

template <>
const NameTable<ImplicitType>& nameTable<ImplicitType>() {
    static const NameTable<ImplicitType> t{kImplicit};
    return t;
}
template <>
const NameTable<CsgOp>& nameTable<CsgOp>() {
    static const NameTable<CsgOp> t{kCsg};
    return t;
}
template <>
const NameTable<ParametricType>& nameTable<ParametricType>() {
    static const NameTable<ParametricType> t{kParametric};
    return t;
}

template <>
const NameTable<ShadingModel>& nameTable<ShadingModel>() {
    static const NameTable<ShadingModel> t{kShading};
    return t;
}
template <>
const NameTable<ReflectionModel>& nameTable<ReflectionModel>() {
    static const NameTable<ReflectionModel> t{kReflection, kReflectionAliases};
    return t;
}
template <>
const NameTable<FogMode>& nameTable<FogMode>() {
    static const NameTable<FogMode> t{kFog};
    return t;
}
template <>
const NameTable<AAChoice>& nameTable<AAChoice>() {
    static const NameTable<AAChoice> t{kAA, kAAAliases};
    return t;
}
template <>
const NameTable<ProjectionType>& nameTable<ProjectionType>() {
    static const NameTable<ProjectionType> t{kProjection};
    return t;
}
template <>
const NameTable<ObliquePreset>& nameTable<ObliquePreset>() {
    static const NameTable<ObliquePreset> t{kObliquePreset};
    return t;
}
template <>
const NameTable<AxonometricPreset>& nameTable<AxonometricPreset>() {
    static const NameTable<AxonometricPreset> t{kAxonometricPreset};
    return t;
}
template <>
const NameTable<LightType>& nameTable<LightType>() {
    static const NameTable<LightType> t{kLight};
    return t;
}
template <>
const NameTable<CullMode>& nameTable<CullMode>() {
    static const NameTable<CullMode> t{kCull};
    return t;
}
template <>
const NameTable<ShadowFilter>& nameTable<ShadowFilter>() {
    static const NameTable<ShadowFilter> t{kShadowFilter};
    return t;
}
template <>
const NameTable<ToneMapping>& nameTable<ToneMapping>() {
    static const NameTable<ToneMapping> t{kToneMapping};
    return t;
}
template <>
const NameTable<AlphaMode>& nameTable<AlphaMode>() {
    static const NameTable<AlphaMode> t{kAlphaMode};
    return t;
}
template <>
const NameTable<WrapMode>& nameTable<WrapMode>() {
    static const NameTable<WrapMode> t{kWrap};
    return t;
}
template <>
const NameTable<FilterMode>& nameTable<FilterMode>() {
    static const NameTable<FilterMode> t{kFilter};
    return t;
}

AAChoice aaChoice(const RenderSettings& s) { return s.aa == AAMode::None ? AAChoice{} : AAChoice{s.aa, s.aaRate}; }

Projection obliquePreset(ObliquePreset p) { return p == ObliquePreset::Cavalier ? Projection::cavalier() : Projection::cabinet(); }

std::string_view toString(ShadingModel m) { return nameOf(m); }
std::string_view toString(ReflectionModel m) { return nameOf(m); }
std::string_view toString(FogMode m) { return nameOf(m); }
std::string_view toString(CullMode m) { return nameOf(m); }
std::string_view toString(ToneMapping m) { return nameOf(m); }
std::string_view toString(ShadowFilter m) { return nameOf(m); }
std::string_view toString(ProjectionType t) { return nameOf(t); }
std::string_view toString(LightType t) { return nameOf(t); }
bool parse(std::string_view s, ShadingModel& out) { return parseName(s, out); }
bool parse(std::string_view s, ReflectionModel& out) { return parseName(s, out); }
bool parse(std::string_view s, FogMode& out) { return parseName(s, out); }
bool parse(std::string_view s, ProjectionType& out) { return parseName(s, out); }
bool parse(std::string_view s, LightType& out) { return parseName(s, out); }

}   // namespace sg
