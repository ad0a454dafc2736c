// scene_defaults.h - defaults that follow a scene's size, in one place for every way a scene is
// opened (the window, `viewer render`, `compare`, `inspect`, `convert`, the demo): the same file
// and flags give the same image everywhere.
//
// r = half the diagonal of the scene's visible world bounds (1 when it has no geometry).
//   fog: linear from r to 6 r; exponential halving at 3 r (density ln 2 / 3 r); set when the
//        scene's fog is off and still at RenderSettings' defaults (so a file's own fog is kept
//        and turning fog on later shows something in a 1 mm or a 1 km scene); the fog colour
//        is then the background colour, unless the file set one;
//   fly speed: r per second.
// A scene without a camera gets its framing view from Scene::addDefaultCamera (clip planes
// around the same sphere).
#pragma once

#include "scenegraph/scene.h"

namespace sg {

float sceneRadius(const Scene& scene);
// Fog distances and density for a scene of radius r (see above), whatever the fog mode.
void fitFogToScene(RenderSettings& settings, float radius);
// Applies the size-dependent defaults to a freshly loaded scene (fog as above).
void applySceneDefaults(Scene& scene);
float flySpeedFor(const Scene& scene);

}   // namespace sg
