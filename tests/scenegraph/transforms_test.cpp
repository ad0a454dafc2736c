// transforms_test.cpp - the matrices of docs/math.md element by element, against GLM
// where GLM has an equivalent, and known points landing where docs/math.md says: frustum corners
// on the NDC cube, near -> z_ndc = -1, far -> +1, viewport corners, oblique shifts.
// docs/math.md writes entries as (row r, column c); GLM stores m[c][r].
#include "scenegraph/transforms.h"
#include "scenegraph/projection.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

using namespace sg;

namespace {

// Entry (row r, column c) as written in docs/math.md.
float at(const mat4& m, int r, int c) { return m[c][r]; }

::testing::AssertionResult matNear(const mat4& a, const mat4& b, float eps = 1e-5f) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (std::abs(a[c][r] - b[c][r]) > eps * (1.0f + std::abs(b[c][r])))
                return ::testing::AssertionFailure() << "entry (row " << r << ", col " << c << "): " << a[c][r] << " vs " << b[c][r];
    return ::testing::AssertionSuccess();
}

// Matrices written row by row, as printed in docs/math.md.
mat4 rows(std::initializer_list<float> v) {
    mat4 m(0.0f);
    int i = 0;
    for (float x : v) {
        m[i % 4][i / 4] = x;
        ++i;
    }
    return m;
}

vec3 project(const mat4& m, const vec3& p) {
    vec4 c = m * vec4(p, 1.0f);
    return vec3(c) / c.w;
}

::testing::AssertionResult vecNear(const vec3& a, const vec3& b, float eps = 1e-4f) {
    if (glm::length(a - b) <= eps) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << ") vs (" << b.x << ", " << b.y << ", " << b.z << ")";
}

}   // namespace

TEST(TransformsTest, TranslationAndScaleEntries) {
    mat4 t = translation(vec3(2, -3, 4));
    EXPECT_TRUE(matNear(t, rows({1, 0, 0, 2, 0, 1, 0, -3, 0, 0, 1, 4, 0, 0, 0, 1})));
    EXPECT_TRUE(matNear(t, glm::translate(mat4(1.0f), vec3(2, -3, 4))));
    mat4 s = scaling(vec3(2, 3, -4));
    EXPECT_TRUE(matNear(s, rows({2, 0, 0, 0, 0, 3, 0, 0, 0, 0, -4, 0, 0, 0, 0, 1})));
    EXPECT_TRUE(matNear(s, glm::scale(mat4(1.0f), vec3(2, 3, -4))));
    // S p = (sx px, sy py, sz pz).
    EXPECT_TRUE(vecNear(vec3(s * vec4(1, 1, 1, 1)), vec3(2, 3, -4)));
}

TEST(TransformsTest, RotationEntriesMatchSeedsAndGlm) {
    for (float phi : {0.3f, -1.2f, 2.5f}) {
        float c = std::cos(phi), s = std::sin(phi);
        EXPECT_TRUE(matNear(rotationX(phi), rows({1, 0, 0, 0, 0, c, -s, 0, 0, s, c, 0, 0, 0, 0, 1})));
        EXPECT_TRUE(matNear(rotationY(phi), rows({c, 0, s, 0, 0, 1, 0, 0, -s, 0, c, 0, 0, 0, 0, 1})));
        EXPECT_TRUE(matNear(rotationZ(phi), rows({c, -s, 0, 0, s, c, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1})));
        EXPECT_TRUE(matNear(rotationX(phi), glm::rotate(mat4(1.0f), phi, vec3(1, 0, 0))));
        EXPECT_TRUE(matNear(rotationY(phi), glm::rotate(mat4(1.0f), phi, vec3(0, 1, 0))));
        EXPECT_TRUE(matNear(rotationZ(phi), glm::rotate(mat4(1.0f), phi, vec3(0, 0, 1))));
        // Orthogonal: R R^T = I, det +1.
        for (const mat4& r : {rotationX(phi), rotationY(phi), rotationZ(phi)}) {
            EXPECT_TRUE(matNear(r * glm::transpose(r), mat4(1.0f)));
            EXPECT_NEAR(glm::determinant(r), 1.0f, 1e-5f);
        }
    }
    // Positive angles are anticlockwise: Rz(90deg) takes x to y, Rx takes y to z, Ry takes z to x.
    EXPECT_TRUE(vecNear(vec3(rotationZ(kPi / 2) * vec4(1, 0, 0, 0)), vec3(0, 1, 0)));
    EXPECT_TRUE(vecNear(vec3(rotationX(kPi / 2) * vec4(0, 1, 0, 0)), vec3(0, 0, 1)));
    EXPECT_TRUE(vecNear(vec3(rotationY(kPi / 2) * vec4(0, 0, 1, 0)), vec3(1, 0, 0)));
}

