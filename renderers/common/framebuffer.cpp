// framebuffer.cpp - Framebuffer storage (see framebuffer.h: sizing, growing a large image's
// colour and depth side by side, the visibility and counter buffers, clear) and the image tools
// built on it: compareImages() (mean and max difference, fraction within a tolerance, PSNR) for
// the tests and the difference view, diffImage() (a heat map of the differences over a dim
// copy), and downsample() (the SSAA resolve: a box filter in linear light).
#include "renderers/framebuffer.h"

#include "renderers/shading.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace rnd {

void Framebuffer::resize(int w, int h) {
    resizeForOverwrite(w, h);
    std::fill(color.begin(), color.end(), uint8_t(0));
    std::fill(depth.begin(), depth.end(), 1.0f);
}

void Framebuffer::resizeForOverwrite(int w, int h) {
    width = std::max(w, 0);
    height = std::max(h, 0);
    // A new image's vectors are zero-filled as they grow, and the first touch of each page is a
    // page fault: ~4 ms at 1280x720 on one thread, most of a first frame's extra cost. Colour and
    // depth grow side by side.
    const size_t nc = size_t(width) * height * 4, nd = size_t(width) * height;
    if (color.size() != nc && depth.size() != nd && nd >= (size_t(1) << 16))
        tbb::parallel_invoke([&] { color.resize(nc); }, [&] { depth.resize(nd); });
    color.resize(nc);
    depth.resize(nd);
    drawable.clear();
    primitive.clear();
    overdraw.clear();
    costNodes.clear();
    costPrims.clear();
}

void Framebuffer::allocate(Aov aov) {
    const size_t n = size_t(width) * height;
    switch (aov) {
    case Aov::Depth: depth.assign(n, 1.0f); break;
    case Aov::Visibility:
    case Aov::Normal:
    case Aov::Id:
        drawable.assign(n, 0u);
        primitive.assign(n, kNoPrimitive);
        break;
    case Aov::Overdraw: overdraw.assign(n, 0u); break;
    case Aov::TraversalCost:
        costNodes.assign(n, 0u);
        costPrims.assign(n, 0u);
        break;
    }
}

bool Framebuffer::has(Aov aov) const {
    const size_t n = size_t(width) * height;
    switch (aov) {
    case Aov::Depth: return depth.size() == n && !depth.empty();
    case Aov::Visibility:
    case Aov::Normal:
    case Aov::Id: return drawable.size() == n && primitive.size() == n && !drawable.empty();
    case Aov::Overdraw: return overdraw.size() == n && !overdraw.empty();
    case Aov::TraversalCost: return costNodes.size() == n && costPrims.size() == n && !costNodes.empty();
    }
    return false;
}

void Framebuffer::takeVisibilityAndCounters(Framebuffer&& src) {
    drawable = std::move(src.drawable);
    primitive = std::move(src.primitive);
    overdraw = std::move(src.overdraw);
    costNodes = std::move(src.costNodes);
    costPrims = std::move(src.costPrims);
}

void Framebuffer::clear(const uint8_t rgba[4], float d) {
    uint32_t pixel;   // one 4-byte store per pixel (the compiler makes wide stores of the loop)
    std::memcpy(&pixel, rgba, 4);
    uint8_t* const out = color.data();
    const size_t n = color.size() / 4;
    for (size_t i = 0; i < n; ++i) std::memcpy(out + 4 * i, &pixel, 4);
    std::fill(depth.begin(), depth.end(), d);
}

std::string ImageDiff::describe() const {
    char buf[160];
    std::snprintf(buf, sizeof buf, "mean %.3f/255, max %d/255, %.3f%% within tolerance, PSNR %.2f dB", meanAbs, maxAbs, fractionWithin * 100.0, psnr);
    return buf;
}

ImageDiff compareImages(const Framebuffer& a, const Framebuffer& b, int tolerance) {
    ImageDiff d;
    if (a.width != b.width || a.height != b.height || a.width * a.height == 0) {
        d.meanAbs = 255;
        d.maxAbs = 255;
        d.fractionWithin = 0;
        return d;
    }
    size_t n = size_t(a.width) * a.height, within = 0;
    double sum = 0, sq = 0;
    for (size_t i = 0; i < n; ++i) {
        int worst = 0;
        for (int c = 0; c < 3; ++c) {
            int diff = std::abs(int(a.color[i * 4 + c]) - int(b.color[i * 4 + c]));
            sum += diff;
            sq += double(diff) * diff;
            worst = std::max(worst, diff);
        }
        d.maxAbs = std::max(d.maxAbs, worst);
        if (worst <= tolerance) ++within;
    }
    d.meanAbs = sum / (3.0 * n);
    d.fractionWithin = double(within) / n;
    double mse = sq / (3.0 * n);
    d.psnr = mse == 0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(255.0 * 255.0 / mse);
    return d;
}

Framebuffer diffImage(const Framebuffer& a, const Framebuffer& b, int threshold) {
    Framebuffer out;
    out.resize(a.width, a.height);
    if (a.width != b.width || a.height != b.height) return out;
    for (size_t i = 0; i < size_t(a.width) * a.height; ++i) {
        int worst = 0;
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(a.color[i * 4 + c]) - int(b.color[i * 4 + c])));
        uint8_t* p = &out.color[i * 4];
        if (worst <= threshold) {
            // Below threshold: a dim grey copy of the first image for context.
            uint8_t g = uint8_t((a.color[i * 4] + a.color[i * 4 + 1] + a.color[i * 4 + 2]) / 12);
            p[0] = p[1] = p[2] = g;
        } else {
            // Heat map: red at small differences rising through yellow to white at 255.
            float t = std::min(1.0f, worst / 64.0f);
            p[0] = 255;
            p[1] = uint8_t(255 * std::clamp(t * 1.5f - 0.25f, 0.0f, 1.0f));
            p[2] = uint8_t(255 * std::clamp(t * 2.0f - 1.0f, 0.0f, 1.0f));
        }
        p[3] = 255;
    }
    return out;
}

// Box filter of f x f samples. Colour is averaged in linear light (decode sRGB, average,
// encode), as MSAA resolves and the ray caster's samples are: averaging the sRGB bytes would
// make a 25%-covered white edge pixel 64 instead of 137. Alpha is averaged as is; depth keeps
// the nearest sample.
Framebuffer downsample(const Framebuffer& src, int f) {
    Framebuffer out;
    if (f <= 1) return src;
    static const std::array<float, 256> kLinear = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[i] = decodeSRGB(float(i) / 255.0f);
        return t;
    }();
    out.resize(src.width / f, src.height / f);
    const float inv = 1.0f / float(f * f);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            float acc[3] = {0, 0, 0};
            int alpha = 0;
            float dmin = 1.0f;
            for (int sy = 0; sy < f; ++sy)
                for (int sx = 0; sx < f; ++sx) {
                    const uint8_t* p = src.pixel(x * f + sx, y * f + sy);
                    for (int c = 0; c < 3; ++c) acc[c] += kLinear[p[c]];
                    alpha += p[3];
                    dmin = std::min(dmin, src.depth[size_t(y * f + sy) * src.width + x * f + sx]);
                }
            uint8_t* o = out.pixel(x, y);
            for (int c = 0; c < 3; ++c) o[c] = toByteSRGB(acc[c] * inv);
            o[3] = uint8_t((alpha + f * f / 2) / (f * f));
            out.depth[size_t(y) * out.width + x] = dmin;
        }
    return out;
}

}   // namespace rnd
