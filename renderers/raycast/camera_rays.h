// camera_rays.h - primary rays that line up pixel for pixel with the rasterizers: a window
// position (GL convention: origin bottom-left, pixel centres at +0.5) is unprojected through
// inverse(proj * view) at NDC z = -1 and z = +1; the ray is the segment between the two points
// (t = 0 on the near plane, t = 1 on the far plane). This covers perspective, orthographic and
// oblique projections uniformly, and clips exactly like the rasterizers' near/far planes.
// The inverse and the two points are computed in double precision: with far/near ratios of
// 1e6 and more (near planes of 1e-5 in a scene of hundreds) the float inverse loses the far
// point entirely (w near 0), and a ray that is not finite anyway misses everything.
#pragma once

#include "raycast/bvh.h"
#include "scenegraph/frame.h"

#include <emmintrin.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rnd::rt {

class CameraRays {
public:
    CameraRays(const sg::FrameCamera& cam, int width, int height)
        : m_viewProj(cam.proj * cam.view),
          m_inv(glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view))),
          m_viewProjD(glm::dmat4(cam.proj) * glm::dmat4(cam.view)),
          m_forward(-glm::dvec3(cam.viewInverse[2])),
          m_w(double(width)),
          m_h(double(height)) {
        // m_inv * (x, y, z, 1) is (m0 x + m1 y) + (m2 z + m3) in glm's own order of operations;
        // the (z, 1) halves are the same for every pixel, so they are made once (bit for bit
        // what the full product gives).
        m_zw[0] = m_inv[2] * glm::dvec4(-1.0) + m_inv[3] * glm::dvec4(1.0);
        m_zw[1] = m_inv[2] * glm::dvec4(1.0) + m_inv[3] * glm::dvec4(1.0);
        m_zw[2] = m_inv[2] * glm::dvec4(0.0) + m_inv[3] * glm::dvec4(1.0);
        // The largest coordinate of a ray origin: the near points form a convex quadrilateral
        // (or, unprojected with a w of changing sign, no bound at all: infinity).
        for (int corner = 0; corner < 4; ++corner) {
            const glm::dvec4 a = column(corner & 1 ? float(width) : 0.0f) + row(corner & 2 ? float(height) : 0.0f) + m_zw[0];
            const double s = a.w > 0.0 ? std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z)}) / a.w : std::numeric_limits<double>::infinity();
            m_originScale = std::max(m_originScale, s);
        }
    }

    // The window rectangle (GL window coordinates x0, y0, x1, y1) that holds the window position
    // of every camera ray that can meet a point of the box [lo, hi], or false where there is no
    // such bound (part of the box lies at or behind the eye's plane, or nothing is finite).
    // The ray of window position q is the line of points that project to q, so a point of the
    // box met by the exact ray of q projects to q, inside the hull of the projected corners. A
    // traced ray is that ray rounded to float; it passes within 1e-6 x (its origin's and the
    // point's largest coordinate) of it; moved into an instance's space and its hit seen from
    // world space, that grows by up to the instance's spread (|L|_F |L^-1|_F, 3 for rotations
    // with a uniform scale). So the box is grown by 1e-4 x max(1, spread / 10) x those first
    // (slab and triangle tests round far less), and the rectangle by a pixel (the double
    // projection's own rounding is far below).
    bool windowBounds(const sg::vec3& lo, const sg::vec3& hi, float spread, float rect[4]) const {
        const glm::dvec3 bmin(lo), bmax(hi);
        const double boxScale =
            std::max({std::abs(bmin.x), std::abs(bmin.y), std::abs(bmin.z), std::abs(bmax.x), std::abs(bmax.y), std::abs(bmax.z)});
        const double eps = 1e-4 * std::max(1.0, double(spread) / 10.0) * (m_originScale + boxScale);
        if (!std::isfinite(eps)) return false;
        double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
        for (int corner = 0; corner < 8; ++corner) {
            const glm::dvec3 p(corner & 1 ? bmax.x + eps : bmin.x - eps, corner & 2 ? bmax.y + eps : bmin.y - eps,
                               corner & 4 ? bmax.z + eps : bmin.z - eps);
            const glm::dvec4 c = m_viewProjD * glm::dvec4(p, 1.0);
            if (!(c.w > 0.0)) return false;
            const double wx = (0.5 * c.x / c.w + 0.5) * m_w, wy = (0.5 * c.y / c.w + 0.5) * m_h;
            x0 = std::min(x0, wx), x1 = std::max(x1, wx), y0 = std::min(y0, wy), y1 = std::max(y1, wy);
        }
        if (!(std::isfinite(x0) && std::isfinite(x1) && std::isfinite(y0) && std::isfinite(y1))) return false;
        // Clamped to a little beyond the image: a float holds those bounds exactly enough.
        const double lim = 2.0 * (m_w + m_h) + 2.0;
        rect[0] = float(std::clamp(x0 - 1.0, -lim, lim));
        rect[1] = float(std::clamp(y0 - 1.0, -lim, lim));
        rect[2] = float(std::clamp(x1 + 1.0, -lim, lim));
        rect[3] = float(std::clamp(y1 + 1.0, -lim, lim));
        return true;
    }

    // Ray through window position (wx, wy); framebuffer row = height - 1 - floor(wy).
    // When the far plane lies at or beyond infinity in the float projection (far/near so large
    // that -(f + n) / (f - n) rounds to -1 or past it, as the rasterizers also see it), the ray
    // runs from the near plane through NDC z = 0 with no far end (tmax = FLT_MAX).
    Ray ray(float wx, float wy) const { return rayThrough(column(wx) + row(wy)); }
    // ray(wx + 1, wy) and ray(wx, wy + 1) bit for bit (a pixel's neighbours, for texture
    // footprints), through the grid's SSE2 steps with both rays' divisions together.
    void neighbours(float wx, float wy, Ray& right, Ray& up) const {
        __m128d c0[2], c1[2], r0[2], r1[2];
        toPairs(column(wx + 1.0f), c0);
        toPairs(row(wy), r0);
        toPairs(column(wx), c1);
        toPairs(row(wy + 1.0f), r1);
        const Unprojected a = unproject(c0, r0), b = unproject(c1, r1);
        finish(a, right);
        finish(b, up);
    }
    // The x and y shares of a window position's unprojection (m_inv's first two columns times its
    // NDC x and y; ray(wx, wy) goes through column(wx) + row(wy)): a grid's inputs, which a
    // tile makes once per column and row of pixels.
    glm::dvec4 column(float wx) const { return m_inv[0] * glm::dvec4(2.0 * double(wx) / m_w - 1.0); }
    glm::dvec4 row(float wy) const { return m_inv[1] * glm::dvec4(2.0 * double(wy) / m_h - 1.0); }
    // The rays through a grid of window positions, row by row: out[j * nx + i] is ray(wx[i],
    // wy[j]) bit for bit, each column's and row's share of the unprojection made once.
    void grid(const float* wx, int nx, const float* wy, int ny, Ray* out) const {
        constexpr int kMax = 16;
        glm::dvec4 cols[kMax], rows[kMax];
        if (nx > kMax || ny > kMax) {   // (wider than any packet: row by row)
            for (int j = 0; j < ny; ++j)
                for (int i = 0; i < nx; ++i) out[j * nx + i] = ray(wx[i], wy[j]);
            return;
        }
        for (int i = 0; i < nx; ++i) cols[i] = column(wx[i]);
        for (int j = 0; j < ny; ++j) rows[j] = row(wy[j]);
        gridOf(cols, nx, rows, ny, out);
    }
    // grid() with the shares given: out[j * nx + i] is the ray through cols[i] + rows[j].
    void gridOf(const glm::dvec4* cols, int nx, const glm::dvec4* rows, int ny, Ray* out) const {
        if (nx == 4 && ny <= kMaxRows && useAvx2()) {       // a packet's rows, four rays per vector
            PacketScratch<glm::dvec4, 4 * kMaxRows> slow;   // (written where read: glm would zero it)
            for (uint32_t m = rowsOfFour(cols, rows, ny, out, slow.data()); m; m &= m - 1) {
                const int k = __builtin_ctz(m);
                out[k] = rayThrough(slow[k]);
            }
            return;
        }
        // Up to kBatch rays at a time: first every ray's divisions (independent of each other,
        // so they overlap in the divider), then what follows from them.
        constexpr int kBatch = 16;
        Unprojected u[kBatch];
        int pending = 0, done = 0;
        auto flush = [&] {
            for (int k = 0; k < pending; ++k) finish(u[k], out[done + k]);
            done += pending;
            pending = 0;
        };
        for (int j = 0; j < ny; ++j) {
            __m128d r[2];
            toPairs(rows[j], r);
            for (int i = 0; i < nx; ++i) {
                __m128d c[2];   // (no zeroing: glm's vectors clear themselves)
                toPairs(cols[i], c);
                u[pending++] = unproject(c, r);
                if (pending == kBatch) flush();
            }
        }
        flush();
    }

