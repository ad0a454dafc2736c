// diagnostic.cpp - diagnosticImage() and the view names (see diagnostic.h).
#include "renderers/diagnostic.h"

#include "renderers/inspect.h"
#include "renderers/shadow_map_view.h"
#include "scenegraph/camera_model.h"
#include "scenegraph/instances.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace rnd {

namespace {

using sg::vec3;
using sg::vec4;

constexpr std::array<std::pair<DiagnosticView, std::string_view>, 9> kNames = {{{DiagnosticView::Shaded, "shaded"},
                                                                                {DiagnosticView::Depth, "depth"},
                                                                                {DiagnosticView::Normal, "normal"},
                                                                                {DiagnosticView::Id, "id"},
                                                                                {DiagnosticView::Uv, "uv"},
                                                                                {DiagnosticView::Triangles, "triangles"},
                                                                                {DiagnosticView::Overdraw, "overdraw"},
                                                                                {DiagnosticView::Cost, "cost"},
                                                                                {DiagnosticView::ShadowMap, "shadow-map"}}};

void put(Framebuffer& fb, size_t k, float r, float g, float b) {
    uint8_t* p = &fb.color[4 * k];
    p[0] = uint8_t(std::lround(std::clamp(r, 0.0f, 1.0f) * 255.0f));
    p[1] = uint8_t(std::lround(std::clamp(g, 0.0f, 1.0f) * 255.0f));
    p[2] = uint8_t(std::lround(std::clamp(b, 0.0f, 1.0f) * 255.0f));
    p[3] = 255;
}

// Blue -> cyan -> green -> yellow -> red for t in [0, 1].
vec3 heat(float t) {
    t = std::clamp(t, 0.0f, 1.0f);
    const vec3 stops[5] = {{0.1f, 0.2f, 0.9f}, {0.0f, 0.8f, 0.9f}, {0.1f, 0.85f, 0.2f}, {0.95f, 0.9f, 0.1f}, {0.95f, 0.15f, 0.1f}};
    const float x = t * 4.0f;
    const int i = std::min(int(x), 3);
    return glm::mix(stops[i], stops[i + 1], x - float(i));
}

// A well-spread colour per instance id (golden-ratio hue steps), never black.
vec3 idColour(uint32_t id) {
    const float h = std::fmod(float(id) * 0.61803398875f, 1.0f) * 6.0f;
    const float s = 0.65f + 0.35f * float((id / 7) % 2), v = 0.95f - 0.25f * float((id / 3) % 2);
    const float c = v * s, x = c * (1.0f - std::fabs(std::fmod(h, 2.0f) - 1.0f)), m = v - c;
    vec3 rgb = h < 1 ? vec3(c, x, 0) : h < 2 ? vec3(x, c, 0) : h < 3 ? vec3(0, c, x) : h < 4 ? vec3(0, x, c) : h < 5 ? vec3(x, 0, c) : vec3(c, 0, x);
    return rgb + m;
}

// Projected area (pixels) of mesh triangle `tri` of drawable `dm`; 0 when it cannot be projected.
float projectedArea(const sg::FrameInput& f, const sg::DrawMesh& dm, uint32_t tri, int w, int h) {
    const sg::Mesh& m = *dm.mesh;
    if (size_t(tri) * 3 + 2 >= m.indices.size()) return 0.0f;
    vec3 win[3];
    for (int c = 0; c < 3; ++c) {
        const uint32_t i = m.indices[size_t(tri) * 3 + size_t(c)];
        if (i >= m.positions.size()) return 0.0f;
        vec4 clip = f.camera.viewProj * dm.world * vec4(m.positions[i], 1.0f);
        if (!(clip.w > 0)) return 0.0f;
        win[c] = vec3((clip.x / clip.w * 0.5f + 0.5f) * float(w), (clip.y / clip.w * 0.5f + 0.5f) * float(h), 0.0f);
    }
    return 0.5f * std::fabs((win[1].x - win[0].x) * (win[2].y - win[0].y) - (win[1].y - win[0].y) * (win[2].x - win[0].x));
}

std::string format(const char* fmt, double a, double b) {
    char buf[160];
    std::snprintf(buf, sizeof buf, fmt, a, b);
    return buf;
}

}   // namespace

