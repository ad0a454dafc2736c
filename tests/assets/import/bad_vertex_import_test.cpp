// bad_vertex_import_test.cpp - non-finite or absurd vertices (NaN, Inf, |coordinate| > 1e30,
// numbers beyond double's range) in OBJ, OFF, PLY (ASCII, binary, tristrips) and STL (ASCII,
// binary), files generated at run time: the bad vertices are dropped with the faces (and OBJ
// lines) that use them, a point cloud loses only those points, one warning names the file and
// the counts, and the rest loads. A file of nothing but bad vertices is refused in one line;
// truncated files keep their own warning.
#include "import_test_util.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace fs = std::filesystem;
using namespace import_test;

namespace {

fs::path dir() {
    static const fs::path d = scratchDir("bad-vertices");
    return d;
}

assets::LoadResult loadText(const std::string& name, const std::string& text) {
    writeText(dir() / name, text);
    return timedLoad(dir() / name, kHangGuardSeconds);
}

// Every mesh is valid (finite positions, indices in range) and the file loaded with exactly
// one warning, which names the file and says `counts`.
void expectLoadedWithOneWarning(const assets::LoadResult& r, const std::string& name, const std::string& counts) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(r.scene) << r.error;
    for (const auto& m : r.scene->meshes) {
        EXPECT_EQ(m->validate(), "") << m->name;
        for (const sg::vec3& p : m->positions) EXPECT_TRUE(sg::isFinite(p) && std::fabs(p.x) <= 1e30f);
    }
    ASSERT_EQ(r.warnings.size(), 1u) << (r.warnings.empty() ? "" : r.warnings[0] + " / " + r.warnings.back());
    EXPECT_EQ(r.warnings[0].rfind(name + ": ", 0), 0u) << r.warnings[0];
    EXPECT_NE(r.warnings[0].find(counts), std::string::npos) << r.warnings[0];
    EXPECT_EQ(r.warnings[0].find('\n'), std::string::npos);
}

const sg::Mesh& only(const assets::LoadResult& r, sg::PrimitiveMode mode) {
    for (const auto& m : r.scene->meshes)
        if (m->mode == mode) return *m;
    ADD_FAILURE() << "no mesh of that mode";
    return *r.scene->meshes.at(0);
}

// A 4 x 4 grid of points (16), three of them bad, as PLY/OBJ/OFF text lines "x y z".
const char* const kCoords[16] = {"0 0 0", "1 0 0",   "2 0 0", "3 0 0", "0 1 0", "nan 1 0", "2 1 0", "3 1 0",
                                 "0 2 0", "1 inf 0", "2 2 0", "3 2 0", "0 3 0", "1 3 0",   "2 3 0", "3 3 -1e31"};

std::string plyHeader(const char* format, int vertices, int faces, const char* faceElement = "face") {
    std::string h = std::string("ply\nformat ") + format + " 1.0\nelement vertex " + std::to_string(vertices) +
                    "\nproperty float x\nproperty float y\nproperty float z\n";
    if (faces >= 0) h += std::string("element ") + faceElement + " " + std::to_string(faces) + "\nproperty list uchar int vertex_indices\n";
    return h + "end_header\n";
}

// The grid's 9 quads (v = 4 * row + column): the bad vertices 5, 9 and 15 are used by
// quads 0, 1, 3, 4 (vertex 5), 3, 4, 6, 7 (vertex 9) and 8 (vertex 15): 7 quads, 2 left.
std::vector<std::array<int, 4>> gridQuads() {
    std::vector<std::array<int, 4>> q;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) q.push_back({4 * r + c, 4 * r + c + 1, 4 * r + c + 5, 4 * r + c + 4});
    return q;
}

}   // namespace