private:
    // grid's rows of four rays with AVX2 (camera_rays.cpp), where the CPU has it: ray 4j + i
    // through column cols[i] and row rows[j], j < ny <= kMaxRows, into out; returns bit 4j + i
    // for the rays with no far end or something not finite (they take rayThrough(slow[4j + i])).
    static constexpr int kMaxRows = 8;
    uint32_t rowsOfFour(const glm::dvec4 cols[4], const glm::dvec4* rows, int ny, Ray* out, glm::dvec4* slow) const;
    static void toPairs(const glm::dvec4& v, __m128d* p) {   // (x, y) and (z, w)
        p[0] = _mm_loadu_pd(&v.x);
        p[1] = _mm_loadu_pd(&v.z);
    }
    // The ray whose (x, y) share of the unprojection is xy.
    // A point's homogeneous divide is a product with the reciprocal of its w (one division per
    // point, not three: the grid's rays were bound by the divider).
    static glm::dvec3 divide(const glm::dvec4& v) { return glm::dvec3(v) * (1.0 / v.w); }
    Ray rayThrough(const glm::dvec4& xy) const {
        const glm::dvec4 a = xy + m_zw[0], b = xy + m_zw[1];   // the points at NDC z = -1 and z = +1
        const glm::dvec3 org = divide(a);
        Ray r;
        r.org = sg::vec3(org);
        r.tmin = 0.0f;
        r.tmax = 1.0f;
        const glm::dvec3 far = divide(b);
        r.dir = sg::vec3(far - org);
        if (!finite(r.dir) || glm::dot(far - org, m_forward) <= 0.0) {   // no far end: at infinity or "beyond" (behind the eye)
            const glm::dvec4 c = xy + m_zw[2];
            r.dir = sg::vec3(divide(c) - org);
            r.tmax = std::numeric_limits<float>::max();
        }
        if (!finite(r.org) || !finite(r.dir)) r.tmax = -1.0f;   // meets nothing
        return r;
    }

    // rayThrough(col + row) (each as its (x, y) and (z, w) pairs) with SSE2's double pairs: the
    // same IEEE operations on the same values (glm's dvec4 sum, divide()'s reciprocals and products, the double
    // difference rounded to float), two at a time, for rays with a far end; the others (rare:
    // see ray()) go through rayThrough itself. In two steps: unproject (the sums and the
    // divisions), then finish.
    struct Unprojected {
        __m128d xy01, xy23, org01, far01, zz;   // col + row; (org.x, org.y), (far.x, far.y), (org.z, far.z)
    };
    Unprojected unproject(const __m128d* col, const __m128d* row) const {
        Unprojected u;
        u.xy01 = _mm_add_pd(col[0], row[0]);   // glm's col + row
        u.xy23 = _mm_add_pd(col[1], row[1]);
        const __m128d a01 = _mm_add_pd(u.xy01, _mm_loadu_pd(&m_zw[0].x)), a23 = _mm_add_pd(u.xy23, _mm_loadu_pd(&m_zw[0].z));
        const __m128d b01 = _mm_add_pd(u.xy01, _mm_loadu_pd(&m_zw[1].x)), b23 = _mm_add_pd(u.xy23, _mm_loadu_pd(&m_zw[1].z));
        const __m128d rw = _mm_div_pd(_mm_set1_pd(1.0), _mm_unpackhi_pd(a23, b23));   // (1 / a.w, 1 / b.w)
        u.org01 = _mm_mul_pd(a01, _mm_unpacklo_pd(rw, rw));                           // (a.x, a.y) (1 / a.w)
        u.far01 = _mm_mul_pd(b01, _mm_unpackhi_pd(rw, rw));                           // (b.x, b.y) (1 / b.w)
        u.zz = _mm_mul_pd(_mm_unpacklo_pd(a23, b23), rw);                             // (a.z (1 / a.w), b.z (1 / b.w))
        return u;
    }
    void finish(const Unprojected& u, Ray& out) const {
        static_assert(sizeof(Ray) == 32 && offsetof(Ray, dir) == 16, "Ray: org, tmin, dir, tmax packed");
        const __m128d d01 = _mm_sub_pd(u.far01, u.org01);
        const __m128d dz = _mm_sub_sd(_mm_unpackhi_pd(u.zz, u.zz), u.zz);
        // glm::dot(far - org, m_forward): (x fx + y fy) + z fz
        const __m128d p01 = _mm_mul_pd(d01, _mm_loadu_pd(&m_forward.x));
        const double dot = (_mm_cvtsd_f64(p01) + _mm_cvtsd_f64(_mm_unpackhi_pd(p01, p01))) + _mm_cvtsd_f64(dz) * m_forward.z;
        // (org.x, org.y, org.z, tmin = 0) and (dir.x, dir.y, dir.z, tmax = 1), each double rounded to float
        const __m128 orgF = _mm_movelh_ps(_mm_cvtpd_ps(u.org01), _mm_cvtpd_ps(_mm_move_sd(_mm_setzero_pd(), u.zz)));
        const __m128 dirF = _mm_movelh_ps(_mm_cvtpd_ps(d01), _mm_cvtpd_ps(_mm_unpacklo_pd(dz, _mm_set1_pd(1.0))));
        // v - v is NaN exactly where v is infinite or NaN (lanes 0-2 of each).
        const int notFinite = _mm_movemask_ps(_mm_cmpunord_ps(_mm_sub_ps(orgF, orgF), _mm_sub_ps(dirF, dirF))) & 7;
        if (notFinite || !(dot > 0.0)) {
            glm::dvec4 xy;
            _mm_storeu_pd(&xy.x, u.xy01);
            _mm_storeu_pd(&xy.z, u.xy23);
            out = rayThrough(xy);
            return;
        }
        _mm_storeu_ps(&out.org.x, orgF);
        _mm_storeu_ps(&out.dir.x, dirF);
    }

