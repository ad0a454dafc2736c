// raycast_renderer.cpp - the "raycast" backend: CPU ray casting (docs/math.md) with the
// shared Phong shading (renderers/shading.h), shadow rays, optional mirror reflections and
// stratified supersampling, and the display transform (renderers/tone_map.h) on each pixel's
// mean colour; tile-parallel (oneTBB), progressive and cancellable.
//
// Sections: texture footprint, Tracer (hit shading: meshes flat/Gouraud/Phong, analytics),
// RaycastRenderer::render (tiles, AA, progress, cancellation).
//
// Conventions shared with the rasterizers (docs/math.md): primary rays come from
// CameraRays (unprojecting pixel centres, so images line up with the rasterizers); depth is
// window z; two-sided lighting flips normals of back-facing triangles (geometric normal
// pointing along the ray); fog uses |p_eye|. Textures: the rasterizer's sampler (mip chains,
// nearest/bilinear/trilinear), the level chosen from ray differentials - for camera rays and
// for mirror-reflected ones - texels decoded from sRGB before filtering; analytic surfaces
// are untextured.
#include "raycast/raycast_renderer.h"
#include "renderers/debug_switches.h"

#include "common/line_overlay.h"
#include "raycast/camera_rays.h"
#include "raycast/scene_accel.h"
#include "renderers/draw_list.h"
#include "renderers/environment.h"
#include "renderers/pbr.h"
#include "renderers/sampling.h"
#include "renderers/shading.h"
#include "renderers/shadow_map.h"
#include "renderers/texture_sampler.h"
#include "renderers/tone_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>

namespace rnd {

using namespace sg;

namespace {

// --- texture footprint ------------------------------------------------------------------------

// The rays through the neighbouring pixels (one to the right, one up) that go with a ray: its
// ray differentials, from which a textured hit gets its uv derivatives and so its mip level.
// Camera rays keep only their window position (the neighbours are made when a texture needs
// them); reflected rays carry their neighbours, reflected at the same mirror.
struct PixelFootprint {
    const rt::CameraRays* cam = nullptr;
    float wx = 0, wy = 0;
    bool carried = false;
    rt::Ray rx, ry;
    bool neighbours(rt::Ray& x, rt::Ray& y) const {
        if (carried) {
            x = rx;
            y = ry;
            return true;
        }
        if (!cam) return false;
        x = cam->ray(wx + 1.0f, wy);
        y = cam->ray(wx, wy + 1.0f);
        return true;
    }
};

// A neighbouring ray reflected where it meets the mirror's plane (point p, plane normal ng)
// about the same shading normal n as the main ray: exact for flat mirrors; for curved ones it
// leaves out the curvature (the footprint grows less than it should: a finer level, never a
// coarser one). False for rays along the plane.
bool reflectNeighbour(const rt::Ray& a, const vec3& p, const vec3& ng, const vec3& n, rt::Ray& out) {
    const float den = glm::dot(a.dir, ng);
    if (!(std::abs(den) > 1e-30f)) return false;
    const float t = glm::dot(p - a.org, ng) / den;
    if (!std::isfinite(t)) return false;
    const vec3 d = glm::normalize(a.dir);
    out.org = a.org + t * a.dir;
    out.dir = d - 2.0f * glm::dot(d, n) * n;
    out.tmin = 0.0f;
    out.tmax = std::numeric_limits<float>::infinity();
    return isFinite(out.org) && isFinite(out.dir);
}

// uv at the point where ray r meets the plane of triangle P (barycentrics of that point, even
// outside the triangle: derivatives only need the plane). False for rays along the plane.
bool uvOnPlane(const rt::Ray& r, const vec3 P[3], const vec2 uv[3], vec2& out) {
    const vec3 e1 = P[1] - P[0], e2 = P[2] - P[0], n = glm::cross(e1, e2);
    const float denom = glm::dot(r.dir, n);
    if (!(std::abs(denom) > 1e-30f)) return false;
    const vec3 q = r.org + (glm::dot(P[0] - r.org, n) / denom) * r.dir - P[0];
    const float d00 = glm::dot(e1, e1), d01 = glm::dot(e1, e2), d11 = glm::dot(e2, e2);
    const float d20 = glm::dot(q, e1), d21 = glm::dot(q, e2), det = d00 * d11 - d01 * d01;
    if (!(std::abs(det) > 0)) return false;
    const float b1 = (d11 * d20 - d01 * d21) / det, b2 = (d00 * d21 - d01 * d20) / det;
    out = (1.0f - b1 - b2) * uv[0] + b1 * uv[1] + b2 * uv[2];
    return std::isfinite(out.x) && std::isfinite(out.y);
}

// Whether any material of the frame is masked or blended (shadow rays then test alpha).
bool anyTranslucent(const FrameInput& f) {
    auto translucent = [](const Material& m) { return m.alphaMode != AlphaMode::Opaque; };
    for (const DrawMesh& d : f.meshes)
        if (translucent(d.material)) return true;
    for (const DrawAnalytic& a : f.analytics) {
        if (translucent(a.material)) return true;
        if (a.csg)
            for (const CsgTree::Node& n : a.csg->nodes)
                if (translucent(n.material)) return true;
    }
    return false;
}

// uv at a hit (barycentric weights w of triangle P with uvs UV) and, when the ray carries a
// footprint, its screen derivatives from the neighbouring rays met on the triangle's plane.
// False when there is no footprint: sample level 0 then.
bool uvWithFootprint(const PixelFootprint* footprint, const vec3 P[3], const vec2 UV[3], const float w[3], vec2& uv, vec2& ddx, vec2& ddy) {
    uv = w[0] * UV[0] + w[1] * UV[1] + w[2] * UV[2];
    vec2 uvX, uvY;
    rt::Ray nx, ny;
    if (!(footprint && footprint->neighbours(nx, ny) && uvOnPlane(nx, P, UV, uvX) && uvOnPlane(ny, P, UV, uvY))) return false;
    ddx = uvX - uv;
    ddy = uvY - uv;
    return true;
}

// --- Tracer --------------------------------------------------------------------------------------

// The surface a primary ray keeps (see Tracer::trace): where, and what (Framebuffer's
// visibility). p is NaN while the ray has met nothing that writes depth.
struct SurfaceRecord {
    vec3 p{std::numeric_limits<float>::quiet_NaN()};
    uint32_t drawable = 0, primitive = kNoPrimitive;
};

struct Tracer {
    const FrameInput& f;
    const rt::SceneAccel& accel;
    const std::vector<const SampledTexture*>& textures;   // per f.meshes entry, null if none
    const std::vector<MapSamplers>& maps;                 // per f.meshes entry: emissive, occlusion, metallic-roughness, normal
    uint64_t rays = 0;
    bool anyAlpha = false;   // some material is masked or blended (anyTranslucent())
    // The cost view (RenderConfig::traversalCost): the BVH work of the primary ray (bounce 0,
    // every layer it passes through; not shadow or reflection rays) is added here when set.
    rt::TraversalCount* cost = nullptr;
    // The primary ray's first hit when it was already traced (a tile's camera rays go through
    // SceneAccel::intersectPacket): used once, by the next firstSurface call, instead of tracing.
    struct FirstHit {
        bool found = false;
        rt::SceneHit hit;
    };
    const FirstHit* firstHit = nullptr;
    // The pbr model's environment light (null or empty map: none): it lights surfaces and is what
    // rays that leave the scene see (reflection rays always, camera rays when it is the background).
    const EnvironmentLight* env = nullptr;

