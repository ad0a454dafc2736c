// framebuffer.h - what every backend renders into: RGBA8 colour + float depth, any size, and on
// request the other AOVs (aov.h): the visibility of each pixel (which drawable and which of its
// primitives it shows) and per-pixel counters for the overdraw and cost diagnostic views.
// Rows are stored top to bottom (row 0 is the top of the image, as in PNG files).
#pragma once

#include "renderers/aov.h"

#include <cstdint>
#include <string>
#include <vector>

namespace rnd {

inline constexpr uint32_t kNoPrimitive = 0xffffffffu;

struct Framebuffer {
    int width = 0, height = 0;
    std::vector<uint8_t> color;   // width*height*4, sRGB-encoded RGBA8 (display-ready)
    std::vector<float> depth;     // width*height, window-space depth in [0,1] (1 = far / empty)
    // Visibility (empty unless render() was asked for it): the surface seen through each
    // pixel's centre, the one that wrote depth (opaque, masked and kept, a point or a line;
    // never a blended layer), sampled once per pixel whatever the anti-aliasing.
    //   drawable:  0 = nothing; k <= M: frame.meshes[k-1]; k > M: frame.analytics[k-1-M]
    //   primitive: triangle (points: point, lines: segment) index within that mesh;
    //              kNoPrimitive for analytic shapes and empty pixels
    std::vector<uint32_t> drawable, primitive;
    // Per-pixel counters of the diagnostic views (empty unless render() was asked for them;
    // counted at one sample per pixel, see renderers/diagnostic.h for the definitions):
    //   overdraw:  fragments rasterized in the pixel before any depth test (rasterizers)
    //   costNodes: BVH nodes the pixel's primary ray visited (ray caster)
    //   costPrims: triangles (and analytic shapes) the primary ray was tested against
    std::vector<uint32_t> overdraw, costNodes, costPrims;

    void resize(int w, int h);   // colour and depth; drops the visibility and the counters
    // As resize(), but colour and depth keep whatever they held (unspecified values): for a
    // backend that writes every pixel next, so a frame of the same size costs no fill.
    void resizeForOverwrite(int w, int h);
    // The buffers of `aov` at the current size: the visibility all empty (Normal and Id: the
    // visibility they are made from), the counters all 0, the depth all 1.
    void allocate(Aov aov);
    // Whether the image holds `aov` at its size (Normal and Id: the visibility they are made from).
    bool has(Aov aov) const;
    // Takes the visibility and the counters of `src` (an image of the same pixel centres: the
    // one-sample pass of an anti-aliased image), leaving colour and depth as they are.
    void takeVisibilityAndCounters(Framebuffer&& src);
    void clear(const uint8_t rgba[4], float depthValue = 1.0f);
    uint8_t* pixel(int x, int y) { return &color[(size_t(y) * width + x) * 4]; }
    const uint8_t* pixel(int x, int y) const { return &color[(size_t(y) * width + x) * 4]; }
};

// Per-channel comparison of two images of the same size (alpha ignored).
struct ImageDiff {
    double meanAbs = 0;          // mean absolute difference per channel, in 0..255 units
    int maxAbs = 0;              // largest channel difference
    double fractionWithin = 1;   // fraction of pixels whose channels all differ by <= tolerance
    double psnr = 0;             // dB (infinity when identical)
    std::string describe() const;
};
ImageDiff compareImages(const Framebuffer& a, const Framebuffer& b, int tolerance);
// Heat-map of |a - b| (black = equal, red/yellow = large); pixels above threshold highlighted.
Framebuffer diffImage(const Framebuffer& a, const Framebuffer& b, int threshold = 0);
// Box-filters a framebuffer down by an integer factor (SSAA resolve).
Framebuffer downsample(const Framebuffer& src, int factor);

}   // namespace rnd
