// camera_rays.h - primary rays that line up pixel for pixel with the rasterizers: a window
// position (GL convention: origin bottom-left, pixel centres at +0.5) is unprojected through
// inverse(proj * view) at NDC z = -1 and z = +1; the ray is the segment between the two points
// (t = 0 on the near plane, t = 1 on the far plane). This covers perspective, orthographic and
// oblique projections uniformly, and clips exactly like the rasterizers' near/far planes.
#pragma once

#include "raycast/bvh.h"
#include "scenegraph/frame.h"

namespace rnd::rt {

class CameraRays {
public:
    CameraRays(const sg::FrameCamera& cam, int width, int height)
        : m_viewProj(cam.proj * cam.view), m_inv(glm::inverse(cam.proj * cam.view)), m_w(float(width)), m_h(float(height)) {}

    // Ray through window position (wx, wy); framebuffer row = height - 1 - floor(wy).
    Ray ray(float wx, float wy) const {
        float x = 2.0f * wx / m_w - 1.0f, y = 2.0f * wy / m_h - 1.0f;
        sg::vec4 a = m_inv * sg::vec4(x, y, -1.0f, 1.0f), b = m_inv * sg::vec4(x, y, 1.0f, 1.0f);
        Ray r;
        r.org = sg::vec3(a) / a.w;
        r.dir = sg::vec3(b) / b.w - r.org;
        r.tmin = 0.0f;
        r.tmax = 1.0f;
        return r;
    }
    // Window depth (0.5 * ndc_z + 0.5) of a world point, as the rasterizers write it.
    float depth(const sg::vec3& p) const {
        sg::vec4 c = m_viewProj * sg::vec4(p, 1.0f);
        return 0.5f * (c.z / c.w) + 0.5f;
    }
    // Window position (x, y) of a world point.
    sg::vec2 project(const sg::vec3& p) const {
        sg::vec4 c = m_viewProj * sg::vec4(p, 1.0f);
        return {(0.5f * c.x / c.w + 0.5f) * m_w, (0.5f * c.y / c.w + 0.5f) * m_h};
    }
    bool valid() const { return sg::isFinite(m_inv); }

private:
    sg::mat4 m_viewProj, m_inv;
    float m_w, m_h;
};

}   // namespace rnd::rt
