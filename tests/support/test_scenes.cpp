// test_scenes.cpp - the shared test frames of test_scenes.h, built directly as sg::FrameInput:
// frame, mesh, light and material helpers, the GL baseline scenes, textured floors, near-plane
// and triangle-agreement frames, and the BackendConformance reference scenes (lit sphere, fog
// plane, textured quad, projected box, anti-aliased edge).
#include "test_scenes.h"

#include "scenegraph/transforms.h"

#include <cmath>

namespace test_scenes {

using namespace sg;

FrameInput makeFrame(int width, int height, const Projection& projection, const vec3& eye, const vec3& center) {
    FrameInput f;
    mat4 cameraWorld = glm::inverse(sg::lookAt(eye, center, vec3(0, 1, 0)));
    f.camera = makeFrameCamera(cameraWorld, projection, float(width) / float(height), glm::length(center - eye));
    f.settings.background = vec3(0.0f);
    f.ambientLight = vec3(0.0f);
    return f;
}

void addMesh(FrameInput& f, MeshPtr mesh, const Material& m, const mat4& world, TexturePtr texture) {
    DrawMesh d;
    d.mesh = std::move(mesh);
    d.material = m;
    d.texture = std::move(texture);
    d.world = world;
    d.normal = normalMatrix(world);
    d.mirrored = glm::determinant(mat3(world)) < 0.0f;
    f.meshes.push_back(std::move(d));
}

void addMesh(FrameInput& f, const Mesh& mesh, const Material& m, const mat4& world, TexturePtr texture) {
    addMesh(f, std::make_shared<const Mesh>(mesh), m, world, std::move(texture));
}

DrawMesh meshInstance(MeshPtr mesh, const mat4& world, const vec3& color) {
    DrawMesh d;
    d.mesh = std::move(mesh);
    d.world = world;
    d.normal = normalMatrix(world);
    d.mirrored = glm::determinant(mat3(world)) < 0.0f;
    d.material.baseColor = color;
    return d;
}

Mesh quad(float half) {
    Mesh m;
    m.positions = {{-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}};
    m.normals.assign(4, vec3(0, 0, 1));
    m.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

DrawLight directional(const vec3& direction, const vec3& radiance) {
    DrawLight l;
    l.type = LightType::Directional;
    l.direction = glm::normalize(direction);
    l.radiance = radiance;
    return l;
}

DrawLight point(const vec3& position, const vec3& radiance, bool inverseSquare) {
    DrawLight l;
    l.type = LightType::Point;
    l.position = position;
    l.radiance = radiance;
    l.inverseSquare = inverseSquare;
    return l;
}

DrawLight spot(const vec3& position, const vec3& direction, const vec3& radiance, float innerDeg, float outerDeg) {
    DrawLight l;
    l.type = LightType::Spot;
    l.position = position;
    l.direction = glm::normalize(direction);
    l.radiance = radiance;
    l.cosInner = std::cos(glm::radians(innerDeg));
    l.cosOuter = std::cos(glm::radians(outerDeg));
    return l;
}

Material unlit(const vec3& color) {
    Material m;
    m.baseColor = color;
    m.unlit = true;
    return m;
}

namespace {

Material phong(const vec3& color, float ks, float shininess) {
    Material m;
    m.baseColor = color;
    m.ka = 0.2f;
    m.kd = 0.75f;
    m.ks = ks;
    m.shininess = shininess;
    return m;
}

// Floor, sphere, box, torus and a three-light rig (point 1/r^2, directional, spot).
FrameInput shapes(int w, int h, const Projection& proj) {
    FrameInput f = makeFrame(w, h, proj, vec3(0.0f, 1.6f, 5.0f), vec3(0.0f, -0.3f, 0.0f));
    f.settings.background = vec3(0.05f, 0.06f, 0.08f);
    f.ambientLight = vec3(0.3f);
    static const auto tex = checker(64, 8, vec3(0.9f, 0.88f, 0.8f), vec3(0.2f, 0.22f, 0.3f));
    static const auto floorMesh = std::make_shared<const Mesh>(primitives::plane(3.0f, 4));
    static const auto sphereMesh = std::make_shared<const Mesh>(primitives::uvSphere(0.8f, 32, 16));
    static const auto boxMesh = std::make_shared<const Mesh>(primitives::box(vec3(0.5f)));
    static const auto torusMesh = std::make_shared<const Mesh>(primitives::torus(0.6f, 0.2f, 32, 12));
    Material floorMat = phong(vec3(1.0f), 0.1f, 16.0f);
    addMesh(f, floorMesh, floorMat, glm::translate(mat4(1.0f), vec3(0, -1, 0)), tex);
    addMesh(f, sphereMesh, phong(vec3(0.8f, 0.12f, 0.1f), 0.6f, 64.0f), glm::translate(mat4(1.0f), vec3(-1.2f, -0.2f, 0.2f)));
    mat4 box = glm::translate(mat4(1.0f), vec3(1.3f, -0.5f, 0.3f)) * glm::rotate(mat4(1.0f), 0.6f, vec3(0, 1, 0));
    addMesh(f, boxMesh, phong(vec3(0.15f, 0.3f, 0.85f), 0.5f, 32.0f), box, tex);
    mat4 torus = glm::translate(mat4(1.0f), vec3(0.1f, 0.1f, -1.3f)) * glm::rotate(mat4(1.0f), 1.2f, vec3(1, 0, 0));
    Material gold = phong(vec3(0.9f, 0.7f, 0.25f), 0.8f, 48.0f);
    gold.specularTinted = true;
    addMesh(f, torusMesh, gold, torus);
    f.lights.push_back(point(vec3(2.0f, 3.0f, 3.0f), vec3(14.0f, 13.0f, 12.0f), true));
    f.lights.push_back(directional(vec3(-0.3f, -1.0f, -0.5f), vec3(0.2f, 0.25f, 0.35f)));
    f.lights.push_back(spot(vec3(-2.5f, 3.0f, 2.0f), vec3(1.3f, -2.8f, -1.8f), vec3(1.2f, 1.0f, 0.8f), 12.0f, 22.0f));
    return f;
}

}   // namespace

std::vector<std::string> baselineNames() {
    return {"phong",    "gouraud",      "flat",  "blinn_fog_exp2", "fog_linear",      "wireframe_msaa4",
            "cavalier", "orthographic", "ssaa2", "lines_points",   "mirrored_culled", "texture_nearest_clamp"};
}

FrameInput baselineFrame(const std::string& name, int w, int h) {
    Projection persp;
    if (name == "cavalier" || name == "orthographic") {
        Projection p = name == "cavalier" ? Projection::cavalier() : Projection{};
        if (name == "orthographic") p.type = ProjectionType::Orthographic;
        p.orthoHalfHeight = 2.2f;
        return shapes(w, h, p);
    }
    FrameInput f = shapes(w, h, persp);
    RenderSettings& s = f.settings;
    if (name == "gouraud") s.shading = ShadingModel::Gouraud;
    if (name == "flat") s.shading = ShadingModel::Flat;
    if (name == "blinn_fog_exp2") {
        s.reflection = ReflectionModel::BlinnPhong;
        s.fog = FogMode::Exp2;
        s.fogDensity = 0.18f;
        s.fogColor = vec3(0.5f, 0.55f, 0.6f);
    }
    if (name == "fog_linear") {
        s.fog = FogMode::Linear;
        s.fogStart = 4.0f;
        s.fogEnd = 9.0f;
        s.fogColor = vec3(0.6f, 0.5f, 0.4f);
    }
    if (name == "wireframe_msaa4") {
        s.wireframe = true;
        s.wireframeColor = vec3(0.9f, 0.9f, 0.2f);
        s.aa = AAMode::MSAA;
        s.aaRate = 4;
        s.culling = sg::CullMode::On;
    }
    if (name == "ssaa2") {
        s.aa = AAMode::SSAA;
        s.aaRate = 2;
    }
    if (name == "lines_points") {
        Mesh lines;
        lines.mode = PrimitiveMode::Lines;
        Mesh points;
        points.mode = PrimitiveMode::Points;
        for (int i = 0; i <= 12; ++i) {
            float a = float(i) / 12.0f * 6.2831853f;
            lines.positions.push_back(vec3(std::cos(a), std::sin(a), 0.0f) * 1.5f + vec3(0, 0.3f, 1.0f));
            lines.colors.push_back(vec4(0.5f + 0.5f * std::cos(a), 0.5f + 0.5f * std::sin(a), 0.8f, 1.0f));
            points.positions.push_back(vec3(std::cos(a), std::sin(a), 0.0f) * 1.0f + vec3(0, 0.3f, 1.0f));
        }
        for (uint32_t i = 0; i < 12; ++i) lines.indices.insert(lines.indices.end(), {i, i + 1});
        addMesh(f, lines, unlit(vec3(1.0f)));
        addMesh(f, points, unlit(vec3(1.0f, 1.0f, 0.3f)));
    }
    if (name == "mirrored_culled") {
        s.culling = sg::CullMode::On;
        for (auto& d : f.meshes) {   // mirror the whole scene in x: winding flips, image mirrors
            d.world = glm::scale(mat4(1.0f), vec3(-1, 1, 1)) * d.world;
            d.normal = normalMatrix(d.world);
            d.mirrored = !d.mirrored;
        }
        for (auto& l : f.lights) {
            l.position.x = -l.position.x;
            l.direction.x = -l.direction.x;
        }
    }
    if (name == "texture_nearest_clamp") {
        auto t = std::make_shared<Texture>(*checker(8, 4, vec3(1.0f, 0.3f, 0.1f), vec3(0.1f, 0.4f, 1.0f)));
        t->filter = FilterMode::Nearest;
        t->wrapS = WrapMode::ClampToEdge;
        t->wrapT = WrapMode::MirroredRepeat;
        Mesh quad = primitives::plane(1.0f, 1);
        for (auto& uv : quad.uv0) uv = uv * 2.0f - vec2(0.5f);
        addMesh(f, quad, unlit(vec3(1.0f)), glm::translate(mat4(1.0f), vec3(0, 0.5f, 1.5f)) * glm::rotate(mat4(1.0f), 1.2f, vec3(1, 0, 0)), t);
    }
    return f;
}

FrameInput texturedFloorFrame(int w, int h, FilterMode filter, WrapMode wrap, ProjectionType proj, ShadingModel shading) {
    Projection p;
    p.type = proj;
    p.orthoHalfHeight = 2.5f;
    FrameInput f = makeFrame(w, h, p, vec3(0.3f, 1.6f, 4.0f), vec3(0, 0, -1));
    auto tex = checker(64, 8, vec3(0.9f, 0.8f, 0.2f), vec3(0.1f, 0.2f, 0.6f));
    tex->filter = filter;
    tex->wrapS = tex->wrapT = wrap;
    Mesh floor = primitives::plane(6.0f, 8);
    for (auto& uv : floor.uv0) uv *= 4.0f;   // repeat 4x (wrap modes matter)
    Material m;
    m.baseColor = vec3(1.0f);
    m.ks = 0.2f;
    addMesh(f, floor, m, translation(vec3(0, -0.5f, -2)), tex);
    Mesh box = primitives::box(vec3(0.6f));
    addMesh(f, box, m, translation(vec3(-0.8f, 0.2f, 0.5f)) * rotationY(0.6f), tex);
    f.lights.push_back(point(vec3(1, 3, 2), vec3(6.0f), true));
    f.lights.push_back(directional(vec3(-0.3f, -1, -0.4f), vec3(0.3f)));
    f.ambientLight = vec3(0.3f);
    f.settings.shading = shading;
    return f;
}

FrameInput nearPlaneFrame(int w, int h, ProjectionType proj) {
    Projection p;
    p.type = proj;
    p.zNear = 0.3f;
    p.zFar = 30.0f;
    p.orthoHalfHeight = 3.0f;
    FrameInput f = makeFrame(w, h, p, vec3(0, 0.5f, 0), vec3(0, 0.1f, -1));
    Mesh tri;
    tri.positions = {{-30, -1, 20}, {30, -1, 20}, {0, -1, -40}};
    tri.normals = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
    tri.indices = {0, 1, 2};   // counter-clockwise from above: lit side up
    Material m;
    m.baseColor = vec3(0.4f, 0.7f, 0.3f);
    addMesh(f, tri, m);
    f.lights.push_back(point(vec3(0, 3, -5), vec3(20.0f), true));
    f.ambientLight = vec3(0.2f);
    return f;
}

FrameInput triangleAgreementFrame(const Projection& proj, int w, int h) {
    FrameInput f;
    f.settings.shadows = false;
    f.settings.reflections = false;
    f.settings.aa = AAMode::None;
    auto sphere = std::make_shared<Mesh>(primitives::uvSphere(0.8f, 48, 24));
    auto box = std::make_shared<Mesh>(primitives::box(vec3(0.5f)));
    auto ground = std::make_shared<Mesh>(primitives::plane(4.0f, 8));
    auto cyl = std::make_shared<Mesh>(primitives::cylinder(0.4f, 0.6f, 32, false));   // open: back faces visible
    f.meshes.push_back(meshInstance(sphere, glm::translate(mat4(1.0f), vec3(-0.9f, 0.8f, 0)), vec3(0.8f, 0.2f, 0.2f)));
    f.meshes.push_back(
        meshInstance(box, glm::rotate(glm::translate(mat4(1.0f), vec3(1.0f, 0.5f, 0.3f)), 0.6f, vec3(0, 1, 0)), vec3(0.2f, 0.6f, 0.9f)));
    f.meshes.push_back(meshInstance(ground, mat4(1.0f), vec3(0.7f, 0.7f, 0.6f)));
    f.meshes.push_back(meshInstance(cyl, glm::translate(mat4(1.0f), vec3(0.2f, 0.6f, 1.4f)), vec3(0.3f, 0.8f, 0.3f)));
    // Mirrored instance (negative x scale): winding flips, shading must not.
    f.meshes.push_back(
        meshInstance(sphere, glm::scale(glm::translate(mat4(1.0f), vec3(0.2f, 0.5f, -1.5f)), vec3(-0.5f, 0.5f, 0.5f)), vec3(0.9f, 0.8f, 0.2f)));
    f.meshes[1].material.ks = 0.6f;
    f.meshes[1].material.shininess = 16.0f;
    DrawLight l1;
    l1.position = vec3(2.5f, 4.0f, 3.0f);
    l1.radiance = vec3(0.9f);
    DrawLight l2;
    l2.type = LightType::Directional;
    l2.direction = glm::normalize(vec3(-0.3f, -1.0f, -0.5f));
    l2.radiance = vec3(0.3f, 0.3f, 0.4f);
    f.lights = {l1, l2};
    f.ambientLight = vec3(0.3f);
    mat4 cam = glm::inverse(glm::lookAt(vec3(1.5f, 3.0f, 5.5f), vec3(0, 0.4f, 0), vec3(0, 1, 0)));
    f.camera = makeFrameCamera(cam, proj, float(w) / float(h), 6.0f);
    return f;
}

std::shared_ptr<Texture> minificationChecker() {
    auto tex = checker(64, 16, vec3(250.0f / 255.0f), vec3(10.0f / 255.0f));
    tex->filter = FilterMode::Trilinear;
    tex->wrapS = tex->wrapT = WrapMode::Repeat;
    return tex;
}

// --- BackendConformance reference scenes.

FrameInput litSphereFrame(int w, int h, ShadingModel shading, ReflectionModel reflection, SphereLight light, int slices) {
    FrameInput f = makeFrame(w, h, Projection{}, vec3(0.0f, 0.0f, 3.2f), vec3(0.0f));
    f.ambientLight = vec3(0.2f);
    f.settings.shading = shading;
    f.settings.reflection = reflection;
    f.settings.aa = AAMode::None;
    f.settings.shadows = false;
    f.settings.reflections = false;
    Material m;
    m.baseColor = vec3(0.6f, 0.4f, 0.25f);
    m.ka = 0.2f;
    m.kd = 0.7f;
    m.ks = 0.35f;
    m.shininess = 24.0f;   // ka rho A + kd rho L + ks L <= 0.72: no channel ever clamps
    const vec3 toLight = glm::normalize(vec3(-0.5f, 0.6f, 1.0f));
    if (light == SphereLight::Directional)
        f.lights.push_back(directional(-toLight, vec3(0.9f)));
    else
        f.lights.push_back(point(4.0f * toLight, vec3(0.9f), false));
    addMesh(f, std::make_shared<const Mesh>(primitives::uvSphere(1.0f, slices, slices / 2)), m);
    return f;
}

FrameInput fogPlaneFrame(int w, int h, FogMode mode) {
    FrameInput f = makeFrame(w, h, Projection{}, vec3(0.0f, 0.6f, 3.0f), vec3(0.0f, -1.0f, -6.0f));
    f.settings.fog = mode;
    f.settings.fogColor = vec3(0.3f, 0.45f, 0.7f);
    f.settings.fogStart = 2.0f;
    f.settings.fogEnd = 14.0f;
    f.settings.fogDensity = mode == FogMode::Exp2 ? 0.12f : 0.15f;
    f.settings.aa = AAMode::None;
    addMesh(f, primitives::plane(40.0f, 1), unlit(vec3(0.85f, 0.35f, 0.15f)), translation(vec3(0.0f, -1.0f, 0.0f)));
    return f;
}

std::shared_ptr<Texture> texelGrid() {
    auto t = std::make_shared<Texture>();
    t->width = t->height = 4;
    t->rgba.resize(4 * 4 * 4);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            uint8_t* p = &t->rgba[size_t(y * 4 + x) * 4];
            p[0] = uint8_t(40 + 60 * x);
            p[1] = uint8_t(40 + 60 * y);
            p[2] = uint8_t((x + y) % 2 ? 220 : 30);
            p[3] = 255;
        }
    t->filter = FilterMode::Nearest;
    t->wrapS = t->wrapT = WrapMode::ClampToEdge;
    return t;
}

FrameInput texturedQuadFrame(int w, int h, bool tilted) {
    Projection p;
    if (!tilted) {
        p.type = ProjectionType::Orthographic;
        p.orthoHalfHeight = 1.5f;
    }
    FrameInput f = makeFrame(w, h, p, vec3(0.0f, 0.0f, tilted ? 3.5f : 5.0f), vec3(0.0f));
    f.settings.aa = AAMode::None;
    const mat4 world = tilted ? rotationY(glm::radians(20.0f)) * rotationX(glm::radians(-50.0f)) : mat4(1.0f);
    addMesh(f, quad(1.0f), unlit(vec3(1.0f)), world, texelGrid());
    return f;
}

FrameInput projectedBoxFrame(int w, int h, const Projection& proj) {
    Projection p = proj;
    p.orthoHalfHeight = 1.5f;
    FrameInput f = makeFrame(w, h, p, vec3(0.0f, 0.0f, 5.0f), vec3(0.0f));
    f.settings.aa = AAMode::None;
    const mat4 world = translation(vec3(0.2f, -0.1f, -0.3f)) * rotationY(glm::radians(30.0f)) * rotationX(glm::radians(20.0f));
    addMesh(f, primitives::box(vec3(0.6f, 0.4f, 0.5f)), unlit(vec3(1.0f)), world);
    return f;
}

FrameInput aaEdgeFrame(int w, int h, AAMode aa, int rate) {
    Projection p;
    p.type = ProjectionType::Orthographic;
    p.orthoHalfHeight = 1.5f;
    FrameInput f = makeFrame(w, h, p, vec3(0.0f, 0.0f, 5.0f), vec3(0.0f));
    f.settings.aa = aa;
    f.settings.aaRate = rate;
    addMesh(f, quad(1.2f), unlit(vec3(1.0f)), rotationZ(glm::radians(20.0f)));
    return f;
}

}   // namespace test_scenes
