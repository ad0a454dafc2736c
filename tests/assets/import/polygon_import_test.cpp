// polygon_import_test.cpp - what the mesh importers make of polygon faces and of bad vertices
// (files generated at run time):
//   * a U-shaped face in OBJ, OFF, PLY (ASCII and binary) loads as triangles covering the U
//     exactly (area 7, not the fan's), facing the way the face winds;
//   * non-finite or absurd vertices (NaN, Inf, |coordinate| > 1e30) are dropped with the
//     faces that use them (point clouds: only those points), with one warning naming the
//     file and the counts; the rest loads.
#include "import_test_util.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cstring>

namespace fs = std::filesystem;
using namespace import_test;

namespace {

// The U: a 3 x 3 square without the notch [1, 2] x [1, 3]; area 7. Counter-clockwise seen
// from +z; the face starts at an inner corner of the notch, where a fan spills into it.
const float kU[8][2] = {{2, 1}, {1, 1}, {1, 3}, {0, 3}, {0, 0}, {3, 0}, {3, 3}, {2, 3}};
constexpr double kUArea = 7.0;

struct Summary {
    size_t triangles = 0;
    double area = 0;         // sum of triangle areas
    double signedArea = 0;   // sum of triangle areas along +z (negative when facing -z)
};

Summary summarize(const assets::LoadResult& r) {
    Summary s;
    if (!r.scene) return s;
    for (const auto& m : r.scene->meshes) {
        if (m->mode != sg::PrimitiveMode::Triangles) continue;
        s.triangles += m->triangleCount();
        for (size_t i = 0; i + 2 < m->indices.size(); i += 3) {
            const sg::vec3 a = m->positions[m->indices[i]], b = m->positions[m->indices[i + 1]], c = m->positions[m->indices[i + 2]];
            const glm::dvec3 n = glm::cross(glm::dvec3(b - a), glm::dvec3(c - a)) * 0.5;
            s.area += glm::length(n);
            s.signedArea += n.z;
        }
    }
    return s;
}

std::string uObj(bool clockwise) {
    std::string s = "# a U-shaped face\n";
    for (auto& v : kU) s += "v " + std::to_string(v[0]) + " " + std::to_string(v[1]) + " 0\n";
    s += clockwise ? "f 8 7 6 5 4 3 2 1\n" : "f 1 2 3 4 5 6 7 8\n";
    return s;
}
std::string uOff() {
    std::string s = "OFF\n8 1 0\n";
    for (auto& v : kU) s += std::to_string(v[0]) + " " + std::to_string(v[1]) + " 0\n";
    return s + "8 0 1 2 3 4 5 6 7\n";
}
std::string plyHeader(const char* format, int vertices, int faces) {
    return std::string("ply\nformat ") + format + " 1.0\nelement vertex " + std::to_string(vertices) +
           "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(faces) +
           "\nproperty list uchar int vertex_indices\nend_header\n";
}
std::string uPlyAscii() {
    std::string s = plyHeader("ascii", 8, 1);
    for (auto& v : kU) s += std::to_string(v[0]) + " " + std::to_string(v[1]) + " 0\n";
    return s + "8 0 1 2 3 4 5 6 7\n";
}
std::string uPlyBinary() {
    std::string s = plyHeader("binary_little_endian", 8, 1);
    for (auto& v : kU) {
        const float xyz[3] = {v[0], v[1], 0.0f};
        s.append(reinterpret_cast<const char*>(xyz), 12);
    }
    s += char(8);
    for (int32_t i = 0; i < 8; ++i) s.append(reinterpret_cast<const char*>(&i), 4);
    return s;
}

}   // namespace

TEST(PolygonImportTest, UShapedFaceCoversTheU) {
    const fs::path dir = scratchDir("polygon-u");
    const std::pair<const char*, std::string> files[] = {
        {"u.obj", uObj(false)}, {"u.off", uOff()}, {"u.ply", uPlyAscii()}, {"u_binary.ply", uPlyBinary()}};
    for (const auto& [name, text] : files) {
        SCOPED_TRACE(name);
        writeText(dir / name, text);
        assets::LoadResult r = timedLoad(dir / name, kHangGuardSeconds);
        ASSERT_TRUE(r.scene) << r.error;
        EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
        const Summary s = summarize(r);
        EXPECT_EQ(s.triangles, 6u);
        EXPECT_NEAR(s.area, kUArea, 1e-5) << "triangles overlap or spill into the notch";
        EXPECT_NEAR(s.signedArea, kUArea, 1e-5) << "some triangle faces the wrong way";
        for (const auto& m : r.scene->meshes)
            for (const sg::vec3& n : m->normals) EXPECT_NEAR(n.z, 1.0f, 1e-5f);
    }
    // Wound the other way: the same U, facing -z.
    writeText(dir / "u_cw.obj", uObj(true));
    assets::LoadResult r = timedLoad(dir / "u_cw.obj", kHangGuardSeconds);
    ASSERT_TRUE(r.scene) << r.error;
    const Summary s = summarize(r);
    EXPECT_NEAR(s.area, kUArea, 1e-5);
    EXPECT_NEAR(s.signedArea, -kUArea, 1e-5);
    for (const sg::vec3& n : r.scene->meshes.at(0)->normals) EXPECT_NEAR(n.z, -1.0f, 1e-5f);
}
