// pbr.glsl - glTF's BRDF, KHR_lights_punctual's lights and the environment light of
// renderers/common/pbr.cpp and environment.cpp, function for function and name for name (keep
// them in step; renderers/pbr.h has the formulas). Included before lighting.glsl, which calls
// these for REFLECTION == REFLECTION_PBR.
//
// HAS_ENVIRONMENT (0 or 1, a program switch): the environment light is bound: uEnvMap (texture
// unit 5) holds EnvironmentMap's kLevels prefiltered levels as mip levels, uEnvSH its irradiance
// coefficients, uSplitSum (unit 6) the split-sum table.

const float PI = 3.14159265358979323846;

uniform float uMetallic;
uniform float uRoughness;
uniform float uGlossiness;
uniform float uIor;
uniform float uSpecularFactor;
uniform vec3 uSpecularColorFactor;
uniform bool uSpecularGlossiness;

#if HAS_ENVIRONMENT
uniform sampler2D uEnvMap;
uniform sampler2D uSplitSum;
uniform vec3 uEnvSH[9];
uniform float uEnvIntensity;
uniform vec2 uEnvRotation;   // cos, sin of the settings' rotation (EnvironmentLight::toMap)
uniform float uEnvLevels;    // EnvironmentMap::kLevels
#endif

// rnd::SurfaceCoefficients' pbr fields at this vertex or fragment (coefficientsOfMaterial in
// lighting.glsl sets them; mesh.frag changes them per texel by the maps). gAlbedo: rho.
float gMetallic, gRoughness, gF90Dielectric, gOcclusion;
vec3 gF0Dielectric, gSpecularF0, gAlbedo;
bool gSpecularGlossiness;

void pbrCoefficientsOfMaterial(float ks, vec3 specularColor) {
    gMetallic = uMetallic;
    gRoughness = uRoughness;
    float f = (uIor - 1.0) / (uIor + 1.0);
    gF0Dielectric = min(f * f * uSpecularColorFactor, vec3(1.0)) * uSpecularFactor;
    gF90Dielectric = uSpecularFactor;
    gSpecularGlossiness = uSpecularGlossiness;
    gSpecularF0 = vec3(0.04);
    if (uSpecularGlossiness) {
        gSpecularF0 = ks * specularColor;
        gRoughness = 1.0 - uGlossiness;
    }
    gOcclusion = 1.0;
    gAlbedo = vec3(1.0);
}

struct PbrPoint {
    vec3 cdiffFactor;
    vec3 f0;
    float f90;
    float alpha;
    float roughness;
};

float usableRoughness(float r) { return clamp(r, 1e-3, 1.0); }

PbrPoint pbrPoint(vec3 albedo) {
    PbrPoint p;
    if (gSpecularGlossiness) {
        p.f0 = gSpecularF0;
        p.f90 = 1.0;
        p.cdiffFactor = vec3(1.0 - max(gSpecularF0.r, max(gSpecularF0.g, gSpecularF0.b)));
    } else {
        float m = clamp(gMetallic, 0.0, 1.0);
        p.f0 = mix(gF0Dielectric, albedo, m);
        p.f90 = gF90Dielectric + (1.0 - gF90Dielectric) * m;
        p.cdiffFactor = vec3(1.0 - m);
    }
    p.roughness = usableRoughness(gRoughness);
    p.alpha = p.roughness * p.roughness;
    return p;
}

// The height-correlated Smith visibility V = G / (4 n.l n.v).
float visibility(float nl, float nv, float a2) {
    float gv = nl * sqrt(nv * nv * (1.0 - a2) + a2);
    float gl = nv * sqrt(nl * nl * (1.0 - a2) + a2);
    float d = gv + gl;
    return d > 0.0 ? 0.5 / d : 0.0;
}

