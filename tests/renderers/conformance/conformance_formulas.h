// conformance_formulas.h - the closed-form answers the BackendConformance suite holds every
// backend to, written out here from the documented formulas (renderers/include/renderers/
// shading.h, scenegraph/include/scenegraph/settings.h, transforms.h) rather than calling the
// renderers' own shading code, so a shared bug cannot hide: Phong / Blinn-Phong radiance, fog
// visibility, sRGB encoding, the projections, camera rays and ray-sphere / ray-triangle hits,
// the exact area of a pixel square covered by a convex polygon, exposure and the tone-mapping
// operators.
#pragma once

#include "scenegraph/frame.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace conformance {

using sg::mat4;
using sg::vec2;
using sg::vec3;
using sg::vec4;

// sRGB transfer function (IEC 61966-2-1) and the 8-bit encoding of a linear colour.
inline float srgbEncode(float x) {
    x = std::clamp(x, 0.0f, 1.0f);
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}
inline float srgbDecode(float x) { return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f); }
inline std::array<uint8_t, 3> toBytes(const vec3& linear) {
    std::array<uint8_t, 3> b{};
    for (int c = 0; c < 3; ++c) b[size_t(c)] = uint8_t(std::lround(srgbEncode(linear[c]) * 255.0f));
    return b;
}

// --- Exposure and tone mapping (renderers/tone_map.h, docs/math.md), in double precision from
// the published formulas, written in their own form rather than the renderers' (the Neutral
// operator as its specification's cases, not the reference GLSL's mix()).

// Stephen Hill's ACES fit (RRT + sRGB ODT) with the Khronos glTF Sample Viewer's input scale
// 1/0.6: M_out fit(M_in c / 0.6), clamped to [0, 1]. Matrices by rows (the GLSL source lists
// them by columns): sRGB -> AP1 with the RRT's desaturation, and the ODT's back to sRGB.
inline std::array<double, 3> acesReference(const std::array<double, 3>& c) {
    static constexpr double in[3][3] = {{0.59719, 0.35458, 0.04823}, {0.07600, 0.90834, 0.01566}, {0.02840, 0.13383, 0.83777}};
    static constexpr double out[3][3] = {{1.60475, -0.53108, -0.07367}, {-0.10208, 1.10813, -0.00605}, {-0.00327, -0.07276, 1.07602}};
    std::array<double, 3> v{}, f{}, r{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) v[size_t(i)] += in[i][j] * c[size_t(j)] / 0.6;
    for (int i = 0; i < 3; ++i) {
        const double x = v[size_t(i)];
        f[size_t(i)] = (x * (x + 0.0245786) - 0.000090537) / (x * (0.983729 * x + 0.4329510) + 0.238081);
    }
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) r[size_t(i)] += out[i][j] * f[size_t(j)];
        r[size_t(i)] = std::clamp(r[size_t(i)], 0.0, 1.0);
    }
    return r;
}

// Khronos PBR Neutral, as its specification (KhronosGroup/ToneMapping, PBR_Neutral) writes it:
// F90 = 0.04, Ks = 0.8 - F90, Kd = 0.15; x = min(c); f = x - x^2 / (4 F90) for x <= 2 F90, else
// F90; p = max(c - f); p_n = 1 - (1 - Ks)^2 / (p + 1 - 2 Ks); g = 1 / (Kd (p - p_n) + 1);
// out = c - f for p <= Ks, else (c - f) (p_n / p) g + p_n (1 - g).
inline std::array<double, 3> khrNeutralReference(const std::array<double, 3>& c) {
    const double F90 = 0.04, Ks = 0.8 - F90, Kd = 0.15;
    const double x = std::min({c[0], c[1], c[2]});
    const double f = x <= 2 * F90 ? x - x * x / (4 * F90) : F90;
    const double p = std::max({c[0] - f, c[1] - f, c[2] - f});
    std::array<double, 3> r{};
    if (p <= Ks) {
        for (int i = 0; i < 3; ++i) r[size_t(i)] = c[size_t(i)] - f;
        return r;
    }
    const double pn = 1 - (1 - Ks) * (1 - Ks) / (p + 1 - 2 * Ks);
    const double g = 1 / (Kd * (p - pn) + 1);
    for (int i = 0; i < 3; ++i) r[size_t(i)] = (c[size_t(i)] - f) * (pn / p) * g + pn * (1 - g);
    return r;
}

