// environment.cpp - EnvironmentMap (environment.h): the equirectangular radiance resampled to
// the first level, its spherical-harmonic irradiance, the GGX-prefiltered specular levels, the
// built-in studio, the Radiance .hdr reader and the per-name cache.
#include "renderers/environment.h"

#include "renderers/framebuffer.h"
#include "renderers/pbr.h"
#include "renderers/shading.h"

#include <stb_image.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <list>
#include <mutex>

namespace rnd {

using sg::vec2;
using sg::vec3;

namespace {

constexpr float kPi = 3.14159265358979323846f;

// The direction of texel centre (x, y) of a w x h equirectangular level (the inverse of equirectUv).
vec3 texelDirection(int x, int y, int w, int h) {
    const float u = (float(x) + 0.5f) / float(w), v = (float(y) + 0.5f) / float(h);
    const float phi = (u - 0.5f) * 2.0f * kPi, theta = v * kPi;
    const float s = std::sin(theta);
    return {s * std::sin(phi), std::cos(theta), -s * std::cos(phi)};
}

// The box average of a level into one of half its size (a source pyramid for filtered sampling).
EnvironmentMap::Level halve(const EnvironmentMap::Level& a) {
    EnvironmentMap::Level b;
    b.width = std::max(1, a.width / 2);
    b.height = std::max(1, a.height / 2);
    b.rgb.assign(size_t(b.width) * size_t(b.height) * 3, 0.0f);
    for (int y = 0; y < b.height; ++y)
        for (int x = 0; x < b.width; ++x)
            for (int c = 0; c < 3; ++c) {
                float s = 0.0f;
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx) {
                        const int sx = std::min(2 * x + dx, a.width - 1), sy = std::min(2 * y + dy, a.height - 1);
                        s += a.rgb[(size_t(sy) * size_t(a.width) + size_t(sx)) * 3 + size_t(c)];
                    }
                b.rgb[(size_t(y) * size_t(b.width) + size_t(x)) * 3 + size_t(c)] = 0.25f * s;
            }
    return b;
}

// The first level from the source: the mean of the source texels over each target texel
// (downsampling) or the bilinear sample (upsampling), per axis.
EnvironmentMap::Level resample(int sw, int sh, const float* src, int w, int h) {
    EnvironmentMap::Level out;
    out.width = w;
    out.height = h;
    out.rgb.assign(size_t(w) * size_t(h) * 3, 0.0f);
    EnvironmentMap::Level source{sw, sh, std::vector<float>(src, src + size_t(sw) * size_t(sh) * 3)};
    const int fx = std::max(1, sw / w), fy = std::max(1, sh / h);   // source texels per target texel
    tbb::parallel_for(0, h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            vec3 s(0.0f);
            for (int j = 0; j < fy; ++j)
                for (int i = 0; i < fx; ++i) {
                    const float u = (float(x) + (float(i) + 0.5f) / float(fx)) / float(w);
                    const float v = (float(y) + (float(j) + 0.5f) / float(fy)) / float(h);
                    s += sampleLevel(source, u, v);
                }
            s /= float(fx * fy);
            float* o = &out.rgb[(size_t(y) * size_t(w) + size_t(x)) * 3];
            o[0] = s.x;
            o[1] = s.y;
            o[2] = s.z;
        }
    });
    return out;
}

// An orthonormal frame around unit n.
void frameOf(const vec3& n, vec3& t, vec3& b) {
    const vec3 up = std::abs(n.y) < 0.999f ? vec3(0, 1, 0) : vec3(1, 0, 0);
    t = glm::normalize(glm::cross(up, n));
    b = glm::cross(n, t);
}

