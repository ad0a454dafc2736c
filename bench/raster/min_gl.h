// min_gl.h - the minimal GL program bench_raster holds the CPU rasterizer to: one VBO holding
// every triangle of the frame in world space, one glDrawArrays, one Phong + linear fog shader
// (the model of renderers/common/shading.cpp for point and directional lights), one
// glReadPixels. Headless EGL surfaceless like the gl backend (rnd::gl::createHeadlessContext),
// so on a machine without a GPU it measures Mesa llvmpipe itself, without our GL backend's
// per-draw work.
#pragma once

#include "scenegraph/frame.h"

#include <memory>
#include <string>
#include <vector>

namespace bench {

class MinimalGl {
public:
    MinimalGl();
    ~MinimalGl();
    MinimalGl(const MinimalGl&) = delete;
    MinimalGl& operator=(const MinimalGl&) = delete;
    // Creates the context, compiles the shader, uploads the frame's triangles (meshes
    // pre-transformed to world space, material base colour per vertex) and sizes a width x
    // height sRGB colour + 24-bit depth framebuffer. Returns "" or why it failed.
    std::string setup(const sg::FrameInput& f, int width, int height);
    // One frame: clear, draw, read back RGBA8 into `rgba`.
    void render(std::vector<uint8_t>& rgba);
    size_t triangles() const { return m_vertices / 3; }

private:
    struct State;
    std::unique_ptr<State> m;
    size_t m_vertices = 0;
};

}   // namespace bench
