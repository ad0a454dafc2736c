// shadow_map_view.h - the shadow-map view (`--view shadow-map`, View > Diagnostic in the window):
// what a rasterizer's shadow map does to the image, for teaching and for finding bias settings.
// For the light shown (the selected one, else the first with a map), every visible pixel's point
// p is looked up twice:
//   map   the backend's own answer from its maps (Renderer::lightVisibilityMany), as it shaded;
//   exact the ray caster's shadow rays to the same light from its own surface point in the
//         same pixel (a backend with Capabilities::shadowRays renders the same frame; pixels
//         where it sees another surface, e.g. at a tessellated silhouette, are not compared).
// Each is lit when its visibility is >= 0.5. The pixel's colour says how they compare:
//   light grey   lit by both            dark grey   shadowed in both
//   red          shadowed by the map only: acne (self-shadowing: too little bias), or a
//                filter's or a coarse texel's spill over the shadow's edge
//   blue         lit by the map only: peter-panning or a light leak (too much bias, or a
//                caster thinner than the bias), or the spill on the other side of the edge
//   dim blue     the light does not reach the surface (facing away, outside a spot's cone):
//                no shadow question; plain grey (map's answer, no checker tint): not compared;
//                black: background
// Both greys alternate in a checkerboard of the map's texels (p's texel (i, j), (i + j) odd
// darker), so the texels' size on screen shows; the legend gives their median density (map
// texels per screen pixel: below 1 a texel covers several pixels and edges are blocky).
// An inset (top left) shows what the light sees: the map's depth (near white, far dark), its
// texels used by the image's pixels tinted green (how well the map is fitted to the view); a
// point light's six faces as +x -x +y / -y +z -z.
#pragma once

#include "renderers/diagnostic.h"
#include "renderers/framebuffer.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"

#include <cstdint>
#include <vector>

namespace rnd {

// The frame light the view shows: the one of node `selected` when that light has a map, else
// the first light with one; -1 when none has (shadows off, nothing casts, or no light).
int shadowMapViewLight(const sg::FrameInput& f, sg::NodeId selected = sg::kNoNode);

// The image's visible points, where the two backends are asked.
struct ShadowMapViewPoints {
    int light = -1;
    std::vector<uint32_t> pixel;             // y * width + x of each point
    std::vector<sg::vec3> position;          // world
    std::vector<sg::vec3> normal;            // shading normal (what the rasterizers look the maps up with)
    std::vector<sg::vec3> geometricNormal;   // the facet's, facing the viewer (what shadow rays leave from)
};
// The points of `fb` (which needs visibility) for `light`.
ShadowMapViewPoints shadowMapViewPoints(const sg::FrameInput& f, const Framebuffer& fb, int light);

// What the view counted (the legend says the same in words).
struct ShadowMapViewCounts {
    size_t facing = 0;             // compared points the light reaches (lit-facing)
    size_t mapOnlyShadow = 0;      // of those: shadowed by the map, lit by the rays (red)
    size_t mapOnlyLight = 0;       // lit by the map, shadowed by the rays (blue)
    size_t shadowedByMap = 0;      // shadowed by the map
    size_t uncompared = 0;         // lit-facing points where the reference saw another surface
    float texelsPerPixel = 0.0f;   // median map texels per screen pixel
};

// The reference's answers per pixel of `fb`: `exact` (a backend with shadow rays) rendered the
// same frame into `exactImage` (same size, with visibility); each pixel's answer is its shadow
// rays from its own surface point (an analytic shape's exact surface, not the rasterizers'
// tessellation of it), NaN where it sees another surface than fb or nothing.
std::vector<float> referenceVisibility(const sg::FrameInput& f, const Framebuffer& fb, Renderer& exact, const Framebuffer& exactImage, int light);
// Renders the reference image for referenceVisibility (visibility asked); false on failure.
bool renderShadowReference(Renderer& exact, const sg::FrameInput& f, int width, int height, Framebuffer& image);

// The view from the answers (map: the backend's per point, empty when it gave none; exact: the
// reference's per pixel, empty when unknown: then only the map's answer and its texels show).
DiagnosticImage shadowMapViewImage(const sg::FrameInput& f, const Framebuffer& fb, const ShadowMapViewPoints& points, const std::vector<float>& map,
                                   const std::vector<float>& exact, ShadowMapViewCounts* counts = nullptr);

// The whole view in one call: `backend` rendered `fb` for `f`; `exact` (may be null: no
// comparison) is rendered here at fb's size (makeExactShadowBackend).
DiagnosticImage shadowMapView(const sg::FrameInput& f, const Framebuffer& fb, int light, Renderer& backend, Renderer* exact,
                              ShadowMapViewCounts* counts = nullptr);

}   // namespace rnd
