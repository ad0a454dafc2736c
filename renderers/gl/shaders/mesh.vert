// mesh.vert - world-space transform for all shading models; Gouraud lights the vertices here
// (front and back side, chosen per fragment by gl_FrontFacing; with shadow maps the shadowed
// lights' terms apart, for mesh.frag to scale by the fragment's visibility). The renderer prepends
// "#version 330 core", SHADING (SHADING_FLAT, SHADING_GOURAUD or SHADING_PHONG), MAX_LIGHTS, the
// draw's feature switches (see mesh.frag) and lighting.glsl. Outputs the fragment shader of the
// same features does not read are not written (each one costs llvmpipe setup per triangle and
// interpolation per fragment).
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUv;
layout(location = 3) in vec4 aColor;
layout(location = 4) in vec4 aTangent;   // xyz, handedness (normal-mapped meshes only)
layout(location = 5) in vec2 aUv1;       // the second UV set (meshes that have one)

uniform mat4 uModel;
uniform mat3 uNormalMatrix;
uniform mat4 uViewProj;
uniform mat4 uView;
uniform float uPointSize;

out vec3 vWorldPos;
#if FOG != FOG_OFF
out vec3 vEyePos;
#endif
out vec3 vNormal;
#if USES_UV
out vec2 vUv;
#endif
#if USES_UV1
out vec2 vUv1;
#endif
#if VERTEX_COLORS
out vec4 vColor;
#endif
#if HAS_NORMAL_MAP
out vec4 vTangent;   // world xyz; w: handedness, flipped by a mirroring model matrix
#endif
#if SHADING == SHADING_FLAT
flat out vec3 vFlatPos;      // the provoking (first) vertex: where flat shading evaluates the model
flat out vec3 vFlatAlbedo;   // and its albedo (pbr: F0 of metals)
#endif
#if SHADING == SHADING_GOURAUD
out vec3 vMulFront;
out vec3 vAddFront;
out vec3 vMulBack;
out vec3 vAddBack;
#if SHADOW_SLOTS > 0
// The shadowed lights' own terms (lighting.glsl's gLightMul/gLightAdd), 12 floats a light packed
// in three vec4: front mul, front add, back mul, back add (mesh.frag unpacks them).
out vec4 vShadowed[3 * SHADOW_SLOTS];
#endif
#endif

void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);
    vWorldPos = world.xyz;
#if FOG != FOG_OFF
    vEyePos = (uView * world).xyz;
#endif
    vNormal = uNormalMatrix * aNormal;
#if USES_UV
    vUv = aUv;
#endif
#if USES_UV1
    vUv1 = aUv1;
#endif
#if VERTEX_COLORS
    vColor = aColor;
#endif
#if HAS_NORMAL_MAP
    vTangent = vec4(mat3(uModel) * aTangent.xyz, determinant(mat3(uModel)) < 0.0 ? -aTangent.w : aTangent.w);
#endif
    gl_Position = uViewProj * world;
    gl_PointSize = uPointSize;
#if SHADING == SHADING_FLAT
    vFlatPos = world.xyz;
#if VERTEX_COLORS
    vFlatAlbedo = uBaseColor * aColor.rgb;
#else
    vFlatAlbedo = uBaseColor;
#endif
#endif
#if SHADING == SHADING_GOURAUD
    coefficientsOfMaterial();   // the maps apply per fragment (mesh.frag)
#if VERTEX_COLORS
    gAlbedo = uBaseColor * aColor.rgb;   // pbr: the vertex's albedo (rnd::ShadeExtras)
#else
    gAlbedo = uBaseColor;
#endif
    float len = length(vNormal);
    vec3 n = len > 0.0 ? vNormal / len : vec3(0.0, 0.0, 1.0);
    shadeTerms(n, world.xyz, vMulFront, vAddFront);
#if SHADOW_SLOTS > 0
    vec3 frontMul[SHADOW_SLOTS], frontAdd[SHADOW_SLOTS];
    for (int j = 0; j < SHADOW_SLOTS; ++j) {
        frontMul[j] = gLightMul[j];
        frontAdd[j] = gLightAdd[j];
    }
#endif
    shadeTerms(-n, world.xyz, vMulBack, vAddBack);   // two-sided: seen from the back
#if SHADOW_SLOTS > 0
    for (int j = 0; j < SHADOW_SLOTS; ++j) {
        vShadowed[3 * j] = vec4(frontMul[j], frontAdd[j].x);
        vShadowed[3 * j + 1] = vec4(frontAdd[j].yz, gLightMul[j].xy);
        vShadowed[3 * j + 2] = vec4(gLightMul[j].z, gLightAdd[j]);
    }
#endif
#endif
}