std::vector<std::string_view> diagnosticViewNames() {
    std::vector<std::string_view> v;
    for (const auto& [view, name] : kNames) v.push_back(name);
    return v;
}

bool parseDiagnosticView(std::string_view name, DiagnosticView& out) {
    for (const auto& [view, n] : kNames)
        if (n == name) {
            out = view;
            return true;
        }
    return false;
}

std::string_view nameOf(DiagnosticView v) {
    for (const auto& [view, n] : kNames)
        if (view == v) return n;
    return "shaded";
}

AovSet aovsFor(DiagnosticView view) {
    switch (view) {
    case DiagnosticView::Shaded: return {};
    case DiagnosticView::Overdraw: return {Aov::Overdraw};
    case DiagnosticView::Cost: return {Aov::TraversalCost};
    default: return {Aov::Visibility};
    }
}

bool diagnosticViewSupported(DiagnosticView view, const Capabilities& caps) {
    if (view == DiagnosticView::ShadowMap && !caps.shadowMaps) return false;   // (and the visibility its points come from)
    return caps.aovs.hasAll(aovsFor(view));
}

void requestFor(DiagnosticView view, RenderRequest& request) { request.aovs.add(aovsFor(view)); }

DiagnosticImage diagnosticImage(DiagnosticView view, const sg::FrameInput& f, const Framebuffer& fb) {
    DiagnosticImage out;
    bool counts = true;
    for (Aov a : aovsFor(view).list()) counts = counts && fb.has(a);
    if (view == DiagnosticView::Shaded || !counts) {
        out.image = fb;
        out.image.drawable.clear();
        out.image.primitive.clear();
        out.image.overdraw.clear();
        out.image.costNodes.clear();
        out.image.costPrims.clear();
        const char* missing = view == DiagnosticView::Overdraw ? "no fragment counts"
                              : view == DiagnosticView::Cost   ? "no traversal counts"
                                                               : "no visibility";
        out.legend = view == DiagnosticView::Shaded ? "" : std::string(nameOf(view)) + ": " + missing + " for this image yet";
        return out;
    }
    if (view == DiagnosticView::ShadowMap)   // without the backends' answers: the map's texels and the inset
        return shadowMapViewImage(f, fb, shadowMapViewPoints(f, fb, shadowMapViewLight(f)), {}, {});
    const int w = fb.width, h = fb.height;
    const size_t n = size_t(w) * h;
    out.image.resize(w, h);
    for (size_t k = 0; k < n; ++k) out.image.color[4 * k + 3] = 255;
    const sg::InstanceTable ids = sg::instanceTable(f);
    const size_t M = f.meshes.size();
    switch (view) {
    case DiagnosticView::Depth: {
        const std::vector<float> d = sg::opticalDepthMap(f.camera, w, h, fb.depth);
        float lo = INFINITY, hi = 0;
        for (size_t k = 0; k < n; ++k)
            if (fb.drawable[k] && d[k] > 0) lo = std::min(lo, d[k]), hi = std::max(hi, d[k]);
        if (!(hi > 0)) break;
        const float span = std::max(hi - lo, 1e-6f);
        for (size_t k = 0; k < n; ++k)
            if (fb.drawable[k] && d[k] > 0) {
                const float g = 1.0f - 0.85f * (d[k] - lo) / span;
                put(out.image, k, g, g, g);
            }
        out.legend = format("depth along the optical axis: %.3f (white) .. %.3f (dark grey) scene units", lo, hi);
        break;
    }
    case DiagnosticView::Normal: {
        const std::vector<vec3> nrm = normalImage(f, ids, fb);
        for (size_t k = 0; k < n; ++k)
            if (fb.drawable[k]) put(out.image, k, 0.5f * nrm[k].x + 0.5f, 0.5f * nrm[k].y + 0.5f, 0.5f * nrm[k].z + 0.5f);
        out.legend = "world normal: RGB = 0.5 n + 0.5 (+x red, +y green, +z blue)";
        break;
    }
    case DiagnosticView::Id: {
        for (size_t k = 0; k < n; ++k)
            if (const uint32_t id = ids.instanceOf(fb.drawable[k])) {
                const vec3 c = idColour(id);
                put(out.image, k, c.x, c.y, c.z);
            }
        out.legend = std::to_string(ids.node.size() - 1) + " instances, one colour each (hover for the node)";
        break;
    }
    case DiagnosticView::Uv: {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t k = size_t(y) * w + x;
                if (!fb.drawable[k]) continue;
                const SurfaceAt s = surfaceAt(f, ids, fb, x, y);
                if (!s.hasUv)
                    put(out.image, k, 0.6f, 0.0f, 0.6f);
                else
                    put(out.image, k, s.uv.x - std::floor(s.uv.x), s.uv.y - std::floor(s.uv.y), 0.0f);
            }
        out.legend = "uv: red = frac(u), green = frac(v); magenta: no texture coordinates";
        break;
    }
    case DiagnosticView::Triangles: {
        for (size_t k = 0; k < n; ++k) {
            const uint32_t d = fb.drawable[k];
            if (!d) continue;
            if (d > M || fb.primitive[k] == kNoPrimitive || !f.meshes[d - 1].mesh || f.meshes[d - 1].mesh->mode != sg::PrimitiveMode::Triangles) {
                put(out.image, k, 0.35f, 0.35f, 0.35f);   // analytic shapes, points, lines: no triangles of their own
                continue;
            }
            const float area = projectedArea(f, f.meshes[d - 1], fb.primitive[k], w, h);
            const float density = area > 0 ? 1.0f / area : 1.0f;
            const vec3 c = heat((std::log10(std::max(density, 1e-3f)) + 3.0f) / 3.0f);
            put(out.image, k, c.x, c.y, c.z);
        }
        out.legend = "triangles per pixel (1 / projected area), log scale: blue 0.001, cyan 0.006, green 0.03, yellow 0.18, red >= 1; grey: analytic";
        break;
    }
    case DiagnosticView::Overdraw: {
        uint32_t most = 0;
        uint64_t sum = 0, covered = 0;
        for (size_t k = 0; k < n; ++k) {
            const uint32_t c = fb.overdraw[k];
            if (!c) continue;
            most = std::max(most, c);
            sum += c;
            ++covered;
            // Bands, as the legend names them: 1 blue, 2 cyan, 3-4 green, 5-7 yellow, 8+ red.
            const float band = c == 1 ? 0.0f : c == 2 ? 0.25f : c <= 4 ? 0.5f : c <= 7 ? 0.75f : 1.0f;
            const vec3 col = heat(band);
            put(out.image, k, col.x, col.y, col.z);
        }
        out.legend = "overdraw (fragments per pixel before the depth test): 1 blue, 2 cyan, 3-4 green, 5-7 yellow, 8+ red; black: none; max " +
                     std::to_string(most) +
                     format(", mean %.2f over %.0f covered pixels", covered ? double(sum) / double(covered) : 0.0, double(covered));
        break;
    }
    case DiagnosticView::Cost: {
        uint32_t most = 0;
        uint64_t nodes = 0, prims = 0;
        for (size_t k = 0; k < n; ++k) {
            most = std::max(most, fb.costNodes[k] + fb.costPrims[k]);
            nodes += fb.costNodes[k];
            prims += fb.costPrims[k];
        }
        const float top = std::log(float(std::max(most, 2u)));
        for (size_t k = 0; k < n; ++k)
            if (const uint32_t work = fb.costNodes[k] + fb.costPrims[k]) {
                const vec3 col = heat(std::log(float(work)) / top);
                put(out.image, k, col.x, col.y, col.z);
            }
        out.legend = "cost (BVH nodes visited + triangles tested by the primary ray), log scale: 1 blue .. " + std::to_string(most) + " red" +
                     format("; mean %.1f nodes, %.1f triangles per pixel", double(nodes) / double(n), double(prims) / double(n));
        break;
    }
    case DiagnosticView::Shaded:
    case DiagnosticView::ShadowMap: break;
    }
    return out;
}

}   // namespace rnd