    vec3 missed(const rt::Ray& r, int bounce) const {
        if (env && env->map && (bounce > 0 || env->background)) return env->backgroundRadiance(glm::normalize(r.dir));
        return f.settings.background;
    }

    // Surfaces one ray may pass through (cut-outs, blended layers) before it counts as stopped.
    static constexpr int kMaxLayers = 64;

    const Material& materialOf(const rt::SceneHit& h) const {
        if (h.kind == rt::SceneHit::Kind::Mesh) return f.meshes[h.instance].material;
        const DrawAnalytic& a = f.analytics[h.instance];
        if (a.kind == DrawAnalytic::Kind::Csg && a.csg && h.csgLeaf >= 0) return a.csg->nodes[size_t(h.csgLeaf)].material;
        return a.material;
    }

    // Alpha of the surface at a hit, as the rasterizers compute it: material alpha x vertex
    // colour alpha x texture alpha (the texture filtered with the ray's footprint like its colour).
    float surfaceAlpha(const rt::SceneHit& h, const PixelFootprint* footprint, const Material& mat) const {
        float a = mat.alpha;
        if (h.kind != rt::SceneHit::Kind::Mesh) return a;
        const DrawMesh& dm = f.meshes[h.instance];
        const Mesh& mesh = *dm.mesh;
        const uint32_t i[3] = {mesh.indices[3 * h.prim], mesh.indices[3 * h.prim + 1], mesh.indices[3 * h.prim + 2]};
        const float w[3] = {1.0f - h.b1 - h.b2, h.b1, h.b2};
        if (mesh.colors.size() == mesh.positions.size()) a *= w[0] * mesh.colors[i[0]].a + w[1] * mesh.colors[i[1]].a + w[2] * mesh.colors[i[2]].a;
        const SampledTexture* tex = textures[h.instance];
        if (!tex || !tex->hasAlpha() || mesh.uv0.size() != mesh.positions.size()) return a;
        const vec2 UV[3] = {mesh.uv0[i[0]], mesh.uv0[i[1]], mesh.uv0[i[2]]};
        const vec3 P[3] = {vec3(dm.world * vec4(mesh.positions[i[0]], 1.0f)), vec3(dm.world * vec4(mesh.positions[i[1]], 1.0f)),
                           vec3(dm.world * vec4(mesh.positions[i[2]], 1.0f))};
        vec2 uv, ddx, ddy;
        if (uvWithFootprint(footprint, P, UV, w, uv, ddx, ddy)) return a * tex->sampleAlpha(uv, ddx, ddy);
        return a * tex->sampleAlphaLevel(uv, 0, tex->filter() != FilterMode::Nearest);
    }

    // Fraction of light that passes along a shadow ray: 0 behind an opaque surface, cut-outs
    // let it through where they are cut out, blended surfaces let (1 - alpha) through.
    float transmittance(rt::Ray sr) {
        if (!anyAlpha) return accel.occluded(sr) ? 0.0f : 1.0f;
        float T = 1.0f;
        for (int layer = 0; layer < kMaxLayers; ++layer) {
            rt::SceneHit h;
            if (!accel.intersect(sr, h)) return T;
            const Material& m = materialOf(h);
            if (m.alphaMode == AlphaMode::Opaque) return 0.0f;
            const float a = std::clamp(surfaceAlpha(h, nullptr, m), 0.0f, 1.0f);
            if (m.alphaMode == AlphaMode::Mask) {
                if (a >= m.alphaCutoff) return 0.0f;
            } else {
                T *= 1.0f - a;
                if (!(T > 0.0f)) return 0.0f;
            }
            sr.tmin = h.t;
            ++rays;
        }
        return 0.0f;
    }