TEST(TransformsTest, MirrorAndShearEntries) {
    EXPECT_TRUE(matNear(mirrorX(), rows({-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1})));
    EXPECT_TRUE(matNear(mirrorY(), rows({1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1})));
    EXPECT_TRUE(matNear(mirrorZ(), rows({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1})));
    for (const mat4& p : {mirrorX(), mirrorY(), mirrorZ()}) {
        EXPECT_TRUE(matNear(p * glm::transpose(p), mat4(1.0f)));   // orthogonal
        EXPECT_NEAR(glm::determinant(p), -1.0f, 1e-6f);
    }
    // H_xz(s): x' = x + s z (row 0, column 2).
    mat4 h = shear(0, 2, 0.7f);
    EXPECT_TRUE(matNear(h, rows({1, 0, 0.7f, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1})));
    EXPECT_TRUE(vecNear(vec3(h * vec4(1, 2, 3, 1)), vec3(1 + 0.7f * 3, 2, 3)));
    // Every pair (a, b): component a offset by s times component b.
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            mat4 m = shear(a, b, 2.0f);
            vec3 p(1, 2, 3), q = vec3(m * vec4(p, 1));
            vec3 expect = p;
            if (a != b) expect[a] += 2.0f * p[b];
            EXPECT_TRUE(vecNear(q, expect)) << a << b;
        }
    EXPECT_TRUE(matNear(shear(1, 1, 5.0f), mat4(1.0f)));   // a == b: identity
}

TEST(TransformsTest, LookAtBasisMatchesSeedsAndGlm) {
    vec3 eye(3, 2, 5), center(0.5f, -1, 0), up(0, 1, 0);
    mat4 v = lookAt(eye, center, up);
    EXPECT_TRUE(matNear(v, glm::lookAt(eye, center, up)));
    vec3 zc = glm::normalize(eye - center);
    vec3 xc = glm::normalize(glm::cross(up, zc));   // x^c = up x z^c / |up x z^c|
    vec3 yc = glm::cross(zc, xc);                   // y^c = z^c x x^c
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(at(v, 0, c), xc[c], 1e-6f);
        EXPECT_NEAR(at(v, 1, c), yc[c], 1e-6f);
        EXPECT_NEAR(at(v, 2, c), zc[c], 1e-6f);
    }
    // The eye goes to the origin, the target onto the -z axis, up stays in the upper half.
    EXPECT_TRUE(vecNear(vec3(v * vec4(eye, 1)), vec3(0.0f)));
    vec3 t = vec3(v * vec4(center, 1));
    EXPECT_NEAR(t.x, 0, 1e-5f);
    EXPECT_NEAR(t.y, 0, 1e-5f);
    EXPECT_NEAR(t.z, -glm::distance(eye, center), 1e-5f);
    EXPECT_GT((v * vec4(eye + up, 1)).y, 0.0f);
    // Up parallel to the view direction still gives an orthonormal basis.
    mat4 w = lookAt(vec3(0, 5, 0), vec3(0), vec3(0, 1, 0));
    EXPECT_TRUE(isFinite(w));
    EXPECT_TRUE(matNear(mat4(mat3(w)) * glm::transpose(mat4(mat3(w))), mat4(1.0f)));
}

