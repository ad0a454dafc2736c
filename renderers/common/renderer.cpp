// renderer.cpp - Renderer::render(): the part of every render that is the same for all backends.
#include "renderers/renderer.h"

#include <chrono>
#include <new>

namespace rnd {

namespace {

// The one-sample configuration the second pass of an anti-aliased image renders with: the
// AOVs that were asked for.
RenderConfig onePixelPass(RenderConfig c, AovSet aovs) {
    c.aa = sg::AAMode::None;
    c.msaaSamples = c.ssaaFactor = c.samplesPerPixel = 1;
    c.aovs = aovs;
    return c;
}

// Why a backend without `aov` in its capabilities cannot render a request for it.
const char* cannotFill(Aov aov) {
    switch (aov) {
    case Aov::Depth: return "cannot write depth";
    case Aov::Visibility:
    case Aov::Normal:
    case Aov::Id: return "cannot tell which surface each pixel shows (no visibility buffer)";
    case Aov::Overdraw: return "cannot count fragments per pixel (the overdraw view)";
    case Aov::TraversalCost: return "cannot count BVH nodes and triangles per ray (the cost view)";
    }
    return "cannot fill an AOV";
}

// Why a render that was asked for `aov` fails when the backend did not fill it.
const char* didNotFill(Aov aov) {
    switch (aov) {
    case Aov::Depth: return "the backend did not fill the depth buffer";
    case Aov::Visibility:
    case Aov::Normal:
    case Aov::Id: return "the backend did not fill the visibility buffer";
    case Aov::Overdraw: return "the backend did not fill the overdraw counters";
    case Aov::TraversalCost: return "the backend did not fill the traversal cost counters";
    }
    return "the backend did not fill an AOV";
}

}   // namespace

Device Renderer::device() const { return {true, false, "CPU"}; }

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
    const Capabilities caps = capabilities();
    // Normal and Id are made from the visibility; depth comes with every pass, the others at
    // one sample per pixel.
    const AovSet asked = renderedAovs(request.aovs);
    for (Aov a : asked.list())
        if (!caps.aovs.has(a)) {
            stats.error = cannotFill(a);
            return finish(stats);
        }
    const AovSet oneSample = asked.without(Aov::Depth);
    if (request.singleSample && config.samplesPerPixel > 1) {
        config.aa = sg::AAMode::None;
        config.msaaSamples = config.ssaaFactor = config.samplesPerPixel = 1;
        config.aaUsed = "none";
    }
    const bool onePixel = config.samplesPerPixel == 1;
    config.aovs = onePixel ? oneSample : AovSet{};
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
        if (stats.ok && !onePixel && !oneSample.empty()) {
            // Anti-aliased: the visibility and the counters come from a one-sample pass at the
            // pixel centres.
            Framebuffer vis;
            RenderStats v = doRender(frame, onePixelPass(config, oneSample), vis, control);
            if (!v.ok) {
                stats.ok = false;
                stats.cancelled = v.cancelled;
                stats.error = v.error.empty() ? "visibility pass failed" : v.error;
            } else {
                target.takeVisibilityAndCounters(std::move(vis));
                stats.triangles += v.triangles;
                stats.rays += v.rays;
            }
        }
        for (Aov a : oneSample.list())
            if (stats.ok && !target.has(a)) {
                stats.ok = false;
                stats.error = didNotFill(a);
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

std::vector<float> Renderer::lightVisibilityMany(const sg::FrameInput& frame, int light, const std::vector<sg::vec3>& p,
                                                 const std::vector<sg::vec3>& ng) {
    if (light < 0 || size_t(light) >= frame.lights.size() || p.size() != ng.size()) return {};
    std::vector<float> out(p.size(), 1.0f);
    for (size_t i = 0; i < p.size(); ++i) {
        const std::vector<float> v = lightVisibility(frame, p[i], ng[i]);
        if (v.size() != frame.lights.size()) return {};
        out[i] = v[size_t(light)];
    }
    return out;
}

bool hasFeature(const Capabilities& caps, sg::Feature feature) {
    switch (feature) {
    case sg::Feature::None: return true;
    case sg::Feature::Shadows: return caps.shadows;
    case sg::Feature::ShadowMaps: return caps.shadowMaps;
    case sg::Feature::ShadowRays: return caps.shadowRays;
    case sg::Feature::Reflections: return caps.reflections;
    case sg::Feature::Wireframe: return caps.wireframe;
    }
    return true;
}

bool isSoftwareGLRenderer(std::string_view r) {
    for (std::string_view name : {"llvmpipe", "softpipe", "Software Rasterizer", "swrast", "SWR"})
        if (r.find(name) != std::string_view::npos) return true;
    return false;
}

}   // namespace rnd
