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

uint8_t encodeByte(float linear) { return toByteSRGB(linear); }

}   // namespace

SampledTexture::SampledTexture(const sg::Texture& t) : m_wrapS(t.wrapS), m_wrapT(t.wrapT), m_filter(t.filter) {
    Level base;
    base.w = std::max(t.width, 1);
    base.h = std::max(t.height, 1);
    base.texels.assign(size_t(base.w) * base.h, vec3(1.0f));
    if (t.width > 0 && t.height > 0 && t.rgba.size() >= size_t(t.width) * t.height * 4)
        for (int r = 0; r < t.height; ++r)
            for (int c = 0; c < t.width; ++c)   // file row r is GL row h-1-r
                base.texels[size_t(t.height - 1 - r) * base.w + c] = srgbBytesToLinear(&t.rgba[(size_t(r) * t.width + c) * 4]);
    m_levels.push_back(std::move(base));
    if (m_filter != sg::FilterMode::Trilinear) return;
    // Mip chain: each level halves (floor, min 1); 2x2 box average in linear, re-quantised to
    // 8-bit sRGB like an SRGB8 texture level.
    while (m_levels.back().w > 1 || m_levels.back().h > 1) {
        const Level& p = m_levels.back();
        Level l;
        l.w = std::max(p.w / 2, 1);
        l.h = std::max(p.h / 2, 1);
        l.texels.resize(size_t(l.w) * l.h);
        for (int y = 0; y < l.h; ++y)
            for (int x = 0; x < l.w; ++x) {
                vec3 s(0.0f);
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx) s += p.texels[size_t(std::min(2 * y + dy, p.h - 1)) * p.w + std::min(2 * x + dx, p.w - 1)];
                s *= 0.25f;
                uint8_t b[3] = {encodeByte(s.x), encodeByte(s.y), encodeByte(s.z)};
                l.texels[size_t(y) * l.w + x] = srgbBytesToLinear(b);
            }
        m_levels.push_back(std::move(l));
    }
}

vec3 SampledTexture::sampleLevel(vec2 uv, int level, bool bilinear) const {
    const Level& l = m_levels[std::clamp(level, 0, int(m_levels.size()) - 1)];
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return l.texels[0];
    float fx = uv.x * l.w, fy = uv.y * l.h;
    // Keep the coordinates in a range where int conversion is safe (wraps are periodic).
    auto reduce = [](float f, int n) {
        float p = 2.0f * n;
        return std::fabs(f) > 1e6f ? f - p * std::floor(f / p) : f;
    };
    fx = reduce(fx, l.w);
    fy = reduce(fy, l.h);
    if (!bilinear) {
        int i = wrapIndex(int(std::floor(fx)), l.w, m_wrapS), j = wrapIndex(int(std::floor(fy)), l.h, m_wrapT);
        return l.texels[size_t(j) * l.w + i];
    }
    fx -= 0.5f;
    fy -= 0.5f;
    float x0f = std::floor(fx), y0f = std::floor(fy);
    float ax = fx - x0f, ay = fy - y0f;
    int x0 = int(x0f), y0 = int(y0f);
    int i0 = wrapIndex(x0, l.w, m_wrapS), i1 = wrapIndex(x0 + 1, l.w, m_wrapS);
    int j0 = wrapIndex(y0, l.h, m_wrapT), j1 = wrapIndex(y0 + 1, l.h, m_wrapT);
    const vec3& a = l.texels[size_t(j0) * l.w + i0];
    const vec3& b = l.texels[size_t(j0) * l.w + i1];
    const vec3& c = l.texels[size_t(j1) * l.w + i0];
    const vec3& d = l.texels[size_t(j1) * l.w + i1];
    return (a * (1 - ax) + b * ax) * (1 - ay) + (c * (1 - ax) + d * ax) * ay;
}

vec3 SampledTexture::sample(vec2 uv, vec2 ddx, vec2 ddy) const {
    if (m_filter == sg::FilterMode::Nearest) return sampleLevel(uv, 0, false);
    if (m_filter == sg::FilterMode::Bilinear || m_levels.size() == 1) return sampleLevel(uv, 0, true);
    // GL: rho = max(|d(uv*size)/dx|, |d(uv*size)/dy|), lambda = log2(rho).
    const Level& b = m_levels[0];
    float ax = ddx.x * b.w, ay = ddx.y * b.h, bx = ddy.x * b.w, by = ddy.y * b.h;
    float rho2 = std::max(ax * ax + ay * ay, bx * bx + by * by);
    float lambda = rho2 > 0 ? 0.5f * std::log2(rho2) : -100.0f;
    if (!(lambda > 0.0f)) return sampleLevel(uv, 0, true);   // magnification (or NaN)
    float maxLevel = float(m_levels.size() - 1);
    lambda = std::min(lambda, maxLevel);
    int l0 = int(lambda);
    float f = lambda - l0;
    vec3 c0 = sampleLevel(uv, l0, true);
    if (f <= 0.0f || l0 + 1 > int(maxLevel)) return c0;
    return c0 * (1 - f) + sampleLevel(uv, l0 + 1, true) * f;
}

const SampledTexture* SamplerCache::get(const sg::TexturePtr& t) {
    if (!t || t->width <= 0 || t->height <= 0 || t->rgba.size() < size_t(t->width) * size_t(t->height) * 4) return nullptr;
    Entry& e = m_entries[t->id];
    if (!e.tex || e.version != t->version || e.filter != t->filter || e.wrapS != t->wrapS || e.wrapT != t->wrapT) {
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