    static float offsetScale(const vec3& p) { return 1e-4f * (1.0f + std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z)))); }

    // Shadow rays to every light from p (geometric normal ng facing the viewer side). With
    // shading points (positions q and normals n where the lights are evaluated: the hit, or a
    // Gouraud triangle's vertices), a light that reaches none of them gets no ray: its terms
    // are zero there whatever the visibility (lightReaches), so the image is the same.
    void lightVisibility(const vec3& p, const vec3& ng, float* visible, const vec3* q = nullptr, const vec3* n = nullptr, int points = 0) {
        for (size_t i = 0; i < f.lights.size(); ++i) {
            visible[i] = 1.0f;
            if (!f.settings.shadows) continue;
            if (points > 0) {
                bool reaches = false;
                for (int k = 0; k < points && !reaches; ++k) reaches = lightReaches(f.lights[i], q[k], n[k], f.settings.reflection);
                if (!reaches) continue;
            }
            LightSample ls = sampleLight(f.lights[i], p);
            float side = glm::dot(ng, ls.toLight) >= 0 ? 1.0f : -1.0f;
            float eps = offsetScale(p);
            if (f.lights[i].hasSize() && f.settings.shadowRays > 1) {
                visible[i] = softVisibility(f.lights[i], p, side * ng, eps);
                continue;
            }
            rt::Ray sr;
            sr.org = p + side * eps * ng;
            sr.dir = ls.toLight;
            sr.tmin = 0.0f;
            sr.tmax = std::isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) - eps : std::numeric_limits<float>::infinity();
            if (!(sr.tmax > 0)) continue;
            ++rays;
            visible[i] = transmittance(sr);
        }
    }

    // The fraction of a light with a size that reaches p (n: the geometric normal on the light's
    // centre's side): settings.shadowRays rays to points of the source (softShadowRay), their
    // transmittances averaged; a ray below p's surface counts as blocked (the surface hides that
    // part of the source). The points are shifted by a hash of p: noise, not bands.
    float softVisibility(const DrawLight& L, const vec3& p, const vec3& n, float eps) {
        const int count = f.settings.shadowRays;
        uint32_t seed = 0x2545f491u;
        for (int a = 0; a < 3; ++a) {
            uint32_t bits;
            std::memcpy(&bits, &p[a], sizeof bits);
            seed = hash32(seed ^ bits);
        }
        const vec2 rotation(unitFloat(seed), unitFloat(hash32(seed)));
        float sum = 0.0f;
        for (int k = 0; k < count; ++k) {
            const ShadowRayTarget t = softShadowRay(L, p, k, count, rotation);
            if (!(glm::dot(t.dir, n) > 0.0f)) continue;
            rt::Ray sr;
            sr.org = p + eps * n;
            sr.dir = t.dir;
            sr.tmin = 0.0f;
            sr.tmax = std::isfinite(t.distance) ? t.distance * (1.0f - 1e-4f) - eps : std::numeric_limits<float>::infinity();
            if (!(sr.tmax > 0)) continue;
            ++rays;
            sum += transmittance(sr);
        }
        return sum / float(count);
    }

    // A hit after shading: the point, its shading normal n and geometric normal ng (both on the
    // side the ray came from), the material and the lit colour (linear, before reflection and fog).
    struct ShadedHit {
        vec3 p, n, ng, color;
        const Material* mat = nullptr;
        // pbr, per-pixel shading: the coefficients and albedo the colour was shaded with (the
        // traced reflection replaces the environment's prefiltered one by them); lit false otherwise.
        bool lit = false;
        SurfaceCoefficients coeff;
        vec3 albedo{0.0f};
    };

    // The surface the ray stops at: the first opaque or blended one, passing masked surfaces
    // where they are cut out (r.tmin moves behind them, layer counts them, at most kMaxLayers).
    // False when the ray leaves the scene. alpha: the blended surface's coverage (else 1).
    // count: where the traversal cost is added (primary rays of the cost view), or null.
    bool firstSurface(rt::Ray& r, rt::SceneHit& h, float& alpha, int& layer, const PixelFootprint* footprint, rt::TraversalCount* count = nullptr) {
        for (;;) {
            if (firstHit) {
                const FirstHit* pre = firstHit;
                firstHit = nullptr;
                if (!pre->found) return false;
                h = pre->hit;
            } else if (!accel.intersect(r, h, f.settings.culling, count)) {
                return false;
            }
            const Material& m = materialOf(h);
            if (m.alphaMode == AlphaMode::Opaque) return true;
            alpha = std::clamp(surfaceAlpha(h, footprint, m), 0.0f, 1.0f);
            if (m.alphaMode == AlphaMode::Blend) return true;
            if (alpha >= m.alphaCutoff || ++layer >= kMaxLayers) {
                alpha = 1.0f;
                return true;
            }
            r.tmin = h.t;   // cut out here: the ray goes on behind
            ++rays;
        }
    }

    // The normal map's normal (perturbNormal) with the world tangent interpolated like the
    // normal; n is the interpolated normal facing the viewer, flipped back for the map when the
    // hit is on the back. Mirrored instances flip the handedness (cross(n, t) flips with them).
    vec3 mappedNormal(const DrawMesh& dm, uint32_t i0, uint32_t i1, uint32_t i2, float w0, float w1, float w2, const vec3& n, bool back,
                      const MapSample& ms) const {
        const Mesh& mesh = *dm.mesh;
        const sg::mat3 m3(dm.world);
        const vec3 t = m3 * (w0 * vec3(mesh.tangents[i0]) + w1 * vec3(mesh.tangents[i1]) + w2 * vec3(mesh.tangents[i2]));
        const vec4 tw(t, mesh.tangents[i0].w * (dm.mirrored ? -1.0f : 1.0f));
        const float scale = dm.material.normalScale;
        return back ? -perturbNormal(-n, tw, ms.normalTexel, scale) : perturbNormal(n, tw, ms.normalTexel, scale);
    }

    // Shades a triangle hit: interpolated position (s.p), normals, vertex colours, texture
    // (filtered with the footprint), then the shading model with shadow rays into vis.
    void shadeMeshHit(const rt::SceneHit& h, const rt::Ray& r, const vec3& eye, const PixelFootprint* footprint, float* vis, ShadedHit& s) {
        vec3 &p = s.p, &n = s.n, &ng = s.ng, &color = s.color;
        const Material*& mat = s.mat;
        const DrawMesh& dm = f.meshes[h.instance];
        const Mesh& mesh = *dm.mesh;
        mat = &dm.material;
        const uint32_t i0 = mesh.indices[3 * h.prim], i1 = mesh.indices[3 * h.prim + 1], i2 = mesh.indices[3 * h.prim + 2];
        const float w0 = 1.0f - h.b1 - h.b2, w1 = h.b1, w2 = h.b2;
        const vec3 P[3] = {vec3(dm.world * vec4(mesh.positions[i0], 1.0f)), vec3(dm.world * vec4(mesh.positions[i1], 1.0f)),
                           vec3(dm.world * vec4(mesh.positions[i2], 1.0f))};
        p = w0 * P[0] + w1 * P[1] + w2 * P[2];
        // Outward geometric normal: the CCW side, the CW side for mirrored instances
        // (as GL's glFrontFace(GL_CW) for them).
        vec3 gn = glm::cross(P[1] - P[0], P[2] - P[0]);
        float gl = glm::length(gn);
        gn = gl > 0 ? gn / gl : vec3(0, 1, 0);
        if (dm.mirrored) gn = -gn;
        const bool back = glm::dot(gn, r.dir) > 0;   // seen from its back: flip (two-sided)
        ng = back ? -gn : gn;
        const bool hasN = mesh.normals.size() == mesh.positions.size();
        const bool hasC = mesh.colors.size() == mesh.positions.size();
        const bool hasUV = mesh.uv0.size() == mesh.positions.size();
        vec3 albedoV[3];
        for (int k = 0; k < 3; ++k) albedoV[k] = mat->baseColor;
        if (hasC) {
            albedoV[0] *= vec3(mesh.colors[i0]);
            albedoV[1] *= vec3(mesh.colors[i1]);
            albedoV[2] *= vec3(mesh.colors[i2]);
        }
        vec3 texColor(1.0f);
        const MapSamplers& mm = maps[h.instance];
        const bool hasMaps = hasUV && mm.any();
        MapSample ms;
        if (const SampledTexture* tex = textures[h.instance]; (tex || hasMaps) && hasUV) {
            const vec2 UV[3] = {mesh.uv0[i0], mesh.uv0[i1], mesh.uv0[i2]};
            const float w[3] = {w0, w1, w2};
            UvFootprint uvs[2];   // without a footprint the derivatives stay 0: level 0
            const bool footprinted = uvWithFootprint(footprint, P, UV, w, uvs[0].uv, uvs[0].ddx, uvs[0].ddy);
            if (tex)
                texColor = footprinted ? tex->sample(uvs[0].uv, uvs[0].ddx, uvs[0].ddy)
                                       : tex->sampleLevel(uvs[0].uv, 0, tex->filter() != FilterMode::Nearest);
            if (hasMaps) {
                if (mm.uv1) {
                    const vec2 UV1[3] = {mesh.uv1[i0], mesh.uv1[i1], mesh.uv1[i2]};
                    uvWithFootprint(footprint, P, UV1, w, uvs[1].uv, uvs[1].ddx, uvs[1].ddy);
                }
                ms = sampleMaps(mm, uvs);
            }
        }
        vec3 Nv[3];
        for (int k = 0; k < 3; ++k) {
            uint32_t idx = k == 0 ? i0 : k == 1 ? i1 : i2;
            vec3 nn = hasN ? dm.normal * mesh.normals[idx] : gn;
            float l = glm::length(nn);
            Nv[k] = l > 1e-20f ? nn / l : gn;
            if (back) Nv[k] = -Nv[k];
        }
        const ShadingModel model = f.settings.shading;
        vec3 albedo = (w0 * albedoV[0] + w1 * albedoV[1] + w2 * albedoV[2]) * texColor;
        if (model == ShadingModel::Gouraud && !mat->unlit) {
            // The model's two albedo-linear terms (shadeTerms) at the three vertices,
            // interpolated with the hit's barycentrics (perspective-correct by
            // construction), as the rasterizers do; texture and vertex colours apply per
            // hit. The shadow rays of the hit point scale each light at every vertex.
            lightVisibility(p, ng, vis, P, Nv, 3);
            const float wk[3] = {w0, w1, w2};
            ShadeTerms t;
            for (int k = 0; k < 3; ++k) {
                ShadeTerms tk = shadeTerms(*mat, P[k], Nv[k], eye, f, vis, {albedoV[k], env});
                t.mul += wk[k] * tk.mul;
                t.add += wk[k] * tk.add;
            }
            if (hasMaps) applyMapsToTerms(t, *mat, ms, f.ambientLight, f.settings.reflection);
            color = t.apply(albedo);
            n = w0 * Nv[0] + w1 * Nv[1] + w2 * Nv[2];
            n = glm::length(n) > 0 ? glm::normalize(n) : ng;
        } else if (model == ShadingModel::Flat && !mat->unlit) {
            // One evaluation per triangle, at its first vertex with the face normal (as the
            // rasterizers, whose provoking vertex it is); the hit's shadow rays scale the lights.
            n = ng;
            lightVisibility(p, ng, vis, &P[0], &ng, 1);
            ShadeTerms t = shadeTerms(*mat, P[0], ng, eye, f, vis, {albedoV[0], env});
            if (hasMaps) applyMapsToTerms(t, *mat, ms, f.ambientLight, f.settings.reflection);
            color = t.apply(albedo);
        } else {
            if (model == ShadingModel::Flat || !hasN)
                n = ng;
            else {
                n = w0 * Nv[0] + w1 * Nv[1] + w2 * Nv[2];
                float l = glm::length(n);
                n = l > 1e-20f ? n / l : ng;
                if (ms.hasNormal && mesh.tangents.size() == mesh.positions.size()) n = mappedNormal(dm, i0, i1, i2, w0, w1, w2, n, back, ms);
            }
            if (!mat->unlit) lightVisibility(p, ng, vis, &p, &n, 1);
            const SurfaceCoefficients coeff = hasMaps ? coefficientsAt(*mat, ms) : coefficientsOf(*mat);
            color = shade(coeff, SurfacePoint{p, n, albedo}, eye, f, mat->unlit ? nullptr : vis, env);
            s.lit = !mat->unlit;
            s.coeff = coeff;
            s.albedo = albedo;
        }
    }

    // Shades an analytic hit (implicit shape, CSG leaf, parametric surface, grid) at s.p.
    void shadeAnalyticHit(const rt::SceneHit& h, const rt::Ray& r, const vec3& eye, float* vis, ShadedHit& s) {
        vec3 &p = s.p, &n = s.n, &ng = s.ng, &color = s.color;
        const Material*& mat = s.mat;
        const DrawAnalytic& a = f.analytics[h.instance];
        mat = &a.material;
        if (a.kind == DrawAnalytic::Kind::Csg && a.csg && h.csgLeaf >= 0) mat = &a.csg->nodes[size_t(h.csgLeaf)].material;
        n = h.normal;
        if (glm::dot(n, r.dir) > 0) n = -n;   // analytic surfaces: face the ray
        ng = n;
        if (!mat->unlit) lightVisibility(p, ng, vis, &p, &n, 1);
        s.coeff = coefficientsOf(*mat);
        s.lit = !mat->unlit;
        s.albedo = mat->baseColor;
        color = shade(s.coeff, SurfacePoint{p, n, mat->baseColor}, eye, f, mat->unlit ? nullptr : vis, env);
    }

    // pbr with reflections on: smooth surfaces reflect the scene itself. The environment's
    // specular term ao FssEss R(r, roughness) (pbr.h) is replaced by ao FssEss L(r), L traced
    // along the mirror direction (what a ray that leaves the scene sees is the environment),
    // fully up to roughness 0.05 and fading out by 0.25, where the prefiltered blur takes over.
    // Returns what to add to the shaded colour.
    vec3 tracedSpecular(const ShadedHit& s, const vec3& dirN, int bounce, const PixelFootprint* footprint) {
        const float w = std::clamp((0.25f - s.coeff.roughness) / 0.2f, 0.0f, 1.0f);
        if (w <= 0.0f) return vec3(0.0f);
        const PbrPoint pt = pbrPoint(s.coeff, s.albedo);
        const vec3 v = -dirN;
        const float ndv = glm::dot(s.n, v);
        const vec2 ab = splitSum(std::clamp(ndv, 0.0f, 1.0f), pt.roughness);
        const vec3 fssEss = pt.f0 * ab.x + vec3(pt.f90 * ab.y);
        const vec3 prefiltered = env && env->map ? env->specular(2.0f * ndv * s.n - v, pt.roughness) : vec3(0.0f);
        return w * s.coeff.occlusion * fssEss * (reflection(s, dirN, bounce, footprint) - prefiltered);
    }

    // The colour seen in the mirror direction at s (dirN: the incoming ray, normalized), the
    // pixel footprint carried along when both neighbour rays reflect too.
    vec3 reflection(const ShadedHit& s, const vec3& dirN, int bounce, const PixelFootprint* footprint) {
        const vec3 &p = s.p, &n = s.n, &ng = s.ng;
        rt::Ray rr;
        vec3 rd = dirN - 2.0f * glm::dot(dirN, n) * n;
        rr.org = p + offsetScale(p) * ng;
        rr.dir = rd;
        rr.tmin = 0.0f;
        rr.tmax = std::numeric_limits<float>::infinity();
        PixelFootprint rf;
        rt::Ray nx, ny;
        rf.carried = footprint && footprint->neighbours(nx, ny) && reflectNeighbour(nx, p, ng, n, rf.rx) && reflectNeighbour(ny, p, ng, n, rf.ry);
        return trace(rr, p, bounce + 1, nullptr, rf.carried ? &rf : nullptr);
    }

    // Radiance along the ray (linear), depth of the first hit (window z via the camera) when
    // depthOut is given; eye = where the viewer is for this ray (camera eye or bounce origin).
    // footprint: the ray's differentials (texture mip selection); null: textures at level 0.
    // Masked surfaces cut out at the hit are passed through; a blended surface is composited
    // over what the ray meets behind it ("over", in linear light). Primary rays (bounce 0) come
    // back fogged by their own hit's eye distance, so layers are fogged before they blend, as
    // the rasterizers do. hitPos: the nearest surface that is not blended (the depth the
    // rasterizers keep, since blended surfaces do not write depth) and what it is.
    vec3 trace(const rt::Ray& ray, const vec3& eye, int bounce, SurfaceRecord* hitPos, const PixelFootprint* footprint = nullptr, int layer = 0) {
        ++rays;
        rt::SceneHit h;
        rt::Ray r = ray;
        float alpha = 1.0f;
        if (!firstSurface(r, h, alpha, layer, footprint, bounce == 0 ? cost : nullptr)) return missed(r, bounce);
        const bool blended = materialOf(h).alphaMode == AlphaMode::Blend;
        if (blended) alpha = std::clamp(alpha, 0.0f, 1.0f);
        SurfaceRecord* const ownHit = blended ? nullptr : hitPos;
        vec3 dirN = glm::normalize(r.dir);
        float visible[64];
        std::vector<float> visHeap;
        float* vis = visible;
        if (f.lights.size() > 64) {
            visHeap.resize(f.lights.size());
            vis = visHeap.data();
        }

        ShadedHit s;
        s.p = r.org + h.t * r.dir;
        if (h.kind == rt::SceneHit::Kind::Mesh)
            shadeMeshHit(h, r, eye, footprint, vis, s);
        else
            shadeAnalyticHit(h, r, eye, vis, s);
        if (ownHit) {
            const bool mesh = h.kind == rt::SceneHit::Kind::Mesh;
            ownHit->p = s.p;
            ownHit->drawable = uint32_t(mesh ? h.instance + 1 : f.meshes.size() + h.instance + 1);
            ownHit->primitive = mesh ? h.prim : kNoPrimitive;
        }
        vec3 color = s.color;

        if (f.settings.reflections && s.mat->reflectivity > 0.0f && bounce < f.settings.maxBounces)
            color = glm::mix(color, reflection(s, dirN, bounce, footprint), std::clamp(s.mat->reflectivity, 0.0f, 1.0f));
        else if (f.settings.reflections && f.settings.reflection == ReflectionModel::Pbr && s.lit && bounce < f.settings.maxBounces)
            color += tracedSpecular(s, dirN, bounce, footprint);
        if (bounce == 0) color = applyFog(f.settings, color, glm::length(vec3(f.camera.view * vec4(s.p, 1.0f))));
        if (blended && (alpha < 1.0f || hitPos) && layer + 1 < kMaxLayers) {
            rt::Ray behind = r;
            behind.tmin = h.t;
            const vec3 back = trace(behind, eye, bounce, hitPos, footprint, layer + 1);
            color = alpha * color + (1.0f - alpha) * back;
        }
        return color;
    }
};

