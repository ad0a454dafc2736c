// inspect.cpp - surfaceAt(), pixelTerms(), normalImage() (see inspect.h).
#include "renderers/inspect.h"

#include "renderers/pbr.h"

#include "renderers/shading.h"
#include "renderers/texture_sampler.h"
#include "renderers/tone_map.h"
#include "scenegraph/camera_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rnd {

using sg::vec2;
using sg::vec3;
using sg::vec4;

namespace {

// The ray through the centre of pixel (x, y) (top-left origin): the points of the near and far
// planes it passes through, in world space.
struct PixelRay {
    glm::dvec3 origin, dir;
};
PixelRay pixelRay(const sg::FrameCamera& cam, int w, int h, int x, int y) {
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    const double nx = 2.0 * (x + 0.5) / w - 1.0, ny = 1.0 - 2.0 * (y + 0.5) / h;
    glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
    const glm::dvec3 pa = glm::dvec3(a) / a.w, pb = glm::dvec3(b) / b.w;
    return {pa, pb - pa};
}

// World position of the pixel's depth-buffer value (window z in [0, 1]).
vec3 unprojectDepth(const sg::FrameCamera& cam, int w, int h, int x, int y, float z) {
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    glm::dvec4 p = inv * glm::dvec4(2.0 * (x + 0.5) / w - 1.0, 1.0 - 2.0 * (y + 0.5) / h, 2.0 * z - 1.0, 1.0);
    return vec3(glm::dvec3(p) / p.w);
}

// Where the ray meets the plane of triangle (a, b, c): barycentric weights (may lie slightly
// outside [0, 1] at edges). False when the ray is parallel to the plane.
bool rayPlaneBary(const PixelRay& r, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, glm::dvec3& bary, glm::dvec3& p) {
    const glm::dvec3 e1 = b - a, e2 = c - a, n = glm::cross(e1, e2);
    const double denom = glm::dot(n, r.dir);
    const double area2 = glm::dot(n, n);
    if (std::fabs(denom) < 1e-300 || area2 <= 0) return false;
    const double t = glm::dot(n, a - r.origin) / denom;
    p = r.origin + t * r.dir;
    const glm::dvec3 q = p - a;
    const double b1 = glm::dot(glm::cross(q, e2), n) / area2, b2 = glm::dot(glm::cross(e1, q), n) / area2;
    bary = {1.0 - b1 - b2, b1, b2};
    return true;
}

// A normal from the depths around (x, y) (same drawable only): analytic shapes other than
// implicit primitives. 0 when no horizontal or no vertical neighbour is on the same surface.
vec3 normalFromDepth(const sg::FrameInput& f, const Framebuffer& fb, int x, int y) {
    auto at = [&](int i, int j, vec3& out) {
        if (i < 0 || j < 0 || i >= fb.width || j >= fb.height) return false;
        const size_t k = size_t(j) * fb.width + i;
        if (fb.drawable[k] != fb.drawable[size_t(y) * fb.width + x] || fb.depth[k] >= 1.0f) return false;
        out = unprojectDepth(f.camera, fb.width, fb.height, i, j, fb.depth[k]);
        return true;
    };
    vec3 c, px, py;
    if (!at(x, y, c)) return vec3(0.0f);
    vec3 dx(0.0f), dy(0.0f);
    if (at(x + 1, y, px))
        dx = px - c;
    else if (at(x - 1, y, px))
        dx = c - px;
    if (at(x, y + 1, py))
        dy = c - py;   // rows go down the image
    else if (at(x, y - 1, py))
        dy = py - c;
    vec3 n = glm::cross(dx, dy);
    const float len = glm::length(n);
    return len > 0 ? n / len : vec3(0.0f);
}

// uv where the ray through pixel (x, y) meets the plane of P (extrapolated past the triangle).
bool uvOnPlane(const sg::FrameCamera& cam, int w, int h, int x, int y, const glm::dvec3 P[3], const vec2 UV[3], vec2& uv) {
    glm::dvec3 b, p;
    if (!rayPlaneBary(pixelRay(cam, w, h, x, y), P[0], P[1], P[2], b, p)) return false;
    uv = float(b.x) * UV[0] + float(b.y) * UV[1] + float(b.z) * UV[2];
    return true;
}

void meshSurface(const sg::FrameInput& f, const sg::DrawMesh& dm, const PixelRay& ray, const Framebuffer& fb, int x, int y, SurfaceAt& s) {
    const sg::Mesh& m = *dm.mesh;
    const size_t k = size_t(y) * fb.width + x;
    s.position = unprojectDepth(f.camera, fb.width, fb.height, x, y, fb.depth[k]);
    if (m.mode != sg::PrimitiveMode::Triangles || size_t(s.primitive) * 3 + 2 >= m.indices.size()) return;   // points, lines
    const uint32_t i[3] = {m.indices[3 * size_t(s.primitive)], m.indices[3 * size_t(s.primitive) + 1], m.indices[3 * size_t(s.primitive) + 2]};
    if (i[0] >= m.positions.size() || i[1] >= m.positions.size() || i[2] >= m.positions.size()) return;
    glm::dvec3 P[3];
    for (int c = 0; c < 3; ++c) P[c] = glm::dvec3(dm.world * vec4(m.positions[i[c]], 1.0f));
    glm::dvec3 bary, p;
    if (!rayPlaneBary(ray, P[0], P[1], P[2], bary, p)) return;
    s.triangle = true;
    s.position = vec3(p);
    s.barycentric = vec3(bary);
    const vec3 w = s.barycentric;
    if (m.uv0.size() == m.positions.size()) {
        s.hasUv = true;
        const vec2 UV[3] = {m.uv0[i[0]], m.uv0[i[1]], m.uv0[i[2]]};
        s.uv = w.x * UV[0] + w.y * UV[1] + w.z * UV[2];
        vec2 ux, uy;
        if (uvOnPlane(f.camera, fb.width, fb.height, x + 1, y, P, UV, ux)) s.uvDx = ux - s.uv;
        if (uvOnPlane(f.camera, fb.width, fb.height, x, y + 1, P, UV, uy)) s.uvDy = uy - s.uv;
    }
    const vec3 ng = glm::normalize(dm.normal * glm::cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]));
    vec3 n = ng;
    if (f.settings.shading != sg::ShadingModel::Flat && m.normals.size() == m.positions.size()) {
        const vec3 ni = dm.normal * (w.x * m.normals[i[0]] + w.y * m.normals[i[1]] + w.z * m.normals[i[2]]);
        if (glm::length(ni) > 0) n = glm::normalize(ni);
    }
    const bool back = glm::dot(glm::dvec3(ng), ray.dir) > 0;   // seen from the back: the side facing the viewer
    if (back) n = -n;
    s.geometricNormal = back ? -ng : ng;
    if (!(glm::dot(n, n) > 0)) n = vec3(0.0f);
    s.normal = n;
}

