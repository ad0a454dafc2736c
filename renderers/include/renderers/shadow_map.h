// shadow_map.h - shadow maps, the rasterizers' shadows: one description that the GL backend
// (gl_shadows.cpp, shaders/shadow.glsl, mirroring shadowVisibility name for name) and the CPU
// rasterizer (its own depth pass, renderShadowDepth below) both follow, so that their shadows
// agree with each other and can be compared with the ray caster's exact shadow rays.
// docs/math.md, "Shadow maps", has the formulas:
//
//   Which maps (planShadows): one per directional or spot light, six per point light.
//     directional: orthographic along the light, fitted in x and y to the part of the scene the
//       camera sees (the camera frustum between the scene's nearest and farthest depths,
//       intersected with the scene's bounds), in depth to the whole scene (every caster);
//     spot: perspective from the light along its axis, the outer cone plus a margin;
//     point: perspective, 90 degrees, the six faces of a cube (+x, -x, +y, -y, +z, -z).
//   Each map holds the depth d in [0, 1] of the nearest surface, linear along the map's axis
//   (d = (z - near)/(far - near), z the eye depth; for a perspective map not the window depth,
//   whose float precision near 1 would not do with a light inside the scene), both faces drawn,
//   cleared to 1, at texel centres ((i + 0.5)/N, (j + 0.5)/N), row 0 at v = 0 (GL's convention).
//   Lookup of world point p with surface normal n (the shading normal, or under flat and Gouraud
//   shading the face normal; turned toward the light):
//     t   = texel size in world units at p (orthographic: extent / N; perspective:
//           2 tan(fov/2) / N times p's depth along the map's axis)
//     p'  = p + normalBias t n                                   (normal offset)
//     (u, v, z) = the map's projection of p',  z_lin its linear depth along the axis
//     lit(texel) = (z_lin - depthBias t - near)/(far - near) <= d(texel)   (depth bias)
//     visibility = mean of lit over the k x k texels nearest (u, v) (k = 1 without PCF);
//     texels outside the map are lit.
#pragma once

#include "scenegraph/frame.h"
#include "scenegraph/math.h"

#include <cstddef>
#include <utility>
#include <vector>

namespace rnd {

// One depth map: a view from the light.
struct ShadowView {
    sg::mat4 view{1.0f};       // world -> light eye (looking down -z)
    sg::mat4 viewProj{1.0f};   // world -> light clip (x, y as GL; the depth stored is linear, below)
    bool perspective = false;
    float nearZ = 0.0f, farZ = 1.0f;   // the planes, as distances along the axis
    float texelAtUnit = 0.0f;          // texel size in world units (perspective: at distance 1)

