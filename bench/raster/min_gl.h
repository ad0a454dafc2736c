// min_gl.h - the minimal GL program bench_raster holds the CPU rasterizer to: the frame's
// triangles in world space in one VBO, one Phong + linear fog shader (the model of
// renderers/common/shading.cpp for point and directional lights), one glReadPixels. Headless
// EGL surfaceless like the gl backend (rnd::gl::createHeadlessContext), so on a machine without
// a GPU it measures Mesa llvmpipe itself, without our GL backend's per-draw work.
// Two submissions: Order::Scene, every triangle unindexed in the scene's order, one
// glDrawArrays (the reference as it first was: llvmpipe shades a vertex once per triangle and,
// drawing far geometry first, fragments that nearer ones later cover); Order::Fair, llvmpipe
// at its best on the same image: each vertex once with an index buffer (glDrawElements),
// clusters of consecutive triangles drawn nearest first so its early depth test rejects hidden
// fragments, and back faces culled where our rasterizer culls them (sg::cullsBackFaces).
// BENCH_GL_CLUSTER=N sets the triangles per sorted cluster (default 64; 16-256 measured alike,
// single triangles were slower: they break up the vertex reuse of neighbouring triangles).
#pragma once

#include "scenegraph/frame.h"

#include <memory>
#include <string>
#include <vector>

namespace bench {

class MinimalGl {
public:
    enum class Order { Scene, Fair };
    MinimalGl();
    ~MinimalGl();
    MinimalGl(const MinimalGl&) = delete;
    MinimalGl& operator=(const MinimalGl&) = delete;
    // Creates the context, compiles the shader, uploads the frame's triangles (meshes
    // pre-transformed to world space, material base colour per vertex) in `order` and sizes a
    // width x height sRGB colour + 24-bit depth framebuffer. Returns "" or why it failed.
    std::string setup(const sg::FrameInput& f, int width, int height, Order order = Order::Scene);
    // One frame: clear, draw, read back RGBA8 into `rgba` (makes this program's context current).
    void render(std::vector<uint8_t>& rgba);
    // Makes this program's context current (render() does it too; call it first to keep the
    // switch out of a timed frame when two programs take turns).
    void activate();
    size_t triangles() const { return m_triangles; }
    size_t vertices() const { return m_vertices; }   // vertices in the buffer
    size_t draws() const;                            // draw calls per frame

private:
    struct State;
    std::unique_ptr<State> m;
    size_t m_vertices = 0, m_triangles = 0;
};

}   // namespace bench
