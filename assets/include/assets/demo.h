// demo.h - the bundled demo scene: a small room with meshes, a textured object, implicit
// spheres and a quadric, a CSG object, a parametric patch, a density grid, several lights and
// a camera. Built in code, so it needs no files.
#pragma once

#include "scenegraph/scene.h"

namespace assets {

sg::Scene makeDemoScene();
// A procedural checker texture (used by the demo and tests).
std::shared_ptr<sg::Texture> makeCheckerTexture(int size, int checks, sg::vec3 a, sg::vec3 b);

}   // namespace assets
