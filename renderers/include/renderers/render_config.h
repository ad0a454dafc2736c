// render_config.h - what a backend actually renders with, resolved once for every backend.
//
// RenderSettings say what the user asked for ("msaa8", tessellation 64, shadows on). A backend
// can honour some of it exactly, some of it approximately (the CPU rasterizer takes 4 MSAA
// samples, a driver may allow fewer), and some not at all (no shadows in a rasterizer).
// resolveRenderConfig() turns settings + a backend's Capabilities into the one configuration
// the backend renders with, and records every difference as a one-line note, so that nothing
// is replaced silently: Renderer::render() calls it, backends read AA and tessellation from
// the RenderConfig (never from RenderSettings::aa/aaRate/tessellation), and the UI shows the
// notes.
#pragma once

#include "renderers/aov.h"
#include "scenegraph/frame.h"

#include <string>
#include <vector>

namespace rnd {

struct Capabilities;

struct RenderConfig {
    int width = 0, height = 0;          // the output image
    sg::AAMode aa = sg::AAMode::None;   // the anti-aliasing mode used
    int msaaSamples = 1;                // MSAA: coverage samples per pixel (1 = off)
    int ssaaFactor = 1;                 // SSAA: factor x factor samples per pixel (1 = off)
    int samplesPerPixel = 1;            // samples (or rays) per pixel actually taken
    int tessellation = 64;              // grid resolution / segments of analytic shapes
    // The AOVs (aov.h) besides colour and depth to fill in this pass: the visibility
    // (Framebuffer::drawable/primitive), fragments rasterized per pixel (Framebuffer::overdraw)
    // and the primary ray's BVH work (Framebuffer::costNodes/costPrims). render() asks for them
    // only with one sample per pixel at the pixel centre (it renders them in a second pass when
    // the image is anti-aliased), so backends write the one surface they see through each
    // pixel centre and count at one sample per pixel.
    AovSet aovs;
    std::string aaAsked = "none";   // RenderSettings::aaName() as asked
    std::string aaUsed = "none";    // the same spelling for what is used
    // Settings the backend does not honour as asked, one line each ("msaa8 -> msaa4: raster
    // takes 4 samples per pixel"); empty when everything is honoured exactly.
    std::vector<std::string> notes;
    // Features asked for that the backend does not draw at all ("shadows", "wireframe", ...).
    std::vector<std::string> unsupported;

    // "msaa4 (4 samples/pixel)" - what the statistics panel shows.
    std::string describe() const;
};

// Resolves the settings of `frame` for a backend with capabilities `caps` at width x height.
// Returns false and sets *error (one line, without the backend's name) when the backend cannot
// render the frame at all: invalid settings, or an image size outside 1..caps.maxImageSize
// (also counting SSAA's larger image where the backend renders one).
// Rules: MSAA takes the largest supported sample count <= the asked one (else the smallest
// supported); SSAA the same with factors; a backend without the mode renders without AA. Each
// such change adds a note. Shadows, reflections, wireframe and points/lines that are asked for
// (or present in the frame) but not drawn by the backend are listed in `unsupported`.
bool resolveRenderConfig(const sg::FrameInput& frame, const Capabilities& caps, int width, int height, RenderConfig& out, std::string* error);

}   // namespace rnd
