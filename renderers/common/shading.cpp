// shading.cpp - the Phong evaluation of shading.h shared by the CPU rasterizer and the ray
// caster: light samples (direction, 1/r^2, spot smoothstep), material coefficients and the
// texture maps applied to them (normal, emissive, occlusion, metallic-roughness), the light
// terms (Phong or Blinn-Phong), fog, and sRGB encode/decode, with an exact table-driven
// linear-to-byte conversion so that no pixel pays for pow().
#include "renderers/shading.h"

#include "renderers/pbr.h"
#include "renderers/srgb_encoder.h"
#include "renderers/texture_sampler.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

namespace rnd {

using namespace sg;

LightSample sampleLight(const DrawLight& light, const vec3& p) {
    LightSample s;
    if (light.type == LightType::Directional) {
        s.toLight = -light.direction;
        s.radiance = light.radiance;
        s.distance = std::numeric_limits<float>::infinity();
        return s;
    }
    vec3 d = light.position - p;
    float dist2 = glm::dot(d, d);
    s.distance = std::sqrt(dist2);
    s.toLight = s.distance > 0 ? d / s.distance : vec3(0, 1, 0);
    s.radiance = light.radiance;
    if (light.inverseSquare) s.radiance /= std::max(dist2, 1e-8f);   // docs/math.md: 1/r^2
    if (light.type == LightType::Spot) {
        float c = glm::dot(-s.toLight, light.direction);
        float t = light.cosInner > light.cosOuter ? (c - light.cosOuter) / (light.cosInner - light.cosOuter) : (c >= light.cosOuter ? 1.0f : 0.0f);
        t = std::clamp(t, 0.0f, 1.0f);
        s.radiance *= t * t * (3.0f - 2.0f * t);   // smoothstep between the cones
    }
    return s;
}

SurfaceCoefficients coefficientsOf(const Material& m) {
    SurfaceCoefficients c;
    c.ka = m.ka;
    c.kd = m.kd;
    c.ks = m.ks;
    c.shininess = m.shininess;
    c.specularTinted = m.specularTinted;
    c.unlit = m.unlit;
    c.specularColor = m.specularColor;
    c.emissive = m.emissive;
    c.metallic = m.metallic;
    c.roughness = m.roughness;
    const float f = (m.ior - 1.0f) / (m.ior + 1.0f);
    c.f0Dielectric = glm::min(f * f * m.specularColorFactor, vec3(1.0f)) * m.specularFactor;
    c.f90Dielectric = m.specularFactor;
    c.specularGlossiness = m.specularGlossiness;
    if (m.specularGlossiness) {   // the importer keeps the specular colour as ks x specularColor
        c.specularF0 = m.ks * m.specularColor;
        c.roughness = 1.0f - m.glossiness;
    }
    return c;
}

MapSample sampleMaps(const MapSamplers& maps, const UvFootprint uvs[2]) {
    auto at = [&](uint8_t bit) -> const UvFootprint& { return uvs[(maps.uv1 & bit) ? 1 : 0]; };
    MapSample s;
    if (const SampledTexture* nm = maps.normal) {
        const UvFootprint& f = at(sg::Material::NormalMap);
        s.hasNormal = true;
        s.normalTexel = nm->sample(f.uv, f.ddx, f.ddy);
    }
    if (const SampledTexture* em = maps.emissive) {
        const UvFootprint& f = at(sg::Material::EmissiveMap);
        s.emissive = em->sample(f.uv, f.ddx, f.ddy);
    }
    if (const SampledTexture* occ = maps.occlusion) {
        const UvFootprint& f = at(sg::Material::OcclusionMap);
        s.occlusion = occ->sample(f.uv, f.ddx, f.ddy).x;
    }
    if (const SampledTexture* mr = maps.metallicRoughness) {
        const UvFootprint& f = at(sg::Material::MetallicRoughnessMap);
        const vec3 t = mr->sample(f.uv, f.ddx, f.ddy);
        s.hasMetallicRoughness = true;
        s.roughness = t.y;
        s.metallic = t.z;
        s.pbrTexel = vec4(t, mr->sampleAlpha(f.uv, f.ddx, f.ddy));
    }
    return s;
}

vec3 perturbNormal(const vec3& n, const vec4& t, const vec3& texel, float scale) {
    vec3 m = 2.0f * texel - 1.0f;
    m.x *= scale;
    m.y *= scale;
    vec3 T = vec3(t) - n * glm::dot(n, vec3(t));
    const float lt = glm::length(T);
    if (!(lt > 1e-12f)) return n;
    T /= lt;
    const vec3 B = (t.w < 0.0f ? -1.0f : 1.0f) * glm::cross(n, T);
    const vec3 p = m.x * T + m.y * B + m.z * n;
    const float lp = glm::length(p);
    return lp > 1e-12f ? p / lp : n;
}

SurfaceCoefficients coefficientsAt(const Material& m, const MapSample& s) {
    SurfaceCoefficients c = coefficientsOf(m);
    c.occlusion = 1.0f + m.occlusionStrength * (s.occlusion - 1.0f);
    c.ka *= c.occlusion;
    c.emissive *= s.emissive;
    if (s.hasMetallicRoughness && m.specularGlossiness) {
        c.specularF0 = m.ks * m.specularColor * vec3(s.pbrTexel);
        c.roughness = 1.0f - m.glossiness * s.pbrTexel.w;
        const vec3 spec = m.ks * m.specularColor * vec3(s.pbrTexel);
        const float ks = std::max({spec.x, spec.y, spec.z});
        c.kd = 1.0f;
        c.ks = ks;
        c.specularColor = ks > 0.0f ? spec / ks : vec3(1.0f);
        c.specularTinted = false;
        c.shininess = phongFromMetallicRoughness(0.0f, 1.0f - m.glossiness * s.pbrTexel.w).shininess;
    } else if (s.hasMetallicRoughness) {
        c.metallic = m.metallic * s.metallic;
        c.roughness = m.roughness * s.roughness;
        const PhongFromPbr p = phongFromMetallicRoughness(m.metallic * s.metallic, m.roughness * s.roughness);
        c.kd = p.kd;
        c.ks = p.ks;
        c.shininess = p.shininess;
        c.specularTinted = p.tinted;
    }
    return c;
}

void applyMapsToTerms(ShadeTerms& t, const Material& m, const MapSample& s, const vec3& ambient, ReflectionModel model) {
    if (m.unlit || model == ReflectionModel::Pbr) {   // pbr: the occlusion needs per-pixel shading
        t.add += m.emissive * (s.emissive - 1.0f);
        return;
    }
    t.mul -= m.ka * m.occlusionStrength * (1.0f - s.occlusion) * ambient;
    t.add += m.emissive * (s.emissive - 1.0f);
}

ShadeTerms lightTerms(const SurfaceCoefficients& m, const vec3& n, const vec3& v, const LightSample& l, ReflectionModel model) {
    ShadeTerms t;
    float nl = glm::dot(n, l.toLight);
    if (nl <= 0.0f) return t;
    float spec;
    if (model == ReflectionModel::Phong) {
        vec3 r = 2.0f * nl * n - l.toLight;   // mirror direction of l about n
        spec = std::max(glm::dot(r, v), 0.0f);
    } else {
        vec3 h = l.toLight + v;
        float len = glm::length(h);
        spec = len > 0 ? std::max(glm::dot(n, h / len), 0.0f) : 0.0f;
    }
    spec = spec > 0.0f ? std::pow(spec, m.shininess) : 0.0f;
    vec3 ln = l.radiance * nl;
    t.mul = ln * m.kd;
    if (m.specularTinted)
        t.mul += ln * (m.ks * spec);   // specular colour = albedo
    else
        t.add = ln * (m.ks * spec) * m.specularColor;
    return t;
}

bool lightReaches(const DrawLight& light, const vec3& p, const vec3& n, ReflectionModel model) {
    return sampleReaches(model == ReflectionModel::Pbr ? samplePunctualLight(light, p) : sampleLight(light, p), n);
}

namespace {
// The unit vector from p toward the eye (+z where they meet).
vec3 toViewer(const vec3& eye, const vec3& p) {
    vec3 v = eye - p;
    const float len = glm::length(v);
    return len > 0 ? v / len : vec3(0, 0, 1);
}

// Light i's own terms at p (v: toViewer); pt: pbrPoint under the pbr model, null otherwise.
ShadeTerms oneLightTerms(const SurfaceCoefficients& m, const PbrPoint* pt, const vec3& p, const vec3& n, const vec3& v, const FrameInput& f,
                         size_t i) {
    if (pt) return pbrLightTerms(*pt, n, v, samplePunctualLight(f.lights[i], p));
    return lightTerms(m, n, v, sampleLight(f.lights[i], p), f.settings.reflection);
}
}   // namespace

ShadeTerms shadeTerms(const SurfaceCoefficients& m, const vec3& p, const vec3& n, const vec3& eye, const FrameInput& f, const float* visible,
                      const ShadeExtras& x) {
    ShadeTerms t;
    if (m.unlit) {
        t.mul = vec3(1.0f);
        t.add = m.emissive;
        return t;
    }
    const vec3 v = toViewer(eye, p);
    const bool pbr = f.settings.reflection == ReflectionModel::Pbr;   // renderers/pbr.h
    PbrPoint pt;
    if (pbr)
        pt = pbrPoint(m, x.albedo);   // ambient light: the environment's terms below
    else
        t.mul = m.ka * f.ambientLight;
    t.add = m.emissive;
    for (size_t i = 0; i < f.lights.size(); ++i) {
        if (visible && visible[i] <= 0.0f) continue;
        const ShadeTerms li = oneLightTerms(m, pbr ? &pt : nullptr, p, n, v, f, i);
        const float w = visible ? visible[i] : 1.0f;
        t.mul += w * li.mul;
        t.add += w * li.add;
    }
    if (pbr && x.environment && x.environment->map) {
        const ShadeTerms e = pbrEnvironmentTerms(pt, n, v, *x.environment, m.occlusion);
        t.mul += e.mul;
        t.add += e.add;
    }
    return t;
}

ShadeTerms lightShareTerms(const SurfaceCoefficients& m, const vec3& p, const vec3& n, const vec3& eye, const FrameInput& f, size_t light,
                           const ShadeExtras& x) {
    if (m.unlit || light >= f.lights.size()) return {};
    const bool pbr = f.settings.reflection == ReflectionModel::Pbr;
    PbrPoint pt;
    if (pbr) pt = pbrPoint(m, x.albedo);
    return oneLightTerms(m, pbr ? &pt : nullptr, p, n, toViewer(eye, p), f, light);
}

vec3 shade(const SurfaceCoefficients& m, const SurfacePoint& s, const vec3& eye, const FrameInput& f, const float* visible,
           const EnvironmentLight* environment) {
    return shadeTerms(m, s.position, s.normal, eye, f, visible, {s.albedo, environment}).apply(s.albedo);
}

vec3 applyFog(const RenderSettings& s, const vec3& color, float d) {
    if (s.fog == FogMode::Off) return color;
    float vis = fogVisibility(s, d);
    return vis * color + (1.0f - vis) * s.fogColor;
}

float encodeSRGB(float x) {
    x = std::clamp(x, 0.0f, 1.0f);
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

float decodeSRGB(float x) { return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f); }

namespace {
// The formula that defines the byte, for finite x in [0, 1].
uint8_t byteByFormula(float x) { return uint8_t(encodeSRGB(x) * 255.0f + 0.5f); }

uint32_t bitsOf(float x) {
    uint32_t b;
    std::memcpy(&b, &x, 4);
    return b;
}

// The byte without pow. Non-negative floats order like their bits, so the floats in [2^-13, 1)
// fall into buckets by exponent and the top 8 mantissa bits; a bucket's first float gives a
// first guess and the thresholds (the smallest float of each byte, found by bisection on the
// formula itself) finish it: exact wherever the formula is monotonic, which the unit test
// checks for every float in [0, 1]. Below 2^-13 the formula gives 0 (255 * 12.92 x < 0.5).
struct SrgbByteTable {
    static constexpr int kMinExp = -13;
    float first[257];                // first[b]: smallest x with byte >= b; first[256] above 1
    uint8_t guess[-kMinExp * 256];   // byte of each bucket's first float
    SrgbByteTable() {
        first[0] = 0.0f;
        for (int b = 1; b < 256; ++b) {
            uint32_t lo = 0, hi = bitsOf(1.0f);   // byte(lo) < b <= byte(hi)
            while (hi - lo > 1) {
                const uint32_t mid = lo + (hi - lo) / 2;
                float x;
                std::memcpy(&x, &mid, 4);
                (byteByFormula(x) >= b ? hi : lo) = mid;
            }
            std::memcpy(&first[b], &hi, 4);
        }
        first[256] = 2.0f;
        for (int i = 0; i < -kMinExp * 256; ++i) guess[i] = byteByFormula(std::ldexp(1.0f + float(i % 256) / 256.0f, kMinExp + i / 256));
    }
    uint8_t operator()(float x) const {
        if (!(x >= 0x1p-13f)) return 0;   // also NaN
        if (x >= 1.0f) return 255;
        int b = guess[(bitsOf(x) - bitsOf(0x1p-13f)) >> 15];
        while (x >= first[b + 1]) ++b;
        return uint8_t(b);
    }
};

const SrgbByteTable& srgbByteTable() {
    static const SrgbByteTable table;
    return table;
}
}   // namespace

uint8_t toByteSRGB(float linear) { return srgbByteTable()(linear); }

float srgbByteThreshold(int b) { return srgbByteTable().first[std::clamp(b, 0, 256)]; }

vec3 srgbBytesToLinear(const uint8_t* rgb) {
    static const auto table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[i] = decodeSRGB(i / 255.0f);
        return t;
    }();
    return vec3(table[rgb[0]], table[rgb[1]], table[rgb[2]]);
}

