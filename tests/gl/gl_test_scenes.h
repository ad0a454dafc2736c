// gl_test_scenes.h - small frames built directly as sg::FrameInput for the GL tests: a camera
// helper, mesh/light helpers and the scenes the baseline images show.
#pragma once

#include "renderers/framebuffer.h"
#include "scenegraph/frame.h"
#include "test_support.h"

#include <string>
#include <vector>

namespace gltest {

// A frame with a camera at `eye` looking at `center` (up +y), black background, no ambient.
sg::FrameInput makeFrame(int width, int height, const sg::Projection& projection, const sg::vec3& eye, const sg::vec3& center);
void addMesh(sg::FrameInput& f, const sg::Mesh& mesh, const sg::Material& m, const sg::mat4& world = sg::mat4(1.0f),
             sg::TexturePtr texture = nullptr);
void addMesh(sg::FrameInput& f, sg::MeshPtr mesh, const sg::Material& m, const sg::mat4& world = sg::mat4(1.0f), sg::TexturePtr texture = nullptr);
sg::DrawLight directional(const sg::vec3& direction, const sg::vec3& radiance);
sg::DrawLight point(const sg::vec3& position, const sg::vec3& radiance, bool inverseSquare);
sg::DrawLight spot(const sg::vec3& position, const sg::vec3& direction, const sg::vec3& radiance, float innerDeg, float outerDeg);
sg::Material unlit(const sg::vec3& color);
using testing_support::checker;   // tests/support: shared by the GL, raster and ray-caster tests

// The baseline scenes: name -> frame at the given size.
std::vector<std::string> baselineNames();
sg::FrameInput baselineFrame(const std::string& name, int width, int height);

// Channel c of pixel (x, y) (x right, y down from the top row).
inline int channel(const rnd::Framebuffer& fb, int x, int y, int c) { return fb.pixel(x, y)[c]; }

}   // namespace gltest
