// texture_orientation_test.cpp - texture orientation of real files, in every backend: glTF puts
// uv (0,0) at the image's first (top-left) pixel with v going down; OBJ puts v = 0 at the
// image's bottom row. A quad whose image is red | green on the top row and blue | white on the
// bottom, mapped so that the image appears upright, must show red at the top left, green top
// right, blue bottom left and white bottom right, seen from the front, in all three backends
// and from both formats.
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "render_support.h"
#include "renderers/renderer.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <fstream>

namespace fs = std::filesystem;

namespace {

// 2x2 image, rows top to bottom: red, green / blue, white.
void writeQuadrantsPng(const fs::path& path) {
    const uint8_t rgba[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
    fs::remove(path);
    ASSERT_EQ(assets::writePng(path, 2, 2, rgba, /*overwrite=*/true), "");
}

// A glTF quad in the z = 0 plane facing +z, uv (0,0) at its top-left corner (x = -1, y = 1).
fs::path writeGltfQuad(const fs::path& dir) {
    // positions (4 x vec3) then uvs (4 x vec2) then indices (6 x u16), as one base64 buffer.
    const float pos[12] = {-1, 1, 0, 1, 1, 0, 1, -1, 0, -1, -1, 0};
    const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    const uint16_t idx[6] = {0, 3, 2, 0, 2, 1};   // counter-clockwise seen from +z
    std::string bytes(reinterpret_cast<const char*>(pos), sizeof pos);
    bytes.append(reinterpret_cast<const char*>(uv), sizeof uv);
    bytes.append(reinterpret_cast<const char*>(idx), sizeof idx);
    static const char* b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string enc;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v =
            uint8_t(bytes[i]) << 16 | (i + 1 < bytes.size() ? uint8_t(bytes[i + 1]) << 8 : 0) | (i + 2 < bytes.size() ? uint8_t(bytes[i + 2]) : 0);
        enc += b64[v >> 18 & 63];
        enc += b64[v >> 12 & 63];
        enc += i + 1 < bytes.size() ? b64[v >> 6 & 63] : '=';
        enc += i + 2 < bytes.size() ? b64[v & 63] : '=';
    }
    fs::path gltf = dir / "quad.gltf";
    std::ofstream out(gltf);
    out << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2,"material":0}]}],
"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0},"metallicFactor":0},"extensions":{},"doubleSided":true}],
"extensionsUsed":["KHR_materials_unlit"],
"textures":[{"source":0,"sampler":0}],"samplers":[{"magFilter":9728,"minFilter":9728}],"images":[{"uri":"quadrants.png"}],
"buffers":[{"byteLength":)"
        << bytes.size() << R"(,"uri":"data:application/octet-stream;base64,)" << enc << R"("}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":32},{"buffer":0,"byteOffset":80,"byteLength":12}],
"accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,-1,0],"max":[1,1,0]},
{"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"},{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}]})";
    return gltf;
}

// The same quad as OBJ + MTL: v = 0 at the bottom.
fs::path writeObjQuad(const fs::path& dir) {
    std::ofstream(dir / "quad.mtl") << "newmtl pic\nKd 1 1 1\nmap_Kd quadrants.png\n";
    fs::path obj = dir / "quad.obj";
    std::ofstream(obj) << "mtllib quad.mtl\nusemtl pic\n"
                          "v -1 1 0\nv 1 1 0\nv 1 -1 0\nv -1 -1 0\n"
                          "vt 0 1\nvt 1 1\nvt 1 0\nvt 0 0\n"
                          "f 1/1 4/4 3/3 2/2\n";
    return obj;
}

// Renders the file's scene head-on (orthographic camera at +z) and checks the four quadrants.
void checkQuadrants(const std::string& backend, const fs::path& file) {
    assets::LoadResult r = assets::loadScene(file);
    ASSERT_TRUE(r.scene) << file << ": " << r.error;
    sg::Scene& scene = *r.scene;
    sg::Camera cam;
    cam.projection.type = sg::ProjectionType::Orthographic;
    cam.projection.orthoHalfHeight = 1.25f;
    sg::NodeId c = scene.addNode("camera", scene.root(), cam);
    scene.lookAt(c, sg::vec3(0, 0, 3), sg::vec3(0.0f));
    scene.activeCamera = c;
    scene.settings.shadows = false;
    const int W = 40, H = 40;
    sg::FrameInput f = sg::flatten(scene, 1.0f, c);
    for (sg::DrawMesh& d : f.meshes) d.material.unlit = true;   // the texel colour itself
    rnd::Framebuffer fb;
    ASSERT_TRUE(testing_support::renderBackend(backend, f, W, H, fb));
    struct Probe {
        int x, y;
        uint8_t r, g, b;
        const char* where;
    };
    const Probe probes[] = {{12, 12, 255, 0, 0, "top left (red)"},
                            {28, 12, 0, 255, 0, "top right (green)"},
                            {12, 28, 0, 0, 255, "bottom left (blue)"},
                            {28, 28, 255, 255, 255, "bottom right (white)"}};
    for (const Probe& p : probes) {
        const uint8_t* px = fb.pixel(p.x, p.y);
        // Each channel on the right side of the middle (bilinear filtering of the OBJ's
        // mip-mapped texture blends a little of the neighbouring texel in).
        auto near = [](int got, int want) { return want > 128 ? got > 200 : got < 100; };
        EXPECT_TRUE(near(px[0], p.r) && near(px[1], p.g) && near(px[2], p.b))
            << backend << " " << file.filename() << " " << p.where << ": got " << int(px[0]) << "," << int(px[1]) << "," << int(px[2]);
    }
}

class TextureOrientation : public ::testing::TestWithParam<std::string> {
protected:
    fs::path dir() {
        // One folder per test: ctest runs the glTF and OBJ cases of a backend in parallel, and
        // each rewrites quadrants.png.
        const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
        fs::path d = testing_support::outputDir("conformance") / ("orientation-" + GetParam() + "-" + test.substr(0, test.find('/')));
        fs::create_directories(d);
        writeQuadrantsPng(d / "quadrants.png");
        return d;
    }
};

TEST_P(TextureOrientation, GltfUvOriginIsTheImagesTopLeft) { checkQuadrants(GetParam(), writeGltfQuad(dir())); }
TEST_P(TextureOrientation, ObjUvOriginIsTheImagesBottomLeft) { checkQuadrants(GetParam(), writeObjQuad(dir())); }

INSTANTIATE_TEST_SUITE_P(EveryBackend, TextureOrientation, ::testing::ValuesIn(rnd::rendererNames()), [](const auto& info) { return info.param; });

}   // namespace
