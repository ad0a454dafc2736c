// renderer.h - the contract every backend implements ("gl", "raster", "raycast").
//
// A renderer takes one sg::FrameInput and renders it into a Framebuffer of any size.
// Renderer::render() is the one entry point and is not virtual: it validates the settings,
// checks the size against the backend's Capabilities, resolves one RenderConfig (AA mode and
// the sample count actually used, SSAA factor, tessellation; see render_config.h), checks
// for cancellation, calls the backend's doRender() (twice when visibility or a per-pixel
// counter is asked for an anti-aliased image: the second pass at one sample per pixel), times the call and fills
// RenderStats with what was asked and what was used. Backends implement name(),
// capabilities() and doRender().
//
// Slow backends render progressively: they write finished tiles straight into the target,
// report progress and check for cancellation between tiles, so callers may run render() on a
// worker thread and show the target as it fills. Backends cache derived data (GPU buffers,
// BVHs, tessellations) keyed by mesh/geometry id + version between calls.
#pragma once

#include "renderers/framebuffer.h"
#include "renderers/render_config.h"
#include "scenegraph/frame.h"
#include "scenegraph/params.h"

#include <atomic>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rnd {

// Where render() may be called.
enum class ContextAffinity {
    AnyThread,          // needs nothing from the caller: any thread, any time
    CurrentGLContext,   // renders with the GL context current on the calling thread (e.g. the
                        // window's, so call it on the thread that owns it); with none current
                        // it makes its own headless context, so a worker thread works too
};

// What a backend can do. The UI and the command line decide from these, never from names.
struct Capabilities {
    ContextAffinity affinity = ContextAffinity::AnyThread;
    bool progressive = false;      // render() reports progress per tile and can be cancelled
    bool exactImplicits = false;   // implicit shapes/CSG intersected analytically (vs tessellated)
    bool shadows = false;          // honours RenderSettings::shadows
    bool shadowMaps = false;       // its shadows are shadow maps (RenderSettings::shadowMapSize ... honoured)
    bool shadowRays = false;       // its shadows are shadow rays (RenderSettings::shadowRays honoured)
    bool reflections = false;      // honours RenderSettings::reflections
    bool wireframe = false;        // draws RenderSettings::wireframe
    bool pointsAndLines = false;   // draws meshes of PrimitiveMode::Points / Lines
    // The AOVs (aov.h) it fills: Depth always; Visibility, Overdraw and TraversalCost when a
    // RenderRequest asks for them (Normal and Id are made from the Visibility, never listed).
    AovSet aovs = {Aov::Depth};
    std::vector<int> msaaSamples;     // MSAA sample counts taken as asked, ascending ({} = no MSAA)
    std::vector<int> ssaaFactors;     // SSAA factors taken as asked, ascending ({} = no SSAA)
    bool ssaaRendersLarger = false;   // SSAA renders a factor x larger image (counts against maxImageSize)
    int maxImageSize = 16384;         // largest width or height it renders
};

// What a backend runs on here (Renderer::device()). The CPU backends run natively on the CPU;
// the gl backend runs on whatever OpenGL there is, which may be software emulation of a GPU
// (Mesa llvmpipe/softpipe): every GPU stage then runs on the CPU, slower and larger than the
// CPU rasterizer (docs/benchmarks.md). The command line picks its default backend from this
// (defaultRenderBackend() below), never from a name.
struct Device {
    bool usable = true;              // false: the backend cannot render here (`detail` says why)
    bool softwareEmulated = false;   // a GPU API emulated on the CPU
    std::string detail;              // e.g. "CPU", "llvmpipe (LLVM 15.0.6, 256 bits)", a GPU's GL_RENDERER
};

// Whether a GL_RENDERER string names OpenGL emulated on the CPU: Mesa's llvmpipe, softpipe,
// swrast or OpenSWR (and zink running on one of them). The gl backend's device() uses it for
// its own contexts; the window asks it of the context it made itself.
bool isSoftwareGLRenderer(std::string_view glRenderer);

// Whether a backend with these capabilities draws what a parameter needs (params.h).
bool hasFeature(const Capabilities& caps, sg::Feature feature);

// What RenderControl::progress counts.
enum class RenderStage : int {
    Image,    // the image itself (tiles, rows)
    Shapes,   // before it: analytic shapes tessellated anew (a new tessellation level or new
              // shapes: seconds at the highest levels), weighed by tessellationWork()
};

// Shared between the caller and a render in progress (possibly on another thread).
struct RenderControl {
    std::atomic<bool> cancel{false};
    std::atomic<float> progress{0.0f};   // 0..1 of `stage`; starts again from 0 when the stage changes
    std::atomic<RenderStage> stage{RenderStage::Image};
    std::function<void()> onTileDone;   // optional, called from worker threads
};

