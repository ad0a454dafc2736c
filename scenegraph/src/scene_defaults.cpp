// scene_defaults.cpp - see scene_defaults.h.
#include "scenegraph/scene_defaults.h"

#include <cmath>

namespace sg {

float sceneRadius(const Scene& scene) {
    Aabb b = scene.worldBounds();
    if (b.empty()) return 1.0f;
    float r = 0.5f * glm::length(b.extent());
    return std::isfinite(r) && r > 1e-6f ? r : 1.0f;
}

void fitFogToScene(RenderSettings& s, float r) {
    s.fogStart = r;
    s.fogEnd = 6.0f * r;
    s.fogDensity = std::log(2.0f) / (3.0f * r);
}

void applySceneDefaults(Scene& scene) {
    RenderSettings& s = scene.settings;
    const RenderSettings defaults;
    if (s.fog == FogMode::Off && s.fogStart == defaults.fogStart && s.fogEnd == defaults.fogEnd && s.fogDensity == defaults.fogDensity) {
        fitFogToScene(s, sceneRadius(scene));
        // Fog that fades into the background, unless the file chose a fog colour.
        if (s.fogColor == defaults.fogColor) s.fogColor = s.background;
    }
}

float flySpeedFor(const Scene& scene) { return sceneRadius(scene); }

}   // namespace sg