// The report from users: a 16-point PLY cloud with 3 non-finite vertices was refused.
TEST(BadVertexImportTest, PlyPointCloudKeepsTheGoodPoints) {
    std::string ascii = plyHeader("ascii", 16, -1);
    for (const char* v : kCoords) ascii += std::string(v) + "\n";
    assets::LoadResult r = loadText("cloud.ply", ascii);
    expectLoadedWithOneWarning(r, "cloud.ply", "dropped 3 of 16 vertices");
    ASSERT_TRUE(r.scene);
    const sg::Mesh& m = only(r, sg::PrimitiveMode::Points);
    EXPECT_EQ(m.positions.size(), 13u);
    EXPECT_EQ(m.indices.size(), 13u);
    EXPECT_EQ(r.warnings.at(0).find("face"), std::string::npos) << "a point cloud has no faces to drop";

    // Binary, with NaN, -Inf and 1e31 (finite as a float, but absurd) and per-vertex colours.
    std::string bin =
        "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const float pts[5][3] = {{0, 0, 0}, {nan, 0, 0}, {1, -inf, 0}, {0, 1, 1e31f}, {1, 1, 1}};
    for (int i = 0; i < 5; ++i) {
        bin.append(reinterpret_cast<const char*>(pts[i]), 12);
        bin += char(i * 50);
        bin += char(0);
        bin += char(255);
    }
    r = loadText("cloud_binary.ply", bin);
    expectLoadedWithOneWarning(r, "cloud_binary.ply", "dropped 3 of 5 vertices");
    ASSERT_TRUE(r.scene);
    const sg::Mesh& b = only(r, sg::PrimitiveMode::Points);
    ASSERT_EQ(b.positions.size(), 2u);
    EXPECT_EQ(b.positions[1], sg::vec3(1, 1, 1));
    ASSERT_EQ(b.colors.size(), 2u);   // attributes follow their vertices
    EXPECT_NEAR(b.colors[1].r, 200 / 255.0f, 1e-6f);
}

TEST(BadVertexImportTest, FacesUsingBadVerticesAreDropped) {
    // PLY (ASCII): 9 quads over the grid, 7 use a bad vertex.
    std::string ply = plyHeader("ascii", 16, 9);
    for (const char* v : kCoords) ply += std::string(v) + "\n";
    for (auto q : gridQuads())
        ply += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " " + std::to_string(q[3]) + "\n";
    assets::LoadResult r = loadText("grid.ply", ply);
    expectLoadedWithOneWarning(r, "grid.ply", "dropped 3 of 16 vertices (non-finite or |coordinate| > 1e30) and 7 faces that use them");
    ASSERT_TRUE(r.scene);
    EXPECT_EQ(uniqueTriangles(*r.scene), 4u);   // quads 2 and 5
    EXPECT_EQ(r.scene->meshes.at(0)->positions.size(), 13u);

    // OFF: the same grid.
    std::string off = "OFF\n16 9 0\n";
    for (const char* v : kCoords) off += std::string(v) + "\n";
    for (auto q : gridQuads())
        off += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " " + std::to_string(q[3]) + "\n";
    r = loadText("grid.off", off);
    expectLoadedWithOneWarning(r, "grid.off", "dropped 3 of 16 vertices (non-finite or |coordinate| > 1e30) and 7 faces that use them");
    ASSERT_TRUE(r.scene);
    EXPECT_EQ(uniqueTriangles(*r.scene), 4u);

    // OBJ: the grid, plus a line through a bad vertex, one through good ones, and points.
    std::string obj;
    for (const char* v : kCoords) obj += std::string("v ") + v + "\n";
    for (auto q : gridQuads())
        obj +=
            "f " + std::to_string(q[0] + 1) + " " + std::to_string(q[1] + 1) + " " + std::to_string(q[2] + 1) + " " + std::to_string(q[3] + 1) + "\n";
    obj += "l 1 6 7\nl 1 2 3\np 1 6 16 2\n";
    r = loadText("grid.obj", obj);
    expectLoadedWithOneWarning(r, "grid.obj", "dropped 3 of 16 vertices (non-finite or |coordinate| > 1e30) and 7 faces and 1 line that use them");
    ASSERT_TRUE(r.scene);
    EXPECT_EQ(uniqueTriangles(*r.scene), 4u);
    EXPECT_EQ(only(r, sg::PrimitiveMode::Lines).indices.size(), 4u);    // 1-2, 2-3
    EXPECT_EQ(only(r, sg::PrimitiveMode::Points).indices.size(), 2u);   // vertices 1 and 2

    // PLY tristrips: one strip over the grid's first two rows; triangles touching vertex 5 go.
    std::string strip = plyHeader("ascii", 16, 1, "tristrips");
    for (const char* v : kCoords) strip += std::string(v) + "\n";
    strip += "8 0 4 1 5 2 6 3 7\n";   // 6 triangles, 3 of them use vertex 5
    r = loadText("strip.ply", strip);
    expectLoadedWithOneWarning(r, "strip.ply", "and 3 faces");
    ASSERT_TRUE(r.scene);
    EXPECT_EQ(uniqueTriangles(*r.scene), 3u);
}

