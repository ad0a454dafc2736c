// mesh_internal.h - private to assets/src/mesh/: what the OBJ, OFF, PLY and STL importers share
// (limits, a text cursor, number and coordinate parsing, the load context, bad-vertex
// bookkeeping, polygon triangulation and the scene building) and their documentation.
//
// OBJ (+MTL), OFF, PLY (ASCII / binary, faces or tristrips, point clouds) and STL (ASCII /
// binary) import. The files:
//   load.cpp     detail::loadMeshFile: reads the file, picks the format by extension and turns
//                a failure (Fail, out of memory) into the load's error
//   builder.cpp  the shared part: number and coordinate parsing, bad vertices, polygons into
//                triangles (assets/polygon.h), the scene of the parsed meshes
//   obj.cpp      OBJ + MTL
//   off.cpp      OFF
//   ply.cpp      PLY
//   stl.cpp      STL
//
// ---- Why our own parsers instead of OpenMesh 9.0 (Debian) -----------------------------------
// Debian's OpenMesh would be the obvious choice; these are small, bounded parsers of our own
// because OpenMesh failed what a viewer needs on the test data (checked with read_mesh on a
// PolyMesh_ArrayKernelT):
//   * PLY: `tristrips` elements are "unsupported" (cow.ply / igea.ply load with 0 faces), and
//     Box.ply (CR-only header line ends) fails to load at all.
//   * STL: its half-edge kernel drops faces it cannot insert (Spider_ascii.stl: 1312 of 1368
//     triangles, with "complex edge" messages on stderr), so counts do not match the file.
//   * OFF read from memory (istream, the only way to keep the file access ours) yields 0
//     vertices; reading by path would let it open FIFOs/devices itself.
//   * Huge header counts throw std::bad_alloc, truncated files report success, faces with bad
//     indices vanish silently, OBJ mtllib paths are followed anywhere.
// A viewer needs triangle soups, not a manifold half-edge structure, so the importer keeps
// every face (polygons triangulated by assets/polygon.h: convex ones as a fan, concave ones by
// ear clipping), checks header counts against the file size before allocating, reports
// truncation and dropped faces as warnings, drops vertices that are not finite or lie beyond
// kMaxCoordinate together with the faces using them (one warning with the counts; a point
// cloud keeps its other points), polls cancel/progress, and reads MTL files and textures only
// through ConfinedDir (model folder only).
// Mapping: one node per material group (OBJ usemtl) or one node; normals from the file when
// complete, else smooth area-weighted (Mesh::computeNormals; STL vertices are welded by exact
// position first). Colours are taken as linear. MTL: Kd -> baseColor, Ks -> ks (max channel)
// and specularColor (Ks / ks), Ns -> shininess (clamped 1..2048), d / Tr -> alpha, Ke ->
// emissive, map_Kd -> diffuseTexture (PNG/JPEG via decodeImage; missing -> warning). An OBJ
// without mtllib but with UVs picks up <stem>.png/.jpg or <stem>_texture.png/.jpg from its
// folder (spot.obj ships that way).
#pragma once

#include "import_common.h"

#include "assets/polygon.h"
#include "assets/scene_io.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace assets::detail::meshfile {

// ---- Limits, a text cursor, numbers ----------------------------------------------------------
inline constexpr uint64_t kMaxFileBytes = 4ull << 30;
inline constexpr uint64_t kMaxTriangles = 50'000'000;
inline constexpr uint64_t kMaxVertices = 100'000'000;
inline constexpr uint64_t kMaxMtlBytes = 64ull << 20;
inline constexpr uint64_t kMaxTextureFileBytes = 512ull << 20;
inline constexpr size_t kPoll = 1u << 15;

// What the importers throw; loadMeshFile reports it as "<file>: <why>".
struct Fail {
    std::string why;
};

// Reads whitespace-separated tokens; line-aware where the format needs it.
struct Cursor {
    const char* p;
    const char* end;
    bool atEnd() const { return p >= end; }
    void skipBlanks() {
        while (p < end && (*p == ' ' || *p == '\t' || *p == '\f' || *p == '\v')) ++p;
    }
    void skipWs() {
        while (p < end && (std::isspace(static_cast<unsigned char>(*p)))) ++p;
    }
    void skipLine() {
        while (p < end && *p != '\n' && *p != '\r') ++p;
        while (p < end && (*p == '\n' || *p == '\r')) ++p;
    }
    bool atLineEnd() {
        skipBlanks();
        return p >= end || *p == '\n' || *p == '\r' || *p == '#';
    }
    std::string_view token() {   // within the line
        skipBlanks();
        const char* s = p;
        while (p < end && !std::isspace(static_cast<unsigned char>(*p))) ++p;
        return {s, size_t(p - s)};
    }
    std::string_view anyToken() {   // across lines
        skipWs();
        const char* s = p;
        while (p < end && !std::isspace(static_cast<unsigned char>(*p))) ++p;
        return {s, size_t(p - s)};
    }
    std::string_view restOfLine() {
        skipBlanks();
        const char* s = p;
        while (p < end && *p != '\n' && *p != '\r') ++p;
        const char* e = p;
        while (e > s && std::isspace(static_cast<unsigned char>(e[-1]))) --e;
        return {s, size_t(e - s)};
    }
};

