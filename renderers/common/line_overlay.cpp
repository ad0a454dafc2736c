// line_overlay.cpp - drawPointsLinesWireframe() (see line_overlay.h).
#include "common/line_overlay.h"

#include "common/window_lines.h"
#include "renderers/shading.h"
#include "renderers/tone_map.h"

#include <algorithm>
#include <cmath>

namespace rnd {

using namespace rnd::lines;
using sg::vec3;
using sg::vec4;

namespace {

// Which drawable and primitive a point or line pixel belongs to (wireframe: none, the
// surface under the edge keeps the pixel's visibility).
struct Provenance {
    uint32_t drawable = 0, primitive = kNoPrimitive;
};

// Where line pixels go: the framebuffer's depth and visibility, and their colour either as bytes
// through the frame's display transform or, when the caller keeps a linear frame (`linear`, rows
// top-down), into it for the caller to encode.
struct LineTarget {
    Framebuffer& fb;
    vec3* linear = nullptr;
    DisplayTransform display;
};

void writeLinePixel(LineTarget& t, int i, int j, float z, const vec3& linear, float bias, const Provenance& from = {}) {
    Framebuffer& fb = t.fb;
    int row = fb.height - 1 - j;
    const size_t at = size_t(row) * fb.width + i;
    if (!fb.overdraw.empty()) ++fb.overdraw[at];   // the overdraw view: every fragment, before the depth test
    float& dst = fb.depth[at];
    if (!(z < dst + bias)) return;   // LESS (wireframe: LEQUAL with a small offset)
    dst = std::min(dst, z);
    if (from.drawable && fb.has(Aov::Visibility)) {
        fb.drawable[at] = from.drawable;
        fb.primitive[at] = from.primitive;
    }
    if (t.linear) {
        t.linear[at] = linear;
        return;
    }
    const vec3 shown = t.display(linear);
    uint8_t* p = fb.pixel(i, row);
    p[0] = toByteSRGB(shown.x);
    p[1] = toByteSRGB(shown.y);
    p[2] = toByteSRGB(shown.z);
    p[3] = 255;
}

// End point of a line: clip position, unfogged linear colour, eye distance (for fog).
struct LineEnd {
    vec4 clip;
    vec3 color;
    float eyeDist;
};

// Draws segment a-b: clipped in clip space, DDA in window space; depth, colour and fog
// distance interpolated perspective-correctly per pixel, fog applied per pixel (as GL does).
void drawSegment(LineTarget& lt, LineEnd a, LineEnd b, const GuardBand& g, const sg::RenderSettings& st, float bias, const Provenance& from = {}) {
    const Framebuffer& fb = lt.fb;
    vec4 ca = a.clip, cb = b.clip;
    float t0 = 0, t1 = 1;
    {
        vec4 ta = ca, tb = cb;
        if (!clipSegment(ta, tb, g)) return;
        // Recover the clip parameters to interpolate the attributes.
        vec4 dd = cb - ca;
        int axis = 0;
        for (int k = 1; k < 4; ++k)
            if (std::fabs(dd[k]) > std::fabs(dd[axis])) axis = k;
        if (dd[axis] != 0) {
            t0 = (ta[axis] - ca[axis]) / dd[axis];
            t1 = (tb[axis] - ca[axis]) / dd[axis];
        }
        ca = ta;
        cb = tb;
    }
    auto lerp = [](const LineEnd& x, const LineEnd& y, float t) {
        return LineEnd{x.clip + t * (y.clip - x.clip), x.color + t * (y.color - x.color), x.eyeDist + t * (y.eyeDist - x.eyeDist)};
    };
    LineEnd ea = lerp(a, b, t0), eb = lerp(a, b, t1);
    vec4 wa = toWindow(ca, fb.width, fb.height), wb = toWindow(cb, fb.width, fb.height);
    const bool fog = st.fog != sg::FogMode::Off;
    drawLineDDA(wa.x, wa.y, wb.x, wb.y, fb.width, fb.height, [&](int i, int j, float t) {
        float z = std::clamp(wa.z + t * (wb.z - wa.z), 0.0f, 1.0f);   // window z: screen-linear
        float tp = t * wb.w / ((1 - t) * wa.w + t * wb.w);            // perspective-correct
        vec3 c = ea.color + tp * (eb.color - ea.color);
        if (fog) c = applyFog(st, c, ea.eyeDist + tp * (eb.eyeDist - ea.eyeDist));
        writeLinePixel(lt, i, j, z, c, bias, from);
    });
}

// One draw's vertices in clip space, world space and their outcodes.
struct Vertices {
    std::vector<vec4> clip;
    std::vector<vec3> world;
    std::vector<uint8_t> code;
};
Vertices transform(const PreparedDraw& d, const sg::FrameInput& f, const GuardBand& g) {
    Vertices v;
    const sg::Mesh& m = *d.mesh;
    const sg::mat4 viewProj = f.camera.proj * f.camera.view;
    v.clip.resize(m.positions.size());
    v.world.resize(m.positions.size());
    v.code.resize(m.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
        vec4 w = *d.world * vec4(m.positions[i], 1.0f);
        v.world[i] = vec3(w);
        v.clip[i] = viewProj * w;
        v.code[i] = outcode(v.clip[i], g);
    }
    return v;
}

void drawPointsAndLines(const PreparedDraw& d, const Vertices& v, const sg::FrameInput& f, LineTarget& lt, float pointSize, const GuardBand& g) {
    const Framebuffer& fb = lt.fb;
    const sg::Mesh& m = *d.mesh;
    const auto& st = f.settings;
    const bool hasColors = m.colors.size() == m.positions.size();
    auto eyeDist = [&](const vec3& wpos) { return glm::length(vec3(f.camera.view * vec4(wpos, 1.0f))); };
    auto end = [&](uint32_t i) {
        vec3 c = d.material->baseColor * (hasColors ? vec3(m.colors[i]) : vec3(1.0f)) + d.material->emissive;
        return LineEnd{v.clip[i], c, eyeDist(v.world[i])};
    };
    const size_t n = m.indices.empty() ? m.positions.size() : m.indices.size();
    auto idx = [&](size_t k) { return m.indices.empty() ? uint32_t(k) : m.indices[k]; };
    if (m.mode == sg::PrimitiveMode::Lines) {
        for (size_t k = 0; k + 1 < n; k += 2) {
            uint32_t ia = idx(k), ib = idx(k + 1);
            if (ia >= v.clip.size() || ib >= v.clip.size() || ((v.code[ia] | v.code[ib]) & kInvalid)) continue;
            drawSegment(lt, end(ia), end(ib), g, st, 0.0f, Provenance{d.drawable, uint32_t(k / 2)});
        }
        return;
    }
    for (size_t k = 0; k < n; ++k) {
        uint32_t ia = idx(k);
        if (ia >= v.clip.size() || v.code[ia] != 0) continue;
        vec4 w = toWindow(v.clip[ia], fb.width, fb.height);
        LineEnd e = end(ia);
        vec3 c = st.fog != sg::FogMode::Off ? applyFog(st, e.color, e.eyeDist) : e.color;
        float h = 0.5f * pointSize;
        int i0 = int(std::ceil(w.x - h - 0.5f)), i1 = int(std::ceil(w.x + h - 0.5f)) - 1;
        int j0 = int(std::ceil(w.y - h - 0.5f)), j1 = int(std::ceil(w.y + h - 0.5f)) - 1;
        for (int j = std::max(j0, 0); j <= std::min(j1, fb.height - 1); ++j)
            for (int i = std::max(i0, 0); i <= std::min(i1, fb.width - 1); ++i)
                writeLinePixel(lt, i, j, std::clamp(w.z, 0.0f, 1.0f), c, 0.0f, Provenance{d.drawable, uint32_t(k)});
    }
}

const sg::Material& materialOf(const PreparedDraw& d, size_t tri) {
    if (d.triangleMaterial && d.materials && tri < d.triangleMaterial->size() && (*d.triangleMaterial)[tri] < d.materials->size())
        return (*d.materials)[(*d.triangleMaterial)[tri]];
    return *d.material;
}

void drawWireframe(const PreparedDraw& d, const Vertices& v, const sg::FrameInput& f, LineTarget& lt, const GuardBand& g) {
    const Framebuffer& fb = lt.fb;
    const sg::Mesh& m = *d.mesh;
    const auto& st = f.settings;
    auto eyeDist = [&](const vec3& wpos) { return glm::length(vec3(f.camera.view * vec4(wpos, 1.0f))); };
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
        const uint32_t i[3] = {m.indices[t], m.indices[t + 1], m.indices[t + 2]};
        if (i[0] >= v.clip.size() || i[1] >= v.clip.size() || i[2] >= v.clip.size()) continue;
        const uint8_t all = v.code[i[0]] & v.code[i[1]] & v.code[i[2]], any = v.code[i[0]] | v.code[i[1]] | v.code[i[2]];
        if (all || (any & kInvalid)) continue;
        if (any == 0 && sg::cullsBackFaces(st.culling, materialOf(d, t / 3).doubleSided)) {
            // Culled faces draw no edges (GL culls polygons in line mode too).
            vec4 a = toWindow(v.clip[i[0]], fb.width, fb.height), b = toWindow(v.clip[i[1]], fb.width, fb.height),
                 c = toWindow(v.clip[i[2]], fb.width, fb.height);
            float area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
            if ((area > 0) == d.mirrored) continue;
        }
        for (int k = 0; k < 3; ++k) {
            LineEnd a{v.clip[i[k]], st.wireframeColor, eyeDist(v.world[i[k]])};
            LineEnd b{v.clip[i[(k + 1) % 3]], st.wireframeColor, eyeDist(v.world[i[(k + 1) % 3]])};
            drawSegment(lt, a, b, g, st, 2e-4f);
        }
    }
}

}   // namespace

void drawPointsLinesWireframe(const std::vector<PreparedDraw>& draws, const sg::FrameInput& f, Framebuffer& fb, float pointSize, sg::vec3* linear) {
    const GuardBand g = guardBand(fb.width, fb.height);
    LineTarget lt{fb, linear, DisplayTransform(f.settings)};
    for (const PreparedDraw& d : draws) {
        const bool tris = d.mesh->mode == sg::PrimitiveMode::Triangles;
        if (tris && !f.settings.wireframe) continue;
        const Vertices v = transform(d, f, g);
        if (tris)
            drawWireframe(d, v, f, lt, g);
        else
            drawPointsAndLines(d, v, f, lt, pointSize, g);
    }
}

}   // namespace rnd
