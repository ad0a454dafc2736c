// tracer.h - the ray caster's per-ray work (included by raycast_renderer.cpp only): the pixel
// footprint of a ray (ray differentials for texture levels) and Tracer, which traces a ray
// through the scene and shades what it meets (meshes flat/Gouraud/Phong, analytic shapes; shadow
// rays one by one or from a tile's packets, cut-outs and blended layers, mirror reflections,
// traced pbr specular, fog).
//
// Conventions shared with the rasterizers (docs/math.md): two-sided lighting flips normals of
// back-facing triangles (geometric normal pointing along the ray); fog uses |p_eye|. Textures:
// the rasterizer's sampler (mip chains, nearest/bilinear/trilinear), the level chosen from ray
// differentials - for camera rays and for mirror-reflected ones - texels decoded from sRGB
// before filtering; analytic surfaces are untextured.
#pragma once

#include "raycast/camera_rays.h"
#include "raycast/lane_shading.h"
#include "raycast/scene_accel.h"
#include "raycast/world_vertices.h"
#include "renderers/environment.h"
#include "renderers/framebuffer.h"
#include "renderers/pbr.h"
#include "renderers/sampling.h"
#include "renderers/shading.h"
#include "renderers/shadow_map.h"
#include "renderers/texture_sampler.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <vector>

