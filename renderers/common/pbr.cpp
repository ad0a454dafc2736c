// pbr.cpp - glTF's BRDF, the split-sum table, punctual lights in KHR_lights_punctual's units and
// the environment's terms (pbr.h has the formulas).
#include "renderers/pbr.h"
#include "renderers/sampling.h"

#include <algorithm>
#include <cmath>

namespace rnd {

using sg::vec2;
using sg::vec3;

namespace {
constexpr float kPi = 3.14159265358979323846f;

// The height-correlated Smith visibility V = G / (4 n.l n.v).
float visibility(float nl, float nv, float a2) {
    const float gv = nl * std::sqrt(nv * nv * (1.0f - a2) + a2);
    const float gl = nv * std::sqrt(nl * nl * (1.0f - a2) + a2);
    const float d = gv + gl;
    return d > 0.0f ? 0.5f / d : 0.0f;
}

// The roughness the BRDF uses: at least 1e-3 (alpha 1e-6), where the GGX peak still fits a float.
float usableRoughness(float r) { return std::clamp(r, 1e-3f, 1.0f); }

}   // namespace

float radicalInverse(uint32_t i) {
    i = (i << 16u) | (i >> 16u);
    i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
    i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
    i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
    i = ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
    return float(i) * 2.3283064365386963e-10f;
}

vec3 ggxHalfVector(int i, int n, float a2) {
    const float e1 = (float(i) + 0.5f) / float(n), e2 = radicalInverse(uint32_t(i));
    const float cosT = std::sqrt((1.0f - e1) / (1.0f + (a2 - 1.0f) * e1)), sinT = std::sqrt(std::max(0.0f, 1.0f - cosT * cosT));
    const float phi = 2.0f * kPi * e2;
    return {sinT * std::cos(phi), sinT * std::sin(phi), cosT};
}

vec2 splitSumIntegral(float nv, float roughness, int samples) {
    nv = std::clamp(nv, 1e-4f, 1.0f);
    const float a = usableRoughness(roughness) * usableRoughness(roughness), a2 = a * a;
    const vec3 v(std::sqrt(1.0f - nv * nv), 0.0f, nv);   // n = +z
    double A = 0.0, B = 0.0;
    for (int i = 0; i < samples; ++i) {
        const vec3 h = ggxHalfVector(i, samples, a2);
        const float vh = glm::dot(v, h);
        const vec3 l = 2.0f * vh * h - v;
        const float nl = l.z, nh = h.z;
        if (nl <= 0.0f || vh <= 0.0f) continue;
        // f cos / pdf with pdf = D (n.h) / (4 v.h):  V (n.l) 4 (v.h) / (n.h)
        const float g = visibility(nl, nv, a2) * nl * 4.0f * vh / nh;
        const float fc = std::pow(1.0f - vh, 5.0f);
        A += double(g * (1.0f - fc));
        B += double(g * fc);
    }
    return {float(A / samples), float(B / samples)};
}

const std::vector<vec2>& splitSumTable() {
    static const std::vector<vec2> table = [] {
        std::vector<vec2> t(size_t(kSplitSumSize) * kSplitSumSize);
        for (int r = 0; r < kSplitSumSize; ++r)
            for (int c = 0; c < kSplitSumSize; ++c)
                t[size_t(r) * kSplitSumSize + size_t(c)] =
                    splitSumIntegral((float(c) + 0.5f) / kSplitSumSize, (float(r) + 0.5f) / kSplitSumSize, 1024);
        return t;
    }();
    return table;
}

vec2 splitSum(float nv, float roughness) {
    const std::vector<vec2>& t = splitSumTable();
    const float x = std::clamp(nv, 0.0f, 1.0f) * kSplitSumSize - 0.5f, y = std::clamp(roughness, 0.0f, 1.0f) * kSplitSumSize - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const float tx = x - fx, ty = y - fy;
    const int x0 = std::clamp(int(fx), 0, kSplitSumSize - 1), x1 = std::clamp(int(fx) + 1, 0, kSplitSumSize - 1);
    const int y0 = std::clamp(int(fy), 0, kSplitSumSize - 1), y1 = std::clamp(int(fy) + 1, 0, kSplitSumSize - 1);
    auto at = [&](int xx, int yy) { return t[size_t(yy) * kSplitSumSize + size_t(xx)]; };
    return (1.0f - ty) * ((1.0f - tx) * at(x0, y0) + tx * at(x1, y0)) + ty * ((1.0f - tx) * at(x0, y1) + tx * at(x1, y1));
}

PbrPoint pbrPoint(const SurfaceCoefficients& c, const vec3& albedo) {
    PbrPoint p;
    if (c.specularGlossiness) {
        p.f0 = c.specularF0;
        p.f90 = 1.0f;
        p.cdiffFactor = vec3(1.0f - std::max({c.specularF0.x, c.specularF0.y, c.specularF0.z}));
    } else {
        const float m = std::clamp(c.metallic, 0.0f, 1.0f);
        p.f0 = glm::mix(c.f0Dielectric, albedo, m);
        p.f90 = c.f90Dielectric + (1.0f - c.f90Dielectric) * m;
        p.cdiffFactor = vec3(1.0f - m);
    }
    p.roughness = usableRoughness(c.roughness);
    p.alpha = p.roughness * p.roughness;
    return p;
}

LightSample samplePunctualLight(const sg::DrawLight& light, const vec3& p) {
    LightSample s;
    s.radiance = light.radiance;
    if (light.type == sg::LightType::Directional) {
        s.toLight = -light.direction;
        s.distance = std::numeric_limits<float>::infinity();
        return s;
    }
    const vec3 d = light.position - p;
    const float dist2 = glm::dot(d, d);
    s.distance = std::sqrt(dist2);
    s.toLight = s.distance > 0 ? d / s.distance : vec3(0, 1, 0);
    if (light.inverseSquare) s.radiance /= std::max(dist2, 1e-8f);
    if (light.range > 0.0f) {   // KHR_lights_punctual's window
        const float q = dist2 / (light.range * light.range);
        const float w = std::clamp(1.0f - q * q, 0.0f, 1.0f);
        s.radiance *= w * w;
    }
    if (light.type == sg::LightType::Spot) {
        const float scale = 1.0f / std::max(light.cosInner - light.cosOuter, 1e-3f);
        const float t = std::clamp((glm::dot(-s.toLight, light.direction) - light.cosOuter) * scale, 0.0f, 1.0f);
        s.radiance *= t * t;
    }
    return s;
}

ShadeTerms pbrLightTerms(const PbrPoint& p, const vec3& n, const vec3& v, const LightSample& l) {
    ShadeTerms t;
    const float nl = glm::dot(n, l.toLight);
    if (nl <= 0.0f) return t;
    const float nv = std::max(glm::dot(n, v), 0.0f);
    vec3 h = l.toLight + v;
    const float hl = glm::length(h);
    h = hl > 0.0f ? h / hl : n;
    const float vh = std::max(glm::dot(v, h), 0.0f), nh = std::max(glm::dot(n, h), 0.0f);
    const float c = 1.0f - vh, c2 = c * c;
    const vec3 F = p.f0 + (vec3(p.f90) - p.f0) * (c2 * c2 * c);
    const float a2 = p.alpha * p.alpha;
    const float q = nh * nh * (a2 - 1.0f) + 1.0f;
    const float D = a2 / (kPi * q * q);
    const vec3 ln = l.radiance * nl;
    t.mul = ln * (vec3(1.0f) - F) * p.cdiffFactor * (1.0f / kPi);
    t.add = ln * F * (D * visibility(nl, nv, a2));
    return t;
}

ShadeTerms pbrEnvironmentTerms(const PbrPoint& p, const vec3& n, const vec3& v, const EnvironmentLight& env, float occlusion) {
    ShadeTerms t;
    if (!env.map) return t;
    const float ndv = glm::dot(n, v);
    const float nv = std::clamp(ndv, 0.0f, 1.0f);
    const vec2 ab = splitSum(nv, p.roughness);
    const vec3 fssEss = p.f0 * ab.x + vec3(p.f90 * ab.y);
    const float ems = 1.0f - (ab.x + ab.y);
    const vec3 fAvg = p.f0 + (vec3(1.0f) - p.f0) * (1.0f / 21.0f);
    const vec3 fmsEms = ems * fssEss * fAvg / (vec3(1.0f) - ems * fAvg);
    const vec3 r = 2.0f * ndv * n - v;   // the view direction mirrored about n
    const vec3 irradiance = env.diffuse(n), radiance = env.specular(r, p.roughness);
    t.mul = occlusion * (vec3(1.0f) - fssEss - fmsEms) * p.cdiffFactor * irradiance;
    t.add = occlusion * (fssEss * radiance + fmsEms * irradiance);
    return t;
}

}   // namespace rnd
