// min_embree.cpp - the minimal Embree renderer of bench_raycast_frame (see min_embree.h): the
// scene in world space, then per 4x4 packet: camera rays, their hits, one coherent shadow
// packet per light, shading and bytes.
#include "min_embree.h"

#include "renderers/draw_list.h"
#include "renderers/shading.h"
#include "renderers/texture_sampler.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <xmmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>

namespace bench {

using namespace sg;

struct MinimalEmbree::State {
    struct Geom {   // one draw in world space
        std::vector<vec3> p, n;
        std::vector<vec2> uv;
        std::vector<uint32_t> idx;
        const Material* mat = nullptr;
        const std::vector<uint16_t>* triMat = nullptr;   // per-triangle materials (CSG)
        const std::vector<Material>* mats = nullptr;
        const Texture* tex = nullptr;
        const rnd::SampledTexture* sampler = nullptr;   // tex's mip levels (filtered lookups)
    };
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<Geom> geoms;
    // Instanced: one object-space scene per mesh (shared by its instances), each draw an instance
    // of it in `scene`; a hit's draw is then its instance ID, not its geometry ID.
    bool instanced = false;
    std::unordered_map<const Mesh*, RTCScene> meshScenes;
    rnd::TessellationCache tess;
    bool nearest = false;         // textures at level 0, nearest texel (the reference before filtered lookups)
    rnd::SamplerCache samplers;   // the mip chains, as the CPU backends keep them
    float decode[256];            // sRGB byte -> linear
    uint8_t encode[4097];         // linear [0, 1] in steps of 1/4096 -> sRGB byte
    ~State() {
        for (auto& ms : meshScenes) rtcReleaseScene(ms.second);
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

MinimalEmbree::MinimalEmbree() = default;
MinimalEmbree::~MinimalEmbree() = default;
size_t MinimalEmbree::triangles() const {
    size_t n = 0;
    for (const State::Geom& g : m->geoms) n += g.idx.size() / 3;
    return n;
}

std::string MinimalEmbree::setup(const FrameInput& f, int tessellation, const std::string& config, bool instanced, bool nearestTextures) {
    m = std::make_unique<State>();
    m->instanced = instanced;
    m->nearest = nearestTextures;
    for (int i = 0; i < 256; ++i) m->decode[i] = rnd::decodeSRGB(float(i) / 255.0f);
    for (int i = 0; i <= 4096; ++i) m->encode[i] = uint8_t(rnd::encodeSRGB(float(i) / 4096.0f) * 255.0f + 0.5f);
    m->device = rtcNewDevice(config.c_str());
    if (!m->device) return "rtcNewDevice failed";
    m->scene = rtcNewScene(m->device);
    for (const rnd::PreparedDraw& d : rnd::prepareDraws(f, tessellation, m->tess)) {
        const Mesh& mesh = *d.mesh;
        if (mesh.mode != PrimitiveMode::Triangles || mesh.indices.empty()) continue;
        State::Geom g;
        for (const vec3& p : mesh.positions) g.p.push_back(vec3(*d.world * vec4(p, 1.0f)));
        if (mesh.normals.size() == mesh.positions.size())
            for (const vec3& n : mesh.normals) {   // world, unit
                const vec3 w = d.normal * n;
                const float l = glm::length(w);
                g.n.push_back(l > 1e-20f ? w / l : vec3(0.0f));
            }
        if (d.texture && mesh.uv0.size() == mesh.positions.size() && (g.sampler = m->samplers.get(d.texture))) {   // (null: an unusable texture)
            g.uv = mesh.uv0;
            g.tex = d.texture.get();
        }
        g.idx = mesh.indices;
        if (d.mirrored)   // front faces counter-clockwise in world space for every draw
            for (size_t t = 0; t < g.idx.size(); t += 3) std::swap(g.idx[t + 1], g.idx[t + 2]);
        g.mat = d.material;
        g.triMat = d.triangleMaterial;
        g.mats = d.materials;
        auto triangles = [&](const std::vector<vec3>& p, const std::vector<uint32_t>& idx) {
            RTCGeometry eg = rtcNewGeometry(m->device, RTC_GEOMETRY_TYPE_TRIANGLE);
            std::memcpy(rtcSetNewGeometryBuffer(eg, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, p.size()), p.data(), p.size() * 12);
            std::memcpy(rtcSetNewGeometryBuffer(eg, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, idx.size() / 3), idx.data(), idx.size() * 4);
            rtcCommitGeometry(eg);
            return eg;
        };
        RTCGeometry eg;
        if (instanced) {   // the mesh's own scene (made once per mesh), placed by the draw's world matrix
            RTCScene& ms = m->meshScenes[&mesh];
            if (!ms) {
                ms = rtcNewScene(m->device);
                RTCGeometry mg = triangles(mesh.positions, mesh.indices);
                rtcAttachGeometryByID(ms, mg, 0);
                rtcReleaseGeometry(mg);
                rtcCommitScene(ms);
            }
            eg = rtcNewGeometry(m->device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(eg, ms);
            rtcSetGeometryTransform(eg, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &(*d.world)[0][0]);
            rtcCommitGeometry(eg);
        } else {
            eg = triangles(g.p, g.idx);
        }
        rtcAttachGeometryByID(m->scene, eg, unsigned(m->geoms.size()));
        rtcReleaseGeometry(eg);
        m->geoms.push_back(std::move(g));
    }
    rtcCommitScene(m->scene);
    return rtcGetDeviceError(m->device) == RTC_ERROR_NONE ? "" : "Embree error during setup";
}

namespace {

// uv where the camera ray through window position (wx, wy) meets the plane of a triangle: a
// neighbouring pixel's uv, for the footprint (the rays as render() makes them).
bool uvOnPlane(const vec3& o0, const vec3& ox, const vec3& oy, const vec3& f0, const vec3& fx, const vec3& fy, float wx, float wy,
               const rnd::TrianglePlaneUv& plane, vec2& out) {
    const vec3 o = o0 + wx * ox + wy * oy, d = f0 + wx * fx + wy * fy - o;
    return plane.at(o, d, out);
}

}   // namespace

void MinimalEmbree::render(const FrameInput& f, int W, int H, std::vector<uint8_t>& rgba) const {
    rgba.resize(size_t(W) * H * 4);
    // Camera rays as rnd::rt::CameraRays makes them (near-plane point to far-plane point, t in
    // [0, 1]); both points are affine in the window position, so three of each give them all.
    const glm::dmat4 inv = glm::inverse(glm::dmat4(f.camera.proj) * glm::dmat4(f.camera.view));
    auto at = [&](double x, double y, double z) {
        const glm::dvec4 a = inv * glm::dvec4(2.0 * x / W - 1.0, 2.0 * y / H - 1.0, z, 1.0);
        return glm::dvec3(a) / a.w;
    };
    const vec3 o0(at(0, 0, -1)), ox(at(1, 0, -1) - at(0, 0, -1)), oy(at(0, 1, -1) - at(0, 0, -1));
    const vec3 f0(at(0, 0, 1)), fx(at(1, 0, 1) - at(0, 0, 1)), fy(at(0, 1, 1) - at(0, 0, 1));
    const vec3 eye = f.camera.eye;
    const RenderSettings& st = f.settings;
    const vec3 bg = glm::clamp(st.background, 0.0f, 1.0f);
    constexpr int kTile = 16;
    const int tilesX = (W + kTile - 1) / kTile, tilesY = (H + kTile - 1) / kTile;
    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 1), [&](const tbb::blocked_range<int>& r) {
        const unsigned csr = _mm_getcsr();
        _mm_setcsr(csr | 0x8040);   // FTZ | DAZ, as our ray caster
        for (int tile = r.begin(); tile < r.end(); ++tile) {
            const int x0 = tile % tilesX * kTile, y0 = tile / tilesX * kTile, x1 = std::min(x0 + kTile, W), y1 = std::min(y0 + kTile, H);
            for (int py = y0; py < y1; py += 4)
                for (int px = x0; px < x1; px += 4) {
                    RTCIntersectContext ctx;
                    rtcInitIntersectContext(&ctx);
                    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
                    alignas(64) int valid[16];
                    RTCRayHit16 rh;
                    for (int i = 0; i < 16; ++i) {
                        const int x = px + (i & 3), row = py + (i >> 2);
                        valid[i] = x < x1 && row < y1 ? -1 : 0;
                        const float wx = float(x) + 0.5f, wy = float(H - 1 - row) + 0.5f;
                        const vec3 o = o0 + wx * ox + wy * oy, d = f0 + wx * fx + wy * fy - o;
                        rh.ray.org_x[i] = o.x, rh.ray.org_y[i] = o.y, rh.ray.org_z[i] = o.z;
                        rh.ray.dir_x[i] = d.x, rh.ray.dir_y[i] = d.y, rh.ray.dir_z[i] = d.z;
                        rh.ray.tnear[i] = 0.0f, rh.ray.tfar[i] = 1.0f, rh.ray.mask[i] = ~0u, rh.ray.flags[i] = 0, rh.ray.time[i] = 0;
                        rh.hit.geomID[i] = rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
                    }
                    rtcIntersect16(valid, m->scene, &ctx, &rh);
                    // Per lane: position, shading normal, geometric normal (both toward the ray), material, albedo.
                    vec3 P[16], N[16], G[16], albedo[16], mul[16], add[16];
                    const Material* mat[16];
                    bool hit[16];
                    for (int i = 0; i < 16; ++i) {
                        hit[i] = valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
                        if (!hit[i]) continue;
                        const State::Geom& g = m->geoms[m->instanced ? rh.hit.instID[0][i] : rh.hit.geomID[i]];
                        const uint32_t t = rh.hit.primID[i], i0 = g.idx[3 * t], i1 = g.idx[3 * t + 1], i2 = g.idx[3 * t + 2];
                        const float u = rh.hit.u[i], v = rh.hit.v[i], w = 1.0f - u - v;
                        P[i] = w * g.p[i0] + u * g.p[i1] + v * g.p[i2];
                        vec3 gn = glm::cross(g.p[i1] - g.p[i0], g.p[i2] - g.p[i0]);
                        const float gl = glm::length(gn);
                        gn = gl > 0.0f ? gn / gl : vec3(0, 1, 0);   // degenerate (a tessellated pole): as ours
                        const bool back = rh.ray.dir_x[i] * gn.x + rh.ray.dir_y[i] * gn.y + rh.ray.dir_z[i] * gn.z > 0.0f;
                        G[i] = back ? -gn : gn;
                        N[i] = G[i];
                        if (!g.n.empty()) {   // two-sided: the normals flip with the face
                            const vec3 n = w * g.n[i0] + u * g.n[i1] + v * g.n[i2];
                            N[i] = glm::normalize(back ? -n : n);
                        }
                        mat[i] = g.triMat ? &(*g.mats)[(*g.triMat)[t]] : g.mat;
                        albedo[i] = mat[i]->baseColor;
                        if (g.tex && !m->nearest) {   // filtered as ours: the uv footprint of the neighbouring pixels' rays
                            const vec2 uv = w * g.uv[i0] + u * g.uv[i1] + v * g.uv[i2];
                            const float wx = float(px + (i & 3)) + 0.5f, wy = float(H - 1 - (py + (i >> 2))) + 0.5f;
                            vec2 uvX, uvY;
                            const vec3 tri[3] = {g.p[i0], g.p[i1], g.p[i2]};
                            const vec2 triUv[3] = {g.uv[i0], g.uv[i1], g.uv[i2]};
                            const rnd::TrianglePlaneUv plane(tri, triUv);
                            const bool footprint = uvOnPlane(o0, ox, oy, f0, fx, fy, wx + 1.0f, wy, plane, uvX) &&
                                                   uvOnPlane(o0, ox, oy, f0, fx, fy, wx, wy + 1.0f, plane, uvY);
                            albedo[i] *= footprint ? g.sampler->sample(uv, uvX - uv, uvY - uv)
                                                   : g.sampler->sampleLevel(uv, 0, g.sampler->filter() != FilterMode::Nearest);
                        } else if (g.tex) {   // level 0, nearest, repeat; file row r is GL row h - 1 - r
                            const vec2 uv = w * g.uv[i0] + u * g.uv[i1] + v * g.uv[i2];
                            const int tw = g.tex->width, th = g.tex->height;
                            const int tx = ((int(std::floor(uv.x * tw)) % tw) + tw) % tw, ty = ((int(std::floor(uv.y * th)) % th) + th) % th;
                            const uint8_t* c = &g.tex->rgba[(size_t(th - 1 - ty) * tw + tx) * 4];
                            albedo[i] *= g.tex->srgb ? vec3(m->decode[c[0]], m->decode[c[1]], m->decode[c[2]]) : vec3(c[0], c[1], c[2]) / 255.0f;
                        }
                        mul[i] = mat[i]->unlit ? vec3(1.0f) : mat[i]->ka * f.ambientLight;
                        add[i] = mat[i]->emissive;
                    }
                    for (const DrawLight& L : f.lights) {
                        // The light at each lit lane (the terms of renderers/common/shading.cpp), its shadow rays as one packet.
                        vec3 toL[16], rad[16];
                        alignas(64) int shadowValid[16];
                        RTCRay16 sr;
                        for (int i = 0; i < 16; ++i) {
                            shadowValid[i] = 0;
                            sr.org_x[i] = sr.org_y[i] = sr.org_z[i] = sr.dir_x[i] = sr.dir_y[i] = sr.dir_z[i] = 0.0f;
                            sr.tnear[i] = 0.0f, sr.tfar[i] = -1.0f, sr.mask[i] = ~0u, sr.flags[i] = 0, sr.time[i] = 0;   // inactive lane
                            if (!hit[i] || mat[i]->unlit) continue;
                            float dist = INFINITY;
                            toL[i] = -L.direction;
                            rad[i] = L.radiance;
                            if (L.type != LightType::Directional) {
                                const vec3 d = L.position - P[i];
                                dist = glm::length(d);
                                toL[i] = dist > 0 ? d / dist : vec3(0, 1, 0);
                                if (L.inverseSquare) rad[i] /= std::max(dist * dist, 1e-8f);
                                if (L.type == LightType::Spot) {
                                    const float c = glm::dot(-toL[i], L.direction);
                                    const float s = std::clamp(L.cosInner > L.cosOuter ? (c - L.cosOuter) / (L.cosInner - L.cosOuter)
                                                               : c >= L.cosOuter       ? 1.0f
                                                                                       : 0.0f,
                                                               0.0f, 1.0f);
                                    rad[i] *= s * s * (3.0f - 2.0f * s);
                                }
                            }
                            if (!(glm::dot(N[i], toL[i]) > 0.0f) || rad[i] == vec3(0.0f)) continue;
                            const vec3& p = P[i];
                            const float eps = 1e-4f * (1.0f + std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))));
                            const vec3 o = p + (glm::dot(G[i], toL[i]) >= 0.0f ? eps : -eps) * G[i];
                            const float tmax = std::isfinite(dist) ? dist * (1.0f - 1e-4f) - eps : INFINITY;
                            if (!st.shadows) {
                                shadowValid[i] = 1;   // lit, no ray
                                continue;
                            }
                            shadowValid[i] = tmax > 0.0f ? -1 : 1;
                            sr.org_x[i] = o.x, sr.org_y[i] = o.y, sr.org_z[i] = o.z;
                            sr.dir_x[i] = toL[i].x, sr.dir_y[i] = toL[i].y, sr.dir_z[i] = toL[i].z;
                            sr.tnear[i] = 0.0f, sr.tfar[i] = tmax, sr.mask[i] = ~0u, sr.flags[i] = 0, sr.time[i] = 0;
                        }
                        alignas(64) int traced[16];
                        bool any = false;
                        for (int i = 0; i < 16; ++i) any |= (traced[i] = shadowValid[i] == -1 ? -1 : 0) != 0;
                        if (any) rtcOccluded16(traced, m->scene, &ctx, &sr);
                        for (int i = 0; i < 16; ++i) {
                            if (!shadowValid[i] || (traced[i] && sr.tfar[i] < 0.0f)) continue;
                            const vec3 v = glm::normalize(eye - P[i]), &n = N[i], &l = toL[i];
                            const float nl = glm::dot(n, l);
                            float spec;
                            if (st.reflection == ReflectionModel::BlinnPhong) {
                                const vec3 h = l + v;
                                const float len = glm::length(h);
                                spec = len > 0 ? std::max(glm::dot(n, h / len), 0.0f) : 0.0f;
                            } else {
                                spec = std::max(glm::dot(2.0f * nl * n - l, v), 0.0f);
                            }
                            spec = spec > 0.0f ? std::pow(spec, mat[i]->shininess) : 0.0f;
                            const vec3 ln = rad[i] * nl;
                            mul[i] += ln * mat[i]->kd;
                            if (mat[i]->specularTinted)
                                mul[i] += ln * (mat[i]->ks * spec);
                            else
                                add[i] += ln * (mat[i]->ks * spec) * mat[i]->specularColor;
                        }
                    }
                    for (int i = 0; i < 16; ++i) {
                        if (!valid[i]) continue;
                        vec3 c = bg;
                        if (hit[i]) {
                            c = albedo[i] * mul[i] + add[i];
                            const float fv = fogVisibility(st, glm::length(P[i] - eye));
                            c = glm::clamp(fv * c + (1.0f - fv) * st.fogColor, 0.0f, 1.0f);
                        }
                        uint8_t* out = &rgba[(size_t(py + (i >> 2)) * W + size_t(px + (i & 3))) * 4];
                        for (int k = 0; k < 3; ++k) out[k] = m->encode[int(c[k] * 4096.0f + 0.5f)];
                        out[3] = 255;
                    }
                }
        }
        _mm_setcsr(csr);
    });
}

}   // namespace bench
