// shadow_map_view.cpp - the shadow-map view (see shadow_map_view.h): the points of the image, the
// comparison of the backend's map answers with the ray caster's, the texel checkerboard and its
// density, and the inset of what the light sees.
#include "renderers/shadow_map_view.h"

#include "renderers/inspect.h"
#include "renderers/shading.h"
#include "renderers/shadow_map.h"
#include "renderers/tessellate.h"
#include "scenegraph/instances.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace rnd {

namespace {

using sg::vec3;
using sg::vec4;

void put(Framebuffer& fb, size_t k, const vec3& c) {
    auto byte = [](float v) { return uint8_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); };
    fb.color[4 * k + 0] = byte(c.x);
    fb.color[4 * k + 1] = byte(c.y);
    fb.color[4 * k + 2] = byte(c.z);
    fb.color[4 * k + 3] = 255;
}

ShadowPlan planOf(const sg::FrameInput& f) { return planShadows(f, shadowCasterBounds(f)); }

// Where p falls in light `light`'s maps: the view, and (u, v) in [0, 1) inside it.
struct MapPos {
    int view = -1;
    float u = 0, v = 0;
    bool inside = false;
};
MapPos mapPos(const ShadowPlan& plan, const sg::DrawLight& L, int light, const vec3& p) {
    MapPos m;
    m.view = plan.firstView[size_t(light)] + (L.type == sg::LightType::Point ? pointLightFace(p - L.position) : 0);
    const vec4 c = plan.views[size_t(m.view)].viewProj * vec4(p, 1.0f);
    if (!(c.w > 0.0f)) return m;
    m.u = 0.5f * c.x / c.w + 0.5f;
    m.v = 0.5f * c.y / c.w + 0.5f;
    m.inside = m.u >= 0.0f && m.u < 1.0f && m.v >= 0.0f && m.v < 1.0f;
    return m;
}

// What the light sees, for the inset: the frame's casters (analytic shapes coarsely
// tessellated) in world space, drawn by the CPU depth pass at the inset's size.
struct InsetCasters {
    std::vector<std::vector<float>> positions;
    std::vector<std::shared_ptr<const sg::Mesh>> keep;
    std::vector<ShadowCaster> casters;
    void add(const sg::Mesh& m, const sg::mat4* world) {
        if (m.mode != sg::PrimitiveMode::Triangles || m.indices.size() < 3 || m.positions.empty()) return;
        std::vector<float>& xyz = positions.emplace_back();
        xyz.reserve(3 * m.positions.size());
        for (const vec3& q : m.positions) {
            const vec3 w = world ? vec3(*world * vec4(q, 1.0f)) : q;
            xyz.insert(xyz.end(), {w.x, w.y, w.z});
        }
        ShadowCaster c;
        c.positions = xyz.data();
        c.idx = m.indices.data();
        c.triangles = m.indices.size() / 3;
        c.vertices = m.positions.size();
        casters.push_back(c);
    }
};
InsetCasters insetCasters(const sg::FrameInput& f) {
    InsetCasters ic;
    ic.positions.reserve(f.meshes.size() + f.analytics.size());   // (casters point into them)
    for (const sg::DrawMesh& d : f.meshes)
        if (d.mesh && castsShadow(d.material)) ic.add(*d.mesh, &d.world);
    for (const sg::DrawAnalytic& a : f.analytics) {
        if (!castsShadow(a.material)) continue;
        Tessellation t = tessellate(a, 24);
        if (!t.mesh) continue;
        ic.keep.push_back(t.mesh);
        ic.add(*t.mesh, t.worldSpace ? nullptr : &a.world);
    }
    return ic;
}

