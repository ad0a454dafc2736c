// window_lines.h - clip space to window coordinates and thin lines, shared by the CPU
// rasterizer (its triangles and lines) and the point/line/wireframe overlay that both CPU
// backends draw (common/line_overlay.cpp). GL conventions: window origin bottom-left, pixel
// (i, j) centred at (i + 0.5, j + 0.5), window z = 0.5 z_ndc + 0.5.
#pragma once

#include "scenegraph/math.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace rnd::lines {

constexpr float kGuardPixels = 8192.0f;   // guard band beyond the viewport (x, y)

// Outcode bits: near (z < -w), far (z > w), and the four guard-band planes |x|,|y| <= g*w.
// Triangles whose vertices have no bits set need no clipping; near and far are clipped
// exactly, x and y only outside the guard band (the viewport scissor does the rest).
namespace clipbits {
enum : uint8_t { kClipNear = 1, kClipFar = 2, kClipLeft = 4, kClipRight = 8, kClipBottom = 16, kClipTop = 32, kInvalid = 64 };
}   // namespace clipbits
using namespace clipbits;

struct GuardBand {
    float gx = 1, gy = 1;
};
inline GuardBand guardBand(int width, int height) {
    return {1.0f + 2.0f * kGuardPixels / std::max(width, 1), 1.0f + 2.0f * kGuardPixels / std::max(height, 1)};
}

// kInvalid marks a non-finite position: triangles using it are dropped, not clipped.
inline uint8_t outcode(const sg::vec4& c, const GuardBand& g) {
    if (!(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && std::isfinite(c.w))) return kInvalid | kClipNear;
    uint8_t o = 0;
    if (!(c.z >= -c.w)) o |= kClipNear;   // also catches NaN
    if (!(c.z <= c.w)) o |= kClipFar;
    if (c.x < -g.gx * c.w) o |= kClipLeft;
    if (c.x > g.gx * c.w) o |= kClipRight;
    if (c.y < -g.gy * c.w) o |= kClipBottom;
    if (c.y > g.gy * c.w) o |= kClipTop;
    return o;
}

// Window coordinates (x, y, z, 1/w) of a clip-space position for a width x height viewport.
inline sg::vec4 toWindow(const sg::vec4& c, int width, int height) {
    float iw = 1.0f / c.w;
    return {(c.x * iw * 0.5f + 0.5f) * width, (c.y * iw * 0.5f + 0.5f) * height, c.z * iw * 0.5f + 0.5f, iw};
}

// Clips segment a-b (clip space) to near/far and the guard band; false when nothing is left.
inline bool clipSegment(sg::vec4& a, sg::vec4& b, const GuardBand& g) {
    float t0 = 0, t1 = 1;
    auto clipPlane = [&](float da, float db) {
        if (da < 0 && db < 0) return false;
        if (da < 0)
            t0 = std::max(t0, da / (da - db));
        else if (db < 0)
            t1 = std::min(t1, da / (da - db));
        return t0 <= t1;
    };
    if (!clipPlane(a.z + a.w, b.z + b.w) || !clipPlane(a.w - a.z, b.w - b.z) || !clipPlane(a.x + g.gx * a.w, b.x + g.gx * b.w) ||
        !clipPlane(g.gx * a.w - a.x, g.gx * b.w - b.x) || !clipPlane(a.y + g.gy * a.w, b.y + g.gy * b.w) ||
        !clipPlane(g.gy * a.w - a.y, g.gy * b.w - b.y))
        return false;
    sg::vec4 na = a + t0 * (b - a), nb = a + t1 * (b - a);
    a = na;
    b = nb;
    return true;
}

// Calls fn(i, j, t) for the pixels of the segment a -> b (window coordinates): one pixel per
// column (x-major) or row (y-major) whose centre lies in [start, end) along the major axis,
// the minor coordinate stepped incrementally by the slope and sampled at that centre (GL's
// diamond-exit rule for thin lines, approximately); t in [0,1] is the screen-space position
// of the sample along the segment. Half-open, so joined segments do not repeat a pixel.
template <class Fn>
inline void drawLineDDA(float ax, float ay, float bx, float by, int width, int height, Fn&& fn) {
    float dx = bx - ax, dy = by - ay;
    if (!(std::fabs(dx) < 1e6f && std::fabs(dy) < 1e6f)) return;   // non-finite or absurd
    const bool xMajor = std::fabs(dx) >= std::fabs(dy);
    const float a0 = xMajor ? ax : ay, len = xMajor ? dx : dy;
    const float b0 = xMajor ? ay : ax, d = xMajor ? dy : dx;
    if (len == 0) return;
    const float slope = d / len;
    const int majorSize = xMajor ? width : height, minorSize = xMajor ? height : width;
    int lo = int(std::ceil(std::min(a0, a0 + len) - 0.5f)), hi = int(std::ceil(std::max(a0, a0 + len) - 0.5f)) - 1;
    lo = std::max(lo, 0);
    hi = std::min(hi, majorSize - 1);
    for (int k = lo; k <= hi; ++k) {
        float c = k + 0.5f;
        float t = (c - a0) / len;
        int m = int(std::floor(b0 + (c - a0) * slope));
        if (m < 0 || m >= minorSize) continue;
        if (xMajor)
            fn(k, m, t);
        else
            fn(m, k, t);
    }
}

}   // namespace rnd::lines
