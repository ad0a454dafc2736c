// renderer.h - the interface every backend implements ("gl", "raster", "raycast").
//
// A renderer takes one sg::FrameInput and renders it into a Framebuffer of any size. Slow
// backends render progressively: they write finished tiles straight into the target, report
// progress and check for cancellation between tiles, so callers may run render() on a worker
// thread and show the target as it fills. Backends cache derived data (GPU buffers, BVHs,
// tessellations) keyed by mesh/geometry id + version between calls.
#pragma once

#include "renderers/framebuffer.h"
#include "scenegraph/frame.h"

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace rnd {

struct Capabilities {
    bool progressive = false;      // render() reports progress per tile and can be cancelled
    bool exactImplicits = false;   // implicit shapes/CSG intersected analytically (vs tessellated)
    bool shadows = false;          // honours RenderSettings::shadows
    bool reflections = false;      // honours RenderSettings::reflections
    bool msaa = false;
    bool ssaa = false;
    int maxMsaaSamples = 0;
    bool needsGLContext = false;
};

// Shared between the caller and a render in progress (possibly on another thread).
struct RenderControl {
    std::atomic<bool> cancel{false};
    std::atomic<float> progress{0.0f};   // 0..1
    std::function<void()> onTileDone;    // optional, called from worker threads
};

struct RenderStats {
    bool ok = false;
    bool cancelled = false;
    std::string error;   // one line, when !ok
    double milliseconds = 0;
    uint64_t triangles = 0;   // triangles submitted
    uint64_t rays = 0;        // rays traced (ray caster)
};

class Renderer {
public:
    virtual ~Renderer() = default;
    virtual std::string_view name() const = 0;
    virtual Capabilities capabilities() const = 0;
    // Renders the frame into `target` (resized to width x height). Thread-compatible: one
    // render at a time per renderer instance.
    virtual RenderStats render(const sg::FrameInput& frame, int width, int height, Framebuffer& target, RenderControl* control = nullptr) = 0;
};

// Backend names in display order: {"gl", "raster", "raycast"} (those built).
std::vector<std::string> rendererNames();
// Makes a backend by name; on an unknown name returns null and sets *error to a message that
// lists the valid names.
std::unique_ptr<Renderer> makeRenderer(std::string_view name, std::string* error = nullptr);

}   // namespace rnd