namespace rnd::raycast {

using namespace sg;

// --- texture footprint ------------------------------------------------------------------------

// The rays through the neighbouring pixels (one to the right, one up) that go with a ray: its
// ray differentials, from which a textured hit gets its uv derivatives and so its mip level.
// Camera rays keep only their window position (the neighbours are made when a texture needs
// them, unless both were made already: madeX, madeY, the camera rays of those pixels, which
// are cam->neighbours' rays bit for bit); reflected rays carry their neighbours, reflected at
// the same mirror.
struct PixelFootprint {
    const rt::CameraRays* cam = nullptr;
    float wx = 0, wy = 0;
    bool carried = false;
    rt::Ray rx, ry;
    const rt::Ray* madeX = nullptr;   // cam's ray through (wx + 1, wy), or null
    const rt::Ray* madeY = nullptr;   // and through (wx, wy + 1)
    bool neighbours(rt::Ray& x, rt::Ray& y) const {
        if (carried) {
            x = rx;
            y = ry;
            return true;
        }
        if (!cam) return false;
        if (madeX && madeY) {
            x = *madeX;
            y = *madeY;
            return true;
        }
        cam->neighbours(wx, wy, x, y);
        return true;
    }
};

// A neighbouring ray reflected where it meets the mirror's plane (point p, plane normal ng)
// about the same shading normal n as the main ray: exact for flat mirrors; for curved ones it
// leaves out the curvature (the footprint grows less than it should: a finer level, never a
// coarser one). False for rays along the plane.
inline bool reflectNeighbour(const rt::Ray& a, const vec3& p, const vec3& ng, const vec3& n, rt::Ray& out) {
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

// Whether any material of the frame is masked or blended (shadow rays then test alpha).
inline bool anyTranslucent(const FrameInput& f) {
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
inline bool uvWithFootprint(const PixelFootprint* footprint, const vec3 P[3], const vec2 UV[3], const float w[3], vec2& uv, vec2& ddx, vec2& ddy) {
    uv = w[0] * UV[0] + w[1] * UV[1] + w[2] * UV[2];
    vec2 uvX, uvY;
    rt::Ray nx, ny;
    if (!(footprint && footprint->neighbours(nx, ny))) return false;
    const TrianglePlaneUv plane(P, UV);   // (the neighbours' uv where they meet the triangle's plane)
    if (!(plane.at(nx.org, nx.dir, uvX) && plane.at(ny.org, ny.dir, uvY))) return false;
    ddx = uvX - uv;
    ddy = uvY - uv;
    return true;
}

// --- Tracer --------------------------------------------------------------------------------------

// A triangle hit's world vertices P, point p (interpolated), outward geometric normal gn and
// that normal on the ray's side ng (back: the ray sees the triangle's back).
struct MeshHitFrame {
    vec3 P[3], p, gn, ng;
    bool back = false;
};
// wv: the instance's world vertices (the same values, made once), or null.
inline MeshHitFrame meshHitFrame(const DrawMesh& dm, const rt::SceneHit& h, const rt::Ray& r, const rt::WorldVertices* wv) {
    const Mesh& mesh = *dm.mesh;
    const uint32_t i0 = mesh.indices[3 * h.prim], i1 = mesh.indices[3 * h.prim + 1], i2 = mesh.indices[3 * h.prim + 2];
    const float w0 = 1.0f - h.b1 - h.b2, w1 = h.b1, w2 = h.b2;
    MeshHitFrame fr;
    if (wv) {
        fr.P[0] = wv->positions[i0];
        fr.P[1] = wv->positions[i1];
        fr.P[2] = wv->positions[i2];
    } else {
        fr.P[0] = vec3(dm.world * vec4(mesh.positions[i0], 1.0f));
        fr.P[1] = vec3(dm.world * vec4(mesh.positions[i1], 1.0f));
        fr.P[2] = vec3(dm.world * vec4(mesh.positions[i2], 1.0f));
    }
    fr.p = w0 * fr.P[0] + w1 * fr.P[1] + w2 * fr.P[2];
    // Outward geometric normal: the CCW side, the CW side for mirrored instances
    // (as GL's glFrontFace(GL_CW) for them).
    vec3 gn = glm::cross(fr.P[1] - fr.P[0], fr.P[2] - fr.P[0]);
    const float gl = glm::length(gn);
    gn = gl > 0 ? gn / gl : vec3(0, 1, 0);
    if (dm.mirrored) gn = -gn;
    fr.gn = gn;
    fr.back = glm::dot(gn, r.dir) > 0;   // seen from its back: flip (two-sided)
    fr.ng = fr.back ? -gn : gn;
    return fr;
}

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
    // Per f.meshes entry, its vertices in world space (WorldVertexCache), null where not made;
    // null: none at all.
    const std::vector<const rt::WorldVertices*>* world = nullptr;
    uint64_t rays = 0;
    bool anyAlpha = false;   // some material is masked or blended (anyTranslucent())
    // The cost view (RenderConfig::traversalCost): the BVH work of the primary ray (bounce 0,
    // every layer it passes through; not shadow or reflection rays) is added here when set.
    rt::TraversalCount* cost = nullptr;
    // The primary ray's first hit when it was already traced (a tile's camera rays go through
    // SceneAccel::intersectPacket): used once, by the next firstSurface call, instead of tracing.
    // A mesh hit's frame (meshHitFrame) is kept with it once made: the shadow packets ask for
    // it first, the shading again (one vertex fetch and transform per hit instead of two).
    struct FirstHit {
        bool found = false;
        rt::SceneHit hit;
        mutable bool framed = false;
        mutable MeshHitFrame frame;
    };
    const FirstHit* firstHit = nullptr;
    // The FirstHit that the last firstSurface call returned as the surface (null when it traced).
    const FirstHit* surfaceFrom = nullptr;
    // The shadow rays of a primary hit when they were already traced (a tile's packets, see
    // presetShadows): for the surface point p with geometric normal ng, bit i of `known` says
    // light i's visibility is known, bit i of `lit` gives it (1 or 0: opaque scenes, hard shadows).
    // Used once, by the next lightVisibility call, and only for that same p and ng.
    struct PresetVisibility {
        vec3 p{0.0f}, ng{0.0f};
        uint64_t known = 0, lit = 0;
    };
    const PresetVisibility* preset = nullptr;
    // The pbr model's environment light (null or empty map: none): it lights surfaces and is what
    // rays that leave the scene see (reflection rays always, camera rays when it is the background).
    const EnvironmentLight* env = nullptr;
    // Per f.meshes entry, coefficientsOf(its material), made once per frame (null: made per hit).
    const std::vector<SurfaceCoefficients>* meshCoefficients = nullptr;
    SurfaceCoefficients coefficientsOfMesh(uint32_t mesh) const {
        return meshCoefficients ? (*meshCoefficients)[mesh] : coefficientsOf(f.meshes[mesh].material);
    }

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
        const PresetVisibility* pre = preset;
        preset = nullptr;
        const uint64_t known = pre && sameBits(pre->p, p) && sameBits(pre->ng, ng) ? pre->known : 0;
        for (size_t i = 0; i < f.lights.size(); ++i) {
            visible[i] = 1.0f;
            if (!f.settings.shadows) continue;
            const bool isKnown = i < 64 && ((known >> i) & 1);
            if (isKnown && ((pre->lit >> i) & 1)) continue;   // lit: 1, whether the light reaches the points or not
            if (points > 0) {
                bool reaches = false;
                for (int k = 0; k < points && !reaches; ++k) reaches = lightReaches(f.lights[i], q[k], n[k], f.settings.reflection);
                if (!reaches) continue;
            }
            if (isKnown) {   // blocked
                visible[i] = 0.0f;
                continue;
            }
            if (softLight(f.lights[i])) {
                const LightSample ls = sampleLight(f.lights[i], p);
                const float side = glm::dot(ng, ls.toLight) >= 0 ? 1.0f : -1.0f;
                visible[i] = softVisibility(f.lights[i], p, side * ng, offsetScale(p));
                continue;
            }
            const rt::Ray sr = shadowRay(f.lights[i], p, ng);
            if (!(sr.tmax > 0)) continue;
            ++rays;
            visible[i] = transmittance(sr);
        }
    }

    static bool sameBits(const vec3& a, const vec3& b) { return std::memcmp(&a, &b, sizeof(vec3)) == 0; }
    bool softLight(const DrawLight& L) const { return L.hasSize() && f.settings.shadowRays > 1; }

    // The hard shadow ray toward light L from p (geometric normal ng): it starts eps off the
    // surface on the light's side and stops just short of the light (tmax <= 0: no ray).
    static rt::Ray shadowRay(const DrawLight& L, const vec3& p, const vec3& ng) { return shadowRay(sampleLight(L, p), p, ng); }
    static rt::Ray shadowRay(const LightSample& ls, const vec3& p, const vec3& ng) {
        const float side = glm::dot(ng, ls.toLight) >= 0 ? 1.0f : -1.0f;
        const float eps = offsetScale(p);
        rt::Ray sr;
        sr.org = p + side * eps * ng;
        sr.dir = ls.toLight;
        sr.tmin = 0.0f;
        sr.tmax = std::isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) - eps : std::numeric_limits<float>::infinity();
        return sr;
    }