TEST(TransformsTest, PerspectiveFovyAspect) {
    float fovy = radians(60.0f), aspect = 1.5f, n = 0.5f, f = 50.0f;
    mat4 p = perspective(fovy, aspect, n, f);
    float ct = 1.0f / std::tan(fovy / 2);   // F = cot(fovy/2) in docs/math.md
    // docs/math.md: diag(F/aspect, F, ...) with -1 in the last row. The third row carries the
    // "flip z": -(far+near)/(far-near), -2 far near/(far-near) (as in the frustum
    // form and OpenGL), so that near maps to -1 and far to +1.
    EXPECT_TRUE(matNear(p, rows({ct / aspect, 0, 0, 0, 0, ct, 0, 0, 0, 0, -(f + n) / (f - n), -2 * f * n / (f - n), 0, 0, -1, 0})));
    EXPECT_TRUE(matNear(p, glm::perspective(fovy, aspect, n, f)));
    // Corners of the near and far rectangles land on the NDC cube corners.
    for (float z : {n, f}) {
        float hy = z * std::tan(fovy / 2), hx = hy * aspect;
        float zn = z == n ? -1.0f : 1.0f;
        for (float sx : {-1.0f, 1.0f})
            for (float sy : {-1.0f, 1.0f}) EXPECT_TRUE(vecNear(project(p, vec3(sx * hx, sy * hy, -z)), vec3(sx, sy, zn)));
    }
    // The symmetric frustum with l = -r, b = -t is the same matrix.
    float t = n * std::tan(fovy / 2), r = t * aspect;
    EXPECT_TRUE(matNear(p, frustum(-r, r, -t, t, n, f)));
}

TEST(TransformsTest, GeneralFrustum) {
    float l = -0.3f, r = 0.5f, b = -0.1f, t = 0.4f, n = 0.5f, f = 20.0f;
    mat4 m = frustum(l, r, b, t, n, f);
    EXPECT_TRUE(matNear(m, rows({2 * n / (r - l), 0, (r + l) / (r - l), 0, 0, 2 * n / (t - b), (t + b) / (t - b), 0, 0, 0, -(f + n) / (f - n),
                                 -2 * f * n / (f - n), 0, 0, -1, 0})));
    EXPECT_TRUE(matNear(m, glm::frustum(l, r, b, t, n, f)));
    // (l, b, -n) -> (-1, -1, -1), (r, t, -n) -> (1, 1, -1); far corners scaled by f/n -> z = +1.
    EXPECT_TRUE(vecNear(project(m, vec3(l, b, -n)), vec3(-1, -1, -1)));
    EXPECT_TRUE(vecNear(project(m, vec3(r, t, -n)), vec3(1, 1, -1)));
    EXPECT_TRUE(vecNear(project(m, vec3(l, t, -n)), vec3(-1, 1, -1)));
    float k = f / n;
    EXPECT_TRUE(vecNear(project(m, vec3(r * k, b * k, -f)), vec3(1, -1, 1), 1e-3f));
    EXPECT_TRUE(vecNear(project(m, vec3(l * k, t * k, -f)), vec3(-1, 1, 1), 1e-3f));
}

TEST(TransformsTest, Orthographic) {
    float l = -2, r = 3, b = -1, t = 1.5f, n = 0.5f, f = 10;
    mat4 m = orthographic(l, r, b, t, n, f);
    EXPECT_TRUE(matNear(
        m, rows({2 / (r - l), 0, 0, -(r + l) / (r - l), 0, 2 / (t - b), 0, -(t + b) / (t - b), 0, 0, -2 / (f - n), -(f + n) / (f - n), 0, 0, 0, 1})));
    EXPECT_TRUE(matNear(m, glm::ortho(l, r, b, t, n, f)));
    EXPECT_TRUE(vecNear(project(m, vec3(l, b, -n)), vec3(-1, -1, -1)));
    EXPECT_TRUE(vecNear(project(m, vec3(r, t, -f)), vec3(1, 1, 1)));
}

