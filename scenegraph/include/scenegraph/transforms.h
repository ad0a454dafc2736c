// transforms.h - the homogeneous 4x4 transforms of docs/math.md, written out element by
// element so tests can hold them to the formulas. Column-major storage: m[col][row], so the
// matrix entry (row r, column c) as written in docs/math.md is m[c][r].
#pragma once

#include "scenegraph/math.h"

namespace sg {

mat4 translation(const vec3& t);
mat4 rotationX(float phi);   // radians, positive = anticlockwise looking down -x
mat4 rotationY(float phi);
mat4 rotationZ(float phi);
mat4 scaling(const vec3& s);
mat4 mirrorX();   // P_x: x -> -x
mat4 mirrorY();
mat4 mirrorZ();
// Shear H_ab(s): component a is offset by s times component b (a != b, 0=x,1=y,2=z).
// H_xz(s) p = (px + s pz, py, pz) (docs/math.md, model transforms).
mat4 shear(int a, int b, float s);

// View transform (world -> camera) of a camera at eye looking at center: camera looks
// down -z, x^c = up x z^c / |up x z^c|, y^c = z^c x x^c, with z^c = (eye - center)/|...|.
mat4 lookAt(const vec3& eye, const vec3& center, const vec3& up);

// Projections to the canonical view volume [-1,1]^3 (OpenGL clip space).
mat4 perspective(float fovyRadians, float aspect, float zNear, float zFar);
mat4 frustum(float l, float r, float b, float t, float zNear, float zFar);
mat4 orthographic(float l, float r, float b, float t, float zNear, float zFar);
// Oblique parallel projection: orthographic after shearing view space so that a line
// receding along -z by depth d is drawn at `angle` (radians, from the screen x axis)
// with length factor*d. factor 1 = cavalier, 0.5 = cabinet. zRef is the view-space z of the
// plane that stays in place (the focus plane), so framing does not shift with depth.
mat4 oblique(float l, float r, float b, float t, float zNear, float zFar, float angle, float factor, float zRef);
// Shear part of the oblique projection alone (view space -> sheared view space).
mat4 obliqueShear(float angle, float factor, float zRef);

// Viewport transform: NDC [-1,1]^3 -> window coordinates x in [x0, x0+w], y in [y0, y0+h]
// (y up, origin lower left, as in GL), z in [0,1].
mat4 viewport(float x0, float y0, float w, float h);

}   // namespace sg