    // Where a primary hit's shading will ask for shadows: the point p and the geometric normal ng
    // on the ray's side, computed as shadeMeshHit / shadeAnalyticHit do (meshHitFrame). False for
    // hits that ask for none (unlit materials).
    bool shadowPoint(const FirstHit& fh, const rt::Ray& r, vec3& p, vec3& ng) const {
        const rt::SceneHit& h = fh.hit;
        if (materialOf(h).unlit) return false;
        if (h.kind == rt::SceneHit::Kind::Mesh) {
            const MeshHitFrame& fr = frameOf(fh, r);
            p = fr.p;
            ng = fr.ng;
            return true;
        }
        p = r.org + h.t * r.dir;
        ng = glm::dot(h.normal, r.dir) > 0 ? -h.normal : h.normal;
        return true;
    }

    // The shadow rays of up to kMaxPacket primary hits (*camRays[k], *hits[k]; opaque scenes
    // only), traced light by light as packets (SceneAccel::occludedPacket) into *presets[k], which the
    // shading of hit k then uses instead of tracing them one by one (lightVisibility, where the
    // point and normal are bit for bit the same). A light is traced where it reaches the
    // geometric normal's side (lightReaches at p with ng); shading normals that reach further
    // are traced one by one later, as before.
    void presetShadows(const rt::Ray* const* camRays, const FirstHit* const* hits, int n, PresetVisibility* const* presets) {
        rt::PacketScratch<rt::Ray> sr;
        PresetVisibility* out[rt::kMaxPacket];
        uint64_t pending = 0;
        n = std::min(n, rt::kMaxPacket);
        frameMeshHits(camRays, hits, n);
        for (int k = 0; k < n; ++k) {
            out[k] = presets[k];
            out[k]->known = out[k]->lit = 0;
            if (hits[k]->found && shadowPoint(*hits[k], *camRays[k], out[k]->p, out[k]->ng)) pending |= uint64_t(1) << k;
        }
        const size_t lights = std::min<size_t>(f.lights.size(), 64);
        const bool pbr = f.settings.reflection == ReflectionModel::Pbr;
        // The Phong models' lights in lanes (shadowRays), the points eight at a time, set up once.
        constexpr int kLanes = ShadowLanes::kLanes;
        ShadowLanes groups[rt::kMaxPacket / kLanes];
        int laneHit[rt::kMaxPacket];
        int nGroups = 0;
        if (!pbr) {
            int g = -1;
            for (uint64_t m = pending; m; m &= m - 1) {
                const int k = __builtin_ctzll(m);
                if (g < 0 || groups[g].count == kLanes) groups[++g].count = 0;
                const int l = groups[g].count++;
                laneHit[g * kLanes + l] = k;
                for (int a = 0; a < 3; ++a) {
                    groups[g].p[a][l] = out[k]->p[a];
                    groups[g].ng[a][l] = out[k]->ng[a];
                }
            }
            nGroups = g + 1;
        }
        for (size_t i = 0; i < lights && pending; ++i) {
            const DrawLight& L = f.lights[i];
            if (softLight(L)) continue;
            uint64_t active = 0;
            for (int g = 0; g < nGroups; ++g) {
                shadowRays(groups[g], L);
                for (unsigned m = groups[g].reaches; m; m &= m - 1) {
                    const int l = __builtin_ctz(m), k = laneHit[g * kLanes + l];
                    sr[k] = groups[g].rays[l];
                    out[k]->known |= uint64_t(1) << i;
                    if (sr[k].tmax > 0)
                        active |= uint64_t(1) << k;
                    else
                        out[k]->lit |= uint64_t(1) << i;
                }
            }
            for (uint64_t m = pbr ? pending : 0; m; m &= m - 1) {
                const int k = __builtin_ctzll(m);
                const LightSample ls = sampleLight(L, out[k]->p);
                if (!lightReaches(L, out[k]->p, out[k]->ng, f.settings.reflection)) continue;   // (pbr's sample)
                sr[k] = shadowRay(ls, out[k]->p, out[k]->ng);
                out[k]->known |= uint64_t(1) << i;
                if (sr[k].tmax > 0)
                    active |= uint64_t(1) << k;
                else
                    out[k]->lit |= uint64_t(1) << i;
            }
            if (!active) continue;
            rays += uint64_t(__builtin_popcountll(active));
            const uint64_t blocked = accel.occludedPacket(sr.data(), n, active);
            for (uint64_t m = active & ~blocked; m; m &= m - 1) out[__builtin_ctzll(m)]->lit |= uint64_t(1) << i;
        }
    }