void drawInset(const sg::FrameInput& f, const ShadowPlan& plan, int light, const std::vector<MapPos>& where, Framebuffer& img) {
    const bool point = f.lights[size_t(light)].type == sg::LightType::Point;
    const int faces = plan.viewCount[size_t(light)], cols = point ? 3 : 1;
    const int side = std::clamp(std::min(img.width, img.height) / 3, 16, 256);
    const int fs = point ? std::max(side / 2, 8) : side;
    const int x0 = 8, y0 = 8;
    if (x0 + cols * fs + 1 > img.width || y0 + (faces / cols) * fs + 1 > img.height) return;   // too small an image
    const InsetCasters ic = insetCasters(f);
    std::vector<float> depth(size_t(fs) * fs);
    std::vector<uint8_t> used(size_t(fs) * fs);
    for (int face = 0; face < faces; ++face) {
        const int view = plan.firstView[size_t(light)] + face;
        renderShadowDepth(plan.views[size_t(view)], fs, ic.casters, depth.data());
        std::fill(used.begin(), used.end(), uint8_t(0));
        for (size_t i = 0; i < where.size(); ++i)
            if (where[i].inside && where[i].view == view)
                used[size_t(std::min(int(where[i].v * fs), fs - 1)) * fs + size_t(std::min(int(where[i].u * fs), fs - 1))] = 1;
        const int fx = x0 + (face % cols) * fs, fy = y0 + (face / cols) * fs;
        for (int iy = 0; iy < fs; ++iy)
            for (int ix = 0; ix < fs; ++ix) {
                const size_t t = size_t(fs - 1 - iy) * fs + size_t(ix);   // row 0 of the map at the bottom (v = 0)
                const float d = depth[t];
                vec3 c = d >= 1.0f ? vec3(0.05f, 0.05f, 0.10f) : vec3(1.0f - 0.8f * d);
                if (used[t]) c = 0.5f * c + 0.5f * vec3(0.1f, 0.9f, 0.2f);
                put(img, size_t(fy + iy) * img.width + size_t(fx + ix), c);
            }
    }
    // A white frame around the faces.
    const int x1 = x0 + cols * fs, y1 = y0 + (faces / cols) * fs;
    for (int x = x0 - 1; x <= x1; ++x)
        for (int y : {y0 - 1, y1})
            if (x >= 0 && y >= 0 && x < img.width && y < img.height) put(img, size_t(y) * img.width + size_t(x), vec3(1.0f));
    for (int y = y0 - 1; y <= y1; ++y)
        for (int x : {x0 - 1, x1})
            if (x >= 0 && y >= 0 && x < img.width && y < img.height) put(img, size_t(y) * img.width + size_t(x), vec3(1.0f));
}

const char* typeName(sg::LightType t) {
    switch (t) {
    case sg::LightType::Directional: return "sun";
    case sg::LightType::Spot: return "spot";
    default: return "point";
    }
}

}   // namespace

int shadowMapViewLight(const sg::FrameInput& f, sg::NodeId selected) {
    const ShadowPlan plan = planOf(f);
    if (plan.empty()) return -1;
    int first = -1;
    for (size_t l = 0; l < f.lights.size() && l < plan.viewCount.size(); ++l) {
        if (plan.viewCount[l] == 0) continue;
        if (selected != sg::kNoNode && f.lights[l].node == selected) return int(l);
        if (first < 0) first = int(l);
    }
    return first;
}

ShadowMapViewPoints shadowMapViewPoints(const sg::FrameInput& f, const Framebuffer& fb, int light) {
    ShadowMapViewPoints pts;
    pts.light = light;
    if (light < 0 || size_t(light) >= f.lights.size() || !fb.has(Aov::Visibility)) return pts;
    const sg::InstanceTable ids = sg::instanceTable(f);
    for (int y = 0; y < fb.height; ++y)
        for (int x = 0; x < fb.width; ++x) {
            const size_t k = size_t(y) * fb.width + size_t(x);
            if (!fb.drawable[k]) continue;
            const SurfaceAt s = surfaceAt(f, ids, fb, x, y);
            if (!s.hit || s.normal == vec3(0.0f)) continue;   // background, lines and points
            pts.pixel.push_back(uint32_t(k));
            pts.position.push_back(s.position);
            pts.normal.push_back(s.normal);
            pts.geometricNormal.push_back(s.geometricNormal);
        }
    return pts;
}

