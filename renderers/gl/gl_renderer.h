// gl_renderer.h - factory for the "gl" backend (see renderers/renderer.h).
#pragma once

#include "renderers/renderer.h"

namespace rnd {
std::unique_ptr<Renderer> makeGlRenderer();
}  // namespace rnd
