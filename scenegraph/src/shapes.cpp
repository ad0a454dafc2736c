// shapes.cpp - evaluation of the analytic shapes of shapes.h: bounds, implicit value (negative
// inside) and normal of plane, sphere, box, cylinder, cone, torus and bounded quadric; point
// and partial derivatives of the parametric torus and bicubic Bezier patch (and the default
// patch); trilinear sampling and gradient of density grids (and the metaballs grid); the enums'
// names.
#include "scenegraph/shapes.h"
#include "scenegraph/setting_names.h"

namespace sg {

namespace {
float boxValue(const vec3& p, const vec3& h) {
    vec3 q = glm::abs(p) - h;
    return glm::length(glm::max(q, vec3(0.0f))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
}
vec3 boxNormal(const vec3& p, const vec3& h) {
    // Face whose slab is closest to being violated (largest |p_i| / h_i).
    vec3 q = glm::abs(p) / glm::max(h, vec3(1e-30f));
    int axis = q.x > q.y ? (q.x > q.z ? 0 : 2) : (q.y > q.z ? 1 : 2);
    vec3 n(0.0f);
    n[axis] = p[axis] >= 0 ? 1.0f : -1.0f;
    return n;
}
vec3 safeNormalize(const vec3& v, const vec3& fallback = vec3(0, 1, 0)) {
    float l = glm::length(v);
    return l > 1e-30f && std::isfinite(l) ? v / l : fallback;
}
float coneRadiusAt(const ImplicitShape& s, float y) { return s.radius * (s.halfHeight - y) / (2.0f * s.halfHeight); }
}   // namespace

Aabb ImplicitShape::localBounds() const {
    switch (type) {
    case ImplicitType::Plane: return {vec3(-planeHalfSize, -1e-4f, -planeHalfSize), vec3(planeHalfSize, 1e-4f, planeHalfSize)};
    case ImplicitType::Sphere: return {vec3(-radius), vec3(radius)};
    case ImplicitType::Box: return {-halfExtents, halfExtents};
    case ImplicitType::Cylinder:
    case ImplicitType::Cone: return {vec3(-radius, -halfHeight, -radius), vec3(radius, halfHeight, radius)};
    case ImplicitType::Torus: {
        float e = majorRadius + minorRadius;
        return {vec3(-e, -minorRadius, -e), vec3(e, minorRadius, e)};
    }
    case ImplicitType::Quadric: return quadricBounds;
    }
    return {};
}

float ImplicitShape::value(const vec3& p) const {
    switch (type) {
    case ImplicitType::Plane: return p.y;
    case ImplicitType::Sphere: return glm::length(p) - radius;
    case ImplicitType::Box: return boxValue(p, halfExtents);
    case ImplicitType::Cylinder: {
        float rr = std::sqrt(p.x * p.x + p.z * p.z);
        return std::max(rr - radius, std::abs(p.y) - halfHeight);
    }
    case ImplicitType::Cone: {
        float rr = std::sqrt(p.x * p.x + p.z * p.z);
        float h = 2.0f * halfHeight;
        float c = h / std::sqrt(h * h + radius * radius);   // cos of the half angle
        return std::max((rr - coneRadiusAt(*this, p.y)) * c, std::abs(p.y) - halfHeight);
    }
    case ImplicitType::Torus: {
        float q = std::sqrt(p.x * p.x + p.z * p.z) - majorRadius;
        return std::sqrt(q * q + p.y * p.y) - minorRadius;
    }
    case ImplicitType::Quadric: {
        vec4 x(p, 1.0f);
        float q = glm::dot(x, quadric * x);
        vec3 c = quadricBounds.center(), h = 0.5f * quadricBounds.extent();
        return std::max(q, boxValue(p - c, h));
    }
    }
    return 1.0f;
}

vec3 ImplicitShape::normal(const vec3& p) const {
    switch (type) {
    case ImplicitType::Plane: return vec3(0, 1, 0);
    case ImplicitType::Sphere: return safeNormalize(p);
    case ImplicitType::Box: return boxNormal(p, halfExtents);
    case ImplicitType::Cylinder: {
        float rr = std::sqrt(p.x * p.x + p.z * p.z);
        if (std::abs(p.y) - halfHeight > rr - radius) return vec3(0, p.y >= 0 ? 1.0f : -1.0f, 0);
        return safeNormalize(vec3(p.x, 0, p.z));
    }
    case ImplicitType::Cone: {
        float rr = std::sqrt(p.x * p.x + p.z * p.z);
        float h = 2.0f * halfHeight;
        float c = h / std::sqrt(h * h + radius * radius);
        if (-halfHeight - p.y > (rr - coneRadiusAt(*this, p.y)) * c) return vec3(0, -1, 0);
        vec3 radial = rr > 1e-30f ? vec3(p.x, 0, p.z) / rr : vec3(1, 0, 0);
        return safeNormalize(radial + vec3(0, radius / h, 0));
    }
    case ImplicitType::Torus: {
        vec3 radial = safeNormalize(vec3(p.x, 0, p.z), vec3(1, 0, 0));
        return safeNormalize(p - majorRadius * radial);
    }
    case ImplicitType::Quadric: {
        // Gradient of x^T Q x is (Q + Q^T) x; its xyz part is the normal direction.
        vec4 x(p, 1.0f);
        vec3 c = quadricBounds.center(), h = 0.5f * quadricBounds.extent();
        vec4 q = quadric * x;
        if (boxValue(p - c, h) > glm::dot(x, q)) return boxNormal(p - c, h);
        vec4 g = (quadric + glm::transpose(quadric)) * x;
        return safeNormalize(vec3(g));
    }
    }
    return vec3(0, 1, 0);
}

// --- parametric ---------------------------------------------------------------------------

vec3 ParametricSurface::evaluate(float u, float v) const {
    if (type == ParametricType::Torus) {
        float a = 2 * kPi * u, b = 2 * kPi * v;
        vec3 dir(std::sin(a), 0, std::cos(a));
        return majorRadius * dir + minorRadius * (std::cos(b) * dir + vec3(0, std::sin(b), 0));
    }
    float bu[4], dbu[4], bv[4], dbv[4];
    cubicBernstein(u, bu, dbu);
    cubicBernstein(v, bv, dbv);
    vec3 p(0.0f);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) p += bu[i] * bv[j] * control[j * 4 + i];
    return p;
}

void ParametricSurface::partials(float u, float v, vec3& dPdu, vec3& dPdv) const {
    if (type == ParametricType::Torus) {
        float a = 2 * kPi * u, b = 2 * kPi * v;
        vec3 dir(std::sin(a), 0, std::cos(a)), ddir(std::cos(a), 0, -std::sin(a));
        dPdu = 2 * kPi * (majorRadius + minorRadius * std::cos(b)) * ddir;
        dPdv = 2 * kPi * minorRadius * (-std::sin(b) * dir + vec3(0, std::cos(b), 0));
        return;
    }
    float bu[4], dbu[4], bv[4], dbv[4];
    cubicBernstein(u, bu, dbu);
    cubicBernstein(v, bv, dbv);
    dPdu = dPdv = vec3(0.0f);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            dPdu += dbu[i] * bv[j] * control[j * 4 + i];
            dPdv += bu[i] * dbv[j] * control[j * 4 + i];
        }
}