TEST(TransformsTest, ViewportMapsNdcCornersToPixelCorners) {
    float x0 = 10, y0 = 20, w = 640, h = 480;
    mat4 v = viewport(x0, y0, w, h);
    EXPECT_TRUE(matNear(v, rows({w / 2, 0, 0, x0 + w / 2, 0, h / 2, 0, y0 + h / 2, 0, 0, 0.5f, 0.5f, 0, 0, 0, 1})));
    EXPECT_TRUE(vecNear(project(v, vec3(-1, -1, -1)), vec3(x0, y0, 0)));
    EXPECT_TRUE(vecNear(project(v, vec3(1, 1, 1)), vec3(x0 + w, y0 + h, 1)));
    EXPECT_TRUE(vecNear(project(v, vec3(1, -1, 0)), vec3(x0 + w, y0, 0.5f)));
    EXPECT_TRUE(vecNear(project(v, vec3(0, 0, 0)), vec3(x0 + w / 2, y0 + h / 2, 0.5f)));
    // Agrees with glm::project (which applies the same viewport mapping).
    mat4 proj = perspective(radians(50.0f), w / h, 0.1f, 100.0f);
    vec3 p(0.3f, -0.2f, -2.0f);
    vec3 g = glm::project(p, mat4(1.0f), proj, vec4(x0, y0, w, h));
    EXPECT_TRUE(vecNear(project(v * proj, p), g, 1e-3f));
}

TEST(TransformsTest, ObliqueShiftsByFactorTimesDepth) {
    float angle = radians(30.0f), zRef = -4.0f;
    for (float factor : {1.0f, 0.5f}) {   // cavalier, cabinet
        mat4 s = obliqueShear(angle, factor, zRef);
        for (float d : {0.0f, 1.0f, 2.5f}) {
            vec3 p(0.3f, -0.2f, zRef - d);   // d behind the reference plane
            vec3 q = vec3(s * vec4(p, 1));
            EXPECT_TRUE(vecNear(q, vec3(p.x + factor * d * std::cos(angle), p.y + factor * d * std::sin(angle), p.z)));
        }
        mat4 o = oblique(-2, 2, -1.5f, 1.5f, 0.1f, 20.0f, angle, factor, zRef);
        EXPECT_TRUE(matNear(o, orthographic(-2, 2, -1.5f, 1.5f, 0.1f, 20.0f) * s));
        // A unit edge receding along -z is drawn with length `factor` (in view units).
        vec3 a = project(o, vec3(0, 0, zRef)), b = project(o, vec3(0, 0, zRef - 1));
        vec2 dn = vec2(b - a) * vec2(2.0f, 1.5f);   // NDC back to view units
        EXPECT_NEAR(glm::length(dn), factor, 1e-5f);
        EXPECT_NEAR(std::atan2(dn.y, dn.x), angle, 1e-5f);
        // Points on the reference plane do not move.
        EXPECT_TRUE(vecNear(project(o, vec3(1, 1, zRef)), project(orthographic(-2, 2, -1.5f, 1.5f, 0.1f, 20.0f), vec3(1, 1, zRef))));
    }
}