// Level k (roughness k / (kLevels - 1)) by GGX importance sampling with n = v = r (Karis 2013),
// each sample read from the source pyramid at the level whose texel covers the sample's solid
// angle (Krivanek and Colbert 2008: filtered importance sampling, few samples, no fireflies).
void prefilter(const std::vector<EnvironmentMap::Level>& pyramid, float roughness, EnvironmentMap::Level& out) {
    constexpr int kSamples = 64;
    const float a = roughness * roughness, a2 = a * a;
    struct Sample {
        vec3 h;      // half vector in the local frame (z = n)
        float lod;   // source level
    };
    std::vector<Sample> samples;
    const float texelSolidAngle = 4.0f * kPi / float(pyramid[0].width * pyramid[0].height);
    for (int i = 0; i < kSamples; ++i) {
        const vec3 h = ggxHalfVector(i, kSamples, a2);
        const float cosT = h.z;
        // pdf of l = 2 h (n.h) - n with n = v: D(h) (n.h) / (4 (v.h)) = D / 4.
        const float d = a2 / (kPi * std::pow(cosT * cosT * (a2 - 1.0f) + 1.0f, 2.0f));
        const float sampleSolidAngle = 1.0f / (float(kSamples) * d * 0.25f + 1e-20f);
        const float lod = std::clamp(0.5f * std::log2(sampleSolidAngle / texelSolidAngle) + 1.0f, 0.0f, float(pyramid.size() - 1));
        samples.push_back({h, lod});
    }
    tbb::parallel_for(0, out.height, [&](int y) {
        for (int x = 0; x < out.width; ++x) {
            const vec3 n = texelDirection(x, y, out.width, out.height);
            vec3 t, b;
            frameOf(n, t, b);
            vec3 sum(0.0f);
            float weight = 0.0f;
            for (const Sample& s : samples) {
                const vec3 h = s.h.x * t + s.h.y * b + s.h.z * n;
                const float nh = s.h.z;
                const vec3 l = 2.0f * nh * h - n;
                const float nl = glm::dot(n, l);
                if (nl <= 0.0f) continue;
                const vec2 uv = equirectUv(l);
                const int l0 = int(s.lod);
                const int l1 = std::min(l0 + 1, int(pyramid.size()) - 1);
                const float f = s.lod - float(l0);
                const vec3 c = (1.0f - f) * sampleLevel(pyramid[size_t(l0)], uv.x, uv.y) + f * sampleLevel(pyramid[size_t(l1)], uv.x, uv.y);
                sum += c * nl;
                weight += nl;
            }
            const vec3 r = weight > 0.0f ? sum / weight : vec3(0.0f);
            float* o = &out.rgb[(size_t(y) * size_t(out.width) + size_t(x)) * 3];
            o[0] = r.x;
            o[1] = r.y;
            o[2] = r.z;
        }
    });
}

}   // namespace

namespace {
// atan2(y, x) by range reduction to [0, 1] and a degree-11 odd minimax polynomial (error below
// 1e-5 rad, a fiftieth of a texel of a 1024-wide level): every shaded pixel reads the map.
float fastAtan2(float y, float x) {
    const float ax = std::abs(x), ay = std::abs(y);
    const float mx = std::max(ax, ay), mn = std::min(ax, ay);
    if (!(mx > 0.0f)) return 0.0f;
    const float a = mn / mx, s = a * a;
    float r = ((((-0.0117212f * s + 0.05265332f) * s - 0.11643287f) * s + 0.19354346f) * s - 0.33262348f) * s + 0.99997723f;
    r *= a;
    if (ay > ax) r = 1.57079637f - r;
    if (x < 0.0f) r = 3.14159274f - r;
    return y < 0.0f ? -r : r;
}
// acos(x) as sqrt(1 - |x|) times a degree-7 polynomial (Abramowitz and Stegun 4.4.46, error
// below 2e-8), mirrored for x < 0.
float fastAcos(float x) {
    const float a = std::min(std::abs(x), 1.0f);
    float p = -0.0012624911f;
    for (float c : {0.0066700901f, -0.0170881256f, 0.0308918810f, -0.0501743046f, 0.0889789874f, -0.2145988016f, 1.5707963050f}) p = p * a + c;
    const float r = std::sqrt(1.0f - a) * p;
    return x < 0.0f ? kPi - r : r;
}
}   // namespace

