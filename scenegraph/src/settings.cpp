// settings.cpp - RenderSettings::validate() (the parameter table's ranges plus the rules that
// span fields: linear fog needs end > start, MSAA 2/4/8, SSAA 2 to 4), the anti-aliasing choice
// by name (aaName / setAA; the names are in setting_names.cpp) and fogVisibility(), the fog
// factor f(d) of docs/math.md.
#include "scenegraph/settings.h"
#include "scenegraph/params.h"
#include "scenegraph/setting_names.h"

#include <algorithm>
#include <cmath>

namespace sg {

std::string RenderSettings::validate() const {
    if (std::string err = checkParams(*this); !err.empty()) return err;
    if (fog == FogMode::Linear && !(fogEnd > fogStart)) return "linear fog needs end > start";
    if (aa == AAMode::MSAA && aaRate != 2 && aaRate != 4 && aaRate != 8) return "MSAA rate must be 2, 4 or 8";
    if (aa == AAMode::SSAA && (aaRate < 2 || aaRate > 4)) return "SSAA rate must be 2, 3 or 4";
    return {};
}

std::string RenderSettings::aaName() const { return std::string(nameOf(aaChoice(*this))); }

bool RenderSettings::setAA(std::string_view name) {
    AAChoice c;
    if (!parseName(name, c)) return false;
    aa = c.mode;
    if (c.mode != AAMode::None) aaRate = c.rate;   // none keeps the rate for switching back on
    return true;
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

}   // namespace sg
