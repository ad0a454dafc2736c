#include "scenegraph/settings.h"
#include "scenegraph/light.h"

#include <charconv>

namespace sg {

std::string RenderSettings::validate() const {
    auto finite = [](float v) { return std::isfinite(v); };
    if (!finite(fogStart) || !finite(fogEnd) || !finite(fogDensity)) return "fog parameters must be finite";
    if (fog == FogMode::Linear && !(fogEnd > fogStart)) return "linear fog needs end > start";
    if (fogDensity < 0) return "fog density must be >= 0";
    if (aa == AAMode::MSAA && aaRate != 2 && aaRate != 4 && aaRate != 8) return "MSAA rate must be 2, 4 or 8";
    if (aa == AAMode::SSAA && (aaRate < 2 || aaRate > 4)) return "SSAA rate must be 2, 3 or 4";
    if (maxBounces < 0 || maxBounces > 16) return "max bounces must be in 0..16";
    if (tessellation < 4 || tessellation > 512) return "tessellation must be in 4..512";
    if (!isFinite(fogColor) || !isFinite(background) || !isFinite(wireframeColor)) return "colours must be finite";
    return {};
}

std::string RenderSettings::aaName() const {
    switch (aa) {
    case AAMode::None: return "none";
    case AAMode::MSAA: return "msaa" + std::to_string(aaRate);
    case AAMode::SSAA: return "ssaa" + std::to_string(aaRate);
    }
    return "none";
}

bool RenderSettings::setAA(std::string_view name) {
    if (name == "none" || name == "off") {
        aa = AAMode::None;
        return true;
    }
    AAMode mode;
    if (name.substr(0, 4) == "msaa")
        mode = AAMode::MSAA;
    else if (name.substr(0, 4) == "ssaa")
        mode = AAMode::SSAA;
    else
        return false;
    int rate = 0;
    auto rest = name.substr(4);
    auto [p, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), rate);
    if (ec != std::errc() || p != rest.data() + rest.size()) return false;
    if (mode == AAMode::MSAA && rate != 2 && rate != 4 && rate != 8) return false;
    if (mode == AAMode::SSAA && (rate < 2 || rate > 4)) return false;
    aa = mode;
    aaRate = rate;
    return true;
}

std::string_view toString(ShadingModel m) {
    switch (m) {
    case ShadingModel::Flat: return "flat";
    case ShadingModel::Gouraud: return "gouraud";
    case ShadingModel::Phong: return "phong";
    }
    return "?";
}
std::string_view toString(ReflectionModel m) { return m == ReflectionModel::Phong ? "phong" : "blinn"; }
std::string_view toString(FogMode m) {
    switch (m) {
    case FogMode::Off: return "off";
    case FogMode::Linear: return "linear";
    case FogMode::Exp: return "exp";
    case FogMode::Exp2: return "exp2";
    }
    return "?";
}
bool parse(std::string_view s, ShadingModel& out) {
    for (auto m : {ShadingModel::Flat, ShadingModel::Gouraud, ShadingModel::Phong})
        if (s == toString(m)) {
            out = m;
            return true;
        }
    return false;
}
bool parse(std::string_view s, ReflectionModel& out) {
    if (s == "phong") {
        out = ReflectionModel::Phong;
        return true;
    }
    if (s == "blinn" || s == "blinn-phong") {
        out = ReflectionModel::BlinnPhong;
        return true;
    }
    return false;
}
bool parse(std::string_view s, FogMode& out) {
    for (auto m : {FogMode::Off, FogMode::Linear, FogMode::Exp, FogMode::Exp2})
        if (s == toString(m)) {
            out = m;
            return true;
        }
    return false;
}

float fogVisibility(const RenderSettings& s, float d) {
    switch (s.fog) {
    case FogMode::Off: return 1.0f;
    case FogMode::Linear: return std::clamp((s.fogEnd - d) / (s.fogEnd - s.fogStart), 0.0f, 1.0f);
    case FogMode::Exp: return std::exp(-s.fogDensity * d);
    case FogMode::Exp2: {
        float x = s.fogDensity * d;
        return std::exp(-x * x);
    }
    }
    return 1.0f;
}

std::string_view toString(LightType t) {
    switch (t) {
    case LightType::Point: return "point";
    case LightType::Directional: return "directional";
    case LightType::Spot: return "spot";
    }
    return "?";
}
bool parse(std::string_view s, LightType& out) {
    for (auto t : {LightType::Point, LightType::Directional, LightType::Spot})
        if (s == toString(t)) {
            out = t;
            return true;
        }
    return false;
}

}   // namespace sg
