// inspect.h - where a pixel came from: the surface a backend's visibility buffer names at a
// pixel, reconstructed exactly from the frame (the ray through the pixel centre meets that
// triangle), and the terms of the local shading model there. The same code serves the pixel
// inspector, `viewer inspect`, the normal export and the diagnostic views, so the three
// backends are described by one set of formulas and differ only in what they saw.
//
// Pixel coordinates count from the image's top-left corner; the ray through pixel (x, y)
// passes through its centre (x + 0.5, y + 0.5), unprojected with the inverse of the frame's
// view-projection (perspective, orthographic and oblique alike).
#pragma once

#include "renderers/framebuffer.h"
#include "scenegraph/frame.h"
#include "scenegraph/instances.h"

#include <vector>

namespace rnd {

// The surface at a pixel, from its visibility.
struct SurfaceAt {
    bool hit = false;   // false: background (nothing below is meaningful)
    uint32_t drawable = 0, primitive = kNoPrimitive, instance = 0;
    sg::NodeId node = sg::kNoNode;
    bool analytic = false;   // an analytic shape (no triangle, no uv)
    bool triangle = false;   // a mesh triangle: barycentric and (when the mesh has them) uv are set
    bool hasUv = false;
    sg::vec3 position{0.0f};           // world
    sg::vec3 barycentric{0.0f};        // weights of the triangle's vertices 0, 1, 2 (in index order)
    sg::vec2 uv{0.0f};                 // TEXCOORD_0 interpolated
    sg::vec2 uvDx{0.0f}, uvDy{0.0f};   // uv's change to the next pixel right / down (texture footprint)
    sg::vec3 normal{0.0f};             // world, unit, facing the viewer; 0 for points and lines
    sg::vec3 geometricNormal{0.0f};    // the facet's (analytic shapes: = normal), facing the viewer
    int csgLeaf = -1;                  // CSG: the leaf whose surface the point is on (its material)
    float opticalDepth = 0.0f;         // along the camera's optical axis (sg::opticalDepth), 0 = nothing
    float eyeDistance = 0.0f;          // |eye-space position| (what fog uses)
};

// The surface at (x, y) of `fb` (which must have visibility) for `frame`.
// Mesh triangles: the ray through the pixel centre meets the triangle's plane (so the
// position, barycentrics and uv are exact, not interpolated from a depth buffer); the normal
// is the interpolated vertex normal (the facet normal with flat shading or without normals),
// without normal maps. Analytic shapes: the position from the depth buffer, the normal from
// the shape (implicit primitives) or from neighbouring depths (toward the viewer for a pixel
// with no neighbour on the same surface).
SurfaceAt surfaceAt(const sg::FrameInput& frame, const sg::InstanceTable& ids, const Framebuffer& fb, int x, int y);

// One light's part in a pixel's colour (linear), before fog.
struct LightPart {
    sg::vec3 radiance{0.0f};   // L_i att_i: the light's radiance reaching the point
    float visibility = 1.0f;   // v_i: shadow (0 blocked .. 1 reaches)
    float nDotL = 0.0f;        // max(n . l_i, 0)
    sg::vec3 diffuse{0.0f};    // L_i att_i (n.l_i) kd rho
    sg::vec3 specular{0.0f};   // L_i att_i (n.l_i) ks spec_i (rho or specularColor)
};

// The local model's terms at the pixel (renderers/shading.h), evaluated there with the
// material's own coefficients: colour = fog(ambient + emissive + sum(diffuse + specular)),
// each light's part scaled by its shadow visibility v_i (Renderer::lightVisibility; 1 where
// the backend draws no shadows). The base colour texture is sampled with the pixel's
// footprint; other texture maps are not applied and Gouraud's interpolation is not
// reproduced, so `predicted` equals the backends' pixel for Phong/flat surfaces without them.
struct PixelTerms {
    bool lit = false;         // false: unlit material, point or line (colour = albedo + emissive)
    sg::vec3 albedo{0.0f};    // rho: base colour x vertex colour x texture
    sg::vec3 ambient{0.0f};   // ka rho L_ambient
    sg::vec3 emissive{0.0f};
    std::vector<LightPart> lights;
    float fogVisibility = 1.0f;   // f(d): 1 = no fog
    sg::vec3 beforeFog{0.0f};     // ambient + emissive + sum(diffuse + specular)
    sg::vec3 predicted{0.0f};     // f beforeFog + (1 - f) fogColour, through the display transform (tone_map.h), clamped
};
// lightVisibility: one value per frame light (empty: every light reaches the point).
PixelTerms pixelTerms(const sg::FrameInput& frame, const SurfaceAt& s, const std::vector<float>& lightVisibility = {});

// World normals of every pixel (0 where there is no surface or no normal), rows top-down.
std::vector<sg::vec3> normalImage(const sg::FrameInput& frame, const sg::InstanceTable& ids, const Framebuffer& fb);

}   // namespace rnd