float rand01(uint32_t& s) {
    s = hash32(s + 0x9e3779b9u);
    return unitFloat(s);
}

// --- a frame's tiles ----------------------------------------------------------------------------

// What every tile of a frame shares (RaycastRenderer::doRender sets it up).
struct FrameJob {
    const FrameInput& f;
    const RenderConfig& cfg;
    const rt::CameraRays& cam;
    int w, h;
    int sx, sy;                         // strata per pixel (see RaycastRenderer::capabilities)
    bool packets;                       // the tile's camera rays are traced first, in packets
    bool countCost;                     // the cost view: one centre ray per pixel, counted
    DisplayTransform display;           // exposure and tone mapping of each pixel's mean colour
    static constexpr int kTile = 32;    // pixels per tile side
    static constexpr int kPacket = 4;   // pixels per packet side (4x4: the benchmark's best, docs/benchmarks.md)
    static_assert(kPacket * kPacket <= rt::kMaxPacket);
};

// The strata per pixel of cfg: MSAA n as n jittered rays (2 -> 2x1, 4 -> 2x2, 8 -> 4x2), SSAA f
// as f x f.
void strataOf(const RenderConfig& cfg, int& sx, int& sy) {
    sx = cfg.ssaaFactor;
    sy = cfg.ssaaFactor;
    if (cfg.msaaSamples > 1) {
        sx = cfg.msaaSamples >= 4 ? (cfg.msaaSamples >= 8 ? 4 : 2) : cfg.msaaSamples;
        sy = cfg.msaaSamples / sx;
    }
}