    // The depth along the axis of a stored map depth d.
    float linearDepth(float d) const { return nearZ + d * (farZ - nearZ); }
};

// Whether two views are the same bit for bit (a map drawn from one is the other's).
bool sameShadowView(const ShadowView& a, const ShadowView& b);

// At most this many maps per frame (GL's uniform arrays): lights whose maps would pass it, in
// the frame's order, get none (lit everywhere) in both rasterizers.
constexpr int kMaxShadowViews = 48;
// PCSS (docs/math.md, "Soft shadows"): the blocker search reads kPcssSearch x kPcssSearch texels
// spread over its radius; neither that radius nor the penumbra's exceeds kPcssMaxRadius texels.
constexpr int kPcssSearch = 4;
constexpr int kPcssMaxRadius = 24;

// Which maps a frame's lights get.
struct ShadowPlan {
    int size = 0;   // texels per side of every map
    sg::ShadowFilter filter = sg::ShadowFilter::Pcf;
    int pcf = 3;                                 // k of k x k (1 without PCF)
    float depthBias = 1.0f, normalBias = 1.0f;   // in texels
    std::vector<ShadowView> views;               // all maps, light by light
    std::vector<int> firstView, viewCount;       // per frame light (viewCount 0: no map, lit)
    bool empty() const { return views.empty(); }
};

// Gouraud shading with shadow maps (docs/math.md, "Shadow maps"): each light's terms are
// interpolated from the vertices on their own and scaled by the pixel's visibility, which GL
// carries in vertex outputs (12 floats a light: both sides' two terms; GL 3.3 guarantees 60
// varying components, 26 of which Gouraud may already use). So at most this many lights, the
// first ones with maps in the frame's order, are shadowed under Gouraud shading; further lights
// are summed at the vertices unshadowed (lit), in both rasterizers. Flat shading has no bound.
constexpr int kGouraudShadowedLights = 2;
// The lights Gouraud shading shadows under `plan`: the first kGouraudShadowedLights of those with
// a map, below `maxLights`.
std::vector<int> gouraudShadowedLights(const ShadowPlan& plan, size_t maxLights = size_t(-1));

// The world bounds of everything in the frame that casts (meshes of triangles, analytic shapes).
sg::Aabb shadowCasterBounds(const sg::FrameInput& f);
// The plan for f's lights (empty when settings.shadows is off or nothing casts).
ShadowPlan planShadows(const sg::FrameInput& f, const sg::Aabb& casters);

// Float storage straight from the operating system (pageAlloc, with huge pages from 4 MB up):
// the maps are tens of megabytes, allocated as renderers come and go on different threads, and
// malloc kept such blocks in its per-thread arenas (a long window session grew by hundreds of
// megabytes); these go back when freed. resize() keeps the mapping when it is large enough and
// does not keep the contents.
class PageBuffer {
public:
    PageBuffer() = default;
    PageBuffer(const PageBuffer&) = delete;
    PageBuffer& operator=(const PageBuffer&) = delete;
    PageBuffer(PageBuffer&& o) noexcept { swap(o); }
    PageBuffer& operator=(PageBuffer&& o) noexcept {
        swap(o);
        return *this;
    }
    ~PageBuffer();
    void resize(size_t n);   // throws std::bad_alloc when the system has no memory for it
    void clear() { size_ = 0; }
    size_t size() const { return size_; }
    float* data() { return data_; }
    const float* data() const { return data_; }
    float* begin() { return data_; }
    float* end() { return data_ + size_; }
    const float* begin() const { return data_; }
    const float* end() const { return data_ + size_; }

private:
    void swap(PageBuffer& o) noexcept {
        std::swap(data_, o.data_);
        std::swap(size_, o.size_);
        std::swap(capacity_, o.capacity_);
    }
    float* data_ = nullptr;
    size_t size_ = 0, capacity_ = 0;
};

// The depth maps, size x size floats each, view after view.
struct ShadowMaps {
    int size = 0;
    PageBuffer depth;
    const float* map(int view) const { return depth.data() + size_t(view) * size_t(size) * size_t(size); }
    float* map(int view) { return depth.data() + size_t(view) * size_t(size) * size_t(size); }
};

// World-space triangles that cast: the corners of triangle k are positions idx[3k], idx[3k + 1],
// idx[3k + 2] (idx null: 3k, 3k + 1, 3k + 2), each position three floats, `stride` bytes apart.
struct ShadowCaster {
    const void* positions = nullptr;
    size_t stride = 3 * sizeof(float);
    const uint32_t* idx = nullptr;
    size_t triangles = 0;
    size_t vertices = 0;   // positions there are (a triangle with a corner past them is skipped)
};
// Whether a material's triangles go into the maps: blended surfaces do not (the ray caster lets
// 1 - alpha through them; a depth map has no partial answer), nor cut-outs whose constant alpha is
// already below the cutoff (never drawn); other cut-outs cast whole (no alpha test per texel).
inline bool castsShadow(const sg::Material& m) {
    if (m.alphaMode == sg::AlphaMode::Blend) return false;
    return !(m.alphaMode == sg::AlphaMode::Mask && m.alpha < m.alphaCutoff);
}

// The CPU depth pass's kernels: Auto, the vector one the CPU offers (AVX2, or SSE2 where it has
// no AVX2 or VIEWER_RASTER_SSE=1), and Scalar, the reference it is held to bit for bit (tests).
enum class ShadowDepthKernel { Auto, Scalar };
const char* shadowDepthKernelName(ShadowDepthKernel kernel);   // "avx2", "sse2" or "scalar"

// The CPU depth pass: clears one view's map (size x size) to 1 and rasterizes the casters into
// it, both faces, depth test less, at pixel centres with the top-left rule (as GL's rasterizer).
void renderShadowDepth(const ShadowView& v, int size, const std::vector<ShadowCaster>& casters, float* map,
                       ShadowDepthKernel kernel = ShadowDepthKernel::Auto);

// The map of a point light's face for the direction from the light to p (views: first of six).
int pointLightFace(const sg::vec3& fromLight);

// Fraction of light `light` of the frame that reaches world point p (unit surface normal n, the
// shading normal, either side), by the plan's maps: 1 lit, 0 shadowed, between at PCF edges.
float shadowVisibility(const ShadowPlan& plan, const ShadowMaps& maps, const sg::DrawLight& L, int light, const sg::vec3& p, const sg::vec3& n);

// PCSS's shift of its taps inside their grid cells, in [0, 1) (axis 0: x, 1: y), hashed from the
// receiver's texel (i, j) of map `view` (shadow.glsl's pcssJitter, bit for bit).
float pcssJitter(int i, int j, int view, int axis);

// Soft shadows in the ray caster (docs/math.md, "Soft shadows"; soft_shadows.cpp): shadow ray k
// of n from p toward a light that has a size (DrawLight::hasSize). The source is a disc facing p:
// radius L.radius around the light's position (point, spot), or the directions within its angular
// radius of the light's (directional). Its point is Hammersley point k of n, ((k + 0.5)/n,
// radicalInverse(k)), shifted by `rotation` modulo 1 (one shift per shaded point: noise, not
// bands), mapped to the unit disc by Shirley and Chiu's concentric map. distance: to that point
// (infinite for a directional light).
struct ShadowRayTarget {
    sg::vec3 dir{0.0f, 0.0f, 1.0f};
    float distance = 0.0f;
};
ShadowRayTarget softShadowRay(const sg::DrawLight& L, const sg::vec3& p, int k, int n, const sg::vec2& rotation);

}   // namespace rnd
