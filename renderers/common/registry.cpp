// registry.cpp - makes backends by name, and picks the one `viewer render` uses by default.
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

BackendChoice defaultRenderBackend() {
    const std::unique_ptr<Renderer> gl = makeRenderer("gl");
    const Device d = gl->device();
    if (d.usable && !d.softwareEmulated) return {"gl", ""};
    // The CPU rasterizer draws what GL draws (the agreement tests hold them together), and on
    // the CPU it takes less time and memory than GL emulated there (docs/benchmarks.md).
    const std::string why = d.usable ? "OpenGL here is software only (" + d.detail + ")" : "OpenGL cannot render here (" + d.detail + ")";
    return {"raster", why + "; rendering with the CPU rasterizer (raster backend); --backend gl forces GL"};
}

}   // namespace rnd