// One sample per pixel: the camera rays of tile [x0, x1) x [y0, y1) (rows top-down) traced
// kPacket x kPacket pixels at a time (SceneAccel::intersectPacket: the same hits as one by one),
// into tileRays and tileHits (kTile per row).
void traceCameraPackets(const FrameJob& job, const rt::SceneAccel& accel, int x0, int y0, int x1, int y1, std::vector<rt::Ray>& tileRays,
                        std::vector<Tracer::FirstHit>& tileHits) {
    constexpr int kPacket = FrameJob::kPacket, tile = FrameJob::kTile;
    for (int py = y0; py < y1; py += kPacket)
        for (int px = x0; px < x1; px += kPacket) {
            rt::Ray pr[kPacket * kPacket];
            rt::SceneHit ph[kPacket * kPacket];
            int n = 0;
            for (int row = py; row < std::min(py + kPacket, y1); ++row)
                for (int x = px; x < std::min(px + kPacket, x1); ++x) pr[n++] = job.cam.ray(float(x) + 0.5f, float(job.h - 1 - row) + 0.5f);
            const uint64_t found = accel.intersectPacket(pr, n, ~uint64_t(0), ph, job.f.settings.culling);
            n = 0;
            for (int row = py; row < std::min(py + kPacket, y1); ++row)
                for (int x = px; x < std::min(px + kPacket, x1); ++x, ++n) {
                    tileRays[size_t(row - y0) * tile + size_t(x - x0)] = pr[n];
                    Tracer::FirstHit& fh = tileHits[size_t(row - y0) * tile + size_t(x - x0)];
                    fh.found = (found >> n) & 1;
                    if (fh.found) fh.hit = ph[n];
                }
        }
}

