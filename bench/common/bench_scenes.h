// bench_scenes.h - scenes more than one benchmark draws, built the same way everywhere so that
// their figures compare: the mesh scenes (one mesh on a ground plane, framed like the bunny),
// the single-mesh sphere grids (mesh10k / mesh100k / mesh1M), the instanced ones (spheres...)
// and the grid scenes' camera and key.
#pragma once

#include "scenegraph/mesh.h"
#include "scenegraph/scene.h"

#include <memory>
#include <string>

namespace bench {

struct BenchScene {
    std::string name;
    sg::Scene scene;
    size_t triangles = 0;
};

// The camera (looking down at a grid of `extent` units from the front) and the point key light
// of the grid scenes.
void addGridCameraAndKey(sg::Scene& s, float extent);

// One mesh (a single draw): grid x grid uv-spheres of `seg` slices (seg/2 stacks) and a ground
// plane of `groundSub` x `groundSub` quads, merged, one material, one point light.
BenchScene singleMesh(const std::string& name, int grid, int seg, int groundSub);

// Instances: grid x grid instances of one uv-sphere mesh of `seg` slices (seg/2 stacks) on a
// ground plane, a point key light and a sun (spheres10k / spheres100k / spheres1M; small `seg`:
// many tiny instances).
BenchScene sphereGrid(const std::string& name, int grid, int seg);

// One mesh on a ground plane, scaled to a 2-unit diagonal, seen from the front with a point light
// (the bunny's framing).
BenchScene meshScene(const std::string& name, std::shared_ptr<sg::Mesh> m);

// meshScene of the first mesh of a file the viewer reads (OBJ, OFF, PLY, STL; a glTF's first
// mesh), through the viewer's own importer; false (and a line on stderr) when it has none.
// An empty name: the file's stem.
bool fileScene(const std::string& path, BenchScene& b, std::string name = "");

}   // namespace bench
