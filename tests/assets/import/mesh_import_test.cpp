// mesh_import_test.cpp - mesh import (OBJ/MTL, OFF, PLY, STL): every mesh in testdata/meshes
// against the triangle counts of MANIFEST.md, plus materials, textures, point clouds, lines,
// tristrips and the malformed files of meshes/invalid.
#include "import_test_util.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <map>

namespace fs = std::filesystem;
using namespace import_test;

namespace {
fs::path meshes(const std::string& rel) { return testing_support::testdataDir() / "meshes" / rel; }

assets::LoadResult mustLoad(const fs::path& p) {
    assets::LoadResult r = timedLoad(p, kHangGuardSeconds);
    EXPECT_TRUE(r.scene.has_value()) << r.error;
    return r;
}
const sg::Mesh& onlyMesh(const assets::LoadResult& r) {
    EXPECT_EQ(r.scene->meshes.size(), 1u);
    return *r.scene->meshes.at(0);
}
}   // namespace

// MANIFEST.md "tris" (fan-triangulated); -1: no count given; -2: may be refused (UTF-16).
TEST(MeshImportTest, ManifestTriangleCounts) {
    ASSERT_TRUE(testing_support::requireTestdata());
    const std::map<std::string, long> expected = {
        {"assimp/OBJ/WusonOBJ.obj", 3732},
        {"assimp/OBJ/box.obj", 12},
        {"assimp/OBJ/box_UTF16BE.obj", -2},
        {"assimp/OBJ/box_longline.obj", 944},
        {"assimp/OBJ/cube_with_vertexcolors.obj", 12},
        {"assimp/OBJ/multiple_spaces.obj", 1},
        {"assimp/OBJ/point_cloud.obj", 0},
        {"assimp/OBJ/spider.obj", 1368},
        {"assimp/OBJ/testmixed.obj", 12},
        {"assimp/OFF/Cube.off", 12},
        {"assimp/PLY/Wuson.ply", 3732},
        {"assimp/PLY/cube.ply", 12},
        {"assimp/PLY/cube_binary.ply", 12},
        {"assimp/PLY/cube_binary_header_with_RN_newline.ply", 12},
        {"assimp/PLY/cube_uv.ply", 12},
        {"assimp/PLY/issue623.ply", -1},
        {"assimp/PLY/points.ply", 0},
        {"assimp/PLY/pond.0.ply", 0},
        {"assimp/STL/3DSMaxExport.STL", 2000},
        {"assimp/STL/Spider_ascii.stl", 1368},
        {"assimp/STL/Wuson.stl", 3732},
        {"assimp/STL/sphereWithHole.stl", 285},
        {"assimp/STL/triangle.stl", 1},
        {"assimp/STL/triangle_with_empty_solid.stl", 1},
        {"common-3d-test-models/alligator/alligator.obj", 5981},
        {"common-3d-test-models/beetle-alt/beetle-alt.obj", 38656},
        {"common-3d-test-models/beetle/beetle.obj", 2053},
        {"common-3d-test-models/cheburashka/cheburashka.obj", 13334},
        {"common-3d-test-models/cheburashka/cheburashka.off", 13334},
        {"common-3d-test-models/cow/cow.obj", 5804},
        {"common-3d-test-models/cow/cow.ply", 5804},
        {"common-3d-test-models/homer/homer.obj", 12000},
        {"common-3d-test-models/homer/homer.off", 12000},
        {"common-3d-test-models/igea/igea.ply", 268686},
        {"common-3d-test-models/rocker-arm/rocker-arm.obj", 20088},
        {"common-3d-test-models/rocker-arm/rocker-arm.off", 20088},
        {"common-3d-test-models/spot/spot.obj", 5856},
        {"common-3d-test-models/spot/spot_quadrangulated.obj", 5856},
        {"common-3d-test-models/stanford-bunny/stanford-bunny.obj", 69451},
        {"common-3d-test-models/suzanne/suzanne.obj", 968},
        {"common-3d-test-models/teapot/teapot.obj", 6320},
        {"draco-testdata/Box.ply", 12},
        {"draco-testdata/STL/bunny.stl", 69451},
        {"draco-testdata/STL/test_sphere.stl", 224},
        {"draco-testdata/cube_att.obj", 12},
        {"draco-testdata/cube_att.ply", 12},
        {"draco-testdata/int_point_cloud.ply", 0},
        {"draco-testdata/mat_test.obj", 1300},
        {"draco-testdata/multiple_isolated_triangles.obj", 5},
        {"draco-testdata/non_manifold_wrap.obj", 12},
        {"draco-testdata/point_cloud_test_pos.ply", 0},
        {"draco-testdata/point_cloud_test_pos_norm.ply", 0},
        {"draco-testdata/sphere.obj", 224},
        {"draco-testdata/test_extra_whitespace.ply", 1},
        {"draco-testdata/test_generic.ply", 224},
        {"draco-testdata/test_lines.obj", 0},
        {"draco-testdata/test_more_datatypes.ply", 1},
        {"draco-testdata/test_nm.obj", 170},
        {"draco-testdata/test_pos_color.ply", 224},
        {"draco-testdata/test_sphere.obj", 224},
        {"draco-testdata/triangle_with_degenerate_tex_coords.obj", 1},
    };
    for (const auto& [rel, tris] : expected) {
        SCOPED_TRACE(rel);
        assets::LoadResult r = timedLoad(meshes(rel), kHangGuardSeconds);
        if (tris == -2) {
            if (!r.scene) { EXPECT_NE(r.error.find(fs::path(rel).filename().string()), std::string::npos); }
            continue;
        }
        ASSERT_TRUE(r.scene) << r.error;
        for (const auto& m : r.scene->meshes) {
            EXPECT_EQ(m->validate(), "") << m->name;
            if (m->mode == sg::PrimitiveMode::Triangles) { EXPECT_EQ(m->normals.size(), m->positions.size()); }
        }
        if (tris >= 0) { EXPECT_EQ(uniqueTriangles(*r.scene), size_t(tris)); }
        EXPECT_TRUE(r.scene->valid(r.scene->activeCamera));
        EXPECT_EQ(countPayload(*r.scene, "light"), 1u);
    }
}

