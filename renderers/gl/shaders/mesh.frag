// mesh.frag - per-fragment part of every shading model, texture, unlit, fog, wireframe.
// Prefix as in mesh.vert. Output is linear; the sRGB framebuffer encodes it.
in vec3 vWorldPos;
in vec3 vEyePos;
in vec3 vNormal;
in vec2 vUv;
in vec2 vUv1;
in vec4 vColor;
in vec4 vTangent;
#if SHADING == SHADING_GOURAUD
in vec3 vMulFront;
in vec3 vAddFront;
in vec3 vMulBack;
in vec3 vAddBack;
#endif

uniform sampler2D uTexture;
uniform bool uHasTexture;
// Material maps (rnd::sampleMaps / coefficientsAt in renderers/common/shading.cpp).
uniform sampler2D uEmissiveMap;     // sRGB colour, x uEmissive
uniform sampler2D uOcclusionMap;    // R: ambient occlusion
uniform sampler2D uMetalRoughMap;   // G: roughness, B: metallic (linear)
uniform bool uHasEmissiveMap;
uniform bool uHasOcclusionMap;
uniform bool uHasMetalRoughMap;
uniform sampler2D uNormalMap;       // tangent-space normal, linear RGB = 0.5 n + 0.5
uniform bool uHasNormalMap;         // set only for meshes with tangents
uniform float uNormalScale;
uniform int uUv1Maps;               // sg::Material::uv1Maps: MAP_* bits of the maps that sample vUv1
uniform float uOcclusionStrength;
uniform float uMetallic;
uniform float uRoughness;
uniform bool uSpecGloss;            // uMetalRoughMap holds a specular-glossiness texture (sRGB RGB, A glossiness)
uniform float uGlossiness;
uniform bool uUnlit;        // colour = albedo + emissive (material unlit, lines, points)
uniform float uAlpha;       // material alpha (x texture alpha x vertex alpha)
uniform int uAlphaMode;     // ALPHA_OPAQUE, ALPHA_MASK, ALPHA_BLEND (sg::AlphaMode values)
uniform float uAlphaCutoff;
uniform bool uOverdraw;     // the overdraw view's pass: 1.0 for every fragment, nothing else (additive blending counts them)
uniform bool uSolid;        // wireframe overlay: uSolidColor (fogged)
uniform vec3 uSolidColor;
uniform int uFogMode;       // FOG_OFF, FOG_LINEAR, FOG_EXP, FOG_EXP2 (sg::FogMode values)
uniform vec3 uFogColor;
uniform vec3 uFogParams;    // start, end, density

uniform uint uDrawable;        // Framebuffer::drawable of this draw
uniform uint uPrimitiveBase;   // the draw call's first primitive in its mesh (0xffffffff: analytic)

layout(location = 0) out vec4 fragColor;
// Visibility (written only when the target has the attachment, rnd::RenderConfig::visibility):
// drawable, and the primitive index within its mesh.
layout(location = 1) out uvec2 fragId;

// The UV set a map samples (rnd::sampleMaps): vUv1 where its MAP_* bit is set in uUv1Maps.
vec2 mapUv(int bit) { return (uUv1Maps & bit) != 0 ? vUv1 : vUv; }

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
    if (uFogMode == FOG_LINEAR) return clamp((uFogParams.y - d) / (uFogParams.y - uFogParams.x), 0.0, 1.0);
    if (uFogMode == FOG_EXP) return exp(-uFogParams.z * d);
    if (uFogMode == FOG_EXP2) { float x = uFogParams.z * d; return exp(-x * x); }
    return 1.0;
}