public:
    // Window depth (0.5 * ndc_z + 0.5) of a world point, as the rasterizers write it.
    float depth(const sg::vec3& p) const {
        sg::vec4 c = m_viewProj * sg::vec4(p, 1.0f);
        return 0.5f * (c.z / c.w) + 0.5f;
    }
    // depth() of the four points (x[l], y[l], z[l]) into out[l], in SSE2 lanes: the same
    // operations in the same order (glm's mat4 * vec4 is (m0 x + m1 y) + (m2 z + m3 1), of which
    // only the z and w rows are needed).
    void depth4(const float* x, const float* y, const float* z, float* out) const {
        const __m128 X = _mm_loadu_ps(x), Y = _mm_loadu_ps(y), Z = _mm_loadu_ps(z), one = _mm_set1_ps(1.0f);
        auto row = [&](int r) {
            const __m128 a = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(m_viewProj[0][r]), X), _mm_mul_ps(_mm_set1_ps(m_viewProj[1][r]), Y));
            const __m128 b = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(m_viewProj[2][r]), Z), _mm_mul_ps(_mm_set1_ps(m_viewProj[3][r]), one));
            return _mm_add_ps(a, b);
        };
        const __m128 half = _mm_set1_ps(0.5f);
        _mm_storeu_ps(out, _mm_add_ps(_mm_mul_ps(half, _mm_div_ps(row(2), row(3))), half));
    }
    // Window position (x, y) of a world point.
    sg::vec2 project(const sg::vec3& p) const {
        sg::vec4 c = m_viewProj * sg::vec4(p, 1.0f);
        return {(0.5f * c.x / c.w + 0.5f) * m_w, (0.5f * c.y / c.w + 0.5f) * m_h};
    }
    bool valid() const { return sg::isFinite(sg::mat4(m_inv)); }

private:
    static bool finite(const sg::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

    sg::mat4 m_viewProj;
    glm::dmat4 m_inv;
    glm::dmat4 m_viewProjD;   // proj * view in double (windowBounds)
    glm::dvec4 m_zw[3];       // m_inv's (z, 1) half at NDC z = -1, +1 and 0 (see the constructor)
    glm::dvec3 m_forward;     // the view direction (world)
    double m_w, m_h;
    double m_originScale = 0.0;   // the largest coordinate of a camera ray's origin (windowBounds)
};

}   // namespace rnd::rt
