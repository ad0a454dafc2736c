// mesh.vert - world-space transform for all shading models; Gouraud lights the vertices here
// (front and back side, chosen per fragment by gl_FrontFacing). The renderer prepends
// "#version 330 core", SHADING (SHADING_FLAT, SHADING_GOURAUD or SHADING_PHONG), MAX_LIGHTS and lighting.glsl.
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
out vec3 vEyePos;
out vec3 vNormal;
out vec2 vUv;
out vec2 vUv1;
out vec4 vColor;
out vec4 vTangent;   // world xyz; w: handedness, flipped by a mirroring model matrix
#if SHADING == SHADING_GOURAUD
out vec3 vMulFront;
out vec3 vAddFront;
out vec3 vMulBack;
out vec3 vAddBack;
#endif

void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);
    vWorldPos = world.xyz;
    vEyePos = (uView * world).xyz;
    vNormal = uNormalMatrix * aNormal;
    vUv = aUv;
    vUv1 = aUv1;
    vColor = aColor;
    vTangent = vec4(mat3(uModel) * aTangent.xyz, determinant(mat3(uModel)) < 0.0 ? -aTangent.w : aTangent.w);
    gl_Position = uViewProj * world;
    gl_PointSize = uPointSize;
#if SHADING == SHADING_GOURAUD
    coefficientsOfMaterial();   // the maps apply per fragment (mesh.frag)
    float len = length(vNormal);
    vec3 n = len > 0.0 ? vNormal / len : vec3(0.0, 0.0, 1.0);
    shadeTerms(n, world.xyz, vMulFront, vAddFront);
    shadeTerms(-n, world.xyz, vMulBack, vAddBack);   // two-sided: seen from the back
#endif
}
