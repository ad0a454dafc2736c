// texture_sampler.h - texture sampling for the CPU backends (rasterizer and ray caster, so
// both filter exactly alike), following GL: sRGB texels are
// decoded to linear before filtering (as GL_SRGB8_ALPHA8 textures are), texel centres at
// +0.5, wrap modes REPEAT / CLAMP_TO_EDGE / MIRRORED_REPEAT, NEAREST, LINEAR, and
// LINEAR_MIPMAP_LINEAR with a mip chain built like glGenerateMipmap (2x2 box in linear,
// stored back as 8-bit sRGB). Texture rows are stored top-down in sg::Texture (row 0 = v 1);
// levels here are kept bottom-up so that texel row r covers t in [r/h, (r+1)/h] as in GL.
#pragma once

#include "scenegraph/mesh.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

namespace rnd {

class SampledTexture {
public:
    explicit SampledTexture(const sg::Texture& t);
    // Linear RGB at (u, v) with the screen-space derivatives of (u, v) (for the mip level).
    sg::vec3 sample(sg::vec2 uv, sg::vec2 dUVdx, sg::vec2 dUVdy) const;
    sg::vec3 sampleLevel(sg::vec2 uv, int level, bool bilinear) const;
    // Alpha (stored linearly, as GL does for SRGB8_ALPHA8), filtered like sample(); 1 for
    // textures whose texels are all opaque.
    float sampleAlpha(sg::vec2 uv, sg::vec2 dUVdx, sg::vec2 dUVdy) const;
    float sampleAlphaLevel(sg::vec2 uv, int level, bool bilinear) const;
    bool hasAlpha() const { return m_hasAlpha; }
    int levels() const { return int(m_levels.size()); }
    sg::FilterMode filter() const { return m_filter; }
    bool srgb() const { return m_srgb; }   // colour texture (decoded to linear); false: data, values / 255

private:
    struct Level {
        int w = 0, h = 0;
        std::vector<sg::vec3> texels;   // linear RGB, bottom-up rows
        std::vector<float> alpha;       // same layout; empty when the texture is opaque
    };
    // The mip level (l0, blend weight f toward l0 + 1) GL picks for these derivatives; false
    // for magnification or a non-trilinear filter (level 0).
    bool mipLevel(sg::vec2 ddx, sg::vec2 ddy, int& l0, float& f) const;
    bool m_hasAlpha = false;
    std::vector<Level> m_levels;
    sg::WrapMode m_wrapS, m_wrapT;
    sg::FilterMode m_filter;
    bool m_srgb = true;
};

// uv where rays org + t dir meet the plane of triangle P with uvs uv: the barycentrics of that
// point, inside the triangle or not (a neighbouring pixel's uv, whose difference from the
// pixel's own gives sample()'s derivatives). The triangle's own terms are made once for all the
// rays asked (a footprint asks for two).
class TrianglePlaneUv {
public:
    TrianglePlaneUv(const sg::vec3 P[3], const sg::vec2 uv[3])
        : m_p0(P[0]), m_e1(P[1] - P[0]), m_e2(P[2] - P[0]), m_n(glm::cross(m_e1, m_e2)), m_uv{uv[0], uv[1], uv[2]} {
        m_d00 = glm::dot(m_e1, m_e1), m_d01 = glm::dot(m_e1, m_e2), m_d11 = glm::dot(m_e2, m_e2);
        m_det = m_d00 * m_d11 - m_d01 * m_d01;
    }
    // False for rays along the plane and for degenerate triangles.
    bool at(const sg::vec3& org, const sg::vec3& dir, sg::vec2& out) const {
        const float denom = glm::dot(dir, m_n);
        if (!(std::abs(denom) > 1e-30f)) return false;
        const sg::vec3 q = org + (glm::dot(m_p0 - org, m_n) / denom) * dir - m_p0;
        const float d20 = glm::dot(q, m_e1), d21 = glm::dot(q, m_e2);
        if (!(std::abs(m_det) > 0)) return false;
        const float b1 = (m_d11 * d20 - m_d01 * d21) / m_det, b2 = (m_d00 * d21 - m_d01 * d20) / m_det;
        out = (1.0f - b1 - b2) * m_uv[0] + b1 * m_uv[1] + b2 * m_uv[2];
        return std::isfinite(out.x) && std::isfinite(out.y);
    }

private:
    sg::vec3 m_p0, m_e1, m_e2, m_n;
    sg::vec2 m_uv[3];
    float m_d00, m_d01, m_d11, m_det;
};

// Samplers (mip chains) per texture, rebuilt when a texture's version or its filter/wrap modes
// change (a copy of a texture keeps its id), shared by the
// CPU backends: beginFrame(), get() for each texture drawn, endFrame() drops samplers unused
// for 8 frames. get() returns null for empty or inconsistent textures.
class SamplerCache {
public:
    void beginFrame() { ++m_frame; }
    const SampledTexture* get(const sg::TexturePtr& t);
    void endFrame();

private:
    struct Entry {
        std::unique_ptr<SampledTexture> tex;
        uint64_t version = 0;
        sg::FilterMode filter{};   // sampling state baked into the sampler: a change rebuilds it
        sg::WrapMode wrapS{}, wrapT{};
        uint64_t lastFrame = 0;
    };
    std::unordered_map<uint64_t, Entry> m_entries;
    uint64_t m_frame = 0;
};

}   // namespace rnd
