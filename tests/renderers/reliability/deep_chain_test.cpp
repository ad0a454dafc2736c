// deep_chain_test.cpp - a 1M-deep chain of nodes (deep scene graphs must load, update and
// render without stack overflow). The chain is written as a native JSON scene file and as a
// glTF file, loaded through assets::loadScene like the viewer does, and rendered by every
// backend. Nothing may recurse per level: a 1M-deep recursion overflows the 8 MB main-thread
// stack (and the much smaller worker-thread stacks) many times over.
//
// The chain's links alternate translations of +1 and -1 along y (exact in float), with one
// link halfway down moving +1 along x, so the red unlit quad at the leaf shows up exactly at
// x = +1 only when every level was composed. Built twice: deep_chain_tests (CPU backends,
// label unit) and deep_chain_gl_tests (DEEP_CHAIN_GL: the GL backend, label gl).
#include "assets/scene_io.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "scenegraph/scene.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

namespace {

using namespace sg;

// Both executables may run at once (ctest -j): each writes its files to its own folder.
#ifdef DEEP_CHAIN_GL
#define DEEP_SUITE DeepChainGLTest
constexpr const char* kOutSuite = "deep_chain_gl";
#else
#define DEEP_SUITE DeepChainTest
constexpr const char* kOutSuite = "deep_chain";
#endif
namespace fs = std::filesystem;

constexpr int kDepth = 1'000'000;
constexpr int kW = 96, kH = 64;
const vec3 kRed{1, 0, 0}, kBlue{0, 0, 1};

// Translation of link i (1-based): alternately +y and -y (kDepth is even: they cancel), and
// +x once halfway.
vec3 linkOffset(int i) { return vec3(i == kDepth / 2 ? 1.0f : 0.0f, (i % 2) ? 1.0f : -1.0f, 0); }

std::shared_ptr<Mesh> quad(float half) {
    auto m = std::make_shared<Mesh>();
    m->positions = {{-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}};
    m->normals.assign(4, vec3(0, 0, 1));
    m->indices = {0, 1, 2, 0, 2, 3};
    return m;
}

Material unlit(const std::string& name, vec3 c) {
    Material m;
    m.name = name;
    m.baseColor = c;
    m.unlit = true;
    return m;
}

// Camera at (0, 0, 5) looking at the origin; a blue quad at the root at x = -1 as a control.
void addCameraAndControl(Scene& s) {
    NodeId cam = s.addNode("camera", s.root(), Camera{});
    s.lookAt(cam, vec3(0, 0, 5), vec3(0));
    s.activeCamera = cam;
    NodeId control = s.addNode("control", s.root(), MeshInstance{int(s.meshes.size()), int(s.materials.size())});
    s.meshes.push_back(quad(0.3f));
    s.materials.push_back(unlit("blue", kBlue));
    s.setLocal(control, LocalTransform::fromTRS(vec3(-1, 0, 0)));
}

Scene makeDeepScene() {
    Scene s;
    s.settings.culling = sg::CullMode::Off;
    addCameraAndControl(s);
    NodeId prev = s.root();
    for (int i = 1; i <= kDepth; ++i) {
        prev = s.addNode("", prev);
        s.setLocal(prev, LocalTransform::fromTRS(linkOffset(i)));
    }
    NodeId leaf = s.addNode("leaf", prev, MeshInstance{int(s.meshes.size()), int(s.materials.size())});
    s.meshes.push_back(quad(0.3f));
    s.materials.push_back(unlit("red", kRed));
    (void)leaf;
    return s;
}

// The same chain as glTF text: node 0 is the chain's top, node kDepth the leaf with mesh 0.
std::string deepGltf() {
    // A quad: 4 positions (48 bytes) + 6 uint16 indices (12 bytes), as a base64 data URI.
    const float pos[12] = {-0.3f, -0.3f, 0, 0.3f, -0.3f, 0, 0.3f, 0.3f, 0, -0.3f, 0.3f, 0};
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    std::string bytes(reinterpret_cast<const char*>(pos), sizeof pos);
    bytes.append(reinterpret_cast<const char*>(idx), sizeof idx);
    std::string enc = testing_support::base64Encode(bytes);
    std::string j;
    j.reserve(size_t(kDepth) * 48);
    j += R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [)";
    char buf[128];
    for (int i = 1; i <= kDepth; ++i) {   // node i-1 is link i
        vec3 t = linkOffset(i);
        std::snprintf(buf, sizeof buf, R"({"translation": [%g, %g, 0], "children": [%d]},)", t.x, t.y, i);
        j += buf;
    }
    j += R"({"name": "leaf", "mesh": 0}],)";
    j += R"("meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],)";
    j +=
        R"("materials": [{"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}, "extensions": {"KHR_materials_unlit": {}}, "doubleSided": true}],)";
    j += R"("extensionsUsed": ["KHR_materials_unlit"],)";
    j += R"("buffers": [{"byteLength": 60, "uri": "data:application/octet-stream;base64,)" + enc + R"("}],)";
    j += R"("bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],)";
    j += R"("accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.3, -0.3, 0], "max": [0.3, 0.3, 0]},)";
    j += R"({"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
    return j;
}