// One light's terms (rnd::pbrLightTerms), added to mul and add.
void pbrLightTerms(PbrPoint p, vec3 n, vec3 v, vec3 toLight, vec3 radiance, inout vec3 mul, inout vec3 add) {
    float nl = dot(n, toLight);
    if (nl <= 0.0) return;
    float nv = max(dot(n, v), 0.0);
    vec3 h = toLight + v;
    float hl = length(h);
    h = hl > 0.0 ? h / hl : n;
    float vh = max(dot(v, h), 0.0), nh = max(dot(n, h), 0.0);
    vec3 F = p.f0 + (vec3(p.f90) - p.f0) * pow(1.0 - vh, 5.0);
    float a2 = p.alpha * p.alpha;
    float q = nh * nh * (a2 - 1.0) + 1.0;
    float D = a2 / (PI * q * q);
    vec3 ln = radiance * nl;
    mul += ln * (vec3(1.0) - F) * p.cdiffFactor * (1.0 / PI);
    add += ln * F * (D * visibility(nl, nv, a2));
}

#if HAS_ENVIRONMENT
// rnd::equirectUv: u = 1/2 + atan2(x, -z) / (2 pi), v = acos(y) / pi (row 0 = +y; uploaded
// first, so at t = 0).
vec2 equirectUv(vec3 d) { return vec2(0.5 + atan(d.x, -d.z) / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI); }

vec3 envToMap(vec3 d) { return vec3(uEnvRotation.x * d.x + uEnvRotation.y * d.z, d.y, -uEnvRotation.y * d.x + uEnvRotation.x * d.z); }

// EnvironmentLight::specular: level roughness * (kLevels - 1), trilinear.
vec3 envSpecular(vec3 dir, float roughness) {
    return uEnvIntensity * textureLod(uEnvMap, equirectUv(envToMap(dir)), clamp(roughness, 0.0, 1.0) * (uEnvLevels - 1.0)).rgb;
}

// EnvironmentLight::diffuse: E(n)/pi from the 9 coefficients (rnd::shBasis).
vec3 envDiffuse(vec3 n) {
    vec3 d = envToMap(n);
    vec3 e = uEnvSH[0] * 0.282095 + uEnvSH[1] * (0.488603 * d.y) + uEnvSH[2] * (0.488603 * d.z) + uEnvSH[3] * (0.488603 * d.x) +
             uEnvSH[4] * (1.092548 * d.x * d.y) + uEnvSH[5] * (1.092548 * d.y * d.z) + uEnvSH[6] * (0.315392 * (3.0 * d.z * d.z - 1.0)) +
             uEnvSH[7] * (1.092548 * d.x * d.z) + uEnvSH[8] * (0.546274 * (d.x * d.x - d.y * d.y));
    return uEnvIntensity * max(e, vec3(0.0));
}

// rnd::splitSum: the 32 x 32 table, bilinear at the texel centres, edges clamped.
vec2 splitSum(float nv, float roughness) { return texture(uSplitSum, vec2(clamp(nv, 0.0, 1.0), clamp(roughness, 0.0, 1.0))).rg; }

// rnd::pbrEnvironmentTerms, added to mul and add.
void pbrEnvironmentTerms(PbrPoint p, vec3 n, vec3 v, float occlusion, inout vec3 mul, inout vec3 add) {
    float ndv = dot(n, v);
    float nv = clamp(ndv, 0.0, 1.0);
    vec2 ab = splitSum(nv, p.roughness);
    vec3 fssEss = p.f0 * ab.x + vec3(p.f90 * ab.y);
    float ems = 1.0 - (ab.x + ab.y);
    vec3 fAvg = p.f0 + (vec3(1.0) - p.f0) * (1.0 / 21.0);
    vec3 fmsEms = ems * fssEss * fAvg / (vec3(1.0) - ems * fAvg);
    vec3 r = 2.0 * ndv * n - v;
    vec3 irradiance = envDiffuse(n), radiance = envSpecular(r, p.roughness);
    mul += occlusion * (vec3(1.0) - fssEss - fmsEms) * p.cdiffFactor * irradiance;
    add += occlusion * (fssEss * radiance + fmsEms * irradiance);
}
#endif