// Pixel (x, row) of the tile with corner (x0, y0): its sx x sy stratified rays traced and
// shaded, the mean colour through the display transform as sRGB bytes, the nearest depth, and (centre ray) the visibility and
// the traversal cost when asked.
void shadePixel(const FrameJob& job, Tracer& tr, int x, int row, int x0, int y0, const std::vector<rt::Ray>& tileRays,
                const std::vector<Tracer::FirstHit>& tileHits, Framebuffer& target) {
    constexpr int tile = FrameJob::kTile;
    const int w = job.w, h = job.h, sx = job.sx, sy = job.sy;
    const int wy = h - 1 - row;   // GL window y of this row
    vec3 sum(0.0f);
    float depth = 1.0f;
    uint32_t seed = hash32(uint32_t(x) * 73856093u ^ uint32_t(wy) * 19349663u);
    for (int j = 0; j < sy; ++j)
        for (int i = 0; i < sx; ++i) {
            float ox = 0.5f, oy = 0.5f;
            if (sx * sy > 1) {
                ox = (float(i) + rand01(seed)) / float(sx);
                oy = (float(j) + rand01(seed)) / float(sy);
            }
            // (the packet's ray: the same call with ox = oy = 0.5)
            const rt::Ray r = job.packets ? tileRays[size_t(row - y0) * tile + size_t(x - x0)] : job.cam.ray(float(x) + ox, float(wy) + oy);
            SurfaceRecord hp;
            const PixelFootprint fp{&job.cam, float(x) + ox, float(wy) + oy};
            rt::TraversalCount count;
            if (job.countCost) tr.cost = &count;
            if (job.packets) tr.firstHit = &tileHits[size_t(row - y0) * tile + size_t(x - x0)];
            vec3 c = tr.trace(r, job.f.camera.eye, 0, &hp, &fp);
            if (job.countCost) {   // one centre ray per pixel, like the visibility
                target.costNodes[size_t(row) * w + x] = count.nodes;
                target.costPrims[size_t(row) * w + x] = count.prims;
            }
            if (!std::isnan(hp.p.x)) depth = std::min(depth, std::clamp(job.cam.depth(hp.p), 0.0f, 1.0f));
            if (job.cfg.aovs.has(Aov::Visibility)) {   // one centre ray per pixel (RenderConfig::aovs)
                target.drawable[size_t(row) * w + x] = hp.drawable;
                target.primitive[size_t(row) * w + x] = hp.primitive;
            }
            sum += c;
        }
    sum /= float(sx * sy);
    sum = job.display(sum);                    // after the resolve, as every backend (tone_map.h)
    if (!isFinite(sum)) sum = vec3(1, 0, 1);   // never feed NaN to the byte conversion
    uint8_t* px = target.pixel(x, row);
    px[0] = toByteSRGB(sum.x);
    px[1] = toByteSRGB(sum.y);
    px[2] = toByteSRGB(sum.z);
    px[3] = 255;
    target.depth[size_t(row) * w + x] = depth;
}