TEST(BadVertexImportTest, ObjVertexCloudAndNumbersBeyondRange) {
    // Vertices only: a point cloud of the good ones. "1e400" is beyond double's range (an
    // overflow, not a malformed number); "1e-400" underflows to 0 and is fine.
    assets::LoadResult r = loadText("cloud.obj", "v 0 0 0\nv 1e400 0 0\nv 1 1 1\nv -inf 0 0\nv 1e-400 2 0\n");
    expectLoadedWithOneWarning(r, "cloud.obj", "dropped 2 of 5 vertices");
    ASSERT_TRUE(r.scene);
    const sg::Mesh& m = only(r, sg::PrimitiveMode::Points);
    ASSERT_EQ(m.positions.size(), 3u);
    EXPECT_EQ(m.positions[2], sg::vec3(0, 2, 0));
    // A malformed coordinate keeps its old treatment (zero, one warning of its own).
    r = loadText("malformed.obj", "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
    ASSERT_TRUE(r.scene) << r.error;
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("malformed vertex lines"), std::string::npos) << r.warnings[0];
}

TEST(BadVertexImportTest, StlFacetsWithBadCornersAreDropped) {
    std::string ascii = "solid t\n";
    const char* corners[3][3] = {{"0 0 0", "1 0 0", "0 1 0"}, {"0 0 0", "1 0 nan", "0 1 0"}, {"1 1 1", "2 1 1", "1 2 1e35"}};
    for (auto& f : corners)
        ascii += std::string("facet normal 0 0 1\nouter loop\nvertex ") + f[0] + "\nvertex " + f[1] + "\nvertex " + f[2] + "\nendloop\nendfacet\n";
    ascii += "endsolid t\n";
    assets::LoadResult r = loadText("t.stl", ascii);
    expectLoadedWithOneWarning(r, "t.stl", "dropped 2 of 9 vertices (non-finite or |coordinate| > 1e30) and 2 faces that use them");
    ASSERT_TRUE(r.scene);
    EXPECT_EQ(uniqueTriangles(*r.scene), 1u);

    std::string bin(80, ' ');
    const uint32_t n = 3;
    bin.append(reinterpret_cast<const char*>(&n), 4);
    const float inf = std::numeric_limits<float>::infinity();
    const float tris[3][12] = {
        {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 0, 1, 0, 0, 0, inf, 0, 0, 0, 1, 0}, {0, 0, 1, 5, 5, 5, 6, 5, 5, 5, 6, -2e30f}};
    for (auto& t : tris) {
        bin.append(reinterpret_cast<const char*>(t), 48);
        bin.append(2, '\0');
    }
    r = loadText("t_binary.stl", bin);
    expectLoadedWithOneWarning(r, "t_binary.stl", "dropped 2 of 9 vertices (non-finite or |coordinate| > 1e30) and 2 faces that use them");
    ASSERT_TRUE(r.scene);
    EXPECT_EQ(uniqueTriangles(*r.scene), 1u);
}

