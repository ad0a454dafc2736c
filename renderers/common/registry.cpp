// registry.cpp - makes backends by name.
#include "renderers/renderer.h"

#include "gl/gl_renderer.h"
#include "raster/raster_renderer.h"
#include "raycast/raycast_renderer.h"

namespace rnd {

std::vector<std::string> rendererNames() { return {"gl", "raster", "raycast"}; }

std::unique_ptr<Renderer> makeRenderer(std::string_view name, std::string* error) {
    if (name == "gl") return makeGlRenderer();
    if (name == "raster") return makeRasterRenderer();
    if (name == "raycast") return makeRaycastRenderer();
    if (error) {
        std::string valid;
        for (const auto& n : rendererNames()) valid += (valid.empty() ? "" : ", ") + n;
        *error = "unknown backend '" + std::string(name) + "' (valid: " + valid + ")";
    }
    return nullptr;
}

}   // namespace rnd