// --- RaycastRenderer --------------------------------------------------------------------------------

class RaycastRenderer final : public Renderer {
public:
    std::string_view name() const override { return "raycast"; }
    Capabilities capabilities() const override {
        Capabilities c;
        c.progressive = true;
        c.exactImplicits = true;
        c.shadows = true;
        c.shadowRays = true;   // soft ones: settings.shadowRays rays to a light with a size
        c.reflections = true;
        c.wireframe = true;               // the CPU backends' overlay (common/line_overlay.h), after the rays
        c.pointsAndLines = true;          // the same pixel footprint as the rasterizers
        c.aovs.add(Aov::Visibility);      // what each primary ray keeps
        c.aovs.add(Aov::TraversalCost);   // counted per primary ray when asked (Tracer::cost)
        // MSAA n and SSAA f are both taken as stratified jittered rays per pixel: n rays
        // (2 -> 2x1, 4 -> 2x2, 8 -> 4x2 strata) and f x f rays; each ray is shaded.
        c.msaaSamples = {2, 4, 8};
        c.ssaaFactors = {2, 3, 4};
        c.maxImageSize = 16384;
        return c;
    }

protected:
    RenderStats doRender(const FrameInput& f, const RenderConfig& cfg, Framebuffer& target, RenderControl* control) override {
        RenderStats stats;
        const int w = cfg.width, h = cfg.height;
        target.resize(w, h);
        const DisplayTransform display(f.settings);
        const vec3 background = display(f.settings.background);
        const uint8_t bg[4] = {toByteSRGB(background.x), toByteSRGB(background.y), toByteSRGB(background.z), 255};
        target.clear(bg, 1.0f);
        if (cfg.aovs.has(Aov::Visibility)) target.allocate(Aov::Visibility);
        const bool countCost = cfg.aovs.has(Aov::TraversalCost) && cfg.samplesPerPixel == 1;   // render() asks only for one-sample frames
        if (countCost) target.allocate(Aov::TraversalCost);
        rt::CameraRays cam(f.camera, w, h);
        if (!cam.valid() || !isFinite(f.camera.eye)) {
            stats.error = "camera matrices are not invertible";
            return stats;
        }

        // FTZ/DAZ: denormals in the traversal cost a lot and change nothing visible.
        const unsigned csr = _mm_getcsr();
        m_accel.update(f);
        stats.triangles = f.triangleCount();
        prepareSamplers(f);
        std::string envError;
        m_environment = environmentFor(f.settings, &envError);
        if (!envError.empty()) stats.config.notes.push_back("environment " + envError + " (lit without it)");

        int sx = 1, sy = 1;
        strataOf(cfg, sx, sy);
        // Camera rays in packets where each pixel has one (the cost view counts rays one by one);
        // VIEWER_RAYCAST_PACKETS=0 traces them one by one (timing comparisons: the same image).
        const bool packets = debugSwitches().raycastPackets && sx * sy == 1 && !countCost;
        const FrameJob job{f, cfg, cam, w, h, sx, sy, packets, countCost, display};
        uint64_t rays = 0;
        stats.cancelled = !renderTiles(job, target, control, rays);
        _mm_setcsr(csr);

        stats.rays = rays;
        if (!stats.cancelled) drawOverlay(f, cfg, target);
        stats.ok = !stats.cancelled;
        if (stats.cancelled) stats.error = "cancelled";
        return stats;
    }

public:
    std::vector<float> lightVisibility(const FrameInput& f, const vec3& p, const vec3& ng) override {
        if (!f.settings.shadows || m_textures.size() != f.meshes.size()) return {};
        Tracer tr{f, m_accel, m_textures, m_maps, 0, anyTranslucent(f)};
        std::vector<float> v(f.lights.size(), 1.0f);
        if (!v.empty()) tr.lightVisibility(p, ng, v.data());
        return v;
    }
    std::vector<float> lightVisibilityMany(const FrameInput& f, int light, const std::vector<vec3>& p, const std::vector<vec3>& ng) override {
        if (!f.settings.shadows || m_textures.size() != f.meshes.size() || light < 0 || size_t(light) >= f.lights.size() || p.size() != ng.size())
            return {};
        std::vector<float> out(p.size(), 1.0f);
        const bool translucent = anyTranslucent(f);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, p.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
            Tracer tr{f, m_accel, m_textures, m_maps, 0, translucent};
            std::vector<float> v(f.lights.size(), 1.0f);
            for (size_t i = r.begin(); i < r.end(); ++i) {
                tr.lightVisibility(p[i], ng[i], v.data());
                out[i] = v[size_t(light)];
            }
        });
        return out;
    }