TEST(MeshImportTest, BunnyViaObjAndStl) {
    ASSERT_TRUE(testing_support::requireTestdata());
    assets::LoadResult obj = mustLoad(meshes("common-3d-test-models/stanford-bunny/stanford-bunny.obj"));
    assets::LoadResult stl = mustLoad(meshes("draco-testdata/STL/bunny.stl"));
    ASSERT_TRUE(obj.scene && stl.scene);
    EXPECT_EQ(onlyMesh(obj).triangleCount(), 69451u);
    EXPECT_LE(onlyMesh(obj).positions.size(), 35947u);   // unreferenced vertices are dropped
    EXPECT_GE(onlyMesh(obj).positions.size(), 34000u);
    EXPECT_EQ(onlyMesh(stl).triangleCount(), 69451u);
    // STL corners are welded by position: far fewer vertices than 3 per triangle.
    EXPECT_LT(onlyMesh(stl).positions.size(), 40000u);
    EXPECT_TRUE(obj.warnings.empty());
}

TEST(MeshImportTest, PlyTristripsBinaryAndCrHeader) {
    ASSERT_TRUE(testing_support::requireTestdata());
    assets::LoadResult cow = mustLoad(meshes("common-3d-test-models/cow/cow.ply"));
    ASSERT_TRUE(cow.scene);
    EXPECT_EQ(onlyMesh(cow).triangleCount(), 5804u);
    EXPECT_EQ(onlyMesh(cow).positions.size(), 2903u);
    assets::LoadResult box = mustLoad(meshes("draco-testdata/Box.ply"));   // CR-only header
    ASSERT_TRUE(box.scene);
    EXPECT_EQ(onlyMesh(box).triangleCount(), 12u);
    EXPECT_TRUE(box.warnings.empty()) << box.warnings.front();
}

TEST(MeshImportTest, PointCloudsAndLines) {
    ASSERT_TRUE(testing_support::requireTestdata());
    assets::LoadResult pond = mustLoad(meshes("assimp/PLY/pond.0.ply"));
    ASSERT_TRUE(pond.scene);
    const sg::Mesh& p = onlyMesh(pond);
    EXPECT_EQ(p.mode, sg::PrimitiveMode::Points);
    EXPECT_EQ(p.positions.size(), 70051u);
    EXPECT_EQ(p.indices.size(), 70051u);
    EXPECT_EQ(p.colors.size(), 70051u);
    EXPECT_EQ(p.normals.size(), 70051u);
    assets::LoadResult pts = mustLoad(meshes("assimp/OBJ/point_cloud.obj"));
    ASSERT_TRUE(pts.scene);
    EXPECT_EQ(onlyMesh(pts).mode, sg::PrimitiveMode::Points);
    EXPECT_EQ(onlyMesh(pts).positions.size(), 3u);
    assets::LoadResult lines = mustLoad(meshes("draco-testdata/test_lines.obj"));
    ASSERT_TRUE(lines.scene);
    EXPECT_EQ(onlyMesh(lines).mode, sg::PrimitiveMode::Lines);
    EXPECT_GT(onlyMesh(lines).indices.size(), 100u);
}