SrgbEncoder::SrgbEncoder() {
    // rnd::toByteSRGB's own thresholds, so that this encoder gives its byte for every float.
    // (decodeSRGB((b + 0.5) / 255) differs from them in the last bit on 225 floats of [2^-14, 1].)
    for (int b = 0; b < 256; ++b) next[b] = srgbByteThreshold(b + 1);   // next[255] = 2: never reached
    for (int i = 0; i < kBuckets; ++i) {
        const float first = std::ldexp(1.0f + float(i % 256) / 256.0f, kMinExp + i / 256);
        table[i] = toByteSRGB(first);
        const uint32_t start = 0x39000000u + (uint32_t(i) << 15), end = start + 0x8000u;
        uint32_t thr;
        std::memcpy(&thr, &next[table[i]], 4);
        if (thr <= start)   // the whole bucket is above the threshold: operator() adds one everywhere
            packed[i] = uint32_t(table[i] + 1) << 16 | 0x8000u;
        else if (thr < end)
            packed[i] = uint32_t(table[i]) << 16 | (thr - start);
        else
            packed[i] = uint32_t(table[i]) << 16 | 0x8000u;
    }
}

const SrgbEncoder& srgbEncoder() {
    static const SrgbEncoder e;
    return e;
}

}   // namespace rnd