TEST(TransformsTest, ProjectionMatrixDispatch) {
    Projection p;
    p.fovyDeg = 45;
    p.zNear = 0.2f;
    p.zFar = 30;
    EXPECT_TRUE(matNear(p.matrix(2.0f, 5.0f), glm::perspective(radians(45.0f), 2.0f, 0.2f, 30.0f)));
    p.useFrustum = true;
    EXPECT_TRUE(matNear(p.matrix(2.0f, 5.0f), glm::frustum(p.left, p.right, p.bottom, p.top, 0.2f, 30.0f)));
    p.type = ProjectionType::Orthographic;
    p.orthoHalfHeight = 3;
    EXPECT_TRUE(matNear(p.matrix(2.0f, 5.0f), glm::ortho(-6.0f, 6.0f, -3.0f, 3.0f, 0.2f, 30.0f)));
    Projection cav = Projection::cavalier(), cab = Projection::cabinet();
    EXPECT_EQ(cav.obliqueFactor, 1.0f);
    EXPECT_EQ(cab.obliqueFactor, 0.5f);
    cab.orthoHalfHeight = 3;
    // Oblique: reference plane at the focus distance in front of the camera.
    EXPECT_TRUE(matNear(cab.matrix(2.0f, 5.0f), oblique(-6, 6, -3, 3, cab.zNear, cab.zFar, radians(45.0f), 0.5f, -5.0f)));
    // Bad aspect falls back to 1 instead of producing NaNs.
    EXPECT_TRUE(isFinite(Projection{}.matrix(0.0f, 5.0f)));
    EXPECT_TRUE(isFinite(Projection{}.matrix(std::numeric_limits<float>::quiet_NaN(), 5.0f)));
    ProjectionType t;
    EXPECT_TRUE(parse("oblique", t));
    EXPECT_EQ(t, ProjectionType::Oblique);
    EXPECT_FALSE(parse("fisheye", t));
}

TEST(TransformsTest, NormalMatrixKeepsNormalsPerpendicular) {
    mat4 m = translation(vec3(1, 2, 3)) * shear(0, 2, 0.8f) * scaling(vec3(3, 0.5f, 2)) * rotationY(0.7f);
    mat3 nm = normalMatrix(m);
    EXPECT_TRUE(matNear(mat4(nm), mat4(glm::inverseTranspose(mat3(m)))));
    // Tangents t1, t2 of a plane with normal n = t1 x t2; after the transform, n' . t' = 0.
    vec3 t1 = glm::normalize(vec3(1, 2, -1)), t2 = glm::normalize(vec3(0.5f, -1, 3));
    vec3 n = glm::cross(t1, t2);
    vec3 n2 = nm * n;
    for (vec3 t : {t1, t2, t1 + 2.0f * t2}) {
        vec3 tt = mat3(m) * t;
        EXPECT_NEAR(glm::dot(n2, tt) / (glm::length(n2) * glm::length(tt)), 0.0f, 1e-5f);
    }
    // Transforming n with m itself would not stay perpendicular under shear.
    vec3 wrong = mat3(m) * n;
    EXPECT_GT(std::abs(glm::dot(glm::normalize(wrong), glm::normalize(mat3(m) * t1))), 0.01f);
    // Degenerate matrices give identity rather than NaNs.
    EXPECT_TRUE(matNear(mat4(normalMatrix(scaling(vec3(1, 0, 1)))), mat4(1.0f)));
}

// A glTF camera's aspectRatio: a narrower viewport widens the vertical angle so the author's
// horizontal field stays whole; a wider one keeps the vertical angle.
TEST(ProjectionTest, AuthoredAspectKeepsTheFramedFieldWhole) {
    sg::Projection p;
    p.fovyDeg = 40.0f;
    p.aspectRatio = 16.0f / 9.0f;
    EXPECT_FLOAT_EQ(p.effectiveFovyDeg(2.0f), 40.0f);
    const float portrait = 0.6f;
    const float fovy = p.effectiveFovyDeg(portrait);
    const float halfX = std::atan(std::tan(sg::radians(fovy) * 0.5f) * portrait);
    const float authoredHalfX = std::atan(std::tan(sg::radians(40.0f) * 0.5f) * p.aspectRatio);
    EXPECT_NEAR(halfX, authoredHalfX, 1e-5f);
    EXPECT_NEAR(p.matrix(portrait, 1.0f)[1][1], 1.0f / std::tan(sg::radians(fovy) * 0.5f), 1e-4f);
    p.aspectRatio = 0.0f;
    EXPECT_FLOAT_EQ(p.effectiveFovyDeg(portrait), 40.0f);
}