vec3 ParametricSurface::evaluate(float u, float v, vec3& dPdu, vec3& dPdv) const {
    if (type == ParametricType::Torus) {
        float a = 2 * kPi * u, b = 2 * kPi * v;
        float sa = std::sin(a), ca = std::cos(a), sb = std::sin(b), cb = std::cos(b);
        vec3 dir(sa, 0, ca), ddir(ca, 0, -sa);
        dPdu = 2 * kPi * (majorRadius + minorRadius * cb) * ddir;
        dPdv = 2 * kPi * minorRadius * (-sb * dir + vec3(0, cb, 0));
        return majorRadius * dir + minorRadius * (cb * dir + vec3(0, sb, 0));
    }
    float bu[4], dbu[4], bv[4], dbv[4];
    cubicBernstein(u, bu, dbu);
    cubicBernstein(v, bv, dbv);
    vec3 p(0.0f);
    dPdu = dPdv = vec3(0.0f);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            p += bu[i] * bv[j] * control[j * 4 + i];
            dPdu += dbu[i] * bv[j] * control[j * 4 + i];
            dPdv += bu[i] * dbv[j] * control[j * 4 + i];
        }
    return p;
}

vec3 ParametricSurface::normal(float u, float v) const {
    vec3 du, dv;
    partials(u, v, du, dv);
    vec3 n = glm::cross(du, dv);
    float l = glm::length(n);
    return l > 1e-30f ? n / l : vec3(0, 1, 0);
}