    // The frames of the mesh hits among hits[0, n) along camRays (frameOf), eight at a time
    // (hitFrames: meshHitFrame's values in lanes).
    void frameMeshHits(const rt::Ray* const* camRays, const FirstHit* const* hits, int n) const {
        FrameLanes b;
        const FirstHit* lane[FrameLanes::kLanes];
        auto flush = [&] {
            hitFrames(b);
            for (int l = 0; l < b.count; ++l) {
                MeshHitFrame& fr = lane[l]->frame;
                for (int a = 0; a < 3; ++a) {
                    for (int k = 0; k < 3; ++k) fr.P[k][a] = b.P[k][a][l];
                    fr.p[a] = b.p[a][l];
                    fr.gn[a] = b.gn[a][l];
                    fr.ng[a] = b.ng[a][l];
                }
                fr.back = (b.back >> l) & 1;
                lane[l]->framed = true;
            }
            b.count = 0;
        };
        for (int k = 0; k < n; ++k) {
            const FirstHit& fh = *hits[k];
            if (!fh.found || fh.framed || fh.hit.kind != rt::SceneHit::Kind::Mesh) continue;
            const rt::SceneHit& h = fh.hit;
            const DrawMesh& dm = f.meshes[h.instance];
            const Mesh& mesh = *dm.mesh;
            const rt::WorldVertices* wv = worldOf(h.instance);
            const int l = b.count++;
            for (int v = 0; v < 3; ++v) {   // meshHitFrame's vertices
                const uint32_t idx = mesh.indices[3 * h.prim + uint32_t(v)];
                const vec3 P = wv ? wv->positions[idx] : vec3(dm.world * vec4(mesh.positions[idx], 1.0f));
                for (int a = 0; a < 3; ++a) b.P[v][a][l] = P[a];
            }
            for (int a = 0; a < 3; ++a) b.dir[a][l] = camRays[k]->dir[a];
            b.b1[l] = h.b1;
            b.b2[l] = h.b2;
            b.mirrored = (b.mirrored & ~(1u << l)) | (unsigned(dm.mirrored) << l);
            lane[l] = &fh;
            if (b.count == FrameLanes::kLanes) flush();
        }
        if (b.count) flush();
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
            surfaceFrom = nullptr;
            if (firstHit) {
                const FirstHit* pre = firstHit;
                firstHit = nullptr;
                if (!pre->found) return false;
                h = pre->hit;
                surfaceFrom = pre;
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

    const rt::WorldVertices* worldOf(uint32_t mesh) const { return world ? (*world)[mesh] : nullptr; }

    // The frame of fh's mesh hit along r, made on the first call and kept with the hit.
    const MeshHitFrame& frameOf(const FirstHit& fh, const rt::Ray& r) const {
        if (!fh.framed) {
            fh.frame = meshHitFrame(f.meshes[fh.hit.instance], fh.hit, r, worldOf(fh.hit.instance));
            fh.framed = true;
        }
        return fh.frame;
    }

    // The albedo at the vertices i0, i1, i2: the material's base colour times the vertex colours.
    static void vertexAlbedos(const Material& mat, const Mesh& mesh, uint32_t i0, uint32_t i1, uint32_t i2, vec3 albedoV[3]) {
        for (int k = 0; k < 3; ++k) albedoV[k] = mat.baseColor;
        if (mesh.colors.size() == mesh.positions.size()) {
            albedoV[0] *= vec3(mesh.colors[i0]);
            albedoV[1] *= vec3(mesh.colors[i1]);
            albedoV[2] *= vec3(mesh.colors[i2]);
        }
    }

    // The unit world normals at the vertices i0, i1, i2 of the hit with frame fr, on the ray's
    // side (flipped on a back face): the face normal where the mesh has none or one is too short
    // to normalize. wv: the instance's world vertices, or null.
    [[gnu::always_inline]] static void vertexNormals(const DrawMesh& dm, const rt::WorldVertices* wv, uint32_t i0, uint32_t i1, uint32_t i2,
                                                     const MeshHitFrame& fr, vec3 Nv[3]) {
        const Mesh& mesh = *dm.mesh;
        const vec3& gn = fr.gn;
        const bool hasN = mesh.normals.size() == mesh.positions.size();
        const bool worldN = hasN && wv && !wv->normals.empty();
        for (int k = 0; k < 3; ++k) {
            uint32_t idx = k == 0 ? i0 : k == 1 ? i1 : i2;
            if (worldN) {   // the same values, made once (zero: the face normal)
                const vec3& c = wv->normals[idx];
                Nv[k] = c.x == 0.0f && c.y == 0.0f && c.z == 0.0f ? gn : c;
            } else {
                vec3 nn = hasN ? dm.normal * mesh.normals[idx] : gn;
                float l = glm::length(nn);
                Nv[k] = l > 1e-20f ? nn / l : gn;
            }
            if (fr.back) Nv[k] = -Nv[k];
        }
    }

    // A colour texture's texel at uv: filtered with its derivatives where the ray carries a
    // footprint, level 0 otherwise.
    static vec3 texel(const SampledTexture& tex, const UvFootprint& uv, bool footprinted) {
        return footprinted ? tex.sample(uv.uv, uv.ddx, uv.ddy) : tex.sampleLevel(uv.uv, 0, tex.filter() != FilterMode::Nearest);
    }

    // Shades a triangle hit: interpolated position (s.p), normals, vertex colours, texture
    // (filtered with the footprint), then the shading model with shadow rays into vis. known:
    // the hit's frame when it was already made (frameOf), else null.
    void shadeMeshHit(const rt::SceneHit& h, const rt::Ray& r, const vec3& eye, const PixelFootprint* footprint, float* vis, ShadedHit& s,
                      const MeshHitFrame* known = nullptr) {
        vec3 &p = s.p, &n = s.n, &ng = s.ng, &color = s.color;
        const Material*& mat = s.mat;
        const DrawMesh& dm = f.meshes[h.instance];
        const Mesh& mesh = *dm.mesh;
        mat = &dm.material;
        const uint32_t i0 = mesh.indices[3 * h.prim], i1 = mesh.indices[3 * h.prim + 1], i2 = mesh.indices[3 * h.prim + 2];
        const float w0 = 1.0f - h.b1 - h.b2, w1 = h.b1, w2 = h.b2;
        const rt::WorldVertices* wv = worldOf(h.instance);
        const MeshHitFrame fr = known ? *known : meshHitFrame(dm, h, r, wv);
        const vec3(&P)[3] = fr.P;
        const bool back = fr.back;
        p = fr.p;
        ng = fr.ng;
        const bool hasN = mesh.normals.size() == mesh.positions.size();
        const bool hasUV = mesh.uv0.size() == mesh.positions.size();
        vec3 albedoV[3];
        vertexAlbedos(*mat, mesh, i0, i1, i2, albedoV);
        vec3 texColor(1.0f);
        const MapSamplers& mm = maps[h.instance];
        const bool hasMaps = hasUV && mm.any();
        MapSample ms;
        if (const SampledTexture* tex = textures[h.instance]; (tex || hasMaps) && hasUV) {
            const vec2 UV[3] = {mesh.uv0[i0], mesh.uv0[i1], mesh.uv0[i2]};
            const float w[3] = {w0, w1, w2};
            UvFootprint uvs[2];   // without a footprint the derivatives stay 0: level 0
            const bool footprinted = uvWithFootprint(footprint, P, UV, w, uvs[0].uv, uvs[0].ddx, uvs[0].ddy);
            if (tex) texColor = texel(*tex, uvs[0], footprinted);
            if (hasMaps) {
                if (mm.uv1) {
                    const vec2 UV1[3] = {mesh.uv1[i0], mesh.uv1[i1], mesh.uv1[i2]};
                    uvWithFootprint(footprint, P, UV1, w, uvs[1].uv, uvs[1].ddx, uvs[1].ddy);
                }
                ms = sampleMaps(mm, uvs);
            }
        }
        vec3 Nv[3];
        vertexNormals(dm, wv, i0, i1, i2, fr, Nv);
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
            const SurfaceCoefficients coeff = coefficientsOfMesh(h.instance);
            for (int k = 0; k < 3; ++k) {
                ShadeTerms tk = shadeTerms(coeff, P[k], Nv[k], eye, f, vis, {albedoV[k], env});
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
            ShadeTerms t = shadeTerms(coefficientsOfMesh(h.instance), P[0], ng, eye, f, vis, {albedoV[0], env});
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
            const SurfaceCoefficients coeff = hasMaps ? coefficientsAt(*mat, ms) : coefficientsOfMesh(h.instance);
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

    // A primary ray's colour fogged by the eye distance of its hit at p.
    vec3 fogged(const vec3& color, const vec3& p) const {
        if (f.settings.fog == FogMode::Off) return color;
        return applyFog(f.settings, color, glm::length(vec3(f.camera.view * vec4(p, 1.0f))));
    }

    // laneInputs' texel (out of line: the untextured lanes' loop stays small).
    [[gnu::noinline]] static vec3 laneTexel(const SampledTexture& tex, const Mesh& mesh, uint32_t i0, uint32_t i1, uint32_t i2,
                                            const MeshHitFrame& fr, const float w[3], const PixelFootprint& footprint) {
        const vec2 UV[3] = {mesh.uv0[i0], mesh.uv0[i1], mesh.uv0[i2]};
        UvFootprint uv;
        const bool footprinted = uvWithFootprint(&footprint, fr.P, UV, w, uv.uv, uv.ddx, uv.ddy);
        return texel(tex, uv, footprinted);
    }

    // Lane l of b (lane_shading.h) from the mesh hit fh along r: its frame, vertex normals and
    // albedos, the colour texture's texel where the mesh has one and uvs (textured set: filtered
    // with that camera ray's footprint), the mesh's coefficients (meshCoefficients must be set),
    // and the light bits of its shadow packets' preset where that preset is this hit's (null:
    // none).
    [[gnu::always_inline]] void laneInputs(const FirstHit& fh, const rt::Ray& r, const PresetVisibility* pre, const PixelFootprint* textured,
                                           LaneBatch& b, int l) const {
        const rt::SceneHit& h = fh.hit;
        const DrawMesh& dm = f.meshes[h.instance];
        const Mesh& mesh = *dm.mesh;
        const uint32_t i0 = mesh.indices[3 * h.prim], i1 = mesh.indices[3 * h.prim + 1], i2 = mesh.indices[3 * h.prim + 2];
        const MeshHitFrame& fr = frameOf(fh, r);
        const bool smooth = mesh.normals.size() == mesh.positions.size();
        vec3 Nv[3], albedoV[3];
        if (smooth) vertexNormals(dm, worldOf(h.instance), i0, i1, i2, fr, Nv);
        vertexAlbedos(dm.material, mesh, i0, i1, i2, albedoV);
        const float w[3] = {1.0f - h.b1 - h.b2, h.b1, h.b2};
        b.textured &= ~(1u << l);
        if (textured) {
            const vec3 texColor = laneTexel(*textures[h.instance], mesh, i0, i1, i2, fr, w, *textured);
            for (int a = 0; a < 3; ++a) b.tex[a][l] = texColor[a];
            b.textured |= 1u << l;
        }
        for (int a = 0; a < 3; ++a) {
            b.p[a][l] = fr.p[a];
            b.ng[a][l] = fr.ng[a];
            b.w[a][l] = w[a];
            for (int k = 0; k < 3; ++k) {
                b.vn[k][a][l] = smooth ? Nv[k][a] : fr.ng[a];
                b.va[k][a][l] = albedoV[k][a];
            }
        }
        b.smooth[l] = smooth;
        b.coeff[l] = &(*meshCoefficients)[h.instance];
        const bool same = pre && sameBits(pre->p, fr.p) && sameBits(pre->ng, fr.ng);
        b.known[l] = same ? pre->known : 0;
        b.lit[l] = same ? pre->lit : 0;
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
            shadeMeshHit(h, r, eye, footprint, vis, s, surfaceFrom && surfaceFrom->framed ? &surfaceFrom->frame : nullptr);
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
            color = glm::mix(color, reflection(s, glm::normalize(r.dir), bounce, footprint), std::clamp(s.mat->reflectivity, 0.0f, 1.0f));
        else if (f.settings.reflections && f.settings.reflection == ReflectionModel::Pbr && s.lit && bounce < f.settings.maxBounces)
            color += tracedSpecular(s, glm::normalize(r.dir), bounce, footprint);
        if (bounce == 0) color = fogged(color, s.p);
        if (blended && (alpha < 1.0f || hitPos) && layer + 1 < kMaxLayers) {
            rt::Ray behind = r;
            behind.tmin = h.t;
            const vec3 back = trace(behind, eye, bounce, hitPos, footprint, layer + 1);
            color = alpha * color + (1.0f - alpha) * back;
        }
        return color;
    }
};

}   // namespace rnd::raycast