// Nothing but bad vertices: refused, one line naming the file. Broken files stay refused /
// warned about as before, with the bad vertices counted on top.
TEST(BadVertexImportTest, AllBadIsRefusedAndTruncationStillReported) {
    for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
             {"allbad.ply", plyHeader("ascii", 2, -1) + "nan 0 0\n0 inf 0\n"},
             {"allbad.off", "OFF\n3 1 0\nnan 0 0\n1 nan 0\n0 1 nan\n3 0 1 2\n"},
             {"allbad.obj", "v nan 0 0\nv 1 nan 0\nv 0 1 nan\nf 1 2 3\n"},
             {"allbad.stl",
              "solid x\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n"}}) {
        SCOPED_TRACE(name);
        assets::LoadResult r = loadText(name, text);
        EXPECT_FALSE(r.scene);
        EXPECT_EQ(r.error.rfind(name + ": ", 0), 0u) << r.error;
        EXPECT_NE(r.error.find("1e30"), std::string::npos) << r.error;
        EXPECT_EQ(r.error.find('\n'), std::string::npos);
    }
    // Truncated OFF with a bad vertex: the truncation warning and the bad-vertex warning.
    assets::LoadResult r = loadText("trunc.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\nnan 1 0\n3 0 1 2\n3 1");
    ASSERT_TRUE(r.scene) << r.error;
    ASSERT_EQ(r.warnings.size(), 2u);
    EXPECT_NE(r.warnings[0].find("truncated"), std::string::npos) << r.warnings[0];
    EXPECT_NE(r.warnings[1].find("dropped 1 of 4 vertices"), std::string::npos) << r.warnings[1];
    EXPECT_EQ(uniqueTriangles(*r.scene), 1u);
    // A wrong count (more vertices claimed than the file can hold) is still refused.
    r = loadText("counts.off", "OFF\n400 1 0\nnan 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    EXPECT_FALSE(r.scene);
    EXPECT_NE(r.error.find("400 vertices"), std::string::npos) << r.error;
}

// glTF: the same grid as float32 POSITION (NaN, +Inf, -1e31) with 18 indexed triangles, and as
// a POINTS primitive: the bad vertices go with the triangles (points) that use them, one
// warning, the rest loads (the glTF importer used to refuse the whole file). Each quad is split
// (a,b,c) (a,c,d): quads 1 and 6 keep the triangle without a bad corner, so 12 of 18 go.
TEST(BadVertexImportTest, GltfPrimitivesDropBadVertices) {
    std::vector<float> pos;
    for (int i = 0; i < 16; ++i) {
        float x = float(i % 4), y = float(i / 4), z = 0.0f;
        if (i == 5) x = std::numeric_limits<float>::quiet_NaN();
        if (i == 9) y = std::numeric_limits<float>::infinity();
        if (i == 15) z = -1e31f;
        pos.insert(pos.end(), {x, y, z});
    }
    std::vector<uint32_t> idx;
    for (const auto& q : gridQuads())
        idx.insert(idx.end(), {uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2]), uint32_t(q[0]), uint32_t(q[2]), uint32_t(q[3])});
    std::string bytes(reinterpret_cast<const char*>(pos.data()), pos.size() * 4);
    bytes.append(reinterpret_cast<const char*>(idx.data()), idx.size() * 4);
    auto gltf = [&](int mode, bool indexed) {
        return std::string(R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)") +
               R"("meshes":[{"primitives":[{"attributes":{"POSITION":0})" + (indexed ? std::string(R"(,"indices":1)") : "") +
               ",\"mode\":" + std::to_string(mode) + "}]}]," + R"("buffers":[{"byteLength":)" + std::to_string(bytes.size()) +
               R"(,"uri":"data:application/octet-stream;base64,)" + testing_support::base64Encode(bytes) + R"("}],)" +
               R"("bufferViews":[{"buffer":0,"byteLength":192},{"buffer":0,"byteOffset":192,"byteLength":216}],)" +
               R"("accessors":[{"bufferView":0,"componentType":5126,"count":16,"type":"VEC3"},)" +
               R"({"bufferView":1,"componentType":5125,"count":54,"type":"SCALAR"}]})";
    };
    assets::LoadResult r = loadText("grid.gltf", gltf(4, true));
    expectLoadedWithOneWarning(r, "grid.gltf", "dropped 3 of 16 vertices (non-finite or |coordinate| > 1e30) and 12 triangles that use them");
    ASSERT_TRUE(r.scene);
    EXPECT_EQ(only(r, sg::PrimitiveMode::Triangles).indices.size(), 6u * 3u);

    r = loadText("points.gltf", gltf(0, false));
    expectLoadedWithOneWarning(r, "points.gltf", "dropped 3 of 16 vertices (non-finite or |coordinate| > 1e30) and 3 points that use them");
    ASSERT_TRUE(r.scene);
    EXPECT_EQ(only(r, sg::PrimitiveMode::Points).indices.size(), 13u);
}