// The CSG leaf whose surface passes nearest world point p: the smallest |f| / |grad f| (a
// first-order distance), the gradient by central differences.
int nearestCsgLeaf(const sg::CsgTree& tree, const vec3& p) {
    int best = -1;
    float bestDist = std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < tree.nodes.size(); ++i) {
        const sg::CsgTree::Node& leaf = tree.nodes[i];
        if (leaf.op != -1) continue;
        const vec3 q = vec3(leaf.invWorld * vec4(p, 1.0f));
        const float h = 1e-3f * (1.0f + glm::length(q));
        const vec3 g((leaf.shape.value(q + vec3(h, 0, 0)) - leaf.shape.value(q - vec3(h, 0, 0))) / (2 * h),
                     (leaf.shape.value(q + vec3(0, h, 0)) - leaf.shape.value(q - vec3(0, h, 0))) / (2 * h),
                     (leaf.shape.value(q + vec3(0, 0, h)) - leaf.shape.value(q - vec3(0, 0, h))) / (2 * h));
        const float d = std::fabs(leaf.shape.value(q)) / std::max(glm::length(g), 1e-12f);
        if (d < bestDist) {
            bestDist = d;
            best = int(i);
        }
    }
    return best;
}

void analyticSurface(const sg::FrameInput& f, const sg::DrawAnalytic& a, const PixelRay& ray, const Framebuffer& fb, int x, int y, SurfaceAt& s) {
    const size_t k = size_t(y) * fb.width + x;
    s.position = unprojectDepth(f.camera, fb.width, fb.height, x, y, fb.depth[k]);
    vec3 n(0.0f);
    if (a.kind == sg::DrawAnalytic::Kind::Implicit) {
        const vec3 local = vec3(a.invWorld * vec4(s.position, 1.0f));
        n = a.normal * a.implicit.normal(local);
    } else if (a.kind == sg::DrawAnalytic::Kind::Csg && a.csg) {
        s.csgLeaf = nearestCsgLeaf(*a.csg, s.position);
        if (s.csgLeaf >= 0) {
            const sg::CsgTree::Node& leaf = a.csg->nodes[size_t(s.csgLeaf)];
            n = leaf.normal * leaf.shape.normal(vec3(leaf.invWorld * vec4(s.position, 1.0f)));
        }
    }
    const float len = glm::length(n);
    n = len > 0 ? n / len : vec3(0.0f);
    if (!(glm::dot(n, n) > 0)) n = normalFromDepth(f, fb, x, y);
    if (!(glm::dot(n, n) > 0)) n = vec3(glm::normalize(-ray.dir));   // a lone pixel: facing the viewer
    if (glm::dot(glm::dvec3(n), ray.dir) > 0) n = -n;
    s.normal = s.geometricNormal = n;
}

}   // namespace

