// pixel_probe.cpp - probeAt(), pickAt(), outlineNodes(), probeSummary() (see pixel_probe.h).
#include "ui/pixel_probe.h"

#include "renderers/shading.h"
#include "scenegraph/instances.h"
#include "ui/render_slot.h"
#include "ui/viewer_state.h"

#include <algorithm>
#include <cstdio>

namespace ui {

namespace {

bool pixelOf(const rnd::Framebuffer& fb, float u, float v, int& x, int& y) {
    if (u < 0 || v < 0 || u >= 1 || v >= 1 || fb.width < 1 || fb.height < 1) return false;
    // + 1e-3: a pixel's own edge (u = 12 / width) must not round down into its neighbour.
    x = std::clamp(int(u * float(fb.width) + 1e-3f), 0, fb.width - 1);
    y = std::clamp(int(v * float(fb.height) + 1e-3f), 0, fb.height - 1);
    return true;
}

bool isUnder(const sg::Scene& scene, sg::NodeId n, sg::NodeId ancestor) {
    for (int depth = 0; n != sg::kNoNode && scene.valid(n) && depth < 100000; ++depth) {
        if (n == ancestor) return true;
        n = scene.node(n).parent;
    }
    return false;
}

}   // namespace

ProbeResult probeAt(const ViewerState& st, const ProbeImage& im, float u, float v) {
    ProbeResult r;
    r.backend = im.backend;
    if (!im.image || !im.frame || !pixelOf(*im.image, u, v, r.x, r.y)) return r;
    const uint8_t* px = im.image->pixel(r.x, r.y);
    std::copy(px, px + 3, r.rgb);
    if (!im.image->has(rnd::Aov::Visibility)) return r;
    r.valid = true;
    const sg::InstanceTable ids = sg::instanceTable(*im.frame);
    r.surface = rnd::surfaceAt(*im.frame, ids, *im.image, r.x, r.y);
    if (!r.surface.hit) return r;
    std::vector<float> shadows;
    if (im.slot && im.slot->capabilities().shadows && im.frame->settings.shadows) {
        shadows = im.slot->lightVisibility(r.surface.position, r.surface.geometricNormal);
        r.shadowsKnown = !shadows.empty() || im.frame->lights.empty();
    } else {
        r.shadowsKnown = true;   // the backend draws no shadows: every light reaches
    }
    r.terms = rnd::pixelTerms(*im.frame, r.surface, shadows);
    const sg::Scene& scene = st.doc.scene;
    if (scene.valid(r.surface.node)) {
        r.node = scene.node(r.surface.node).name;
        r.path = sg::nodePath(scene, r.surface.node);
    }
    return r;
}

sg::NodeId pickAt(const ProbeImage& im, float u, float v) {
    int x = 0, y = 0;
    if (!im.image || !im.frame || !im.image->has(rnd::Aov::Visibility) || !pixelOf(*im.image, u, v, x, y)) return sg::kNoNode;
    const uint32_t d = im.image->drawable[size_t(y) * im.image->width + x];
    return d ? sg::instanceTable(*im.frame).nodeOf(d) : sg::kNoNode;
}

void outlineNodes(rnd::Framebuffer& fb, const sg::FrameInput& frame, const sg::Scene& scene, const std::vector<sg::NodeId>& nodes) {
    if (!fb.has(rnd::Aov::Visibility) || nodes.empty()) return;
    const sg::InstanceTable ids = sg::instanceTable(frame);
    std::vector<uint8_t> drawableSelected(ids.ofDrawable.size(), 0);
    for (size_t k = 1; k < ids.ofDrawable.size(); ++k)
        for (sg::NodeId node : nodes)
            drawableSelected[k] = drawableSelected[k] || (scene.valid(node) && isUnder(scene, ids.nodeOf(uint32_t(k)), node));
    const int w = fb.width, h = fb.height;
    std::vector<uint8_t> in(size_t(w) * h);
    for (size_t k = 0; k < in.size(); ++k) {
        const uint32_t d = fb.drawable[k];
        in[k] = d < drawableSelected.size() && drawableSelected[d];
    }
    // Outline: selected pixels within 2 pixels of an unselected one (and the image border).
    static constexpr uint8_t kColour[3] = {255, 160, 40};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!in[size_t(y) * w + x]) continue;
            bool edge = false;
            for (int dy = -2; dy <= 2 && !edge; ++dy)
                for (int dx = -2; dx <= 2 && !edge; ++dx) {
                    const int i = x + dx, j = y + dy;
                    edge = i < 0 || j < 0 || i >= w || j >= h || !in[size_t(j) * w + i];
                }
            if (edge) std::copy(kColour, kColour + 3, fb.pixel(x, y));
        }
}

std::string probeSummary(const PixelProbeState& p) {
    std::string out;
    for (const ProbeResult& r : p.results) {
        char buf[320];
        const sg::vec3& c = r.terms.predicted;
        if (!r.valid)
            std::snprintf(buf, sizeof buf, "%s %d %d no-visibility", r.backend.c_str(), r.x, r.y);
        else if (!r.surface.hit)
            std::snprintf(buf, sizeof buf, "%s %d %d rgb %d %d %d background", r.backend.c_str(), r.x, r.y, r.rgb[0], r.rgb[1], r.rgb[2]);
        else
            std::snprintf(buf, sizeof buf, "%s %d %d rgb %d %d %d node %s triangle %d depth %.4f predicted %d %d %d", r.backend.c_str(), r.x, r.y,
                          r.rgb[0], r.rgb[1], r.rgb[2], r.path.c_str(), r.surface.triangle ? int(r.surface.primitive) : -1, r.surface.opticalDepth,
                          rnd::toByteSRGB(c.x), rnd::toByteSRGB(c.y), rnd::toByteSRGB(c.z));
        out += out.empty() ? "" : "\n";
        out += buf;
    }
    return out;
}

}   // namespace ui
