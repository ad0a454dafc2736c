// openmesh_reference_test.cpp - OpenMesh as the reference implementation for our own mesh
// parsers.
//
// The importers read OBJ/OFF/PLY/STL with small bounded parsers of our own, because Debian's
// OpenMesh 9.0 cannot be used on files from strangers (it follows OBJ mtllib paths anywhere,
// opens FIFOs/devices itself, throws bad_alloc on hostile header counts) and misses real data
// (PLY tristrips, CR-only PLY headers, faces dropped from non-manifold STL). On the well-formed
// classic meshes it reads correctly, it is the yardstick: our triangle counts and bounding
// boxes must equal what OpenMesh reads from the same file.
#include "assets/scene_io.h"
#include "test_support.h"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include <gtest/gtest.h>

namespace {

using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

struct Counts {
    size_t triangles = 0;
    sg::Aabb bounds;
};

Counts viaOpenMesh(const std::filesystem::path& p) {
    PolyMesh m;
    Counts c;
    OpenMesh::IO::Options opt;
    if (!OpenMesh::IO::read_mesh(m, p.string(), opt)) return c;
    for (auto f : m.faces()) c.triangles += m.valence(f) - 2;   // fan triangulation
    for (auto v : m.vertices()) {
        auto q = m.point(v);
        c.bounds.extend(sg::vec3(q[0], q[1], q[2]));
    }
    return c;
}

Counts viaOurs(const std::filesystem::path& p) {
    Counts c;
    assets::LoadResult r = assets::loadScene(p);
    EXPECT_TRUE(r.scene) << r.error;
    if (!r.scene) return c;
    for (sg::NodeId id : r.scene->depthFirstOrder()) {
        auto* mi = std::get_if<sg::MeshInstance>(&r.scene->node(id).payload);
        if (!mi) continue;
        const sg::Mesh& m = *r.scene->meshes[mi->mesh];
        c.triangles += m.triangleCount();
        c.bounds.extend(m.bounds().transformed(r.scene->world(id)));
    }
    return c;
}

}   // namespace

TEST(OpenMeshReferenceTest, OurParsersAgreeWithOpenMeshOnClassicMeshes) {
    ASSERT_TRUE(testing_support::requireTestdata());
    const auto dir = testing_support::testdataDir() / "meshes";
    const char* files[] = {
        "common-3d-test-models/stanford-bunny/stanford-bunny.obj",
        "common-3d-test-models/teapot/teapot.obj",
        "common-3d-test-models/suzanne/suzanne.obj",
        "common-3d-test-models/cheburashka/cheburashka.off",
        "common-3d-test-models/homer/homer.off",
        "common-3d-test-models/rocker-arm/rocker-arm.off",
        "draco-testdata/test_generic.ply",   // (cube_att.ply: OpenMesh keeps 2 of its 12 triangles)
        "draco-testdata/STL/test_sphere.stl",
        "assimp/PLY/cube_binary.ply",
    };
    for (const char* f : files) {
        SCOPED_TRACE(f);
        Counts ref = viaOpenMesh(dir / f), ours = viaOurs(dir / f);
        ASSERT_GT(ref.triangles, 0u) << "OpenMesh could not read the reference file";
        EXPECT_EQ(ours.triangles, ref.triangles);
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(ours.bounds.min[a], ref.bounds.min[a], 1e-5f * (1 + std::abs(ref.bounds.min[a])));
            EXPECT_NEAR(ours.bounds.max[a], ref.bounds.max[a], 1e-5f * (1 + std::abs(ref.bounds.max[a])));
        }
    }
}
