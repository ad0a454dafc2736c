// raster_renderer.h - factory for the "raster" backend (see renderers/renderer.h).
#pragma once

#include "renderers/renderer.h"

namespace rnd {
std::unique_ptr<Renderer> makeRasterRenderer();
}   // namespace rnd
