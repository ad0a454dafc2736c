// mesh.frag - per-fragment part of every shading model, texture, unlit, fog, wireframe.
// Prefix as in mesh.vert. Output is linear; the sRGB framebuffer encodes it (or, into a linear
// target, the display pass maps and encodes it: display.frag).
//
// The draw's features are compile-time switches of the prefix (one program per combination,
// compiled on first use; see Features in gl_renderer.cpp), not uniform branches: llvmpipe runs
// both sides of every branch under a mask, and cannot test depth before a shader that may
// discard, so an uber-shader pays for every feature on every fragment, hidden ones included.
//   HAS_TEXTURE, HAS_EMISSIVE_MAP, HAS_OCCLUSION_MAP, HAS_METAL_ROUGH_MAP, HAS_NORMAL_MAP: 0 or 1
//   SPEC_GLOSS     1: the metal-rough slot holds a specular-glossiness texture
//   USES_UV1       1: some map samples the mesh's second UV set (uUv1Maps says which)
//   VERTEX_COLORS  1: the mesh has vertex colours (else they are 1)
//   UNLIT          1: colour = albedo + emissive (unlit material, lines, points)
//   ALPHA_MODE     ALPHA_OPAQUE, ALPHA_MASK or ALPHA_BLEND (sg::AlphaMode values)
//   FOG            FOG_OFF, FOG_LINEAR, FOG_EXP or FOG_EXP2 (sg::FogMode values)
//   SOLID          1: the wireframe overlay: uSolidColor (fogged)
//   OVERDRAW       1: the overdraw view's pass: 1.0 for every fragment, nothing else
//   VISIBILITY     1: also write fragId (the target has the visibility attachment)
//   LINEAR_TARGET  1: the target is linear float (exposure or tone mapping follow): colour not
//                  clamped at 1
// The frame setup's switches (MAX_LIGHTS, LIGHT_CALLS, REFLECTION, SHADOWS, SHADOW_PCF,
// SHADOW_SLOTS) are lighting.glsl's and shadow.glsl's: with shadow maps, the per-pixel path
// (SHADING_PHONG) gets each light's visibility at the shading normal, flat at the fragment's
// point with the face normal, and Gouraud scales its SHADOW_SLOTS shadowed lights' interpolated
// terms by the visibility at the fragment's point with the face normal (lights beyond those stay
// in the vertices' unshadowed sum; docs/math.md, "Shadow maps").
in vec3 vWorldPos;
#if FOG != FOG_OFF
in vec3 vEyePos;
#endif
in vec3 vNormal;
#if USES_UV
in vec2 vUv;
#endif
#if USES_UV1
in vec2 vUv1;
#endif
#if VERTEX_COLORS
in vec4 vColor;
#endif
#if HAS_NORMAL_MAP
in vec4 vTangent;
#endif
#if SHADING == SHADING_FLAT
flat in vec3 vFlatPos;
flat in vec3 vFlatAlbedo;
#endif
#if SHADING == SHADING_GOURAUD
in vec3 vMulFront;
in vec3 vAddFront;
in vec3 vMulBack;
in vec3 vAddBack;
#if SHADOW_SLOTS > 0
in vec4 vShadowed[3 * SHADOW_SLOTS];   // mesh.vert: per shadowed light front mul, front add, back mul, back add
#endif
#endif

uniform sampler2D uTexture;
// Material maps (rnd::sampleMaps / coefficientsAt in renderers/common/shading.cpp).
uniform sampler2D uEmissiveMap;     // sRGB colour, x uEmissive
uniform sampler2D uOcclusionMap;    // R: ambient occlusion
uniform sampler2D uMetalRoughMap;   // G: roughness, B: metallic (linear); or specular-glossiness (SPEC_GLOSS)
uniform sampler2D uNormalMap;       // tangent-space normal, linear RGB = 0.5 n + 0.5 (meshes with tangents only)
uniform float uNormalScale;
uniform int uUv1Maps;               // sg::Material::uv1Maps: MAP_* bits of the maps that sample vUv1
uniform float uOcclusionStrength;
uniform float uAlpha;       // material alpha (x texture alpha x vertex alpha)
uniform float uAlphaCutoff;
uniform vec3 uSolidColor;
uniform vec3 uFogColor;
uniform vec3 uFogParams;    // start, end, density

layout(location = 0) out vec4 fragColor;
#if VISIBILITY
uniform uint uDrawable;        // Framebuffer::drawable of this draw
uniform uint uPrimitiveBase;   // the draw call's first primitive in its mesh (0xffffffff: analytic)
// Visibility (Aov::Visibility in rnd::RenderConfig::aovs): drawable, and the primitive index within its mesh.
layout(location = 1) out uvec2 fragId;
#endif