SurfaceAt surfaceAt(const sg::FrameInput& f, const sg::InstanceTable& ids, const Framebuffer& fb, int x, int y) {
    SurfaceAt s;
    if (!fb.has(Aov::Visibility) || x < 0 || y < 0 || x >= fb.width || y >= fb.height) return s;
    const size_t k = size_t(y) * fb.width + x;
    s.drawable = fb.drawable[k];
    s.primitive = fb.primitive[k];
    const size_t M = f.meshes.size();
    if (s.drawable == 0 || s.drawable > M + f.analytics.size()) return s;
    s.hit = true;
    s.instance = ids.instanceOf(s.drawable);
    s.node = ids.nodeOf(s.drawable);
    s.opticalDepth = sg::opticalDepth(f.camera, fb.width, fb.height, x, y, fb.depth[k]);
    const PixelRay ray = pixelRay(f.camera, fb.width, fb.height, x, y);
    if (s.drawable <= M) {
        const sg::DrawMesh& dm = f.meshes[s.drawable - 1];
        if (dm.mesh) meshSurface(f, dm, ray, fb, x, y, s);
    } else {
        s.analytic = true;
        analyticSurface(f, f.analytics[s.drawable - 1 - M], ray, fb, x, y, s);
    }
    s.eyeDistance = glm::length(vec3(f.camera.view * vec4(s.position, 1.0f)));
    return s;
}