DiagnosticImage shadowMapViewImage(const sg::FrameInput& f, const Framebuffer& fb, const ShadowMapViewPoints& pts, const std::vector<float>& map,
                                   const std::vector<float>& exact, ShadowMapViewCounts* counts) {
    DiagnosticImage out;
    ShadowMapViewCounts local;
    ShadowMapViewCounts& cnt = counts ? *counts : local;
    cnt = {};
    const int w = fb.width, h = fb.height;
    out.image.resize(w, h);
    for (size_t k = 0; k < size_t(w) * h; ++k) out.image.color[4 * k + 3] = 255;
    const ShadowPlan plan = planOf(f);
    const int light = pts.light;
    if (light < 0 || size_t(light) >= f.lights.size() || plan.empty() || plan.viewCount[size_t(light)] == 0) {
        out.legend = f.settings.shadows ? "shadow-map: no light has a shadow map (no light, or nothing casts)"
                                        : "shadow-map: shadows are off (turn them on to see the maps)";
        return out;
    }
    const sg::DrawLight& L = f.lights[size_t(light)];
    const size_t n = pts.pixel.size();
    const bool haveMap = map.size() == n, haveExact = exact.size() == size_t(w) * size_t(h);
    const float S = float(plan.size);

    // Texel coordinates per pixel (for the density), the colours, the counts.
    std::vector<MapPos> where(n);
    std::vector<int32_t> pointAt(size_t(w) * h, -1);
    size_t facing = 0, acne = 0, leak = 0;
    for (size_t i = 0; i < n; ++i) {
        pointAt[pts.pixel[i]] = int32_t(i);
        where[i] = mapPos(plan, L, light, pts.position[i]);
    }
    // Map texels per screen pixel: the larger of the steps to the right and down neighbours on
    // the same drawable and map face (-1: no such neighbour).
    std::vector<float> texels(n, -1.0f);
    for (size_t i = 0; i < n; ++i) {
        if (!where[i].inside) continue;
        const size_t k = pts.pixel[i];
        for (size_t nb : {k + 1, k + size_t(w)}) {
            if ((nb == k + 1 && (k + 1) % size_t(w) == 0) || nb >= pointAt.size() || pointAt[nb] < 0) continue;
            const MapPos& o = where[size_t(pointAt[nb])];
            if (!o.inside || o.view != where[i].view || fb.drawable[nb] != fb.drawable[k]) continue;
            texels[i] = std::max(texels[i], std::hypot((o.u - where[i].u) * S, (o.v - where[i].v) * S));
        }
    }
    std::vector<float> density;
    density.reserve(n);
    for (float d : texels)
        if (d >= 0.0f) density.push_back(d);
    for (size_t i = 0; i < n; ++i) {
        const size_t k = pts.pixel[i];
        const MapPos& m = where[i];
        // The checkerboard fades out where a texel is smaller than a pixel (it would only alias).
        const float contrast = 0.2f * std::clamp((0.8f - texels[i]) / 0.4f, 0.0f, 1.0f);
        const bool odd = m.inside && ((int(m.u * S) + int(m.v * S)) & 1);
        const float checker = odd ? 1.0f - contrast : 1.0f;
        if (!lightReaches(L, pts.position[i], pts.normal[i], f.settings.reflection)) {
            put(out.image, k, vec3(0.10f, 0.12f, 0.28f) * checker);
            continue;
        }
        ++facing;
        vec3 c;
        if (!haveMap) {
            c = vec3(0.6f);
        } else {
            const bool mapLit = map[i] >= 0.5f;
            if (haveExact && std::isnan(exact[k])) {   // the reference sees another surface here
                --facing;
                ++cnt.uncompared;
                put(out.image, k, mapLit ? vec3(0.62f) : vec3(0.20f));
                continue;
            }
            const bool rayLit = haveExact ? exact[k] >= 0.5f : mapLit;
            cnt.shadowedByMap += !mapLit;
            if (mapLit == rayLit) {
                c = mapLit ? vec3(0.85f, 0.84f, 0.80f) : vec3(0.32f, 0.32f, 0.34f);
            } else if (!mapLit) {
                c = vec3(0.95f, 0.15f, 0.10f);   // the map shadows, the rays reach: acne or spill
                ++acne;
            } else {
                c = vec3(0.15f, 0.55f, 1.00f);   // the map lets light through, the rays do not: leak, peter-panning
                ++leak;
            }
        }
        put(out.image, k, c * checker);
    }

    float median = 0.0f;
    if (!density.empty()) {
        std::nth_element(density.begin(), density.begin() + long(density.size() / 2), density.end());
        median = density[density.size() / 2];
    }

    cnt.facing = facing;
    cnt.mapOnlyShadow = acne;
    cnt.mapOnlyLight = leak;
    cnt.texelsPerPixel = median;
    drawInset(f, plan, light, where, out.image);

    char buf[512];
    const char* filter = plan.filter == sg::ShadowFilter::Pcss ? "PCSS" : plan.filter == sg::ShadowFilter::Pcf ? "PCF" : "no filter";
    std::snprintf(buf, sizeof buf, "shadow-map: light %d (%s), %dx%d, %s %dx%d, bias %.2g/%.2g texels; %.2f map texels per pixel (median)", light,
                  typeName(L.type), plan.size, plan.size, filter, plan.pcf, plan.pcf, double(plan.depthBias), double(plan.normalBias),
                  double(median));
    out.legend = buf;
    if (!haveMap) {
        out.legend += "; the backend gave no map answers (maps are drawn with per-pixel shading)";
    } else if (!haveExact) {
        out.legend += "; no shadow rays to compare with: map lit light grey, shadowed dark grey";
    } else {
        const double pct = facing ? 100.0 / double(facing) : 0.0;
        std::snprintf(buf, sizeof buf,
                      "; of %zu lit-facing pixels, map-only shadow (red: acne, edge spill) %.2f%%, map-only light (blue: "
                      "leak, peter-panning) %.2f%%",
                      facing, double(acne) * pct, double(leak) * pct);
        out.legend += buf;
        if (cnt.uncompared) out.legend += " (" + std::to_string(cnt.uncompared) + " pixels not compared: the ray caster sees another surface)";
        out.legend += "; inset: the map, texels in view green";
    }
    return out;
}