vec2 equirectUv(const vec3& d) {
    const float u = 0.5f + fastAtan2(d.x, -d.z) * (1.0f / (2.0f * kPi));
    const float v = fastAcos(std::clamp(d.y, -1.0f, 1.0f)) * (1.0f / kPi);
    return {u, v};
}

vec3 sampleLevel(const EnvironmentMap::Level& l, float u, float v) {
    if (!(u >= -1.0f && u <= 2.0f)) u = 0.0f;   // NaN (a degenerate direction) reads somewhere, never out of range
    if (!(v >= 0.0f && v <= 1.0f)) v = v > 1.0f ? 1.0f : 0.0f;
    const float x = u * float(l.width) - 0.5f, y = v * float(l.height) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const float tx = x - fx, ty = y - fy;
    // u in [0, 1] (equirectUv) puts floor(x) in [-1, width - 1]; anything else wraps the slow way.
    int x0 = int(fx);
    if (x0 < 0 || x0 >= l.width) x0 = ((x0 % l.width) + l.width) % l.width;
    const int x1 = x0 + 1 == l.width ? 0 : x0 + 1;
    const int y0 = std::clamp(int(fy), 0, l.height - 1), y1 = std::min(std::max(int(fy) + 1, 0), l.height - 1);
    auto at = [&](int xx, int yy) {
        const float* p = &l.rgb[(size_t(yy) * size_t(l.width) + size_t(xx)) * 3];
        return vec3(p[0], p[1], p[2]);
    };
    return (1.0f - ty) * ((1.0f - tx) * at(x0, y0) + tx * at(x1, y0)) + ty * ((1.0f - tx) * at(x0, y1) + tx * at(x1, y1));
}

std::array<float, 9> shBasis(const vec3& d) {
    return {0.282095f,
            0.488603f * d.y,
            0.488603f * d.z,
            0.488603f * d.x,
            1.092548f * d.x * d.y,
            1.092548f * d.y * d.z,
            0.315392f * (3.0f * d.z * d.z - 1.0f),
            1.092548f * d.x * d.z,
            0.546274f * (d.x * d.x - d.y * d.y)};
}

EnvironmentMap::EnvironmentMap(std::string name, int width, int height, const float* rgb) : name_(std::move(name)) {
    // First level: a power of two between 256 and 1024 wide, twice as wide as high.
    int w0 = 256;
    while (w0 < width && w0 < 1024) w0 *= 2;
    const int h0 = w0 / 2;
    levels_.resize(kLevels);
    levels_[0] = resample(width, height, rgb, w0, h0);
    // The source pyramid for the prefilter (box averages of level 0).
    std::vector<Level> pyramid{levels_[0]};
    while (pyramid.back().width > 4) pyramid.push_back(halve(pyramid.back()));
    for (int k = 1; k < kLevels; ++k) {
        Level& l = levels_[size_t(k)];
        l.width = w0 >> k;
        l.height = h0 >> k;
        l.rgb.assign(size_t(l.width) * size_t(l.height) * 3, 0.0f);
        prefilter(pyramid, float(k) / float(kLevels - 1), l);
    }
    // Irradiance: project level 0 on the 9 harmonics (solid angle of texel row y: sin(theta)
    // dtheta dphi), then the cosine lobe's convolution A_l / pi: A0 = pi, A1 = 2 pi / 3, A2 = pi / 4.
    const Level& l0 = levels_[0];
    std::array<double, 27> acc{};
    for (int y = 0; y < l0.height; ++y) {
        const float theta = (float(y) + 0.5f) / float(l0.height) * kPi;
        const double dOmega = double(std::sin(theta)) * (kPi / l0.height) * (2.0 * kPi / l0.width);
        for (int x = 0; x < l0.width; ++x) {
            const std::array<float, 9> yb = shBasis(texelDirection(x, y, l0.width, l0.height));
            const float* p = &l0.rgb[(size_t(y) * size_t(l0.width) + size_t(x)) * 3];
            for (int i = 0; i < 9; ++i)
                for (int c = 0; c < 3; ++c) acc[size_t(i * 3 + c)] += double(p[c]) * double(yb[size_t(i)]) * dOmega;
        }
    }
    const float band[9] = {1.0f, 2.0f / 3.0f, 2.0f / 3.0f, 2.0f / 3.0f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f};
    for (int i = 0; i < 9; ++i)
        sh_[size_t(i)] = band[i] * vec3(float(acc[size_t(i * 3)]), float(acc[size_t(i * 3 + 1)]), float(acc[size_t(i * 3 + 2)]));
}

