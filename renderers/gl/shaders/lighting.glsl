// lighting.glsl - the reflection models of renderers/common/shading.cpp, function for function
// and name for name (sampleLight, lightTerms, shadeTerms; keep the two in step; pbr's pieces are
// in pbr.glsl). Shared by mesh.vert (Gouraud) and mesh.frag (flat, Phong).
//
// shade() is linear in the albedo rho, so it is evaluated as two terms (ShadeTerms in C++):
//   colour = rho * mul + add
//   mul = ka * L_ambient + sum_i att_i L_i max(n.l_i,0) (kd + [tinted] ks spec_i)
//   add = emissive        + sum_i att_i L_i max(n.l_i,0) [untinted] ks spec_i specularColor
// which lets Gouraud evaluate the lights at the vertices and still apply the texture per
// fragment (rho = base colour * vertex colour * texel).
//
// The renderer compiles one program per light setup: its prefix defines MAX_LIGHTS,
// REFLECTION (REFLECTION_PHONG or REFLECTION_BLINN) and LIGHT_CALLS: for a few lights, one lightTerms(i,
// type, inverseSquare, ...) call per light with constant arguments (the compiler drops the
// code of the other light types; a loop over a uniform light count costs llvmpipe about 2x,
// see bench/gl); for many lights a loop over uNumLights reading the type from the .w
// components (one program for all, so it compiles once).
//
// Shadows (SHADOWS 1: shadow maps this frame, as in the CPU rasterizer; docs/math.md, "Shadow
// maps"): per-pixel shading: lightTerms multiplies each light's radiance by shadow.glsl's
// shadowVisibility at p with the shading normal n; flat: the same at the fragment's own point
// gShadowPos (the model is evaluated at the first vertex) with the face normal; Gouraud (in the
// vertex shader): no lookup here, the generated light calls put the SHADOW_SLOTS shadowed
// lights' terms into gLightMul/gLightAdd[j] instead of mul/add, and mesh.frag scales them by the
// fragment's visibility. The ambient, emissive and environment terms are not shadowed.

uniform int uNumLights;                // lights used by the loop form of LIGHT_CALLS
uniform vec4 uLightPos[MAX_LIGHTS];    // xyz: world position; w: type (LIGHT_POINT ...)
uniform vec4 uLightDir[MAX_LIGHTS];    // xyz: world direction the light travels; w: 1 = 1/r^2
uniform vec4 uLightRad[MAX_LIGHTS];    // xyz: radiance (colour * intensity)
uniform vec4 uLightCone[MAX_LIGHTS];   // x: cos inner, y: cos outer, z: range (pbr; 0 = none), w: size (PCSS)

uniform vec3 uEye;          // camera position, world
uniform vec3 uAmbient;      // L_ambient

uniform vec3 uBaseColor;
uniform float uKa;
uniform float uKd;
uniform float uKs;
uniform float uShininess;
uniform bool uSpecTinted;
uniform vec3 uSpecColor;
uniform vec3 uEmissive;

// The coefficients the model uses at this vertex or fragment (rnd::PhongCoefficients): the
// material's uniforms, which mesh.frag changes per texel by the material's maps.
float gKa, gKd, gKs, gShininess;
bool gSpecTinted;
vec3 gSpecColor;
vec3 gEmissive;
void coefficientsOfMaterial() {
    gKa = uKa;
    gKd = uKd;
    gKs = uKs;
    gShininess = uShininess;
    gSpecTinted = uSpecTinted;
    gSpecColor = uSpecColor;
    gEmissive = uEmissive;
    pbrCoefficientsOfMaterial(uKs, uSpecColor);   // pbr.glsl
}

// LIGHT_POINT, LIGHT_DIRECTIONAL, LIGHT_SPOT, SHADING_*, REFLECTION_* and FOG_* are defined by the
// renderer's prefix with the values of the C++ enums (glslEnumDefines() in gl_renderer.cpp).

// sampleLight(): direction toward light i and the radiance arriving at p.
void sampleLight(int i, int type, bool inverseSquare, vec3 p, out vec3 toLight, out vec3 radiance) {
    radiance = uLightRad[i].xyz;
    if (type == LIGHT_DIRECTIONAL) {
        toLight = -uLightDir[i].xyz;
        return;
    }
    if (type != LIGHT_POINT && type != LIGHT_SPOT) {   // a type this shader does not know: no light
        toLight = vec3(0.0, 1.0, 0.0);
        radiance = vec3(0.0);
        return;
    }
    vec3 d = uLightPos[i].xyz - p;
    float dist2 = dot(d, d);
    float dist = sqrt(dist2);
    toLight = dist > 0.0 ? d / dist : vec3(0.0, 1.0, 0.0);
    if (inverseSquare) radiance /= max(dist2, 1e-8);   // docs/math.md: 1/r^2
    if (type == LIGHT_SPOT) {                          // smoothstep between the cones
        float c = dot(-toLight, uLightDir[i].xyz);
        float ci = uLightCone[i].x, co = uLightCone[i].y;
        float t = ci > co ? (c - co) / (ci - co) : (c >= co ? 1.0 : 0.0);
        t = clamp(t, 0.0, 1.0);
        radiance *= t * t * (3.0 - 2.0 * t);
    }
}