// The UV set a map samples (rnd::sampleMaps): vUv1 where its MAP_* bit is set in uUv1Maps.
#if USES_UV
vec2 mapUv(int bit) {
#if USES_UV1
    return (uUv1Maps & bit) != 0 ? vUv1 : vUv;
#else
    return vUv;
#endif
}
#endif

// rnd::perturbNormal() (renderers/common/shading.cpp): the normal map's normal at n (outward).
vec3 perturbNormal(vec3 n, vec4 t, vec3 texel, float scale) {
    vec3 m = 2.0 * texel - 1.0;
    m.xy *= scale;
    vec3 T = t.xyz - n * dot(n, t.xyz);
    float lt = length(T);
    if (!(lt > 1e-12)) return n;
    T /= lt;
    vec3 B = (t.w < 0.0 ? -1.0 : 1.0) * cross(n, T);
    vec3 p = m.x * T + m.y * B + m.z * n;
    float lp = length(p);
    return lp > 1e-12 ? p / lp : n;
}

// sg::phongFromMetallicRoughness() (scenegraph/src/material.cpp).
void phongFromMetallicRoughness(float metallic, float roughness) {
    float m = clamp(metallic, 0.0, 1.0), r = clamp(roughness, 0.0, 1.0);
    float a = r * r;
    gKd = 1.0 - 0.75 * m;
    gKs = clamp(0.04 + 0.96 * m + 0.25 * (1.0 - r) * (1.0 - m), 0.0, 1.0);
    gShininess = a < 1e-3 ? 2048.0 : clamp(2.0 / (a * a) - 2.0, 1.0, 2048.0);
    gSpecTinted = m >= 0.5;
}

// sg::fogVisibility(): f(d) in [0,1], 1 = no fog.
float fogVisibility(float d) {
#if FOG == FOG_LINEAR
    return clamp((uFogParams.y - d) / (uFogParams.y - uFogParams.x), 0.0, 1.0);
#elif FOG == FOG_EXP
    return exp(-uFogParams.z * d);
#elif FOG == FOG_EXP2
    float x = uFogParams.z * d;
    return exp(-x * x);
#else
    return 1.0;
#endif
}