vec3 EnvironmentMap::specular(const vec3& dir, float roughness) const {
    const vec2 uv = equirectUv(dir);
    const float lod = (roughness > 0.0f ? std::min(roughness, 1.0f) : 0.0f) * float(kLevels - 1);   // NaN: level 0
    const int k0 = std::min(int(lod), kLevels - 1), k1 = std::min(k0 + 1, kLevels - 1);
    const float f = lod - float(k0);
    const vec3 a = sampleLevel(levels_[size_t(k0)], uv.x, uv.y);
    if (f <= 0.0f) return a;
    return (1.0f - f) * a + f * sampleLevel(levels_[size_t(k1)], uv.x, uv.y);
}

vec3 EnvironmentMap::diffuse(const vec3& n) const {
    const std::array<float, 9> yb = shBasis(n);
    vec3 e(0.0f);
    for (int i = 0; i < 9; ++i) e += sh_[size_t(i)] * yb[size_t(i)];
    return glm::max(e, vec3(0.0f));
}

std::vector<float> defaultEnvironmentImage(int w, int h) {
    std::vector<float> img(size_t(w) * size_t(h) * 3);
    auto lobe = [](const vec3& d, const vec3& axis, float cosWidth) {   // a soft disc of light
        const float c = glm::dot(d, glm::normalize(axis));
        return std::clamp((c - cosWidth) / (1.0f - cosWidth), 0.0f, 1.0f);
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const vec3 d = texelDirection(x, y, w, h);
            // Dim grey walls (darker toward the ceiling), a darker floor, and softboxes: what a
            // metal reflects reads as a metal, a dielectric gets soft light from all around.
            const float up = d.y;
            vec3 c = up >= 0.0f ? glm::mix(vec3(0.30f, 0.31f, 0.33f), vec3(0.20f, 0.21f, 0.23f), up) : glm::mix(vec3(0.16f), vec3(0.05f), -up);
            const float key = lobe(d, vec3(-0.6f, 0.7f, 0.6f), 0.93f);    // warm key, front left, high
            const float fill = lobe(d, vec3(0.8f, 0.35f, 0.3f), 0.85f);   // cool fill, right
            const float top = lobe(d, vec3(0.0f, 1.0f, 0.0f), 0.80f);     // overhead softbox
            const float rim = lobe(d, vec3(0.2f, 0.4f, -0.9f), 0.95f);    // rim, behind
            c += key * key * vec3(9.0f, 8.4f, 7.5f) + fill * fill * vec3(1.8f, 2.0f, 2.3f) + top * vec3(2.4f) + rim * rim * vec3(3.5f);
            float* o = &img[(size_t(y) * size_t(w) + size_t(x)) * 3];
            o[0] = c.x;
            o[1] = c.y;
            o[2] = c.z;
        }
    return img;
}

std::string loadRadianceHdr(const std::string& path, int& width, int& height, std::vector<float>& rgb) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return path + ": no such file";
    const auto size = std::filesystem::file_size(path, ec);
    if (ec || size > (uintmax_t(1) << 30)) return path + ": cannot read (or larger than 1 GiB)";
    std::ifstream in(path, std::ios::binary);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.size() < 11 ||
        (std::string(bytes.begin(), bytes.begin() + 10) != "#?RADIANCE" && std::string(bytes.begin(), bytes.begin() + 6) != "#?RGBE"))
        return path + ": not a Radiance .hdr file (it must start with #?RADIANCE or #?RGBE)";
    int w = 0, h = 0, n = 0;
    // The header's dimensions first: a hostile size is refused before anything is allocated.
    if (!stbi_info_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n)) return path + ": corrupt .hdr header";
    if (w <= 0 || h <= 0 || w > 16384 || h > 16384)
        return path + ": " + std::to_string(w) + "x" + std::to_string(h) + " is not a size this viewer takes (up to 16384x16384)";
    float* data = stbi_loadf_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n, 3);
    if (!data) {
        const char* why = stbi_failure_reason();
        return path + ": " + (why ? why : "corrupt data");
    }
    width = w;
    height = h;
    rgb.assign(data, data + size_t(w) * size_t(h) * 3);
    stbi_image_free(data);
    for (float& v : rgb)
        if (!std::isfinite(v) || v < 0.0f) v = 0.0f;
    return {};
}

