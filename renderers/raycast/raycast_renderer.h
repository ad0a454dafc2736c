// raycast_renderer.h - factory for the "raycast" backend (see renderers/renderer.h).
#pragma once

#include "renderers/renderer.h"

namespace rnd {
std::unique_ptr<Renderer> makeRaycastRenderer();
}   // namespace rnd