private:
    // Samplers (mip chains) per texture, cached by id + version; one pointer per mesh (m_textures,
    // m_maps: the material maps).
    void prepareSamplers(const FrameInput& f) {
        m_samplers.beginFrame();
        m_textures.assign(f.meshes.size(), nullptr);
        m_maps.assign(f.meshes.size(), {});
        for (size_t i = 0; i < f.meshes.size(); ++i) {
            m_textures[i] = m_samplers.get(f.meshes[i].texture);
            const sg::DrawMesh& dm = f.meshes[i];
            const sg::MaterialMaps& fm = dm.maps;
            const bool hasUv1 = dm.mesh && dm.mesh->uv1.size() == dm.mesh->positions.size();
            m_maps[i] = {m_samplers.get(fm.emissive), m_samplers.get(fm.occlusion), m_samplers.get(fm.metallicRoughness), m_samplers.get(fm.normal),
                         hasUv1 ? dm.material.uv1Maps : uint8_t(0)};
        }
        m_samplers.endFrame();
    }

    // The frame's 32x32 tiles, in parallel (FTZ/DAZ in each worker), with progress and
    // cancellation; adds the rays traced to `rays`. Returns false when cancelled.
    bool renderTiles(const FrameJob& job, Framebuffer& target, RenderControl* control, uint64_t& rays) {
        const FrameInput& f = job.f;
        const bool anyAlpha = anyTranslucent(f);
        constexpr int tile = FrameJob::kTile;
        const int tx = (job.w + tile - 1) / tile, ty = (job.h + tile - 1) / tile, ntiles = tx * ty;
        std::atomic<int> done{0};
        std::atomic<uint64_t> rayCount{0};
        std::atomic<bool> cancelled{false};
        if (control) control->progress = 0.0f;

        tbb::parallel_for(tbb::blocked_range<int>(0, ntiles, 1), [&](const tbb::blocked_range<int>& range) {
            std::vector<Tracer::FirstHit> tileHits(job.packets ? size_t(tile) * tile : 0);
            std::vector<rt::Ray> tileRays(tileHits.size());
            const unsigned old = _mm_getcsr();
            _mm_setcsr(old | 0x8040);   // FTZ | DAZ in this worker
            for (int ti = range.begin(); ti != range.end(); ++ti) {
                if (control && control->cancel.load(std::memory_order_relaxed)) {
                    cancelled = true;
                    break;
                }
                Tracer tr{f, m_accel, m_textures, m_maps, 0, anyAlpha};
                tr.env = &m_environment;
                const int x0 = (ti % tx) * tile, y0 = (ti / tx) * tile;   // y0: framebuffer row (top-down)
                const int x1 = std::min(x0 + tile, job.w), y1 = std::min(y0 + tile, job.h);
                if (job.packets) traceCameraPackets(job, m_accel, x0, y0, x1, y1, tileRays, tileHits);
                for (int row = y0; row < y1; ++row)
                    for (int x = x0; x < x1; ++x) shadePixel(job, tr, x, row, x0, y0, tileRays, tileHits, target);
                rayCount += tr.rays;
                int d = ++done;
                if (control) {
                    control->progress = float(d) / float(ntiles);
                    if (control->onTileDone) control->onTileDone();
                }
            }
            _mm_setcsr(old);
        });
        rays = rayCount.load();
        return !cancelled.load();
    }

    // Points, lines and the wireframe, rasterized over the ray-cast image against its depth
    // exactly as the CPU rasterizer draws them (rays cannot hit zero-width primitives). The
    // wireframe of analytic shapes is their tessellation's, as in the rasterizers. Drawn at the
    // output size: with SSAA the rasterizers' 1-pixel lines come out fainter after downsampling.
    void drawOverlay(const FrameInput& f, const RenderConfig& cfg, Framebuffer& target) {
        std::vector<PreparedDraw> draws;
        if (f.settings.wireframe) {
            draws = prepareDraws(f, cfg.tessellation, m_tess);
            m_tess.nextFrame();
        } else {
            for (const PreparedDraw& d : prepareMeshDraws(f))
                if (d.mesh->mode != sg::PrimitiveMode::Triangles) draws.push_back(d);
        }
        if (!draws.empty()) drawPointsLinesWireframe(draws, f, target, 2.0f);
    }

    rt::SceneAccel m_accel;
    SamplerCache m_samplers;
    // The last frame's samplers per mesh (kept for lightVisibility).
    std::vector<const SampledTexture*> m_textures;
    std::vector<MapSamplers> m_maps;
    EnvironmentLight m_environment;   // this frame's (environmentFor)
    TessellationCache m_tess;         // wireframe of analytic shapes only
};

}   // namespace

std::unique_ptr<Renderer> makeRaycastRenderer() { return std::make_unique<RaycastRenderer>(); }

}   // namespace rnd