PixelTerms pixelTerms(const sg::FrameInput& f, const SurfaceAt& s, const std::vector<float>& lightVisibility) {
    PixelTerms t;
    if (!s.hit) return t;
    const size_t M = f.meshes.size();
    const sg::Material* mat = nullptr;
    const sg::Mesh* mesh = nullptr;
    sg::TexturePtr tex;
    if (s.drawable <= M) {
        const sg::DrawMesh& dm = f.meshes[s.drawable - 1];
        mat = &dm.material;
        mesh = dm.mesh.get();
        tex = dm.texture;
    } else {
        const sg::DrawAnalytic& a = f.analytics[s.drawable - 1 - M];
        mat = &a.material;
        tex = a.texture;
        if (a.csg && s.csgLeaf >= 0 && size_t(s.csgLeaf) < a.csg->nodes.size()) {
            mat = &a.csg->nodes[size_t(s.csgLeaf)].material;
            tex = a.csg->nodes[size_t(s.csgLeaf)].texture;
        }
    }
    vec3 rho = mat->baseColor;
    // Where the model is evaluated: the point, or (flat shading) the triangle's first vertex,
    // with that vertex's albedo for pbr's F0 (as the backends do).
    vec3 at = s.position, rhoAt = mat->baseColor;
    if (f.settings.shading == sg::ShadingModel::Flat && s.triangle && mesh && s.drawable <= M) {
        const uint32_t i0 = mesh->indices[3 * size_t(s.primitive)];
        at = vec3(f.meshes[s.drawable - 1].world * sg::vec4(mesh->positions[i0], 1.0f));
        if (mesh->colors.size() == mesh->positions.size()) rhoAt *= vec3(mesh->colors[i0]);
    } else if (s.triangle && mesh && mesh->colors.size() == mesh->positions.size()) {
        const uint32_t* i = &mesh->indices[3 * size_t(s.primitive)];
        const vec3& w = s.barycentric;
        rhoAt *= w.x * vec3(mesh->colors[i[0]]) + w.y * vec3(mesh->colors[i[1]]) + w.z * vec3(mesh->colors[i[2]]);
    }
    if (s.triangle && mesh && mesh->colors.size() == mesh->positions.size()) {
        const uint32_t* i = &mesh->indices[3 * size_t(s.primitive)];
        const vec3& w = s.barycentric;
        rho *= w.x * vec3(mesh->colors[i[0]]) + w.y * vec3(mesh->colors[i[1]]) + w.z * vec3(mesh->colors[i[2]]);
    }
    if (tex && s.hasUv) rho *= SampledTexture(*tex).sample(s.uv, s.uvDx, s.uvDy);
    t.albedo = rho;
    if (f.settings.shading != sg::ShadingModel::Flat) rhoAt = rho;
    const SurfaceCoefficients c = coefficientsOf(*mat);
    t.emissive = c.emissive;
    t.lit = !c.unlit && glm::dot(s.normal, s.normal) > 0;
    if (!t.lit) {
        t.beforeFog = rho + c.emissive;
    } else if (f.settings.reflection == sg::ReflectionModel::Pbr) {
        // pbr: "ambient" is the environment's share; each light's diffuse is its rho-linear term.
        vec3 v = f.camera.eye - at;
        v = glm::length(v) > 0 ? glm::normalize(v) : vec3(0, 0, 1);
        const PbrPoint pt = pbrPoint(c, rhoAt);
        const EnvironmentLight env = environmentFor(f.settings);
        t.ambient = pbrEnvironmentTerms(pt, s.normal, v, env, c.occlusion).apply(rho);
        t.beforeFog = t.ambient + t.emissive;
        for (size_t i = 0; i < f.lights.size(); ++i) {
            const LightSample ls = samplePunctualLight(f.lights[i], at);
            LightPart part;
            part.radiance = ls.radiance;
            part.visibility = i < lightVisibility.size() ? lightVisibility[i] : 1.0f;
            part.nDotL = std::max(glm::dot(s.normal, ls.toLight), 0.0f);
            const ShadeTerms lt = pbrLightTerms(pt, s.normal, v, ls);
            part.diffuse = part.visibility * lt.mul * rho;
            part.specular = part.visibility * lt.add;
            t.beforeFog += part.diffuse + part.specular;
            t.lights.push_back(part);
        }
    } else {
        t.ambient = c.ka * rho * f.ambientLight;
        vec3 v = f.camera.eye - at;
        v = glm::length(v) > 0 ? glm::normalize(v) : vec3(0, 0, 1);
        t.beforeFog = t.ambient + t.emissive;
        for (size_t i = 0; i < f.lights.size(); ++i) {
            const LightSample ls = sampleLight(f.lights[i], at);
            LightPart part;
            part.radiance = ls.radiance;
            part.visibility = i < lightVisibility.size() ? lightVisibility[i] : 1.0f;
            part.nDotL = std::max(glm::dot(s.normal, ls.toLight), 0.0f);
            const ShadeTerms lt = lightTerms(c, s.normal, v, ls, f.settings.reflection);
            part.diffuse = part.visibility * ls.radiance * part.nDotL * c.kd * rho;
            part.specular = part.visibility * lt.apply(rho) - part.diffuse;
            t.beforeFog += part.diffuse + part.specular;
            t.lights.push_back(part);
        }
    }
    if (f.settings.fog != sg::FogMode::Off) t.fogVisibility = sg::fogVisibility(f.settings, s.eyeDistance);
    const vec3 fogged = t.fogVisibility * t.beforeFog + (1.0f - t.fogVisibility) * f.settings.fogColor;
    t.predicted = glm::clamp(DisplayTransform(f.settings)(fogged), vec3(0.0f), vec3(1.0f));
    return t;
}

std::vector<vec3> normalImage(const sg::FrameInput& f, const sg::InstanceTable& ids, const Framebuffer& fb) {
    std::vector<vec3> out(size_t(fb.width) * fb.height, vec3(0.0f));
    if (!fb.has(Aov::Visibility)) return out;
    for (int y = 0; y < fb.height; ++y)
        for (int x = 0; x < fb.width; ++x)
            if (fb.drawable[size_t(y) * fb.width + x]) out[size_t(y) * fb.width + x] = surfaceAt(f, ids, fb, x, y).normal;
    return out;
}

}   // namespace rnd
