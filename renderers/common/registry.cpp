// registry.cpp - makes backends by name, and picks the one `viewer render` uses by default.
#include "renderers/renderer.h"

#include "gl/gl_renderer.h"
#include "raster/raster_renderer.h"
#include "raycast/raycast_renderer.h"

namespace rnd {

namespace {
const BackendInfo kBackends[] = {
    {"gl", "OpenGL 3.3+ core rasterization (the window's context, or headless EGL)", &makeGlRenderer},
    {"raster", "our CPU rasterizer: clipping, fixed-point edge functions, z-buffer, tiles on oneTBB", &makeRasterRenderer},
    {"raycast", "our CPU ray caster: BVH, exact implicit surfaces and CSG, shadow rays, reflections", &makeRaycastRenderer},
};
}   // namespace

std::span<const BackendInfo> backends() { return kBackends; }

std::vector<std::string> rendererNames() {
    std::vector<std::string> names;
    for (const BackendInfo& b : kBackends) names.emplace_back(b.name);
    return names;
}

std::string rendererNameList(std::string_view last) {
    std::string out;
    const std::vector<std::string> names = rendererNames();
    for (size_t i = 0; i < names.size(); ++i) out += (i == 0 ? "" : i + 1 == names.size() ? " " + std::string(last) + " " : ", ") + names[i];
    return out;
}

std::unique_ptr<Renderer> makeRenderer(std::string_view name, std::string* error) {
    for (const BackendInfo& b : kBackends)
        if (b.name == name) return b.make();
    if (error) {
        std::string valid;
        for (const auto& n : rendererNames()) valid += (valid.empty() ? "" : ", ") + n;
        *error = "unknown backend '" + std::string(name) + "' (valid: " + valid + ")";
    }
    return nullptr;
}

std::unique_ptr<Renderer> makeExactShadowBackend() {
    for (const BackendInfo& b : kBackends) {
        std::unique_ptr<Renderer> r = b.make();
        const Capabilities caps = r->capabilities();
        if (caps.shadowRays && caps.affinity == ContextAffinity::AnyThread) return r;
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
