// renderer.cpp - Renderer::render(): the part of every render that is the same for all backends.
#include "renderers/renderer.h"

#include <chrono>
#include <new>

namespace rnd {

namespace {

// The one-sample configuration the visibility pass of an anti-aliased image renders with.
RenderConfig visibilityPass(RenderConfig c) {
    c.aa = sg::AAMode::None;
    c.msaaSamples = c.ssaaFactor = c.samplesPerPixel = 1;
    c.visibility = true;
    return c;
}

}   // namespace

RenderStats Renderer::render(const sg::FrameInput& frame, int width, int height, Framebuffer& target, RenderControl* control,
                             const RenderRequest& request) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string prefix = std::string(name()) + ": ";
    RenderStats stats;
    auto finish = [&](RenderStats& s) -> RenderStats& {
        if (!s.ok && !s.error.empty() && s.error.compare(0, prefix.size(), prefix) != 0) s.error = prefix + s.error;
        if (!s.ok && s.error.empty()) s.error = prefix + (s.cancelled ? "cancelled" : "render failed");
        s.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return s;
    };

    RenderConfig config;
    std::string error;
    if (!resolveRenderConfig(frame, capabilities(), width, height, config, &error)) {
        stats.error = error;
        return finish(stats);
    }
    if (request.visibility && !capabilities().visibility) {
        stats.error = "cannot tell which surface each pixel shows (no visibility buffer)";
        return finish(stats);
    }
    config.visibility = request.visibility && config.samplesPerPixel == 1;
    stats.config = config;
    if (control && control->cancel.load()) {
        stats.cancelled = true;
        return finish(stats);
    }
    if (control) control->progress = 0.0f;
    try {
        RenderStats done = doRender(frame, config, target, control);
        // Keep the resolved configuration; add what the backend found on the way.
        for (std::string& n : done.config.notes) stats.config.notes.push_back(std::move(n));
        done.config = std::move(stats.config);
        stats = std::move(done);
        if (stats.ok && request.visibility && !config.visibility) {
            // Anti-aliased: the visibility comes from a one-sample pass at the pixel centres.
            Framebuffer vis;
            RenderStats v = doRender(frame, visibilityPass(config), vis, control);
            if (!v.ok) {
                stats.ok = false;
                stats.cancelled = v.cancelled;
                stats.error = v.error.empty() ? "visibility pass failed" : v.error;
            } else {
                target.drawable = std::move(vis.drawable);
                target.primitive = std::move(vis.primitive);
                stats.triangles += v.triangles;
                stats.rays += v.rays;
            }
        }
        if (stats.ok && request.visibility && !target.hasVisibility()) {
            stats.ok = false;
            stats.error = "the backend did not fill the visibility buffer";
        }
    } catch (const std::bad_alloc&) {
        stats.ok = false;
        stats.error = "out of memory at " + std::to_string(width) + "x" + std::to_string(height);
    } catch (const std::exception& e) {
        stats.ok = false;
        stats.error = e.what();
    }
    if (stats.ok && control) control->progress = 1.0f;
    return finish(stats);
}

std::vector<float> Renderer::lightVisibility(const sg::FrameInput&, const sg::vec3&, const sg::vec3&) { return {}; }

}   // namespace rnd