double secondsSince(std::chrono::steady_clock::time_point t0) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }

// Where world point p lands in a kW x kH image (row 0 at the top).
void project(const FrameInput& f, vec3 p, int& x, int& y) {
    vec4 c = f.camera.viewProj * vec4(p, 1.0f);
    x = int((c.x / c.w * 0.5f + 0.5f) * kW);
    y = int((0.5f - c.y / c.w * 0.5f) * kH);
}

bool pixelIs(const rnd::Framebuffer& fb, int x, int y, vec3 c) {
    const uint8_t* p = fb.pixel(x, y);
    return std::abs(int(p[0]) - int(c.r * 255)) <= 2 && std::abs(int(p[1]) - int(c.g * 255)) <= 2 && std::abs(int(p[2]) - int(c.b * 255)) <= 2;
}

// Loads `path`, checks the chain's depth and the leaf's world position, renders with each
// backend of this executable and finds the red leaf at x = +1 and the blue control at x = -1
// (when the scene has one).
void loadAndRender(const fs::path& path, bool hasControl) {
    auto t0 = std::chrono::steady_clock::now();
    assets::LoadResult r = assets::loadScene(path);
    ASSERT_TRUE(r.scene) << r.error;
    std::printf("[ deep ] %s: loaded %zu nodes in %.2f s\n", path.filename().c_str(), r.scene->nodeCount(), secondsSince(t0));
    Scene& s = *r.scene;
    ASSERT_GE(s.nodeCount(), size_t(kDepth) + 1);
    NodeId leaf = s.findByName("leaf");
    ASSERT_NE(leaf, kNoNode);
    int depth = 0;
    for (NodeId n = leaf; n != s.root(); n = s.node(n).parent) ++depth;
    EXPECT_GE(depth, kDepth + 1);
    const mat4& w = s.world(leaf);
    EXPECT_EQ(w[3].x, 1.0f);
    EXPECT_EQ(w[3].y, 0.0f);
    EXPECT_EQ(w[3].z, 0.0f);

    if (s.findByName("camera") == kNoNode) {   // glTF: the same view as the JSON scene
        NodeId cam = s.addNode("camera", s.root(), Camera{});
        s.lookAt(cam, vec3(0, 0, 5), vec3(0));
        s.activeCamera = cam;
    }
    s.settings.culling = sg::CullMode::Off;
    t0 = std::chrono::steady_clock::now();
    FrameInput f = flatten(s, float(kW) / kH);
    std::printf("[ deep ] flatten %.2f s\n", secondsSince(t0));
    int rx, ry, bx, by;
    project(f, vec3(1, 0, 0), rx, ry);
    project(f, vec3(-1, 0, 0), bx, by);
    ASSERT_TRUE(rx > 0 && rx < kW && ry > 0 && ry < kH);

#ifdef DEEP_CHAIN_GL
    const char* backends[] = {"gl"};
#else
    const char* backends[] = {"raster", "raycast"};
#endif
    for (const char* name : backends) {
        auto renderer = rnd::makeRenderer(name);
        ASSERT_TRUE(renderer) << name;
        rnd::Framebuffer fb;
        t0 = std::chrono::steady_clock::now();
        rnd::RenderStats st = renderer->render(f, kW, kH, fb);
        ASSERT_TRUE(st.ok) << name << ": " << st.error;
        std::printf("[ deep ] %s render %.2f s\n", name, secondsSince(t0));
        testing_support::writeImage(fb, kOutSuite, path.filename().string() + "-" + name);
        EXPECT_TRUE(pixelIs(fb, rx, ry, kRed)) << name << ": the leaf at the end of the chain is missing";
        EXPECT_FALSE(pixelIs(fb, kW - 1 - rx, ry, kRed)) << name << ": leaf drawn without the halfway offset";
        if (hasControl) { EXPECT_TRUE(pixelIs(fb, bx, by, kBlue)) << name; }
    }
}

fs::path scratch(const std::string& file) {
    fs::path dir = testing_support::outputDir(kOutSuite);
    fs::create_directories(dir);
    fs::path p = dir / file;
    fs::remove(p);
    return p;
}

TEST(DEEP_SUITE, NativeJsonLoadsAndRenders) {
    fs::path path = scratch("deep-chain.json");
    {
        Scene s = makeDeepScene();
        ASSERT_EQ(assets::saveSceneJson(s, path, false), "");
    }
    loadAndRender(path, true);
    fs::remove(path);
}

TEST(DEEP_SUITE, GltfLoadsAndRenders) {
    fs::path path = scratch("deep-chain.gltf");
    {
        std::ofstream out(path, std::ios::binary);
        out << deepGltf();
        ASSERT_TRUE(out.good());
    }
    loadAndRender(path, false);
    fs::remove(path);
}

}   // namespace