void drawEnvironmentBackground(Framebuffer& target, const sg::FrameCamera& camera, const EnvironmentLight& env, const uint8_t bg[3], vec3* linear,
                               const vec3& bgLinear) {
    if (!env.map) return;
    const sg::mat4 inv = glm::inverse(camera.viewProj);
    const int w = target.width, h = target.height;
    tbb::parallel_for(0, h, [&](int row) {
        const float ny = 1.0f - (float(row) + 0.5f) / float(h) * 2.0f;   // row 0 at the top
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(row) * size_t(w) + size_t(x);
            uint8_t* p = target.pixel(x, row);
            if (target.depth[i] < 1.0f) continue;
            if (linear ? linear[i] != bgLinear : (p[0] != bg[0] || p[1] != bg[1] || p[2] != bg[2])) continue;
            const float nx = (float(x) + 0.5f) / float(w) * 2.0f - 1.0f;
            const sg::vec4 a = inv * sg::vec4(nx, ny, -1.0f, 1.0f), b = inv * sg::vec4(nx, ny, 1.0f, 1.0f);
            const vec3 dir = glm::normalize(vec3(b) / b.w - vec3(a) / a.w);
            const vec3 c = env.backgroundRadiance(dir);
            if (linear) {
                linear[i] = c;
                continue;
            }
            p[0] = toByteSRGB(c.x);
            p[1] = toByteSRGB(c.y);
            p[2] = toByteSRGB(c.z);
        }
    });
}

EnvironmentLight environmentFor(const sg::RenderSettings& s, std::string* error) {
    EnvironmentLight env;
    if (s.reflection != sg::ReflectionModel::Pbr || s.environment == "none" || s.environment.empty()) return env;
    // A few maps by name: switching between two files does not prefilter again.
    static std::mutex mutex;
    static std::list<std::shared_ptr<const EnvironmentMap>> cache;
    static std::list<std::pair<std::string, std::string>> failures;   // name, error
    std::shared_ptr<const EnvironmentMap> map;
    {
        std::lock_guard<std::mutex> lock(mutex);
        for (auto it = cache.begin(); it != cache.end(); ++it)
            if ((*it)->name() == s.environment) {
                map = *it;
                cache.splice(cache.begin(), cache, it);
                break;
            }
        if (!map)
            for (const auto& f : failures)
                if (f.first == s.environment) {
                    if (error) *error = f.second;
                    return env;
                }
        if (!map) {
            if (s.environment == "default") {
                const int w = 512, h = 256;
                const std::vector<float> img = defaultEnvironmentImage(w, h);
                map = std::make_shared<const EnvironmentMap>("default", w, h, img.data());
            } else {
                int w = 0, h = 0;
                std::vector<float> rgb;
                if (std::string e = loadRadianceHdr(s.environment, w, h, rgb); !e.empty()) {
                    failures.emplace_front(s.environment, e);
                    if (failures.size() > 8) failures.pop_back();
                    if (error) *error = e;
                    return env;
                }
                map = std::make_shared<const EnvironmentMap>(s.environment, w, h, rgb.data());
            }
            cache.push_front(map);
            if (cache.size() > 4) cache.pop_back();
        }
    }
    env.map = std::move(map);
    env.intensity = s.environmentIntensity;
    const float r = s.environmentRotationDeg * kPi / 180.0f;
    env.cosRot = std::cos(r);
    env.sinRot = std::sin(r);
    env.background = s.environmentBackground;
    return env;
}

}   // namespace rnd