// rnd::samplePunctualLight (pbr): KHR_lights_punctual's range window and spot falloff.
void samplePunctualLight(int i, int type, bool inverseSquare, vec3 p, out vec3 toLight, out vec3 radiance) {
    radiance = uLightRad[i].xyz;
    if (type == LIGHT_DIRECTIONAL) {
        toLight = -uLightDir[i].xyz;
        return;
    }
    if (type != LIGHT_POINT && type != LIGHT_SPOT) {
        toLight = vec3(0.0, 1.0, 0.0);
        radiance = vec3(0.0);
        return;
    }
    vec3 d = uLightPos[i].xyz - p;
    float dist2 = dot(d, d);
    float dist = sqrt(dist2);
    toLight = dist > 0.0 ? d / dist : vec3(0.0, 1.0, 0.0);
    if (inverseSquare) radiance /= max(dist2, 1e-8);
    float range = uLightCone[i].z;
    if (range > 0.0) {
        float q = dist2 / (range * range);
        float w = clamp(1.0 - q * q, 0.0, 1.0);
        radiance *= w * w;
    }
    if (type == LIGHT_SPOT) {
        float scale = 1.0 / max(uLightCone[i].x - uLightCone[i].y, 1e-3);
        float t = clamp((dot(-toLight, uLightDir[i].xyz) - uLightCone[i].y) * scale, 0.0, 1.0);
        radiance *= t * t;
    }
}

#if REFLECTION == REFLECTION_PBR
PbrPoint gPbr;   // pbrPoint(gAlbedo), set by shadeTerms for the light calls
#endif
#if SHADOWS && SHADING == SHADING_FLAT
vec3 gShadowPos;   // flat: where the maps are read (the fragment's point), set before shadeTerms
#define SHADOW_POS(p) gShadowPos
#else
#define SHADOW_POS(p) p
#endif
#if SHADOW_SLOTS > 0
vec3 gLightMul[SHADOW_SLOTS], gLightAdd[SHADOW_SLOTS];   // Gouraud: the shadowed lights' own terms (shadeTerms zeroes them)
#endif

// lightTerms() of shading.h for light i, added to mul and add; v = unit vector to the eye.
void lightTerms(int i, int type, bool inverseSquare, vec3 n, vec3 p, vec3 v, inout vec3 mul, inout vec3 add) {
    vec3 l, radiance;
#if REFLECTION == REFLECTION_PBR
    samplePunctualLight(i, type, inverseSquare, p, l, radiance);
#else
    sampleLight(i, type, inverseSquare, p, l, radiance);
#endif
#if SHADOWS && SHADING != SHADING_GOURAUD
    radiance *= shadowVisibility(i, type, uLightPos[i].xyz, uLightDir[i].xyz, uLightCone[i].w, SHADOW_POS(p), n);   // shadow.glsl
#endif
#if REFLECTION == REFLECTION_PBR
    pbrLightTerms(gPbr, n, v, l, radiance, mul, add);
    return;
#endif
    float nl = dot(n, l);
    if (nl <= 0.0) return;
#if REFLECTION == REFLECTION_PHONG
    vec3 r = 2.0 * nl * n - l;                         // mirror direction of l about n
    float spec = max(dot(r, v), 0.0);
#elif REFLECTION == REFLECTION_BLINN
    vec3 h = l + v;
    float hl = length(h);
    float spec = hl > 0.0 ? max(dot(n, h / hl), 0.0) : 0.0;
#elif REFLECTION == REFLECTION_PBR
    float spec = 0.0;   // (returned above)
#else
#error "REFLECTION: a sg::ReflectionModel value this shader does not handle"
#endif
    spec = spec > 0.0 ? pow(spec, gShininess) : 0.0;
    vec3 ln = radiance * nl;
    mul += ln * gKd;
    if (gSpecTinted) mul += ln * (gKs * spec);
    else add += ln * (gKs * spec) * gSpecColor;
}

// The two albedo-linear terms of shade() at world position p with unit normal n (already
// facing the viewer for two-sided surfaces).
void shadeTerms(vec3 n, vec3 p, out vec3 mul, out vec3 add) {
#if SHADOW_SLOTS > 0
    for (int j = 0; j < SHADOW_SLOTS; ++j) gLightMul[j] = gLightAdd[j] = vec3(0.0);
#endif
    vec3 v = uEye - p;
    float len = length(v);
    v = len > 0.0 ? v / len : vec3(0.0, 0.0, 1.0);
#if REFLECTION == REFLECTION_PBR
    mul = vec3(0.0);
    add = gEmissive;
    gPbr = pbrPoint(gAlbedo);
    LIGHT_CALLS
#if HAS_ENVIRONMENT
    pbrEnvironmentTerms(gPbr, n, v, gOcclusion, mul, add);
#endif
#else
    mul = gKa * uAmbient;
    add = gEmissive;
    LIGHT_CALLS
#endif
}