TEST(MeshImportTest, ObjMaterialsAndTextures) {
    ASSERT_TRUE(testing_support::requireTestdata());
    assets::LoadResult spider = mustLoad(meshes("assimp/OBJ/spider.obj"));
    ASSERT_TRUE(spider.scene);
    EXPECT_GE(spider.scene->materials.size(), 2u);
    EXPECT_EQ(uniqueTriangles(*spider.scene), 1368u);
    int textured = 0;
    for (const auto& m : spider.scene->materials) textured += m.diffuseTexture >= 0;
    EXPECT_GE(textured, 1) << "backslash texture paths (.\\\\SpiderTex.jpg) resolve";
    for (const auto& w : spider.warnings) std::printf("spider warning: %s\n", w.c_str());

    assets::LoadResult mat = mustLoad(meshes("draco-testdata/mat_test.obj"));
    ASSERT_TRUE(mat.scene);
    EXPECT_GE(mat.scene->materials.size(), 2u);
    EXPECT_GE(countPayload(*mat.scene, "mesh"), 2u);
    bool distinct = false;
    for (const auto& m : mat.scene->materials) distinct |= m.baseColor != mat.scene->materials[0].baseColor;
    EXPECT_TRUE(distinct);

    // spot.obj has no mtllib; its texture lies beside it.
    assets::LoadResult spot = mustLoad(meshes("common-3d-test-models/spot/spot.obj"));
    ASSERT_TRUE(spot.scene);
    ASSERT_EQ(spot.scene->textures.size(), 1u);
    EXPECT_EQ(spot.scene->textures[0]->width, 1024);
    ASSERT_EQ(spot.scene->meshes.size(), 1u);
    EXPECT_FALSE(spot.scene->meshes[0]->uv0.empty());
    sg::NodeId n = spot.scene->depthFirstOrder().at(1);
    auto* mi = std::get_if<sg::MeshInstance>(&spot.scene->node(n).payload);
    ASSERT_TRUE(mi);
    EXPECT_EQ(spot.scene->material(mi->material).diffuseTexture, 0);

    assets::LoadResult vc = mustLoad(meshes("assimp/OBJ/cube_with_vertexcolors.obj"));
    ASSERT_TRUE(vc.scene);
    EXPECT_EQ(onlyMesh(vc).colors.size(), onlyMesh(vc).positions.size());
}

TEST(MeshImportTest, InvalidMeshesGiveClearErrors) {
    ASSERT_TRUE(testing_support::requireTestdata());
    for (const auto& e : fs::recursive_directory_iterator(meshes("invalid"))) {
        if (!e.is_regular_file()) continue;
        std::string ext = e.path().extension().string();
        if (ext != ".obj" && ext != ".off" && ext != ".ply" && ext != ".stl") continue;
        SCOPED_TRACE(e.path().string());
        assets::LoadResult r = timedLoad(e.path(), kHangGuardSeconds);
        if (!r.scene) {
            EXPECT_NE(r.error.find(e.path().filename().string()), std::string::npos) << r.error;
            EXPECT_EQ(r.error.find('\n'), std::string::npos);
        }
        std::printf("%s -> %s\n", e.path().filename().string().c_str(),
                    r.scene ? ("loaded, " + std::to_string(r.warnings.size()) + " warnings").c_str() : r.error.c_str());
    }
}

TEST(MeshImportTest, CancelHonoured) {
    ASSERT_TRUE(testing_support::requireTestdata());
    std::atomic<bool> cancel{true};
    assets::LoadOptions o;
    o.cancel = &cancel;
    for (const char* f :
         {"common-3d-test-models/igea/igea.ply", "common-3d-test-models/stanford-bunny/stanford-bunny.obj", "draco-testdata/STL/bunny.stl"}) {
        assets::LoadResult r = assets::loadScene(meshes(f), o);
        EXPECT_FALSE(r.scene) << f;
        EXPECT_NE(r.error.find("cancelled"), std::string::npos) << r.error;
    }
}
