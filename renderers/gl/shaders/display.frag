// display.frag - the display pass of a linear frame (renderers/tone_map.h): each output pixel
// is the mean of its uSsaa x uSsaa texels of the resolved linear frame (the SSAA box filter, in
// linear light; 1 without SSAA), then the display transform (tone_map.glsl, prepended); the
// sRGB8 target encodes it. Alpha is averaged as it is (1 everywhere, as in the frame).
uniform sampler2D uFrame;        // the linear frame, RGBA16F, uSsaa x the output size
uniform int uSsaa;
uniform float uExposureScale;    // rnd::exposureScale(exposure)

layout(location = 0) out vec4 fragColor;

void main() {
    ivec2 base = ivec2(gl_FragCoord.xy) * uSsaa;
    vec4 sum = vec4(0.0);
    for (int j = 0; j < uSsaa; ++j)
        for (int i = 0; i < uSsaa; ++i) sum += texelFetch(uFrame, base + ivec2(i, j), 0);
    vec4 c = sum / float(uSsaa * uSsaa);
    fragColor = vec4(clamp(displayTransform(c.rgb, uExposureScale), 0.0, 1.0), clamp(c.a, 0.0, 1.0));
}