void main() {
    fragId = uvec2(uDrawable, uPrimitiveBase == 0xffffffffu ? uPrimitiveBase : uPrimitiveBase + uint(gl_PrimitiveID));
    if (uOverdraw) {   // before any discard: a fragment counts whatever its alpha
        fragColor = vec4(1.0);
        return;
    }
    vec3 c;
    float alpha = 1.0;
    if (uSolid) {
        c = uSolidColor;
    } else {
        vec3 albedo = uBaseColor * vColor.rgb;
        alpha = uAlpha * vColor.a;
        if (uHasTexture) {
            vec4 t = texture(uTexture, vUv);   // sRGB texture: colour decoded to linear, alpha as stored
            albedo *= t.rgb;
            alpha *= t.a;
        }
        // The maps, sampled before any discard (implicit derivatives): coefficientsAt().
        float ao = uHasOcclusionMap ? texture(uOcclusionMap, mapUv(MAP_OCCLUSION)).r : 1.0;
        vec3 em = uHasEmissiveMap ? texture(uEmissiveMap, mapUv(MAP_EMISSIVE)).rgb : vec3(1.0);
        vec3 nt = uHasNormalMap ? texture(uNormalMap, mapUv(MAP_NORMAL)).rgb : vec3(0.5, 0.5, 1.0);
        coefficientsOfMaterial();
        gKa *= 1.0 + uOcclusionStrength * (ao - 1.0);
        gEmissive *= em;
        if (uHasMetalRoughMap) {
            vec4 mr = texture(uMetalRoughMap, mapUv(MAP_METALLIC_ROUGHNESS));
            if (uSpecGloss) {   // rnd::coefficientsAt, specular-glossiness
                vec3 spec = uKs * uSpecColor * mr.rgb;
                float ks = max(spec.r, max(spec.g, spec.b));
                phongFromMetallicRoughness(0.0, 1.0 - uGlossiness * mr.a);   // for the exponent
                gKd = 1.0;
                gKs = ks;
                gSpecColor = ks > 0.0 ? spec / ks : vec3(1.0);
                gSpecTinted = false;
            } else {
                phongFromMetallicRoughness(uMetallic * mr.b, uRoughness * mr.g);
            }
        }
        if (uAlphaMode == ALPHA_MASK) {
            if (alpha < uAlphaCutoff) discard;   // cut-out
            alpha = 1.0;
        } else if (uAlphaMode == ALPHA_OPAQUE) {
            alpha = 1.0;
        } else if (uAlphaMode != ALPHA_BLEND) {
            alpha = 0.0;   // unreachable: every sg::AlphaMode is handled above
        }
        if (uUnlit) {
            c = albedo + gEmissive;
        } else {
            vec3 mul, add;
#if SHADING == SHADING_FLAT
            // Face normal of the world-space triangle; cross(dp/dx, dp/dy) always points to
            // the side being seen, i.e. it is already flipped toward the viewer.
            vec3 n = normalize(cross(dFdx(vWorldPos), dFdy(vWorldPos)));
            shadeTerms(n, vWorldPos, mul, add);
#elif SHADING == SHADING_GOURAUD
            // Lit at the vertices with the material's coefficients; occlusion and emissive maps
            // still apply exactly here (applyMapsToTerms): both terms are additive.
            mul = (gl_FrontFacing ? vMulFront : vMulBack) - uKa * uOcclusionStrength * (1.0 - ao) * uAmbient;
            add = (gl_FrontFacing ? vAddFront : vAddBack) + uEmissive * (em - 1.0);
#elif SHADING == SHADING_PHONG
            float len = length(vNormal);
            vec3 n = len > 0.0 ? vNormal / len : vec3(0.0, 0.0, 1.0);
            if (uHasNormalMap) n = perturbNormal(n, vTangent, nt, uNormalScale);   // on the outward side
            if (!gl_FrontFacing) n = -n;                 // two-sided: seen from the back
            shadeTerms(n, vWorldPos, mul, add);
#else
#error "SHADING: a sg::ShadingModel value this shader does not handle"
#endif
            c = albedo * mul + add;
        }
    }
    if (uFogMode != FOG_OFF) {
        float f = fogVisibility(length(vEyePos));   // eye-space distance, not just z
        c = f * c + (1.0 - f) * uFogColor;
    }
    fragColor = vec4(clamp(c, 0.0, 1.0), clamp(alpha, 0.0, 1.0));
}