// What the display shows of linear colour c at exposure ev with operator op, before the sRGB
// encoding: T(2^ev max(c, 0)), clamped to [0, 1] (none: the scaled colour, clipped).
inline vec3 displayReference(const vec3& c, float ev, sg::ToneMapping op) {
    const double s = std::pow(2.0, double(ev));
    std::array<double, 3> x{};
    for (int i = 0; i < 3; ++i) x[size_t(i)] = s * std::max(double(c[i]), 0.0);
    if (op == sg::ToneMapping::Aces) x = acesReference(x);
    if (op == sg::ToneMapping::KhrNeutral) x = khrNeutralReference(x);
    return vec3(float(std::clamp(x[0], 0.0, 1.0)), float(std::clamp(x[1], 0.0, 1.0)), float(std::clamp(x[2], 0.0, 1.0)));
}

// Seeds 3.1 (shading.h), directional and point lights:
//   L = ka rho A + emissive + sum_i att_i L_i max(n.l_i, 0) (kd rho + ks rho_spec max(r_i.v, 0)^m)
// with r_i = 2 (n.l_i) n - l_i (Phong) or (r_i.v) replaced by n.h_i, h = (l + v)/|l + v|
// (Blinn-Phong), att_i = 1/d^2 for inverse-square lights, else 1.
inline vec3 phongRadiance(const sg::Material& m, const vec3& albedo, const vec3& p, const vec3& n, const vec3& eye, const sg::FrameInput& f) {
    const vec3 v = glm::normalize(eye - p);
    vec3 L = m.ka * albedo * f.ambientLight + m.emissive;
    for (const sg::DrawLight& light : f.lights) {
        vec3 l, Li = light.radiance;
        if (light.type == sg::LightType::Directional) {
            l = -light.direction;
        } else {
            const vec3 d = light.position - p;
            const float r = glm::length(d);
            l = d / r;
            if (light.inverseSquare) Li /= r * r;
        }
        const float nl = glm::dot(n, l);
        if (nl <= 0.0f) continue;
        float s = f.settings.reflection == sg::ReflectionModel::Phong ? glm::dot(2.0f * nl * n - l, v) : glm::dot(n, glm::normalize(l + v));
        s = s > 0.0f ? std::pow(s, m.shininess) : 0.0f;
        const vec3 specColor = m.specularTinted ? albedo : m.specularColor;
        L += Li * nl * (m.kd * albedo + m.ks * s * specColor);
    }
    return L;
}

// Fog visibility of eye-space distance d (settings.h): linear (end - d)/(end - start) clamped,
// exp e^(-density d), exp2 e^(-(density d)^2). The colour is f L + (1 - f) C_fog.
inline float fogFactor(const sg::RenderSettings& s, float d) {
    switch (s.fog) {
    case sg::FogMode::Linear: return std::clamp((s.fogEnd - d) / (s.fogEnd - s.fogStart), 0.0f, 1.0f);
    case sg::FogMode::Exp: return std::exp(-s.fogDensity * d);
    case sg::FogMode::Exp2: return std::exp(-(s.fogDensity * d) * (s.fogDensity * d));
    default: return 1.0f;
    }
}

// World -> window (GL convention: x right, y up from the bottom edge, pixel centres at +0.5).
inline vec2 toWindow(const mat4& viewProj, const vec3& p, int w, int h) {
    const vec4 c = viewProj * vec4(p, 1.0f);
    return {(0.5f * c.x / c.w + 0.5f) * float(w), (0.5f * c.y / c.w + 0.5f) * float(h)};
}

struct Ray {
    vec3 org, dir;   // dir unit
};
// The camera ray through window position (wx, wy): unprojected at the near and far planes.
inline Ray windowRay(const sg::FrameCamera& cam, int w, int h, float wx, float wy) {
    const mat4 inv = glm::inverse(cam.proj * cam.view);
    const float x = 2.0f * wx / float(w) - 1.0f, y = 2.0f * wy / float(h) - 1.0f;
    const vec4 a = inv * vec4(x, y, -1.0f, 1.0f), b = inv * vec4(x, y, 1.0f, 1.0f);
    const vec3 pa = vec3(a) / a.w, pb = vec3(b) / b.w;
    return {pa, glm::normalize(pb - pa)};
}
// The ray through the centre of framebuffer pixel (x, row) (row 0 at the top).
inline Ray pixelRay(const sg::FrameCamera& cam, int w, int h, int x, int row) {
    return windowRay(cam, w, h, float(x) + 0.5f, float(h - 1 - row) + 0.5f);
}

