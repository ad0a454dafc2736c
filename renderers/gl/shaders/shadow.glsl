// shadow.glsl - the shadow-map lookup of renderers/common/shadow_map.cpp, name for name and
// operation for operation (pointLightFace, shadowVisibility; keep the two in step;
// renderers/shadow_map.h has the formulas). Included after pbr.glsl and before lighting.glsl,
// whose lightTerms multiplies each light's radiance by shadowVisibility (both reflection
// families; per-pixel and flat shading), and read by mesh.frag for Gouraud's shadowed lights.
//
// SHADOWS (0 or 1, part of the frame setup's key): this frame has shadow maps (rnd::planShadows
// gave views); with 0 nothing here exists and lighting costs what it did without shadows. SHADOW_PCF: k of the k x k filter (1 without PCF), a
// constant so that the loops unroll. SHADOW_PCSS: 1 for PCSS (the k x k taps spread over the
// penumbra). MAX_SHADOW_VIEWS, PCSS_SEARCH, PCSS_MAX_RADIUS: rnd::kMaxShadowViews, kPcssSearch,
// kPcssMaxRadius.
// The maps (gl_shadows.cpp): one layer per plan view of uShadowMaps (texture unit 7, depth
// DEPTH_COMPONENT32F, nearest, no compare mode, read with texelFetch), row 0 at v = 0. The plan
// in the uniform block ShadowPlan (binding point 0), std140, as gl_shadows.cpp fills it.

#if SHADOWS
uniform sampler2DArray uShadowMaps;

layout(std140) uniform ShadowPlan {
    mat4 uShadowViewProj[MAX_SHADOW_VIEWS];   // ShadowView::viewProj
    vec4 uShadowAxis[MAX_SHADOW_VIEWS];       // the third row of ShadowView::view: -dot(axis, (p, 1)) = depth along the axis
    vec4 uShadowRowX[MAX_SHADOW_VIEWS];       // its first and second rows
    vec4 uShadowRowY[MAX_SHADOW_VIEWS];
    vec4 uShadowView[MAX_SHADOW_VIEWS];       // x: perspective (1) or orthographic (0), y: nearZ, z: farZ, w: texelAtUnit
    ivec4 uShadowLight[MAX_LIGHTS];           // x: first view, y: view count (0: no map, lit)
    vec4 uShadowParams;                       // x: size N, y: depthBias, z: normalBias (texels)
};

// The map of a point light's face for the direction from the light to p (views: first of six).
int pointLightFace(vec3 d) {
    float ax = abs(d.x), ay = abs(d.y), az = abs(d.z);
    if (ax >= ay && ax >= az) return d.x > 0.0 ? 0 : 1;
    if (ay >= az) return d.y > 0.0 ? 2 : 3;
    return d.z > 0.0 ? 4 : 5;
}