// What the caller wants besides the colour image and depth.
struct RenderRequest {
    // The AOVs (aov.h) wanted besides the colour image and depth (which every render fills):
    //   Visibility (Framebuffer::drawable/primitive): what each pixel centre shows (picking,
    //     the pixel inspector, id/normal export); Normal and Id ask for it, as they are made from it.
    //   Overdraw (Framebuffer::overdraw) and TraversalCost (Framebuffer::costNodes/costPrims):
    //     per-pixel counters of the diagnostic views "overdraw" and "cost" (renderers/diagnostic.h).
    // All of them are made at one sample per pixel: with anti-aliasing, render() renders them
    // in a second, one-sample pass, so they never mix surfaces. Backends fill them only when
    // asked, so a render that does not ask pays nothing for them; a backend without one in
    // Capabilities::aovs fails the render with an error saying so.
    AovSet aovs;
    // One sample per pixel at the pixel centres whatever the settings' anti-aliasing asks
    // (stats.config says aa "none"): the first full-resolution image of a caller that refines
    // progressively (ui::RenderSlot), the anti-aliased render following it. The visibility and
    // counters then come from this one pass.
    bool singleSample = false;
};

struct RenderStats {
    bool ok = false;
    bool cancelled = false;
    std::string error;         // one line starting with the backend's name, when !ok
    double milliseconds = 0;   // the whole render() call
    uint64_t triangles = 0;    // triangles submitted
    uint64_t rays = 0;         // rays traced (ray caster)
    int shadowMapsDrawn = 0;   // shadow maps drawn (rasterizers; 0 where the last frame's were kept)
    RenderConfig config;       // what was asked and what was used, with notes
};

class Renderer {
public:
    virtual ~Renderer() = default;
    virtual std::string_view name() const = 0;
    virtual Capabilities capabilities() const = 0;
    // What it runs on here. The gl backend finds out once per process without rendering (it
    // asks EGL for its devices, or makes a context and reads GL_RENDERER); the CPU backends
    // answer {usable, not emulated, "CPU"}.
    virtual Device device() const;

    // Renders the frame into `target` (resized to width x height on success). Thread-compatible:
    // one render at a time per renderer instance (see Capabilities::affinity for which thread).
    // On failure returns ok = false with a one-line error and leaves `target` unspecified.
    RenderStats render(const sg::FrameInput& frame, int width, int height, Framebuffer& target, RenderControl* control = nullptr,
                       const RenderRequest& request = {});

    // For the pixel inspector: the fraction of each of frame.lights that reaches world point p
    // (geometric normal ng, facing the viewer) in this backend, i.e. its shadows; `frame` must
    // be the one of the last successful render(). Empty when the backend draws no shadows for
    // it (every light reaches every point).
    virtual std::vector<float> lightVisibility(const sg::FrameInput& frame, const sg::vec3& p, const sg::vec3& ng);
    // The same for many points and one light (the shadow-map view): the fraction of
    // frame.lights[light] reaching each p[i] (normal ng[i]); empty when the backend draws no
    // shadows for it. The default asks lightVisibility point by point.
    virtual std::vector<float> lightVisibilityMany(const sg::FrameInput& frame, int light, const std::vector<sg::vec3>& p,
                                                   const std::vector<sg::vec3>& ng);

protected:
    // The backend's part: render `frame` with `config` (size, AA, tessellation already resolved
    // and valid for this backend) into `target`. Errors need not name the backend; render()
    // prefixes it. May append to stats.config.notes (e.g. a driver limit found late).
    virtual RenderStats doRender(const sg::FrameInput& frame, const RenderConfig& config, Framebuffer& target, RenderControl* control) = 0;
};

// The backends, one row each in registry.cpp (the only list of them in the code): name, one
// line of help (CLI help, UI tooltips) and the factory. Adding a backend is its folder under
// renderers/ (its CMakeLists.txt registers it with the build) plus one row there.
struct BackendInfo {
    std::string_view name;
    std::string_view help;
    std::unique_ptr<Renderer> (*make)();
};
std::span<const BackendInfo> backends();
// Backend names in display order: {"gl", "raster", "raycast"} (the rows of backends()).
std::vector<std::string> rendererNames();
// "gl, raster or raycast" (with `last` between the last two), for help texts.
std::string rendererNameList(std::string_view last = "or");
// Makes a backend by name; on an unknown name returns null and sets *error to a message that
// lists the valid names.
std::unique_ptr<Renderer> makeRenderer(std::string_view name, std::string* error = nullptr);

// The shadow-map view's reference: the first backend with exact shadow rays
// (Capabilities::shadowRays) that runs on any thread; null when there is none.
std::unique_ptr<Renderer> makeExactShadowBackend();

// The backend `viewer render` uses when none is named: "gl", unless its device() here is
// software emulation of a GPU (Mesa llvmpipe without a GPU) or unusable; then the CPU
// rasterizer ("raster"), and `note` says so in one line (why, and how to force GL).
struct BackendChoice {
    std::string name;
    std::string note;   // "" when the first backend was taken
};
BackendChoice defaultRenderBackend();

}   // namespace rnd