void main() {
#if VISIBILITY
    fragId = uvec2(uDrawable, uPrimitiveBase == 0xffffffffu ? uPrimitiveBase : uPrimitiveBase + uint(gl_PrimitiveID));
#endif
#if OVERDRAW
    fragColor = vec4(1.0);   // whatever its alpha: this variant never discards
    return;
#else
    vec3 c;
    float alpha = 1.0;
#if SOLID
    c = uSolidColor;
#else
    vec3 albedo = uBaseColor;
    alpha = uAlpha;
#if VERTEX_COLORS
    albedo *= vColor.rgb;
    alpha *= vColor.a;
#endif
#if HAS_TEXTURE
    vec4 t = texture(uTexture, vUv);   // sRGB texture: colour decoded to linear, alpha as stored
    albedo *= t.rgb;
    alpha *= t.a;
#endif
    // The maps, sampled before any discard (implicit derivatives): coefficientsAt().
    coefficientsOfMaterial();
#if HAS_OCCLUSION_MAP
    float ao = texture(uOcclusionMap, mapUv(MAP_OCCLUSION)).r;
    gOcclusion = 1.0 + uOcclusionStrength * (ao - 1.0);
    gKa *= gOcclusion;
#endif
#if HAS_EMISSIVE_MAP
    vec3 em = texture(uEmissiveMap, mapUv(MAP_EMISSIVE)).rgb;
    gEmissive *= em;
#endif
#if HAS_NORMAL_MAP
    vec3 nt = texture(uNormalMap, mapUv(MAP_NORMAL)).rgb;
#endif
#if HAS_METAL_ROUGH_MAP
    vec4 mr = texture(uMetalRoughMap, mapUv(MAP_METALLIC_ROUGHNESS));
#if SPEC_GLOSS   // rnd::coefficientsAt, specular-glossiness
    gSpecularF0 = uKs * uSpecColor * mr.rgb;
    gRoughness = 1.0 - uGlossiness * mr.a;
    vec3 spec = uKs * uSpecColor * mr.rgb;
    float ks = max(spec.r, max(spec.g, spec.b));
    phongFromMetallicRoughness(0.0, 1.0 - uGlossiness * mr.a);   // for the exponent
    gKd = 1.0;
    gKs = ks;
    gSpecColor = ks > 0.0 ? spec / ks : vec3(1.0);
    gSpecTinted = false;
#else
    gMetallic = uMetallic * mr.b;
    gRoughness = uRoughness * mr.g;
    phongFromMetallicRoughness(uMetallic * mr.b, uRoughness * mr.g);
#endif
#endif
#if ALPHA_MODE == ALPHA_MASK
    if (alpha < uAlphaCutoff) discard;   // cut-out
    alpha = 1.0;
#elif ALPHA_MODE == ALPHA_OPAQUE
    alpha = 1.0;
#elif ALPHA_MODE != ALPHA_BLEND
#error "ALPHA_MODE: a sg::AlphaMode value this shader does not handle"
#endif
#if UNLIT
    c = albedo + gEmissive;
#else
    vec3 mul, add;
    gAlbedo = albedo;   // pbr: F0 of metals
#if SHADING == SHADING_FLAT
    // One evaluation per triangle: at its first (provoking) vertex with the face normal and the
    // material's own coefficients; occlusion and emission maps apply here as for Gouraud.
    // cross(dp/dx, dp/dy) always points to the side being seen (flipped toward the viewer).
    vec3 n = normalize(cross(dFdx(vWorldPos), dFdy(vWorldPos)));
    coefficientsOfMaterial();
    gAlbedo = vFlatAlbedo;
#if SHADOWS
    gShadowPos = vWorldPos;   // each light scaled by the visibility at the fragment's own point
#endif
    shadeTerms(n, vFlatPos, mul, add);
#if HAS_OCCLUSION_MAP && REFLECTION != REFLECTION_PBR
    mul -= uKa * uOcclusionStrength * (1.0 - ao) * uAmbient;
#endif
#if HAS_EMISSIVE_MAP
    add += uEmissive * (em - 1.0);
#endif
#elif SHADING == SHADING_GOURAUD
    // Lit at the vertices with the material's coefficients; occlusion and emissive maps
    // still apply exactly here (applyMapsToTerms): both terms are additive.
    mul = gl_FrontFacing ? vMulFront : vMulBack;
    add = gl_FrontFacing ? vAddFront : vAddBack;
#if SHADOW_SLOTS > 0
    // The shadowed lights' terms, interpolated on their own, scaled by the visibility here (the
    // face normal for the lookup's offsets, either side: the lookup turns it toward the light).
    vec3 ng = normalize(cross(dFdx(vWorldPos), dFdy(vWorldPos)));
    for (int j = 0; j < SHADOW_SLOTS; ++j) {
        int l = j == 0 ? SHADOW_SLOT_LIGHT0 : SHADOW_SLOT_LIGHT1;
        vec4 a = vShadowed[3 * j], b = vShadowed[3 * j + 1], c3 = vShadowed[3 * j + 2];
        vec3 lm = gl_FrontFacing ? a.xyz : vec3(b.zw, c3.x);
        vec3 la = gl_FrontFacing ? vec3(a.w, b.xy) : c3.yzw;
        float vis = shadowVisibility(l, int(uLightPos[l].w + 0.5), uLightPos[l].xyz, uLightDir[l].xyz, uLightCone[l].w, vWorldPos, ng);
        mul += vis * lm;
        add += vis * la;
    }
#endif
#if HAS_OCCLUSION_MAP && REFLECTION != REFLECTION_PBR
    mul -= uKa * uOcclusionStrength * (1.0 - ao) * uAmbient;
#endif
#if HAS_EMISSIVE_MAP
    add += uEmissive * (em - 1.0);
#endif
#elif SHADING == SHADING_PHONG
    float len = length(vNormal);
    vec3 n = len > 0.0 ? vNormal / len : vec3(0.0, 0.0, 1.0);
#if HAS_NORMAL_MAP
    n = perturbNormal(n, vTangent, nt, uNormalScale);   // on the outward side
#endif
    if (!gl_FrontFacing) n = -n;   // two-sided: seen from the back
    shadeTerms(n, vWorldPos, mul, add);
#else
#error "SHADING: a sg::ShadingModel value this shader does not handle"
#endif
    c = albedo * mul + add;
#endif   // UNLIT
#endif   // SOLID
#if FOG != FOG_OFF
    float f = fogVisibility(length(vEyePos));   // eye-space distance, not just z
    c = f * c + (1.0 - f) * uFogColor;
#endif
#if LINEAR_TARGET
    fragColor = vec4(max(c, vec3(0.0)), clamp(alpha, 0.0, 1.0));
#else
    fragColor = vec4(clamp(c, 0.0, 1.0), clamp(alpha, 0.0, 1.0));
#endif
#endif   // OVERDRAW
}