// The receiver's depth at texel (i, j)'s centre (its plane through the biased depth dRecv at
// (su, sv), slopes per texel), and the depth stored there (outside the map: lit).
float shadowReceiver(int i, int j, float dRecv, float su, float sv, float slopeX, float slopeY) {
    return dRecv + slopeX * (float(i) + 0.5 - su) + slopeY * (float(j) + 0.5 - sv);
}
float shadowStored(int i, int j, int N, int vi) {
    if (i < 0 || j < 0 || i >= N || j >= N) return 3.0e38;   // (+infinity in the C++)
    return texelFetch(uShadowMaps, ivec3(i, j, vi), 0).r;
}
// PCSS's shift of its taps inside their grid cells (shadow_map.cpp's pcssJitter, bit for bit).
uint pcssHash(uint x) {
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}
float pcssJitter(int i, int j, int view, int axis) {
    uint h = pcssHash(uint(i) * 73856093u ^ uint(j) * 19349663u ^ uint(view) * 83492791u);
    if (axis != 0) h = pcssHash(h);
    return float(h >> 8u) * (1.0 / 16777216.0);
}
// Fraction of light `light` (its type, position and direction: the DrawLight of the C++) that
// reaches world point p (unit surface normal ng: the shading normal, or flat's and Gouraud's
// face normal; either side), by the
// plan's maps: 1 lit, 0 shadowed, between at PCF edges.
float shadowVisibility(int light, int type, vec3 lightPosition, vec3 lightDirection, float lightSize, vec3 p, vec3 ng) {
    if (uShadowLight[light].y == 0) return 1.0;
    int vi = uShadowLight[light].x;
    if (type == LIGHT_POINT) vi += pointLightFace(p - lightPosition);
    vec4 axis = uShadowAxis[vi], view = uShadowView[vi];
    bool perspective = view.x > 0.5;
    float nearZ = view.y, farZ = view.z, texelAtUnit = view.w;
    vec3 toLight = type == LIGHT_DIRECTIONAL ? -lightDirection : lightPosition - p;
    vec3 n = dot(ng, toLight) < 0.0 ? -ng : ng;   // the side the light is on
    // The texel's size at p, the normal offset, then the receiver's depth less the depth bias.
    float depthP = -(axis.x * p.x + axis.y * p.y + axis.z * p.z + axis.w);
    float t = perspective ? texelAtUnit * depthP : texelAtUnit;
    vec3 q = p + uShadowParams.z * t * n;
    vec4 c = uShadowViewProj[vi] * vec4(q, 1.0);
    if (!(c.w > 0.0)) return 1.0;
    float u = (c.x / c.w) * 0.5 + 0.5, w = (c.y / c.w) * 0.5 + 0.5;
    float zq = -(axis.x * q.x + axis.y * q.y + axis.z * q.z + axis.w);
    float zb = zq - uShadowParams.y * t;
    // The biased depth as the maps store depth (linear, 0 at near, 1 at far); each tap compares
    // the receiver's plane at the tap's texel centre (receiver-plane depth bias, slope clamped at 4).
    float range = farZ - nearZ;
    if (!(range > 0.0)) return 1.0;
    float dRecv = (zb - nearZ) / range;
    vec4 rx = uShadowRowX[vi], ry = uShadowRowY[vi];
    vec3 nl = vec3(rx.x * n.x + rx.y * n.y + rx.z * n.z, ry.x * n.x + ry.y * n.y + ry.z * n.z, axis.x * n.x + axis.y * n.y + axis.z * n.z);
    // The receiver's tilt against the ray to the light (a perspective map's rays leave its axis
    // by up to 45 degrees at a cube face's edge), clamped at a slope of 4.
    float cosRay = perspective ? dot(n, normalize(toLight)) : nl.z;
    float nz = max(cosRay, 0.25 * sqrt(nl.x * nl.x + nl.y * nl.y));   // the light's side: > 0
    float slopeX = nz > 0.0 ? nl.x / nz * t / range : 0.0, slopeY = nz > 0.0 ? nl.y / nz * t / range : 0.0;   // per texel
    int N = int(uShadowParams.x + 0.5);
    const int k = SHADOW_PCF;
    float su = u * float(N), sv = w * float(N);
#if SHADOW_PCSS
    // PCSS (docs/math.md, "Soft shadows"): the blocker search, then k x k taps over the penumbra.
    float zR = zq;
    float kf = float(k);
    int ci = int(floor(su)), cj = int(floor(sv));
    float jx = pcssJitter(ci, cj, vi, 0), jy = pcssJitter(ci, cj, vi, 1);
    float reachNear = (perspective ? lightSize * (zR - nearZ) / max(nearZ, 1e-6) : lightSize * (zR - nearZ)) / t;
    float rs = clamp(reachNear, 0.5 * kf, float(PCSS_MAX_RADIUS));
    float blockers = 0.0, depthSum = 0.0;
    for (int b = 0; b < PCSS_SEARCH * PCSS_SEARCH; ++b) {
        float ox = ((float(b % PCSS_SEARCH) + jx) / float(PCSS_SEARCH) * 2.0 - 1.0) * rs;
        float oy = ((float(b / PCSS_SEARCH) + jy) / float(PCSS_SEARCH) * 2.0 - 1.0) * rs;
        int i = int(floor(su + ox)), j = int(floor(sv + oy));
        float d = shadowStored(i, j, N, vi);
        if (d < shadowReceiver(i, j, dRecv, su, sv, slopeX, slopeY)) {
            blockers += 1.0;
            depthSum += d;
        }
    }
    if (blockers == 0.0) return 1.0;
    float zB = nearZ + depthSum / blockers * range;
    float reachB = (perspective ? lightSize * (zR - zB) / max(zB, 1e-6) : lightSize * (zR - zB)) / t;
    float rf = clamp(reachB, 0.5 * kf, float(PCSS_MAX_RADIUS));
    int lit = 0;
    for (int b = 0; b < k * k; ++b) {
        float ox = ((float(b % k) + jx) / kf * 2.0 - 1.0) * rf, oy = ((float(b / k) + jy) / kf * 2.0 - 1.0) * rf;
        int i = int(floor(su + ox)), j = int(floor(sv + oy));
        lit += shadowReceiver(i, j, dRecv, su, sv, slopeX, slopeY) <= shadowStored(i, j, N, vi) ? 1 : 0;
    }
#else
    int i0 = int(floor(su - 0.5 * float(k) + 0.5)), j0 = int(floor(sv - 0.5 * float(k) + 0.5));
    int lit = 0;
    for (int dj = 0; dj < k; ++dj)   // j = j0 .. j0 + k - 1 (constant bounds: unrolled)
        for (int di = 0; di < k; ++di) {
            int i = i0 + di, j = j0 + dj;
            lit += shadowReceiver(i, j, dRecv, su, sv, slopeX, slopeY) <= shadowStored(i, j, N, vi) ? 1 : 0;
        }
#endif
    return float(lit) / float(k * k);
}
#endif