std::vector<float> referenceVisibility(const sg::FrameInput& f, const Framebuffer& fb, Renderer& exact, const Framebuffer& exactImage, int light) {
    if (exactImage.width != fb.width || exactImage.height != fb.height || !fb.has(Aov::Visibility)) return {};
    const ShadowMapViewPoints own = shadowMapViewPoints(f, exactImage, light);
    std::vector<float> perPixel(size_t(fb.width) * size_t(fb.height), std::nanf(""));
    if (own.pixel.empty()) return perPixel;
    const std::vector<float> v = exact.lightVisibilityMany(f, light, own.position, own.geometricNormal);
    if (v.size() != own.pixel.size()) return {};
    for (size_t i = 0; i < v.size(); ++i) {
        const size_t k = own.pixel[i];
        if (exactImage.drawable[k] == fb.drawable[k]) perPixel[k] = v[i];
    }
    return perPixel;
}

bool renderShadowReference(Renderer& exact, const sg::FrameInput& f, int width, int height, Framebuffer& image) {
    RenderRequest request;
    request.aovs.add(Aov::Visibility);
    return exact.render(f, width, height, image, nullptr, request).ok && image.has(Aov::Visibility);
}

DiagnosticImage shadowMapView(const sg::FrameInput& f, const Framebuffer& fb, int light, Renderer& backend, Renderer* exact,
                              ShadowMapViewCounts* counts) {
    const ShadowMapViewPoints pts = shadowMapViewPoints(f, fb, light);
    std::vector<float> map, rays;
    if (pts.light >= 0 && !pts.pixel.empty()) {
        map = backend.lightVisibilityMany(f, light, pts.position, pts.normal);
        Framebuffer reference;
        if (exact && renderShadowReference(*exact, f, fb.width, fb.height, reference)) rays = referenceVisibility(f, fb, *exact, reference, light);
    }
    return shadowMapViewImage(f, fb, pts, map, rays, counts);
}

}   // namespace rnd