// Nearest t > 0 where the ray meets the sphere, or -1.
inline float hitSphere(const Ray& r, const vec3& centre, float radius) {
    const vec3 o = r.org - centre;
    const float b = glm::dot(o, r.dir), c = glm::dot(o, o) - radius * radius, disc = b * b - c;
    if (disc < 0.0f) return -1.0f;
    const float s = std::sqrt(disc);
    if (-b - s > 0.0f) return -b - s;
    return -b + s > 0.0f ? -b + s : -1.0f;
}

// Moller-Trumbore: t and barycentrics (w0, w1, w2) of the hit, two-sided.
inline bool hitTriangle(const Ray& r, const vec3& a, const vec3& b, const vec3& c, float& t, vec3& bary) {
    const vec3 e1 = b - a, e2 = c - a, p = glm::cross(r.dir, e2);
    const float det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12f) return false;
    const float inv = 1.0f / det;
    const vec3 s = r.org - a;
    const float u = glm::dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f) return false;
    const vec3 q = glm::cross(s, e1);
    const float v = glm::dot(r.dir, q) * inv;
    if (v < 0.0f || u + v > 1.0f) return false;
    t = glm::dot(e2, q) * inv;
    bary = vec3(1.0f - u - v, u, v);
    return t > 0.0f;
}

// Signed distance of point q from the directed line a->b (positive on the left).
inline float leftOf(const vec2& a, const vec2& b, const vec2& q) {
    const vec2 d = b - a;
    return (d.x * (q.y - a.y) - d.y * (q.x - a.x)) / glm::length(d);
}

// Convex hull (counter-clockwise, Andrew's monotone chain).
inline std::vector<vec2> convexHull(std::vector<vec2> pts) {
    std::sort(pts.begin(), pts.end(), [](const vec2& a, const vec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    auto cross = [](const vec2& o, const vec2& a, const vec2& b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); };
    std::vector<vec2> hull(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
        hull[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
        while (k >= t && cross(hull[k - 2], hull[k - 1], pts[i - 1]) <= 0) --k;
        hull[k++] = pts[i - 1];
    }
    hull.resize(k - 1);
    return hull;
}

// Signed distance of q from a counter-clockwise convex polygon's boundary: positive inside
// (distance to the nearest edge line), negative outside (lower bound: the most violated edge).
inline float insideDistance(const std::vector<vec2>& ccw, const vec2& q) {
    float d = 1e30f;
    for (size_t i = 0; i < ccw.size(); ++i) d = std::min(d, leftOf(ccw[i], ccw[(i + 1) % ccw.size()], q));
    return d;
}

inline double polygonArea(const std::vector<vec2>& p) {
    double a = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        const vec2 &u = p[i], &v = p[(i + 1) % p.size()];
        a += double(u.x) * v.y - double(v.x) * u.y;
    }
    return 0.5 * a;
}

inline vec2 polygonCentroid(const std::vector<vec2>& p) {
    double a = 0, cx = 0, cy = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        const vec2 &u = p[i], &v = p[(i + 1) % p.size()];
        const double c = double(u.x) * v.y - double(v.x) * u.y;
        a += c;
        cx += (double(u.x) + v.x) * c;
        cy += (double(u.y) + v.y) * c;
    }
    return vec2(float(cx / (3.0 * a)), float(cy / (3.0 * a)));
}

// Exact fraction of the unit pixel square [x, x+1] x [y, y+1] (window coordinates) inside a
// counter-clockwise convex polygon (Sutherland-Hodgman clipping of the square, then its area).
inline double coveredFraction(const std::vector<vec2>& ccw, float x, float y) {
    std::vector<vec2> poly = {{x, y}, {x + 1, y}, {x + 1, y + 1}, {x, y + 1}};
    for (size_t i = 0; i < ccw.size() && !poly.empty(); ++i) {
        const vec2 a = ccw[i], b = ccw[(i + 1) % ccw.size()];
        std::vector<vec2> out;
        for (size_t j = 0; j < poly.size(); ++j) {
            const vec2 p = poly[j], q = poly[(j + 1) % poly.size()];
            const float dp = leftOf(a, b, p), dq = leftOf(a, b, q);
            if (dp >= 0) out.push_back(p);
            if ((dp >= 0) != (dq >= 0)) out.push_back(p + (q - p) * (dp / (dp - dq)));
        }
        poly = std::move(out);
    }
    return poly.size() < 3 ? 0.0 : std::abs(polygonArea(poly));
}

}   // namespace conformance
