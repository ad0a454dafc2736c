// environment.h - the environment light of the pbr reflection model (image-based lighting),
// computed once per environment and shared by all three backends (docs/math.md,
// "Environment light"):
//   - radiance: an equirectangular map, +y up; direction d = (x, y, z) reads
//       u = 1/2 + atan2(x, -z) / (2 pi),  v = acos(y) / pi   (row 0 = straight up)
//     so the image's centre is the -z direction (what the default camera faces).
//   - specular: the map prefiltered with the GGX lobe for roughness r_k = k / (kLevels - 1),
//     level k of kLevels at (w0 >> k) x (h0 >> k) texels; a lookup at roughness r is the
//     bilinear sample of levels floor(lod) and floor(lod) + 1 mixed by fract(lod), lod = r (kLevels - 1)
//     (what GL's textureLod does with a mipmapped texture: the GL backend uploads these levels).
//   - diffuse: the cosine-weighted mean radiance around a normal, E(n) / pi, from the map's
//     spherical harmonics up to l = 2 (9 coefficients, Ramamoorthi and Hanrahan 2001).
// Rotation (about +y) and intensity come from the render settings at lookup time.
#pragma once

#include "scenegraph/frame.h"
#include "scenegraph/math.h"
#include "scenegraph/settings.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace rnd {

class EnvironmentMap {
public:
    static constexpr int kLevels = 6;
    struct Level {
        int width = 0, height = 0;
        std::vector<float> rgb;   // width x height x 3, row 0 = +y
    };

    // Builds the map from an equirectangular image (width x height linear RGB floats).
    EnvironmentMap(std::string name, int width, int height, const float* rgb);

    const std::string& name() const { return name_; }
    const Level& level(int k) const { return levels_[size_t(k)]; }
    // Irradiance coefficients: E(n)/pi = sum_i sh[i] Y_i(n) (the cosine convolution is in them).
    const std::array<sg::vec3, 9>& sh() const { return sh_; }

    // Lookups in the map's own frame (direction unit; no rotation or intensity).
    sg::vec3 specular(const sg::vec3& dir, float roughness) const;
    sg::vec3 diffuse(const sg::vec3& n) const;

private:
    std::string name_;
    std::vector<Level> levels_;
    std::array<sg::vec3, 9> sh_{};
};

// The 9 real spherical harmonics (l <= 2) at unit direction d, in the order of EnvironmentMap::sh.
std::array<float, 9> shBasis(const sg::vec3& d);
// (u, v) of a unit direction in the map's frame, as above.
sg::vec2 equirectUv(const sg::vec3& d);
// Bilinear sample of a level at (u, v): u wraps, v clamps (GL_REPEAT / GL_CLAMP_TO_EDGE).
sg::vec3 sampleLevel(const EnvironmentMap::Level& l, float u, float v);

// The built-in neutral environment ("default"): a soft studio: a bright overhead area, a warm key
// from the front left, a dim floor, grey walls. Its equirectangular image (width x 2 width / 2).
std::vector<float> defaultEnvironmentImage(int width, int height);

// An environment with the settings' rotation and intensity, as the shading code uses it.
struct EnvironmentLight {
    std::shared_ptr<const EnvironmentMap> map;
    float intensity = 1.0f;
    float cosRot = 1.0f, sinRot = 0.0f;   // world -> map: rotate by -rotation about +y
    bool background = false;

    sg::vec3 toMap(const sg::vec3& d) const { return {cosRot * d.x + sinRot * d.z, d.y, -sinRot * d.x + cosRot * d.z}; }
    sg::vec3 specular(const sg::vec3& worldDir, float roughness) const { return intensity * map->specular(toMap(worldDir), roughness); }
    sg::vec3 diffuse(const sg::vec3& worldNormal) const { return intensity * map->diffuse(toMap(worldNormal)); }
    sg::vec3 backgroundRadiance(const sg::vec3& worldDir) const { return specular(worldDir, 0.0f); }
};

// Writes the environment (backgroundRadiance along each pixel centre's view ray, sRGB bytes)
// into the pixels where nothing was drawn (depth 1 and still the background colour `bg`; a
// blended surface over the background changed it): the CPU rasterizer's background pass. With
// a linear frame (exposure or tone mapping on: its pixels, rows top-down) the radiance goes
// there instead, where the pixel still holds the linear background colour `bgLinear`.
struct Framebuffer;
void drawEnvironmentBackground(Framebuffer& target, const sg::FrameCamera& camera, const EnvironmentLight& env, const uint8_t bg[3],
                               sg::vec3* linear = nullptr, const sg::vec3& bgLinear = sg::vec3(0.0f));

// The environment the settings ask for, or none (an empty map) for reflection models other than
// pbr and for "none". Maps are built once per name and kept (the last few); a file that cannot
// be read gives no map and `error` says "FILE: reason" in one line.
EnvironmentLight environmentFor(const sg::RenderSettings& s, std::string* error = nullptr);
// Loads an equirectangular Radiance .hdr into linear RGB floats: "" on success, else the reason.
std::string loadRadianceHdr(const std::string& path, int& width, int& height, std::vector<float>& rgb);

}   // namespace rnd