Aabb ParametricSurface::localBounds() const {
    Aabb b;
    if (type == ParametricType::Torus) {
        float e = majorRadius + minorRadius;
        return {vec3(-e, -minorRadius, -e), vec3(e, minorRadius, e)};
    }
    for (const vec3& c : control) b.extend(c);   // convex hull property of Bezier patches
    return b;
}

ParametricSurface ParametricSurface::defaultPatch() {
    ParametricSurface s;
    s.type = ParametricType::BezierPatch;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            float x = -1.0f + 2.0f * i / 3.0f, z = 1.0f - 2.0f * j / 3.0f;
            float y = (i == 1 || i == 2) && (j == 1 || j == 2) ? 0.8f : 0.0f;
            if (i == 0 && j == 3) y = 0.3f;
            s.control[j * 4 + i] = vec3(x, y, z);
        }
    return s;
}

// --- density grid -------------------------------------------------------------------------

float DensityGrid::sample(const vec3& p) const {
    if (dims.x < 2 || dims.y < 2 || dims.z < 2 || values.size() != size_t(dims.x) * dims.y * dims.z) return 0.0f;
    vec3 ext = bounds.extent();
    vec3 g = (p - bounds.min) / ext * vec3(dims - 1);
    g = glm::clamp(g, vec3(0.0f), vec3(dims - 1));
    ivec3 i0 = glm::min(ivec3(g), dims - 2);
    vec3 f = g - vec3(i0);
    float c[2][2][2];
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) c[dz][dy][dx] = at(i0.x + dx, i0.y + dy, i0.z + dz);
    float x00 = glm::mix(c[0][0][0], c[0][0][1], f.x), x10 = glm::mix(c[0][1][0], c[0][1][1], f.x);
    float x01 = glm::mix(c[1][0][0], c[1][0][1], f.x), x11 = glm::mix(c[1][1][0], c[1][1][1], f.x);
    return glm::mix(glm::mix(x00, x10, f.y), glm::mix(x01, x11, f.y), f.z);
}

vec3 DensityGrid::gradient(const vec3& p) const {
    vec3 cell = bounds.extent() / vec3(glm::max(dims - 1, ivec3(1)));
    vec3 g;
    for (int a = 0; a < 3; ++a) {
        vec3 d(0.0f);
        d[a] = 0.5f * cell[a];
        g[a] = (sample(p + d) - sample(p - d)) / cell[a];
    }
    return g;
}

DensityGrid DensityGrid::metaballs(int n) {
    DensityGrid g;
    n = std::clamp(n, 2, 256);
    g.dims = ivec3(n);
    g.bounds = {vec3(-1.0f), vec3(1.0f)};
    g.isoValue = 1.0f;
    g.values.resize(size_t(n) * n * n);
    const vec3 centers[3] = {{-0.35f, -0.1f, 0.0f}, {0.35f, 0.05f, 0.1f}, {0.0f, 0.35f, -0.15f}};
    const float radii[3] = {0.42f, 0.36f, 0.3f};
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                vec3 p = g.bounds.min + vec3(x, y, z) / float(n - 1) * g.bounds.extent();
                float v = 0;
                for (int k = 0; k < 3; ++k) {
                    vec3 d = p - centers[k];
                    v += radii[k] * radii[k] / std::max(glm::dot(d, d), 1e-6f);
                }
                g.values[(size_t(z) * n + y) * n + x] = v;
            }
    return g;
}

// --- names (the tables are in setting_names.cpp) ---------------------------------------------

std::string_view toString(ImplicitType t) { return nameOf(t); }
bool parse(std::string_view s, ImplicitType& out) { return parseName(s, out); }
std::string_view toString(CsgOp op) { return nameOf(op); }
bool parse(std::string_view s, CsgOp& out) { return parseName(s, out); }
std::string_view toString(ParametricType t) { return nameOf(t); }
bool parse(std::string_view s, ParametricType& out) { return parseName(s, out); }

}   // namespace sg
