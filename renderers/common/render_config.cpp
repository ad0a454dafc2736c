// render_config.cpp - resolveRenderConfig(): settings + capabilities -> what is rendered.
#include "renderers/render_config.h"

#include "renderers/renderer.h"
#include "scenegraph/setting_names.h"

#include <algorithm>

namespace rnd {

namespace {

// The largest supported value <= asked, else the smallest supported (0 when none).
int pick(const std::vector<int>& supported, int asked) {
    int best = 0;
    for (int v : supported)
        if (v <= asked) best = std::max(best, v);
    if (best == 0 && !supported.empty()) best = *std::min_element(supported.begin(), supported.end());
    return best;
}

std::string joined(const std::vector<int>& v) {
    std::string s;
    for (int x : v) s += (s.empty() ? "" : "/") + std::to_string(x);
    return s;
}

bool hasPointsOrLines(const sg::FrameInput& f) {
    for (const sg::DrawMesh& d : f.meshes)
        if (d.mesh && d.mesh->mode != sg::PrimitiveMode::Triangles) return true;
    return false;
}

}   // namespace

std::string RenderConfig::describe() const {
    std::string s = aaUsed;
    if (samplesPerPixel > 1) s += " (" + std::to_string(samplesPerPixel) + " samples/pixel)";
    if (aaUsed != aaAsked) s += ", asked " + aaAsked;
    return s;
}

bool resolveRenderConfig(const sg::FrameInput& frame, const Capabilities& caps, int width, int height, RenderConfig& out, std::string* error) {
    auto fail = [&](std::string msg) {
        if (error) *error = std::move(msg);
        return false;
    };
    const sg::RenderSettings& s = frame.settings;
    if (std::string e = s.validate(); !e.empty()) return fail(e);

    RenderConfig c;
    c.width = width;
    c.height = height;
    c.tessellation = s.tessellation;   // validate() keeps it in a range every backend takes
    c.aaAsked = s.aaName();

    // Anti-aliasing.
    if (s.aa == sg::AAMode::MSAA) {
        int n = pick(caps.msaaSamples, s.aaRate);
        if (n > 1) {
            c.aa = sg::AAMode::MSAA;
            c.msaaSamples = n;
            if (n != s.aaRate)
                c.notes.push_back(c.aaAsked + " -> " + std::string(sg::nameOf(sg::AAChoice{sg::AAMode::MSAA, n})) + ": takes " +
                                  joined(caps.msaaSamples) + " MSAA samples per pixel");
        } else {
            c.notes.push_back(c.aaAsked + " -> none: no MSAA in this backend");
        }
    } else if (s.aa == sg::AAMode::SSAA) {
        int f = pick(caps.ssaaFactors, s.aaRate);
        if (f > 1) {
            c.aa = sg::AAMode::SSAA;
            c.ssaaFactor = f;
            if (f != s.aaRate) c.notes.push_back(c.aaAsked + " -> ssaa" + std::to_string(f) + ": takes SSAA factors " + joined(caps.ssaaFactors));
        } else {
            c.notes.push_back(c.aaAsked + " -> none: no SSAA in this backend");
        }
    }
    c.samplesPerPixel = c.msaaSamples * c.ssaaFactor * c.ssaaFactor;
    c.aaUsed = sg::nameOf(sg::AAChoice{c.aa, c.aa == sg::AAMode::MSAA ? c.msaaSamples : c.aa == sg::AAMode::SSAA ? c.ssaaFactor : 0});

    // Size: the output, and SSAA's larger image where the backend renders one.
    const int maxSize = std::max(caps.maxImageSize, 1);
    if (width < 1 || height < 1 || width > maxSize || height > maxSize)
        return fail("image size " + std::to_string(width) + "x" + std::to_string(height) + " is out of range 1.." + std::to_string(maxSize));
    if (caps.ssaaRendersLarger && c.ssaaFactor > 1 && (int64_t(width) * c.ssaaFactor > maxSize || int64_t(height) * c.ssaaFactor > maxSize))
        return fail(c.aaUsed + " renders " + std::to_string(int64_t(width) * c.ssaaFactor) + "x" + std::to_string(int64_t(height) * c.ssaaFactor) +
                    ", more than the limit of " + std::to_string(maxSize) + " per side");

    // Features asked for (or present in the frame) that the backend does not draw.
    if (s.shadows && !caps.shadows) c.unsupported.push_back("shadows");
    if (s.reflections && !caps.reflections) c.unsupported.push_back("reflections");
    if (s.wireframe && !caps.wireframe) c.unsupported.push_back("wireframe");
    if (!caps.pointsAndLines && hasPointsOrLines(frame)) c.unsupported.push_back("points/lines");

    out = std::move(c);
    return true;
}

}   // namespace rnd
