// demo.cpp - the bundled demo scene (see demo.h). Everything is made here in code, one helper
// per part of the room (materials, room, crates, turntable, shapes, lights, camera).
#include "assets/demo.h"

#include "scenegraph/transforms.h"

namespace assets {

using namespace sg;

std::shared_ptr<Texture> makeCheckerTexture(int size, int checks, vec3 a, vec3 b) {
    auto t = std::make_shared<Texture>();
    t->name = "checker";
    t->width = t->height = size;
    t->rgba.resize(size_t(size) * size * 4);
    int cell = std::max(1, size / std::max(1, checks));
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            vec3 c = ((x / cell + y / cell) & 1) ? b : a;
            uint8_t* p = &t->rgba[(size_t(y) * size + x) * 4];
            p[0] = uint8_t(c.r * 255 + 0.5f);
            p[1] = uint8_t(c.g * 255 + 0.5f);
            p[2] = uint8_t(c.b * 255 + 0.5f);
            p[3] = 255;
        }
    return t;
}

namespace {
int addMaterial(Scene& s, const std::string& name, vec3 color, float ka, float kd, float ks, float n, int texture = -1) {
    Material m;
    m.name = name;
    m.baseColor = color;
    m.ka = ka;
    m.kd = kd;
    m.ks = ks;
    m.shininess = n;
    m.diffuseTexture = texture;
    s.materials.push_back(m);
    return int(s.materials.size() - 1);
}
int addMesh(Scene& s, Mesh m) {
    s.meshes.push_back(std::make_shared<Mesh>(std::move(m)));
    return int(s.meshes.size() - 1);
}

// The demo's materials (indices into Scene::materials).
struct DemoMaterials {
    int floor, wall, crate, red, blue, gold, green, csg, cut, teal, purple;
};

// Background, ambient light and fog range.
void setDemoSettings(Scene& s) {
    s.settings.ambientLight = vec3(0.35f, 0.37f, 0.42f);
    s.settings.background = vec3(0.05f, 0.055f, 0.07f);
    s.settings.fogColor = s.settings.background;
    s.settings.fogStart = 8.0f;
    s.settings.fogEnd = 30.0f;
}

// The two checker textures (floor, crate) and the materials.
DemoMaterials addDemoMaterials(Scene& s) {
    auto checker = makeCheckerTexture(256, 8, vec3(0.92f, 0.9f, 0.85f), vec3(0.25f, 0.27f, 0.32f));
    checker->name = "floor checker";
    s.textures.push_back(checker);
    auto crate = makeCheckerTexture(128, 4, vec3(0.85f, 0.55f, 0.2f), vec3(0.55f, 0.3f, 0.1f));
    crate->name = "crate checker";
    s.textures.push_back(crate);

    DemoMaterials m;
    m.floor = addMaterial(s, "floor", vec3(1.0f), 0.3f, 0.8f, 0.1f, 16.0f, 0);
    m.wall = addMaterial(s, "wall", vec3(0.75f, 0.72f, 0.68f), 0.3f, 0.8f, 0.05f, 8.0f);
    m.crate = addMaterial(s, "crate", vec3(1.0f), 0.25f, 0.85f, 0.2f, 24.0f, 1);
    m.red = addMaterial(s, "red plastic", vec3(0.8f, 0.12f, 0.1f), 0.2f, 0.8f, 0.6f, 64.0f);
    m.blue = addMaterial(s, "blue gloss", vec3(0.15f, 0.3f, 0.85f), 0.2f, 0.7f, 0.8f, 128.0f);
    m.gold = addMaterial(s, "gold", vec3(0.9f, 0.7f, 0.25f), 0.2f, 0.6f, 0.9f, 48.0f);
    s.materials[m.gold].specularTinted = true;
    m.green = addMaterial(s, "green", vec3(0.2f, 0.7f, 0.3f), 0.2f, 0.8f, 0.4f, 32.0f);
    m.csg = addMaterial(s, "carved stone", vec3(0.7f, 0.7f, 0.75f), 0.25f, 0.75f, 0.3f, 24.0f);
    m.cut = addMaterial(s, "carved face", vec3(0.95f, 0.45f, 0.15f), 0.25f, 0.75f, 0.3f, 24.0f);
    m.teal = addMaterial(s, "teal", vec3(0.1f, 0.65f, 0.65f), 0.2f, 0.8f, 0.5f, 40.0f);
    m.purple = addMaterial(s, "purple", vec3(0.55f, 0.25f, 0.7f), 0.2f, 0.8f, 0.5f, 40.0f);
    return m;
}

// Room: tessellated floor and two walls (meshes).
void addRoom(Scene& s, const DemoMaterials& m) {
    NodeId room = s.addNode("room");
    int floorMesh = addMesh(s, primitives::plane(6.0f, 24));
    s.addNode("floor", room, MeshInstance{floorMesh, m.floor});
    int wallMesh = addMesh(s, primitives::box(vec3(6.0f, 2.5f, 0.1f)));
    NodeId back = s.addNode("back wall", room, MeshInstance{wallMesh, m.wall});
    s.setLocal(back, LocalTransform::fromTRS(vec3(0, 2.5f, -6.1f)));
    NodeId left = s.addNode("left wall", room, MeshInstance{wallMesh, m.wall});
    LocalTransform lt = LocalTransform::fromTRS(vec3(-6.1f, 2.5f, 0));
    lt.setEulerDegrees(vec3(0, 90, 0));
    s.setLocal(left, lt);
}

// A textured crate, and a sheared + mirrored copy (general 4x4 local transform).
void addCrates(Scene& s, const DemoMaterials& m) {
    int crateMesh = addMesh(s, primitives::box(vec3(0.6f)));
    NodeId crateNode = s.addNode("crate", s.root(), MeshInstance{crateMesh, m.crate});
    LocalTransform ct = LocalTransform::fromTRS(vec3(-3.2f, 0.6f, -2.5f));
    ct.setEulerDegrees(vec3(0, 25, 0));
    s.setLocal(crateNode, ct);
    NodeId sheared = s.addNode("sheared crate", s.root(), MeshInstance{crateMesh, m.crate});
    s.setLocalMatrix(sheared, translation(vec3(-4.2f, 0.45f, 0.2f)) * shear(0, 1, 0.5f) * mirrorX() * scaling(vec3(0.75f)));
}

// Mesh torus on a turntable group: a hierarchy with composed transforms.
void addTurntable(Scene& s, const DemoMaterials& m) {
    NodeId turntable = s.addNode("turntable");
    s.setLocal(turntable, LocalTransform::fromTRS(vec3(3.0f, 0.0f, -2.0f)));
    int torusMesh = addMesh(s, primitives::torus(0.7f, 0.25f, 64, 24));
    NodeId torusNode = s.addNode("torus", turntable, MeshInstance{torusMesh, m.gold});
    LocalTransform tt = LocalTransform::fromTRS(vec3(0, 1.0f, 0));
    tt.setEulerDegrees(vec3(60, 0, 20));
    s.setLocal(torusNode, tt);
    int pedestalMesh = addMesh(s, primitives::cylinder(0.6f, 0.2f, 48, true));
    NodeId pedestal = s.addNode("pedestal", turntable, MeshInstance{pedestalMesh, m.wall});
    s.setLocal(pedestal, LocalTransform::fromTRS(vec3(0, 0.2f, 0)));
}

// Implicit spheres and a quadric: hyperboloid of one sheet x^2 + z^2 - y^2 = r^2, clipped to a box.
void addSpheresAndQuadric(Scene& s, const DemoMaterials& m) {
    ImplicitShape sphere;
    sphere.type = ImplicitType::Sphere;
    sphere.radius = 0.8f;
    NodeId s1 = s.addNode("red sphere", s.root(), ImplicitPayload{sphere, m.red});
    s.setLocal(s1, LocalTransform::fromTRS(vec3(-1.0f, 0.8f, 0.8f)));
    sphere.radius = 0.5f;
    NodeId s2 = s.addNode("blue sphere", s.root(), ImplicitPayload{sphere, m.blue});
    s.setLocal(s2, LocalTransform::fromTRS(vec3(0.6f, 0.5f, 2.2f)));

    ImplicitShape hyper;
    hyper.type = ImplicitType::Quadric;
    float r2 = 0.09f;
    hyper.quadric = mat4(1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -r2);
    hyper.quadricBounds = {vec3(-0.75f, -0.7f, -0.75f), vec3(0.75f, 0.7f, 0.75f)};
    NodeId hq = s.addNode("hyperboloid", s.root(), ImplicitPayload{hyper, m.teal});
    s.setLocal(hq, LocalTransform::fromTRS(vec3(1.6f, 0.7f, -3.8f)));
}

// CSG: a rounded block carved by a sphere and drilled by a cylinder.
void addCarvedBlock(Scene& s, const DemoMaterials& m) {
    NodeId csg = s.addNode("carved block", s.root(), CsgPayload{CsgNode{CsgOp::Difference}, m.csg});
    LocalTransform csgT = LocalTransform::fromTRS(vec3(1.2f, 0.7f, 0.4f));
    csgT.setEulerDegrees(vec3(0, -30, 0));
    s.setLocal(csg, csgT);
    ImplicitShape block;
    block.type = ImplicitType::Box;
    block.halfExtents = vec3(0.7f);
    s.addNode("block", csg, ImplicitPayload{block, m.csg});
    ImplicitShape cutter;
    cutter.type = ImplicitType::Sphere;
    cutter.radius = 0.85f;
    NodeId cutNode = s.addNode("scoop", csg, ImplicitPayload{cutter, m.cut});
    s.setLocal(cutNode, LocalTransform::fromTRS(vec3(0.45f, 0.45f, 0.45f)));
    ImplicitShape drill;
    drill.type = ImplicitType::Cylinder;
    drill.radius = 0.25f;
    drill.halfHeight = 1.0f;
    NodeId drillNode = s.addNode("drill", csg, ImplicitPayload{drill, m.cut});
    LocalTransform dt;
    dt.setEulerDegrees(vec3(90, 0, 0));
    s.setLocal(drillNode, dt);
}

// Other implicit primitives (a cone and a torus), a parametric Bezier patch and a density grid
// (metaballs).
void addOtherShapes(Scene& s, const DemoMaterials& m) {
    ImplicitShape cone;
    cone.type = ImplicitType::Cone;
    cone.radius = 0.5f;
    cone.halfHeight = 0.6f;
    NodeId coneNode = s.addNode("cone", s.root(), ImplicitPayload{cone, m.green});
    s.setLocal(coneNode, LocalTransform::fromTRS(vec3(-2.2f, 0.6f, 2.6f)));
    ImplicitShape itorus;
    itorus.type = ImplicitType::Torus;
    itorus.majorRadius = 0.45f;
    itorus.minorRadius = 0.15f;
    NodeId itNode = s.addNode("implicit torus", s.root(), ImplicitPayload{itorus, m.purple});
    LocalTransform itT = LocalTransform::fromTRS(vec3(2.8f, 0.15f, 1.8f));
    s.setLocal(itNode, itT);

    NodeId patch = s.addNode("bezier patch", s.root(), ParametricPayload{ParametricSurface::defaultPatch(), m.green});
    LocalTransform pt = LocalTransform::fromTRS(vec3(-0.8f, 1.6f, -4.3f), quat(1, 0, 0, 0), vec3(1.3f));
    pt.setEulerDegrees(vec3(55, 0, 0));
    s.setLocal(patch, pt);
    auto grid = std::make_shared<DensityGrid>(DensityGrid::metaballs(40));
    NodeId blobs = s.addNode("metaballs", s.root(), GridPayload{grid, m.purple});
    s.setLocal(blobs, LocalTransform::fromTRS(vec3(4.0f, 1.3f, -4.2f), quat(1, 0, 0, 0), vec3(0.9f)));
}

// Lights: a warm key (point, inverse square), a cool fill (directional) and a spot.
void addLights(Scene& s) {
    NodeId key = s.addNode("key light", s.root(), Light{LightType::Point, vec3(1.0f, 0.92f, 0.8f), 22.0f, true});
    s.setLocal(key, LocalTransform::fromTRS(vec3(2.5f, 4.5f, 3.5f)));
    NodeId fill = s.addNode("fill light", s.root(), Light{LightType::Directional, vec3(0.55f, 0.65f, 0.9f), 0.45f, false});
    s.lookAt(fill, vec3(-4, 5, 3), vec3(0, 0, 0));
    Light spot{LightType::Spot, vec3(1.0f, 0.85f, 0.6f), 1.2f, false};
    spot.spotInnerDeg = 14.0f;
    spot.spotOuterDeg = 22.0f;
    NodeId spotNode = s.addNode("spot light", s.root(), spot);
    s.lookAt(spotNode, vec3(-1.0f, 5.5f, -1.0f), vec3(-3.2f, 0.6f, -2.5f));
}

// The camera, made the active one.
void addCamera(Scene& s) {
    Camera cam;
    cam.projection.fovyDeg = 50.0f;
    cam.projection.zNear = 0.1f;
    cam.projection.zFar = 60.0f;
    cam.projection.orthoHalfHeight = 3.6f;
    NodeId camNode = s.addNode("camera", s.root(), cam);
    s.lookAt(camNode, vec3(0.5f, 3.6f, 9.5f), vec3(0.0f, 0.9f, -0.5f));
    s.activeCamera = camNode;
}

}   // namespace

// The parts are added in a fixed order: node ids, material and mesh indices depend on it.
Scene makeDemoScene() {
    Scene s;
    s.name = "demo room";
    setDemoSettings(s);
    const DemoMaterials m = addDemoMaterials(s);
    addRoom(s, m);
    addCrates(s, m);
    addTurntable(s, m);
    addSpheresAndQuadric(s, m);
    addCarvedBlock(s, m);
    addOtherShapes(s, m);
    addLights(s);
    addCamera(s);
    return s;
}

}   // namespace assets