// Whole-token number parse (from_chars, which rejects a leading '+': skip it for signed types).
template <class T>
bool parseNumber(std::string_view t, T& out) {
    if (t.empty()) return false;
    const char* b = t.data();
    if (*b == '+') ++b;
    auto r = std::from_chars(b, t.data() + t.size(), out);
    return r.ec == std::errc() && r.ptr == t.data() + t.size();
}
inline bool toFloat(std::string_view t, float& out) { return parseNumber(t, out); }
// A number beyond double's range reads as +-infinity (or zero when it is tiny) rather than as
// malformed, so that "1e400" in a coordinate counts as a bad vertex, not as a broken file.
bool toDouble(std::string_view t, double& out);
inline bool toInt64(std::string_view t, int64_t& out) { return parseNumber(t, out); }
inline bool toUint64(std::string_view t, uint64_t& out) {
    auto r = std::from_chars(t.data(), t.data() + t.size(), out);
    return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size();
}

// Vertex positions must be finite and within +-kMaxCoordinate (the glTF importer's bound for
// numbers too): beyond it, bounds, normals and camera framing overflow or lose all precision.
// Other vertices are dropped with the faces that use them (BadVertices, below).
inline constexpr double kMaxCoordinate = 1e30;

inline bool goodCoordinate(double d) { return std::fabs(d) <= kMaxCoordinate; }   // false for NaN
inline bool goodPosition(const sg::vec3& p) { return goodCoordinate(p.x) && goodCoordinate(p.y) && goodCoordinate(p.z); }

// A coordinate token of a text format: Ok (out set), Bad (a number, but not finite or beyond
// kMaxCoordinate) or Malformed (not a number).
enum class Coord { Ok, Bad, Malformed };
Coord parseCoordinate(std::string_view t, float& out);
// Three coordinates: the worst of the three (Malformed over Bad over Ok).
Coord parsePosition(std::string_view x, std::string_view y, std::string_view z, sg::vec3& out);

// ASCII lower case.
std::string lower(std::string_view s);

// ---- Mesh building (builder.cpp) -----------------------------------------------------------
// One load: the file, progress / cancellation, warnings, the triangle budget, the triangulator.
struct Ctx {
    const std::filesystem::path& path;
    const Progress& progress;
    std::vector<std::string> warnings;
    uint64_t triangles = 0;
    PolygonTriangulator triangulator{};
    void poll(size_t i, float base, float span, size_t total) const {
        if ((i & (kPoll - 1)) != 0) return;
        if (progress.cancelled()) throw Fail{"cancelled"};
        if (total) progress.set(base + span * float(double(i) / double(total)));
    }
    void countTriangles(uint64_t n) {
        triangles += n;
        if (triangles > kMaxTriangles) throw Fail{"more than " + std::to_string(kMaxTriangles) + " triangles (budget)"};
    }
};

// Vertices with a bad position (see kMaxCoordinate) and what goes with them: the faces (and
// OBJ lines) that use any of them. Reported in one warning; a point cloud just loses the
// points. A file of nothing but bad vertices is refused.
struct BadVertices {
    std::vector<uint8_t> flag;   // flag[i] != 0: vertex i is bad (empty until the first one)
    size_t count = 0, faces = 0, lines = 0;
    void mark(size_t i) {
        if (flag.size() <= i) flag.resize(i + 1, 0);
        flag[i] = 1;
        ++count;
    }
    bool operator[](size_t i) const { return i < flag.size() && flag[i] != 0; }
    bool anyOf(const std::vector<uint32_t>& corners) const {
        return count && std::any_of(corners.begin(), corners.end(), [&](uint32_t i) { return (*this)[i]; });
    }
};

// "<file>: dropped 3 of 16 vertices (non-finite or |coordinate| > 1e30) and 2 faces that use
// them", or nothing when none was bad.
void warnBadVertices(Ctx& ctx, const std::string& file, size_t bad, size_t total, size_t faces, size_t lines = 0);

// Removes the bad vertices (with their attributes) from `mesh` and renumbers its indices, which
// must not refer to them. Fails when no vertex is left.
void dropBadVertices(sg::Mesh& mesh, const BadVertices& bad);

// Triangulates a polygon given by corner indices into mesh.positions (assets/polygon.h:
// convex faces as the fan, concave ones by ear clipping) onto mesh.indices.
void addPolygon(Ctx& ctx, sg::Mesh& mesh, const std::vector<uint32_t>& corners);

// Scene with one node per (mesh, material) and defaults.
sg::Scene makeScene(const std::filesystem::path& path, std::vector<std::pair<sg::Mesh, int>>& parts, std::vector<sg::Material> materials,
                    std::vector<std::shared_ptr<sg::Texture>> textures);

// A scene of one mesh (OFF, PLY): its faces, or a point cloud of all its vertices when it has
// none. Fails when there are no vertices.
LoadResult singleMeshScene(const std::filesystem::path& path, sg::Mesh mesh);

// ---- The formats (obj.cpp, off.cpp, ply.cpp, stl.cpp) ------------------------------------------
// The file's bytes -> a scene with the format's warnings in ctx; a failure throws Fail.
LoadResult loadObj(const std::filesystem::path& path, const std::string& text, Ctx& ctx);
LoadResult loadOff(const std::filesystem::path& path, const std::string& text, Ctx& ctx);
LoadResult loadPly(const std::filesystem::path& path, const std::string& data, Ctx& ctx);
LoadResult loadStl(const std::filesystem::path& path, const std::string& data, Ctx& ctx);

}   // namespace assets::detail::meshfile
