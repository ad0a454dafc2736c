// texture_sampler.cpp - SampledTexture (see texture_sampler.h): the mip chain built as
// glGenerateMipmap builds it, GL's wrap modes, nearest / bilinear / trilinear lookups of colour
// and alpha with the level chosen from the uv derivatives as GL chooses it, and SamplerCache,
// which keeps one SampledTexture per texture version and drops those unused for 8 frames.
#include "renderers/texture_sampler.h"

#include "renderers/shading.h"

#include <algorithm>
#include <cmath>

namespace rnd {

using sg::vec2;
using sg::vec3;

namespace {

int wrapIndex(int i, int n, sg::WrapMode m) {
    switch (m) {
    case sg::WrapMode::Repeat: {
        int r = i % n;
        return r < 0 ? r + n : r;
    }
    case sg::WrapMode::ClampToEdge: return std::clamp(i, 0, n - 1);
    case sg::WrapMode::MirroredRepeat: {
        int p = 2 * n, r = i % p;
        if (r < 0) r += p;
        return r >= n ? p - 1 - r : r;
    }
    }
    return 0;
}

// A texel's colour bytes -> linear values: sRGB-decoded for colour textures, /255 for data.
vec3 texelValue(const uint8_t* rgb, bool srgb) { return srgb ? srgbBytesToLinear(rgb) : vec3(rgb[0], rgb[1], rgb[2]) * (1.0f / 255.0f); }
// Re-quantised to the texture's storage (mip levels): 8-bit sRGB for colour; data textures are
// RGBA16 in GL (renderers/gl), whose 16 bits we treat as exact.
vec3 quantised(const vec3& v, bool srgb) {
    if (!srgb) return glm::clamp(v, 0.0f, 1.0f);
    const uint8_t bytes[3] = {toByteSRGB(v.x), toByteSRGB(v.y), toByteSRGB(v.z)};
    return srgbBytesToLinear(bytes);
}

}   // namespace

SampledTexture::SampledTexture(const sg::Texture& t) : m_wrapS(t.wrapS), m_wrapT(t.wrapT), m_filter(t.filter), m_srgb(t.srgb) {
    Level base;
    base.w = std::max(t.width, 1);
    base.h = std::max(t.height, 1);
    base.texels.assign(size_t(base.w) * base.h, vec3(1.0f));
    const bool filled = t.width > 0 && t.height > 0 && t.rgba.size() >= size_t(t.width) * t.height * 4;
    if (filled)
        for (int r = 0; r < t.height; ++r)
            for (int c = 0; c < t.width; ++c)   // file row r is GL row h-1-r
                base.texels[size_t(t.height - 1 - r) * base.w + c] = texelValue(&t.rgba[(size_t(r) * t.width + c) * 4], t.srgb);
    if (filled)
        for (size_t i = 3; i < size_t(t.width) * t.height * 4; i += 4) m_hasAlpha = m_hasAlpha || t.rgba[i] != 255;
    if (m_hasAlpha) {
        base.alpha.resize(base.texels.size());
        for (int r = 0; r < t.height; ++r)
            for (int c = 0; c < t.width; ++c)
                base.alpha[size_t(t.height - 1 - r) * base.w + c] = float(t.rgba[(size_t(r) * t.width + c) * 4 + 3]) / 255.0f;
    }
    m_levels.push_back(std::move(base));
    if (m_filter != sg::FilterMode::Trilinear) return;
    // Mip chain: each level halves (floor, min 1), filtered like the linear-filtered blit that
    // glGenerateMipmap performs (Mesa's util_gen_mipmap): destination texel x takes the
    // previous level bilinearly at its centre mapped back, (x + 0.5) * w_prev / w - 0.5,
    // clamped to the edge, in linear light; stored re-quantised to 8 bits (sRGB like an SRGB8
    // texture level; data textures unrounded, like GL's RGBA16 levels; alpha: to 8 bits). For even sizes this is the 2x2 box average; for odd
    // (NPOT) sizes the sample points keep the image aligned instead of drifting by half a texel.
    while (m_levels.back().w > 1 || m_levels.back().h > 1) {
        const Level& p = m_levels.back();
        Level l;
        l.w = std::max(p.w / 2, 1);
        l.h = std::max(p.h / 2, 1);
        l.texels.resize(size_t(l.w) * l.h);
        if (m_hasAlpha) l.alpha.resize(l.texels.size());
        const float sx = float(p.w) / float(l.w), sy = float(p.h) / float(l.h);
        for (int y = 0; y < l.h; ++y) {
            const float fy = std::clamp((float(y) + 0.5f) * sy - 0.5f, 0.0f, float(p.h - 1));
            const int y0 = std::min(int(fy), p.h - 1), y1 = std::min(y0 + 1, p.h - 1);
            const float ay = fy - float(y0);
            for (int x = 0; x < l.w; ++x) {
                const float fx = std::clamp((float(x) + 0.5f) * sx - 0.5f, 0.0f, float(p.w - 1));
                const int x0 = std::min(int(fx), p.w - 1), x1 = std::min(x0 + 1, p.w - 1);
                const float ax = fx - float(x0);
                const size_t a = size_t(y0) * p.w + x0, b = size_t(y0) * p.w + x1, c = size_t(y1) * p.w + x0, d = size_t(y1) * p.w + x1;
                const vec3 s = (p.texels[a] * (1 - ax) + p.texels[b] * ax) * (1 - ay) + (p.texels[c] * (1 - ax) + p.texels[d] * ax) * ay;
                l.texels[size_t(y) * l.w + x] = quantised(s, t.srgb);
                if (m_hasAlpha) {
                    const float al = (p.alpha[a] * (1 - ax) + p.alpha[b] * ax) * (1 - ay) + (p.alpha[c] * (1 - ax) + p.alpha[d] * ax) * ay;
                    l.alpha[size_t(y) * l.w + x] = std::round(al * 255.0f) / 255.0f;
                }
            }
        }
        m_levels.push_back(std::move(l));
    }
}

namespace {

// Texel lookup of one level with GL's wrap modes, nearest or bilinear, for colour or alpha.
template <class T>
T filterLevel(const std::vector<T>& texels, int w, int h, sg::WrapMode ws, sg::WrapMode wt, vec2 uv, bool bilinear) {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return texels[0];
    float fx = uv.x * w, fy = uv.y * h;
    // Keep the coordinates in a range where int conversion is safe (wraps are periodic).
    auto reduce = [](float f, int n) {
        float p = 2.0f * n;
        return std::fabs(f) > 1e6f ? f - p * std::floor(f / p) : f;
    };
    fx = reduce(fx, w);
    fy = reduce(fy, h);
    if (!bilinear) {
        int i = wrapIndex(int(std::floor(fx)), w, ws), j = wrapIndex(int(std::floor(fy)), h, wt);
        return texels[size_t(j) * w + i];
    }
    fx -= 0.5f;
    fy -= 0.5f;
    float x0f = std::floor(fx), y0f = std::floor(fy);
    float ax = fx - x0f, ay = fy - y0f;
    int x0 = int(x0f), y0 = int(y0f);
    int i0 = wrapIndex(x0, w, ws), i1 = wrapIndex(x0 + 1, w, ws);
    int j0 = wrapIndex(y0, h, wt), j1 = wrapIndex(y0 + 1, h, wt);
    const T& a = texels[size_t(j0) * w + i0];
    const T& b = texels[size_t(j0) * w + i1];
    const T& c = texels[size_t(j1) * w + i0];
    const T& d = texels[size_t(j1) * w + i1];
    return (a * (1 - ax) + b * ax) * (1 - ay) + (c * (1 - ax) + d * ax) * ay;
}

}   // namespace

vec3 SampledTexture::sampleLevel(vec2 uv, int level, bool bilinear) const {
    const Level& l = m_levels[std::clamp(level, 0, int(m_levels.size()) - 1)];
    return filterLevel(l.texels, l.w, l.h, m_wrapS, m_wrapT, uv, bilinear);
}

float SampledTexture::sampleAlphaLevel(vec2 uv, int level, bool bilinear) const {
    if (!m_hasAlpha) return 1.0f;
    const Level& l = m_levels[std::clamp(level, 0, int(m_levels.size()) - 1)];
    return filterLevel(l.alpha, l.w, l.h, m_wrapS, m_wrapT, uv, bilinear);
}

bool SampledTexture::mipLevel(vec2 ddx, vec2 ddy, int& l0, float& f) const {
    l0 = 0;
    f = 0.0f;
    if (m_filter != sg::FilterMode::Trilinear || m_levels.size() == 1) return false;
    // GL: rho = max(|d(uv*size)/dx|, |d(uv*size)/dy|), lambda = log2(rho).
    const Level& b = m_levels[0];
    float ax = ddx.x * b.w, ay = ddx.y * b.h, bx = ddy.x * b.w, by = ddy.y * b.h;
    float rho2 = std::max(ax * ax + ay * ay, bx * bx + by * by);
    float lambda = rho2 > 0 ? 0.5f * std::log2(rho2) : -100.0f;
    if (!(lambda > 0.0f)) return false;   // magnification (or NaN)
    float maxLevel = float(m_levels.size() - 1);
    lambda = std::min(lambda, maxLevel);
    l0 = int(lambda);
    f = l0 + 1 > int(maxLevel) ? 0.0f : lambda - float(l0);
    return true;
}

vec3 SampledTexture::sample(vec2 uv, vec2 ddx, vec2 ddy) const {
    if (m_filter == sg::FilterMode::Nearest) return sampleLevel(uv, 0, false);
    int l0;
    float f;
    if (!mipLevel(ddx, ddy, l0, f)) return sampleLevel(uv, 0, true);
    vec3 c0 = sampleLevel(uv, l0, true);
    if (f <= 0.0f) return c0;
    return c0 * (1 - f) + sampleLevel(uv, l0 + 1, true) * f;
}

float SampledTexture::sampleAlpha(vec2 uv, vec2 ddx, vec2 ddy) const {
    if (!m_hasAlpha) return 1.0f;
    if (m_filter == sg::FilterMode::Nearest) return sampleAlphaLevel(uv, 0, false);
    int l0;
    float f;
    if (!mipLevel(ddx, ddy, l0, f)) return sampleAlphaLevel(uv, 0, true);
    float a0 = sampleAlphaLevel(uv, l0, true);
    if (f <= 0.0f) return a0;
    return a0 * (1 - f) + sampleAlphaLevel(uv, l0 + 1, true) * f;
}

const SampledTexture* SamplerCache::get(const sg::TexturePtr& t) {
    if (!t || t->width <= 0 || t->height <= 0 || t->rgba.size() < size_t(t->width) * size_t(t->height) * 4) return nullptr;
    Entry& e = m_entries[t->id];
    if (!e.tex || e.version != t->version || e.filter != t->filter || e.wrapS != t->wrapS || e.wrapT != t->wrapT || e.tex->srgb() != t->srgb) {
        e.tex = std::make_unique<SampledTexture>(*t);
        e.version = t->version;
        e.filter = t->filter;
        e.wrapS = t->wrapS;
        e.wrapT = t->wrapT;
    }
    e.lastFrame = m_frame;
    return e.tex.get();
}

void SamplerCache::endFrame() {
    for (auto it = m_entries.begin(); it != m_entries.end();) it = m_frame - it->second.lastFrame > 8 ? m_entries.erase(it) : std::next(it);
}

}   // namespace rnd
