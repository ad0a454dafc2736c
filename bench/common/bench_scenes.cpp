// bench_scenes.cpp - the benchmarks' shared scenes (bench_scenes.h).
#include "bench_scenes.h"

#include "assets/scene_io.h"

#include <cstdio>

namespace bench {

using namespace sg;

void addGridCameraAndKey(Scene& s, float extent) {
    Camera cam;
    cam.projection.fovyDeg = 50.0f;
    cam.projection.zNear = 0.1f;
    cam.projection.zFar = 4.0f * extent + 20.0f;
    NodeId c = s.addNode("camera", s.root(), cam);
    s.lookAt(c, vec3(0.0f, 0.55f * extent + 1.0f, 0.75f * extent + 1.5f), vec3(0.0f, 0.0f, 0.0f));
    s.activeCamera = c;
    NodeId key = s.addNode("key", s.root(), Light{LightType::Point, vec3(1.0f), 1.0f, false});
    s.setLocal(key, LocalTransform::fromTRS(vec3(extent * 0.3f, extent, extent * 0.5f)));
}

BenchScene singleMesh(const std::string& name, int grid, int seg, int groundSub) {
    BenchScene b;
    b.name = name;
    Scene& s = b.scene;
    float spacing = 1.0f, extent = grid * spacing;
    auto m = std::make_shared<Mesh>(primitives::plane(extent, groundSub));
    m->uv0.clear();
    const Mesh sphere = primitives::uvSphere(0.4f * spacing, seg, seg / 2);
    for (int i = 0; i < grid; ++i)
        for (int j = 0; j < grid; ++j) {
            const vec3 at((i - (grid - 1) * 0.5f) * spacing, 0.4f * spacing, (j - (grid - 1) * 0.5f) * spacing);
            const uint32_t base = uint32_t(m->positions.size());
            for (size_t v = 0; v < sphere.positions.size(); ++v) {
                m->positions.push_back(sphere.positions[v] + at);
                m->normals.push_back(sphere.normals[v]);
            }
            for (uint32_t idx : sphere.indices) m->indices.push_back(base + idx);
        }
    s.meshes = {m};
    Material mat;
    mat.baseColor = vec3(0.8f, 0.3f, 0.2f);
    mat.ks = 0.5f;
    s.materials = {mat};
    s.addNode("mesh", s.root(), MeshInstance{0, 0});
    b.triangles = m->triangleCount();
    addGridCameraAndKey(s, extent);
    s.settings.ambientLight = vec3(0.3f);
    return b;
}

BenchScene meshScene(const std::string& name, std::shared_ptr<Mesh> m) {
    BenchScene b;
    b.name = name;
    Scene& s = b.scene;
    Aabb bb = m->bounds();
    auto ground = std::make_shared<Mesh>(primitives::plane(1.0f, 32));
    s.meshes = {m, ground};
    Material mb;
    mb.baseColor = vec3(0.75f, 0.7f, 0.6f);
    s.materials = {mb};
    NodeId n = s.addNode(name, s.root(), MeshInstance{0, 0});
    float scale = 2.0f / glm::length(bb.extent());
    s.setLocal(n, LocalTransform::fromTRS(-bb.center() * scale + vec3(0, 0.5f * bb.extent().y * scale, 0), quat(1, 0, 0, 0), vec3(scale)));
    s.addNode("ground", s.root(), MeshInstance{1, 0});
    Camera cam;
    cam.projection.zNear = 0.05f;
    cam.projection.zFar = 20.0f;
    NodeId c = s.addNode("camera", s.root(), cam);
    s.lookAt(c, vec3(0.0f, 0.9f, 2.0f), vec3(0.0f, 0.45f, 0.0f));
    s.activeCamera = c;
    NodeId key = s.addNode("key", s.root(), Light{LightType::Point, vec3(1.0f), 1.0f, false});
    s.setLocal(key, LocalTransform::fromTRS(vec3(1, 3, 2)));
    b.triangles = m->triangleCount() + ground->triangleCount();
    return b;
}

bool fileScene(const std::string& path, BenchScene& b, std::string name) {
    assets::LoadResult r = assets::loadScene(path);
    if (!r.scene || r.scene->meshes.empty() || !r.scene->meshes.front() || r.scene->meshes.front()->triangleCount() == 0) {
        std::fprintf(stderr, "bench: %s: %s\n", path.c_str(), r.scene ? "no triangle mesh" : r.error.c_str());
        return false;
    }
    if (name.empty()) {
        name = path.substr(path.find_last_of('/') + 1);
        name = name.substr(0, name.find_last_of('.'));
    }
    b = meshScene(name, r.scene->meshes.front());
    return true;
}

BenchScene sphereGrid(const std::string& name, int grid, int seg) {
    BenchScene b;
    b.name = name;
    Scene& s = b.scene;
    float spacing = 1.0f, extent = grid * spacing;
    auto ground = std::make_shared<Mesh>(primitives::plane(extent, 64));
    auto sphere = std::make_shared<Mesh>(primitives::uvSphere(0.4f * spacing, seg, seg / 2));
    s.meshes = {ground, sphere};
    Material mg;
    mg.baseColor = vec3(0.5f, 0.5f, 0.45f);
    Material ms;
    ms.baseColor = vec3(0.8f, 0.3f, 0.2f);
    ms.ks = 0.5f;
    s.materials = {mg, ms};
    s.addNode("ground", s.root(), MeshInstance{0, 0});
    for (int i = 0; i < grid; ++i)
        for (int j = 0; j < grid; ++j) {
            NodeId n = s.addNode("sphere", s.root(), MeshInstance{1, 1});
            s.setLocal(n, LocalTransform::fromTRS(vec3((i - (grid - 1) * 0.5f) * spacing, 0.4f * spacing, (j - (grid - 1) * 0.5f) * spacing)));
        }
    b.triangles = ground->triangleCount() + size_t(grid) * grid * sphere->triangleCount();
    addGridCameraAndKey(s, extent);
    NodeId sun = s.addNode("sun", s.root(), Light{LightType::Directional, vec3(0.6f, 0.7f, 0.9f), 0.4f, false});
    s.lookAt(sun, vec3(-1, 2, 1), vec3(0));
    s.settings.ambientLight = vec3(0.3f);
    return b;
}

}   // namespace bench