// The isometric view (projection.h): an orthographic camera looking along -(1, 1, 1) projects
// the three world axes to equal lengths sqrt(2/3) on the picture plane, 120 degrees apart, with
// +y straight up; in the image (through the projection and the viewport) too, for any pivot,
// distance and aspect.
TEST(ProjectionTest, IsometricViewForeshortensTheAxesEquallyAt120Degrees) {
    const vec3 dir = isometricViewDirection();
    EXPECT_NEAR(glm::length(dir), 1.0f, 1e-6f);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(dir[k], -1.0f / std::sqrt(3.0f), 1e-6f) << k;
    EXPECT_NEAR(kIsometricPitchDeg, degrees(std::atan(1.0f / std::sqrt(2.0f))), 1e-4f);
    Projection ortho;
    ortho.type = ProjectionType::Orthographic;
    ortho.orthoHalfHeight = 3.0f;
    for (const vec3& pivot : {vec3(0.0f), vec3(2.0f, -1.0f, 5.0f)})
        for (float distance : {1.0f, 40.0f})
            for (float aspect : {1.0f, 16.0f / 9.0f}) {
                SCOPED_TRACE(::testing::Message() << "pivot " << pivot.x << "," << pivot.y << "," << pivot.z << " distance " << distance << " aspect "
                                                  << aspect);
                const mat4 world = isometricCameraWorld(pivot, distance);
                EXPECT_NEAR(glm::length(vec3(world[3]) - pivot), distance, 1e-4f * distance);
                EXPECT_TRUE(matNear(mat4(glm::mat3(world)) * glm::transpose(mat4(glm::mat3(world))), mat4(1.0f))) << "a rotation";
                const mat4 view = glm::inverse(world);
                // Picture-plane (eye x, y) images of the unit axes at the pivot, and their images
                // in a viewport of that aspect (pixels: 100 per view unit vertically).
                const float w = 200.0f * aspect, h = 200.0f;
                const mat4 clip = ortho.matrix(aspect, distance) * view;
                vec2 plane[3], image[3];
                for (int a = 0; a < 3; ++a) {
                    vec3 e(0.0f);
                    e[a] = 1.0f;
                    plane[a] = vec2(view * vec4(pivot + e, 1.0f)) - vec2(view * vec4(pivot, 1.0f));
                    const vec4 p = clip * vec4(pivot + e, 1.0f), o = clip * vec4(pivot, 1.0f);
                    image[a] = vec2((p.x / p.w - o.x / o.w) * 0.5f * w, (p.y / p.w - o.y / o.w) * 0.5f * h);
                }
                for (int a = 0; a < 3; ++a) {
                    EXPECT_NEAR(glm::length(plane[a]), std::sqrt(2.0f / 3.0f), 1e-5f) << "axis " << a;
                    EXPECT_NEAR(glm::length(image[a]), 100.0f / ortho.orthoHalfHeight * std::sqrt(2.0f / 3.0f), 1e-3f) << "axis " << a;
                    const int b = (a + 1) % 3;
                    for (const vec2* v : {plane, image}) {
                        const float cosAngle = glm::dot(v[a], v[b]) / (glm::length(v[a]) * glm::length(v[b]));
                        EXPECT_NEAR(degrees(std::acos(std::clamp(cosAngle, -1.0f, 1.0f))), 120.0f, 1e-3f) << "axes " << a << " and " << b;
                    }
                }
                EXPECT_NEAR(plane[1].x, 0.0f, 1e-6f) << "+y is drawn straight up";
                EXPECT_GT(plane[1].y, 0.0f);
            }
}
