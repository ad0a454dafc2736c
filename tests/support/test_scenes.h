// test_scenes.h - frames built directly as sg::FrameInput, shared by the GL, raster, ray-caster
// and conformance tests (one copy in the test_support library instead of sources compiled
// into several binaries): camera/mesh/light helpers, the GL baseline scenes, the agreement
// scenes of the CPU backends and the reference scenes of the BackendConformance suite.
#pragma once

#include "renderers/framebuffer.h"
#include "scenegraph/frame.h"
#include "test_support.h"

#include <string>
#include <vector>

namespace test_scenes {

// A frame with a camera at `eye` looking at `center` (up +y), black background, no ambient.
sg::FrameInput makeFrame(int width, int height, const sg::Projection& projection, const sg::vec3& eye, const sg::vec3& center);
void addMesh(sg::FrameInput& f, const sg::Mesh& mesh, const sg::Material& m, const sg::mat4& world = sg::mat4(1.0f),
             sg::TexturePtr texture = nullptr);
void addMesh(sg::FrameInput& f, sg::MeshPtr mesh, const sg::Material& m, const sg::mat4& world = sg::mat4(1.0f), sg::TexturePtr texture = nullptr);
// A DrawMesh of `mesh` at `world` (normal matrix and mirroring derived) with base colour `color`.
sg::DrawMesh meshInstance(sg::MeshPtr mesh, const sg::mat4& world, const sg::vec3& color);
sg::DrawLight directional(const sg::vec3& direction, const sg::vec3& radiance);
sg::DrawLight point(const sg::vec3& position, const sg::vec3& radiance, bool inverseSquare);
sg::DrawLight spot(const sg::vec3& position, const sg::vec3& direction, const sg::vec3& radiance, float innerDeg, float outerDeg);
sg::Material unlit(const sg::vec3& color);
using testing_support::checker;   // tests/support: shared by the GL, raster and ray-caster tests

// A square quad in the z = 0 plane facing +z, uv (0,0) bottom-left .. (1,1) top-right.
sg::Mesh quad(float half);

// The GL baseline scenes: name -> frame at the given size.
std::vector<std::string> baselineNames();
sg::FrameInput baselineFrame(const std::string& name, int width, int height);

// Raster-vs-GL agreement scenes: a textured, tilted, receding floor + a box (minification and
// magnification), and a floor triangle crossing the camera plane (near-plane clipping).
sg::FrameInput texturedFloorFrame(int w, int h, sg::FilterMode filter, sg::WrapMode wrap, sg::ProjectionType proj, sg::ShadingModel shading);
sg::FrameInput nearPlaneFrame(int w, int h, sg::ProjectionType proj);

// Ray-caster-vs-raster agreement scene: sphere, rotated box (specular), ground, open cylinder
// (back faces visible) and a mirrored sphere, a point and a directional light; shadows,
// reflections and AA off. The camera is framed for a w x h viewport.
sg::FrameInput triangleAgreementFrame(const sg::Projection& proj, int w, int h);
// A 64x64 checker of 4-texel squares (250/255 and 10/255 grey), trilinear, repeating.
std::shared_ptr<sg::Texture> minificationChecker();

// --- Reference scenes of the BackendConformance suite (tests/renderers/conformance). Every parameter a
// check needs (material, light, camera, settings) is read back from the returned frame.

// A sphere of radius 1 at the origin (uvSphere with `slices` x slices/2), camera at (0, 0, 3.2)
// looking at the origin (perspective, 45 degrees), one light of the given kind (directional
// from the upper left front, or a point light there without attenuation), ambient light, a
// material with ka, kd, ks, shininess set and vertex colours never above 1.
enum class SphereLight { Directional, Point };
sg::FrameInput litSphereFrame(int w, int h, sg::ShadingModel shading, sg::ReflectionModel reflection, SphereLight light, int slices);
// An unlit floor (y = -1, one quad of half size 40, colour (0.85, 0.35, 0.15)) receding from a
// camera at (0, 0.6, 3) looking down the -z axis, fog of the given mode toward (0.3, 0.45, 0.7).
sg::FrameInput fogPlaneFrame(int w, int h, sg::FogMode mode);
// A 4x4 texture of 16 distinct colours, nearest filtering, clamp to edge.
std::shared_ptr<sg::Texture> texelGrid();
// quad(1) with texelGrid() (unlit white) seen head-on through an orthographic camera
// (tilted == false), or tilted back 50 degrees about x and turned 20 degrees about y under a
// perspective camera (tilted == true: perspective-correct interpolation matters).
sg::FrameInput texturedQuadFrame(int w, int h, bool tilted);
// An unlit white box (half extents 0.6, 0.4, 0.5) turned about y and x, at (0.2, -0.1, -0.3),
// seen from (0, 0, 5) under `proj` (ortho half height 1.5): for the footprint checks.
sg::FrameInput projectedBoxFrame(int w, int h, const sg::Projection& proj);
// An unlit white quad(1.2) turned 20 degrees about z, camera at (0, 0, 5), orthographic (half
// height 1.5) so its straight edges have known window-space lines; AA as given.
sg::FrameInput aaEdgeFrame(int w, int h, sg::AAMode aa, int rate);

// Channel c of pixel (x, y) (x right, y down from the top row).
inline int channel(const rnd::Framebuffer& fb, int x, int y, int c) { return fb.pixel(x, y)[c]; }

}   // namespace test_scenes
