// transforms.cpp - the 4x4 matrices of docs/math.md written entry by entry (row, column as
// printed there): translation, rotations, scaling, mirrors, shear, lookAt, perspective,
// frustum, orthographic, oblique (orthographic times a shear) and the viewport transform.
#include "scenegraph/transforms.h"

namespace sg {

namespace {
// Sets the entry (row r, column c) as written in docs/math.md; GLM is column-major: m[c][r].
inline void set(mat4& m, int r, int c, float v) { m[c][r] = v; }
}   // namespace

mat4 translation(const vec3& t) {
    mat4 m(1.0f);
    set(m, 0, 3, t.x);
    set(m, 1, 3, t.y);
    set(m, 2, 3, t.z);
    return m;
}

mat4 rotationX(float phi) {
    mat4 m(1.0f);
    float c = std::cos(phi), s = std::sin(phi);
    set(m, 1, 1, c);
    set(m, 1, 2, -s);
    set(m, 2, 1, s);
    set(m, 2, 2, c);
    return m;
}

mat4 rotationY(float phi) {
    mat4 m(1.0f);
    float c = std::cos(phi), s = std::sin(phi);
    set(m, 0, 0, c);
    set(m, 0, 2, s);
    set(m, 2, 0, -s);
    set(m, 2, 2, c);
    return m;
}

mat4 rotationZ(float phi) {
    mat4 m(1.0f);
    float c = std::cos(phi), s = std::sin(phi);
    set(m, 0, 0, c);
    set(m, 0, 1, -s);
    set(m, 1, 0, s);
    set(m, 1, 1, c);
    return m;
}

mat4 scaling(const vec3& s) {
    mat4 m(1.0f);
    set(m, 0, 0, s.x);
    set(m, 1, 1, s.y);
    set(m, 2, 2, s.z);
    return m;
}

mat4 mirrorX() { return scaling(vec3(-1, 1, 1)); }
mat4 mirrorY() { return scaling(vec3(1, -1, 1)); }
mat4 mirrorZ() { return scaling(vec3(1, 1, -1)); }

mat4 shear(int a, int b, float s) {
    mat4 m(1.0f);
    if (a >= 0 && a < 3 && b >= 0 && b < 3 && a != b) set(m, a, b, s);
    return m;
}

mat4 lookAt(const vec3& eye, const vec3& center, const vec3& up) {
    // Camera basis in world coordinates (docs/math.md, lookAt): z^c points back from the target.
    vec3 zc = glm::normalize(eye - center);
    vec3 xc = glm::cross(up, zc);
    float len = glm::length(xc);
    if (len < 1e-6f) {   // up parallel to the view direction: pick any perpendicular
        xc = glm::cross(std::abs(zc.y) < 0.9f ? vec3(0, 1, 0) : vec3(1, 0, 0), zc);
        len = glm::length(xc);
    }
    xc /= len;
    vec3 yc = glm::cross(zc, xc);
    // The camera-to-world matrix has columns (x^c, y^c, z^c, eye); its inverse is the view
    // transform: rotation rows = basis vectors, translation = -R * eye.
    mat4 m(1.0f);
    for (int c = 0; c < 3; ++c) {
        set(m, 0, c, xc[c]);
        set(m, 1, c, yc[c]);
        set(m, 2, c, zc[c]);
    }
    set(m, 0, 3, -glm::dot(xc, eye));
    set(m, 1, 3, -glm::dot(yc, eye));
    set(m, 2, 3, -glm::dot(zc, eye));
    return m;
}

mat4 perspective(float fovy, float aspect, float n, float f) {
    // f = cot(fovy/2); docs/math.md: diag(f/aspect, f, (f+n)/(n-f)) with -1 in the last row.
    float ct = 1.0f / std::tan(0.5f * fovy);
    mat4 m(0.0f);
    set(m, 0, 0, ct / aspect);
    set(m, 1, 1, ct);
    set(m, 2, 2, -(f + n) / (f - n));
    set(m, 2, 3, -2.0f * f * n / (f - n));
    set(m, 3, 2, -1.0f);
    return m;
}

mat4 frustum(float l, float r, float b, float t, float n, float f) {
    mat4 m(0.0f);
    set(m, 0, 0, 2.0f * n / (r - l));
    set(m, 0, 2, (r + l) / (r - l));
    set(m, 1, 1, 2.0f * n / (t - b));
    set(m, 1, 2, (t + b) / (t - b));
    set(m, 2, 2, -(f + n) / (f - n));
    set(m, 2, 3, -2.0f * f * n / (f - n));
    set(m, 3, 2, -1.0f);
    return m;
}

mat4 orthographic(float l, float r, float b, float t, float n, float f) {
    mat4 m(1.0f);
    set(m, 0, 0, 2.0f / (r - l));
    set(m, 0, 3, -(r + l) / (r - l));
    set(m, 1, 1, 2.0f / (t - b));
    set(m, 1, 3, -(t + b) / (t - b));
    set(m, 2, 2, -2.0f / (f - n));
    set(m, 2, 3, -(f + n) / (f - n));
    return m;
}

mat4 obliqueShear(float angle, float factor, float zRef) {
    // A point at depth d = zRef - z behind the reference plane moves by factor*d along
    // (cos angle, sin angle): x' = x + k_x (zRef - z), y' = y + k_y (zRef - z).
    float kx = factor * std::cos(angle), ky = factor * std::sin(angle);
    mat4 m(1.0f);
    set(m, 0, 2, -kx);
    set(m, 0, 3, kx * zRef);
    set(m, 1, 2, -ky);
    set(m, 1, 3, ky * zRef);
    return m;
}

mat4 oblique(float l, float r, float b, float t, float n, float f, float angle, float factor, float zRef) {
    return orthographic(l, r, b, t, n, f) * obliqueShear(angle, factor, zRef);
}

mat4 viewport(float x0, float y0, float w, float h) {
    // docs/math.md: x_w = (x_n + 1) w/2 + x0, y_w = (y_n + 1) h/2 + y0, z_w = (z_n + 1)/2.
    mat4 m(1.0f);
    set(m, 0, 0, 0.5f * w);
    set(m, 0, 3, x0 + 0.5f * w);
    set(m, 1, 1, 0.5f * h);
    set(m, 1, 3, y0 + 0.5f * h);
    set(m, 2, 2, 0.5f);
    set(m, 2, 3, 0.5f);
    return m;
}

}   // namespace sg
