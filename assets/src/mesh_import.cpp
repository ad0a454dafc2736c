// mesh_import.cpp - OBJ (+MTL), OFF, PLY (ASCII / binary, faces or tristrips, point clouds)
// and STL (ASCII / binary) import.
//
// Sections: 1. why not OpenMesh  2. limits, text cursor  3. shared mesh building
// 4. OBJ + MTL  5. OFF  6. PLY  7. STL  8. loadMeshFile
//
// ---- 1. Why our own parsers instead of OpenMesh 9.0 (Debian) --------------------------------
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
#include "import_common.h"
#include "importers.h"

#include "assets/files.h"
#include "assets/image_io.h"
#include "assets/polygon.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <unordered_map>
#include <utility>

namespace fs = std::filesystem;

namespace assets::detail {

namespace {

// ---- 2. Limits and a text cursor -----------------------------------------------------------
constexpr uint64_t kMaxFileBytes = 4ull << 30;
constexpr uint64_t kMaxTriangles = 50'000'000;
constexpr uint64_t kMaxVertices = 100'000'000;
constexpr uint64_t kMaxMtlBytes = 64ull << 20;
constexpr uint64_t kMaxTextureFileBytes = 512ull << 20;
constexpr size_t kPoll = 1u << 15;

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
bool toFloat(std::string_view t, float& out) { return parseNumber(t, out); }
// A number beyond double's range reads as +-infinity (or zero when it is tiny) rather than as
// malformed, so that "1e400" in a coordinate counts as a bad vertex, not as a broken file.
bool toDouble(std::string_view t, double& out) {
    if (t.empty()) return false;
    const char* b = t.data() + (t[0] == '+');
    const char* e = t.data() + t.size();
    const auto r = std::from_chars(b, e, out);
    if (r.ptr != e) return false;
    if (r.ec == std::errc()) return true;
    if (r.ec != std::errc::result_out_of_range) return false;
    const size_t x = t.find_first_of("eE");
    const bool tiny = x != std::string_view::npos ? x + 1 < t.size() && t[x + 1] == '-'
                                                  : t.substr(0, t.find('.')).find_first_of("123456789") == std::string_view::npos;
    out = tiny ? 0.0 : std::numeric_limits<double>::infinity();
    if (t[0] == '-') out = -out;
    return true;
}
bool toInt64(std::string_view t, int64_t& out) { return parseNumber(t, out); }
bool toUint64(std::string_view t, uint64_t& out) {
    auto r = std::from_chars(t.data(), t.data() + t.size(), out);
    return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size();
}

// Vertex positions must be finite and within +-kMaxCoordinate (the glTF importer's bound for
// numbers too): beyond it, bounds, normals and camera framing overflow or lose all precision.
// Other vertices are dropped with the faces that use them (BadVertices, section 3).
constexpr double kMaxCoordinate = 1e30;

bool goodCoordinate(double d) { return std::fabs(d) <= kMaxCoordinate; }   // false for NaN
bool goodPosition(const sg::vec3& p) { return goodCoordinate(p.x) && goodCoordinate(p.y) && goodCoordinate(p.z); }

// A coordinate token of a text format: Ok (out set), Bad (a number, but not finite or beyond
// kMaxCoordinate) or Malformed (not a number).
enum class Coord { Ok, Bad, Malformed };
Coord parseCoordinate(std::string_view t, float& out) {
    double d;
    if (!toDouble(t, d)) return Coord::Malformed;
    if (!goodCoordinate(d)) return Coord::Bad;
    out = float(d);
    return Coord::Ok;
}
// Three coordinates: the worst of the three (Malformed over Bad over Ok).
Coord parsePosition(std::string_view x, std::string_view y, std::string_view z, sg::vec3& out) {
    const Coord c[3] = {parseCoordinate(x, out.x), parseCoordinate(y, out.y), parseCoordinate(z, out.z)};
    for (Coord want : {Coord::Malformed, Coord::Bad})
        if (c[0] == want || c[1] == want || c[2] == want) return want;
    return Coord::Ok;
}

std::string lower(std::string_view s) {
    std::string o(s);
    for (char& c : o) c = char(std::tolower(static_cast<unsigned char>(c)));
    return o;
}

// ---- 3. Shared mesh building ---------------------------------------------------------------
struct Ctx {
    const fs::path& path;
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
void warnBadVertices(Ctx& ctx, const std::string& file, size_t bad, size_t total, size_t faces, size_t lines = 0) {
    if (!bad) return;
    auto counted = [](size_t n, const char* what) { return std::to_string(n) + " " + what + (n == 1 ? "" : "s"); };
    std::string w = file + ": dropped " + std::to_string(bad) + " of " + std::to_string(total) + " vertices (non-finite or |coordinate| > 1e30)";
    if (faces) w += " and " + counted(faces, "face");
    if (lines) w += " and " + counted(lines, "line");
    if (faces || lines) w += bad == 1 ? " that use it" : " that use them";
    ctx.warnings.push_back(std::move(w));
}

// Removes the bad vertices (with their attributes) from `mesh` and renumbers its indices, which
// must not refer to them. Fails when no vertex is left.
void dropBadVertices(sg::Mesh& mesh, const BadVertices& bad) {
    if (!bad.count) return;
    const size_t n = mesh.positions.size();
    if (bad.count >= n) throw Fail{"all " + std::to_string(n) + " vertices are non-finite or have a |coordinate| > 1e30"};
    std::vector<uint32_t> remap(n);
    uint32_t kept = 0;
    for (size_t i = 0; i < n; ++i) remap[i] = bad[i] ? ~0u : kept++;
    auto compact = [&](auto& attr) {
        if (attr.size() != n) return;   // incomplete: makeScene drops it anyway
        size_t o = 0;
        for (size_t i = 0; i < n; ++i)
            if (!bad[i]) attr[o++] = attr[i];
        attr.resize(o);
    };
    compact(mesh.positions);
    compact(mesh.normals);
    compact(mesh.uv0);
    compact(mesh.uv1);
    compact(mesh.colors);
    for (uint32_t& i : mesh.indices) i = remap[i];
}

// Triangulates a polygon given by corner indices into mesh.positions (assets/polygon.h:
// convex faces as the fan, concave ones by ear clipping) onto mesh.indices.
void addPolygon(Ctx& ctx, sg::Mesh& mesh, const std::vector<uint32_t>& corners) {
    ctx.triangulator.triangulate(mesh.positions, corners, mesh.indices);
}

// Scene with one node per (mesh, material) and defaults.
sg::Scene makeScene(const fs::path& path, std::vector<std::pair<sg::Mesh, int>>& parts, std::vector<sg::Material> materials,
                    std::vector<std::shared_ptr<sg::Texture>> textures) {
    sg::Scene s;
    s.name = path.stem().string();
    s.materials = std::move(materials);
    s.textures = std::move(textures);
    for (auto& [mesh, mat] : parts) {
        // An attribute that does not cover every vertex (e.g. a PLY file with two vertex
        // elements of different layouts) is dropped rather than handed out inconsistent.
        const size_t n = mesh.positions.size();
        if (mesh.normals.size() != n) mesh.normals.clear();
        if (mesh.uv0.size() != n) mesh.uv0.clear();
        if (mesh.uv1.size() != n) mesh.uv1.clear();
        if (mesh.colors.size() != n) mesh.colors.clear();
        if (mesh.mode == sg::PrimitiveMode::Triangles && mesh.normals.empty()) mesh.computeNormals();
        s.meshes.push_back(std::make_shared<sg::Mesh>(std::move(mesh)));
        std::string name = s.meshes.back()->name.empty() ? s.name : s.meshes.back()->name;
        s.addNode(name, s.root(), sg::MeshInstance{int(s.meshes.size() - 1), mat});
    }
    addDefaultCameraAndLight(s);
    return s;
}

// A scene of one mesh (OFF, PLY): its faces, or a point cloud of all its vertices when it has
// none. Fails when there are no vertices.
LoadResult singleMeshScene(const fs::path& path, sg::Mesh mesh) {
    if (mesh.positions.empty()) throw Fail{"no vertices"};
    if (mesh.indices.empty()) {
        mesh.mode = sg::PrimitiveMode::Points;
        mesh.indices.resize(mesh.positions.size());
        for (size_t i = 0; i < mesh.indices.size(); ++i) mesh.indices[i] = uint32_t(i);
    }
    std::vector<std::pair<sg::Mesh, int>> parts;
    parts.push_back({std::move(mesh), -1});
    LoadResult r;
    r.scene = makeScene(path, parts, {}, {});
    return r;
}

// ---- 4. OBJ + MTL --------------------------------------------------------------------------
struct ObjMaterial {
    sg::Material mat;
    std::string texture;   // map_Kd, relative
};

std::shared_ptr<sg::Texture> loadTexture(const ConfinedDir& dir, const std::string& rel, Ctx& ctx, const std::string& file) {
    std::vector<unsigned char> bytes;
    std::string why = dir.read(rel, kMaxTextureFileBytes, bytes);
    if (!why.empty()) {
        ctx.warnings.push_back(file + ": texture '" + rel + "' not loaded: " + why);
        return nullptr;
    }
    ImageLoad img = decodeImage(bytes.data(), bytes.size(), rel);
    if (!img.texture) {
        ctx.warnings.push_back(file + ": texture '" + rel + "' not loaded: " + img.error);
        return nullptr;
    }
    img.texture->sourcePath = (dir.root() / rel).string();
    img.texture->name = rel;
    return img.texture;
}

std::string cleanRelPath(std::string_view s) {
    std::string r(s);
    std::replace(r.begin(), r.end(), '\\', '/');
    while (r.rfind("./", 0) == 0) r.erase(0, 2);
    return r;
}

void parseMtl(const ConfinedDir& dir, const std::string& rel, Ctx& ctx, const std::string& file, std::map<std::string, ObjMaterial>& out) {
    std::vector<unsigned char> bytes;
    std::string why = dir.read(rel, kMaxMtlBytes, bytes);
    if (!why.empty()) {
        ctx.warnings.push_back(file + ": material library '" + rel + "' not read: " + why);
        return;
    }
    Cursor c{reinterpret_cast<const char*>(bytes.data()), reinterpret_cast<const char*>(bytes.data()) + bytes.size()};
    ObjMaterial* cur = nullptr;
    auto vec3 = [&](sg::vec3& v) {
        float x, y, z;
        if (!toFloat(c.token(), x)) return false;
        std::string_view t = c.token();
        if (t.empty()) {
            v = sg::vec3(x);
            return true;
        }
        if (!toFloat(t, y) || !toFloat(c.token(), z)) return false;
        v = sg::vec3(x, y, z);
        return true;
    };
    while (!c.atEnd()) {
        std::string key = lower(c.token());
        if (key == "newmtl") {
            std::string name(c.restOfLine());
            cur = &out[name];
            cur->mat.name = name;
        } else if (cur && key == "kd") {
            sg::vec3 v;
            if (vec3(v)) cur->mat.baseColor = glm::clamp(v, sg::vec3(0.0f), sg::vec3(1.0f));
        } else if (cur && key == "ks") {
            sg::vec3 v;
            if (vec3(v)) {
                v = glm::clamp(v, sg::vec3(0.0f), sg::vec3(1.0f));
                float k = std::max({v.x, v.y, v.z});
                cur->mat.ks = k;
                cur->mat.specularColor = k > 0 ? v / k : sg::vec3(1.0f);
            }
        } else if (cur && key == "ke") {
            sg::vec3 v;
            if (vec3(v)) cur->mat.emissive = glm::max(v, sg::vec3(0.0f));
        } else if (cur && key == "ns") {
            float v;
            if (toFloat(c.token(), v) && std::isfinite(v)) cur->mat.shininess = std::clamp(v, 1.0f, 2048.0f);
        } else if (cur && (key == "d" || key == "tr")) {
            float v;
            if (toFloat(c.token(), v) && std::isfinite(v)) cur->mat.alpha = std::clamp(key == "d" ? v : 1.0f - v, 0.0f, 1.0f);
        } else if (cur && key == "map_kd") {
            // Options (-s 1 1 1, -o ...) may precede the name: the file name is the last token.
            std::string_view last;
            for (std::string_view t = c.token(); !t.empty(); t = c.token()) last = t;
            cur->texture = cleanRelPath(last);
        }
        c.skipLine();
    }
}

struct ObjCorner {
    uint32_t v, vt, vn;   // 0-based, ~0u = absent
};

struct ObjFace {
    uint32_t first, count;   // corners[first, first + count)
    int material;            // index into ObjData::matNames, -1: none (before any usemtl)
};

// An OBJ file as read: every corner index of a kept face/line/point is in range of the
// arrays it refers to and names no bad vertex; faces have >= 3 corners, lines >= 2 (others
// were counted as dropped, or in `bad`).
struct ObjData {
    std::vector<sg::vec3> v, vn;
    std::vector<sg::vec4> vc;   // vertex colours (x y z r g b), one per v
    std::vector<sg::vec2> vt;
    std::vector<ObjCorner> corners;   // of the kept faces
    std::vector<ObjFace> faces;
    std::vector<uint32_t> linePoly;   // v indices of line segments (pairs)
    std::vector<uint32_t> pointList;
    std::vector<std::string> mtllibs;
    std::vector<std::string> matNames;   // usemtl order
    size_t dropped = 0, malformedLines = 0;
    BadVertices bad;   // non-finite / absurd positions, with the faces and lines using them
    bool anyColor = false;
};

// OBJ index (1-based, or negative: relative to the end) -> 0-based index below n.
bool resolveObjIndex(int64_t i, size_t n, uint32_t& out) {
    if (i > 0 && uint64_t(i) <= n) {
        out = uint32_t(i - 1);
        return true;
    }
    if (i < 0 && uint64_t(-i) <= n) {
        out = uint32_t(int64_t(n) + i);
        return true;
    }
    return false;
}

// "v x y z [r g b]": appends one position and colour (zero / white when malformed; a
// non-finite or absurd position marks the vertex bad).
void readObjVertex(Cursor& c, ObjData& d) {
    sg::vec3 p;
    const std::string_view x = c.token(), y = c.token(), z = c.token();
    const Coord k = parsePosition(x, y, z, p);
    if (k != Coord::Ok) {
        if (k == Coord::Malformed) ++d.malformedLines;
        if (k == Coord::Bad) d.bad.mark(d.v.size());
        d.v.push_back(sg::vec3(0.0f));
        d.vc.push_back(sg::vec4(1.0f));
    } else {
        d.v.push_back(p);
        float r, g, b;
        std::string_view t = c.token();
        if (!t.empty() && toFloat(t, r) && toFloat(c.token(), g) && toFloat(c.token(), b)) {
            d.anyColor = true;
            d.vc.push_back(sg::vec4(r, g, b, 1.0f));
        } else {
            d.vc.push_back(sg::vec4(1.0f));
        }
    }
    if (d.v.size() > kMaxVertices) throw Fail{"more than " + std::to_string(kMaxVertices) + " vertices (budget)"};
}

// One corner token "v", "v/vt", "v//vn" or "v/vt/vn"; false when an index is malformed or out
// of range of the elements read so far.
bool readObjCorner(std::string_view t, const ObjData& d, ObjCorner& cr) {
    cr = ObjCorner{~0u, ~0u, ~0u};
    bool ok = true;
    size_t s1 = t.find('/');
    int64_t iv, it, in;
    if (!toInt64(t.substr(0, s1), iv) || !resolveObjIndex(iv, d.v.size(), cr.v)) ok = false;
    if (s1 != std::string_view::npos) {
        std::string_view rest = t.substr(s1 + 1);
        size_t s2 = rest.find('/');
        std::string_view a = rest.substr(0, s2);
        if (!a.empty() && (!toInt64(a, it) || !resolveObjIndex(it, d.vt.size(), cr.vt))) ok = false;
        if (s2 != std::string_view::npos) {
            std::string_view b = rest.substr(s2 + 1);
            if (!b.empty() && (!toInt64(b, in) || !resolveObjIndex(in, d.vn.size(), cr.vn))) ok = false;
        }
    }
    return ok;
}

// "f", "l" or "p" (key) with its corners: a face is kept with material curMat (counted against
// the triangle budget), a line as segments, points as v indices; an element with a bad
// index or too few corners is dropped whole, so is a face or line using a bad vertex (counted
// in d.bad); of points only the bad ones are dropped.
void readObjElement(Cursor& c, std::string_view key, int curMat, ObjData& d, Ctx& ctx) {
    uint32_t first = uint32_t(d.corners.size());
    bool ok = true;
    size_t n = 0;
    for (std::string_view t = c.token(); !t.empty() && t[0] != '#'; t = c.token()) {
        ObjCorner cr;
        if (!readObjCorner(t, d, cr)) ok = false;
        d.corners.push_back(cr);
        ++n;
    }
    const bool usesBad = d.bad.count && std::any_of(d.corners.begin() + first, d.corners.end(), [&](const ObjCorner& k) { return d.bad[k.v]; });
    if (!ok || n == 0 || (key == "f" && n < 3) || (key == "l" && n < 2)) {
        ++d.dropped;
        d.corners.resize(first);
    } else if (usesBad && key != "p") {
        ++(key == "f" ? d.bad.faces : d.bad.lines);
        d.corners.resize(first);
    } else if (key == "f") {
        ctx.countTriangles(n - 2);
        d.faces.push_back({first, uint32_t(n), curMat});
    } else {
        for (size_t i = 0; i < n; ++i) {
            if (key == "p") {
                if (!d.bad[d.corners[first + i].v]) d.pointList.push_back(d.corners[first + i].v);
            } else if (i + 1 < n) {
                d.linePoly.push_back(d.corners[first + i].v);
                d.linePoly.push_back(d.corners[first + i + 1].v);
            }
        }
        d.corners.resize(first);
    }
}

// Reads the whole OBJ text (progress 0..0.7). Unknown statements are skipped line by line.
ObjData parseObjText(const std::string& text, Ctx& ctx) {
    ObjData d;
    int curMat = -1;
    Cursor c{text.data(), text.data() + text.size()};
    size_t line = 0;
    while (!c.atEnd()) {
        ctx.poll(++line, 0.0f, 0.7f, 0);
        if ((line & (kPoll - 1)) == 0) ctx.progress.set(0.7f * float(double(c.p - text.data()) / double(text.size())));
        std::string_view key = c.token();
        if (key == "v") {
            readObjVertex(c, d);
        } else if (key == "vt") {
            float s = 0, t = 0;
            if (!toFloat(c.token(), s)) ++d.malformedLines;
            std::string_view tt = c.token();
            if (!tt.empty() && !toFloat(tt, t)) ++d.malformedLines;
            d.vt.push_back({s, t});
        } else if (key == "vn") {
            float x, y, z;
            if (!toFloat(c.token(), x) || !toFloat(c.token(), y) || !toFloat(c.token(), z)) {
                ++d.malformedLines;
                x = 0;
                y = 0;
                z = 1;
            }
            d.vn.push_back({x, y, z});
        } else if (key == "f" || key == "l" || key == "p") {
            readObjElement(c, key, curMat, d, ctx);
        } else if (key == "usemtl") {
            std::string name(c.restOfLine());
            auto it = std::find(d.matNames.begin(), d.matNames.end(), name);
            curMat = int(it - d.matNames.begin());
            if (it == d.matNames.end()) d.matNames.push_back(name);
        } else if (key == "mtllib") {
            for (std::string_view t = c.token(); !t.empty(); t = c.token()) d.mtllibs.push_back(cleanRelPath(t));
        }
        c.skipLine();
    }
    return d;
}

// Materials of an OBJ: one per usemtl name, in order (from the MTL libraries, or defaults),
// plus, for a file without mtllib but with UVs, one for a texture found beside the model.
struct ObjMaterials {
    std::vector<sg::Material> materials;
    std::vector<std::shared_ptr<sg::Texture>> textures;   // each loaded once
    int implicitMat = -1;                                 // the material of faces without usemtl (-1: the default)
};

ObjMaterials resolveObjMaterials(const fs::path& path, const ConfinedDir& dir, const ObjData& d, Ctx& ctx, const std::string& file) {
    ObjMaterials out;
    std::map<std::string, ObjMaterial> lib;
    for (const std::string& m : d.mtllibs) parseMtl(dir, m, ctx, file, lib);
    std::map<std::string, int> texIndex;
    auto textureFor = [&](const std::string& rel) -> int {
        if (rel.empty()) return -1;
        auto it = texIndex.find(rel);
        if (it != texIndex.end()) return it->second;
        int idx = -1;
        if (auto t = loadTexture(dir, rel, ctx, file)) {
            out.textures.push_back(t);
            idx = int(out.textures.size() - 1);
        }
        texIndex[rel] = idx;
        return idx;
    };
    for (const std::string& name : d.matNames) {
        auto it = lib.find(name);
        sg::Material m;
        m.name = name;
        if (it != lib.end()) {
            m = it->second.mat;
            m.diffuseTexture = textureFor(it->second.texture);
        } else if (!d.mtllibs.empty()) {
            ctx.warnings.push_back(file + ": material '" + name + "' not found in the material libraries; default used");
        }
        out.materials.push_back(m);
    }
    // OBJ without mtllib but with UVs: a texture named after the model next to it.
    if (d.mtllibs.empty() && !d.vt.empty()) {
        std::string stem = path.stem().string();
        for (const std::string& cand : {stem + ".png", stem + ".jpg", stem + "_texture.png", stem + "_texture.jpg"}) {
            if (dir.probe(cand).empty()) {
                const int tex = textureFor(cand);
                if (tex >= 0) {
                    sg::Material m;
                    m.name = stem;
                    m.diffuseTexture = tex;
                    out.materials.push_back(m);
                    out.implicitMat = int(out.materials.size() - 1);
                    ctx.warnings.push_back(file + ": no mtllib; using texture '" + cand + "' found beside the model");
                }
                break;
            }
        }
    }
    return out;
}

// One triangle mesh from the faces faceIds, triangulated, with (v, vt, vn) corners
// de-duplicated (by v alone when the file has neither UVs nor normals). UVs / normals are
// kept only when some / all corners have them, colours only when the file has any.
// done: faces converted so far over all groups (progress 0.7..0.95).
sg::Mesh buildObjGroupMesh(const ObjData& d, const std::vector<uint32_t>& faceIds, Ctx& ctx, size_t& done) {
    sg::Mesh mesh;
    const bool simple = d.vt.empty() && d.vn.empty();
    std::vector<uint32_t> remap;
    struct Key {
        uint32_t v, t, n;
        bool operator==(const Key&) const = default;
    };
    struct KeyHash {
        size_t operator()(const Key& k) const { return (size_t(k.v) * 0x9E3779B97F4A7C15ull) ^ (size_t(k.t) * 0xC2B2AE3D27D4EB4Full) ^ k.n; }
    };
    std::unordered_map<Key, uint32_t, KeyHash> map;
    if (simple) remap.assign(d.v.size(), ~0u);
    bool hasUv = false, hasN = true;
    auto vertexOf = [&](const ObjCorner& cr) -> uint32_t {
        uint32_t idx;
        if (simple) {
            if (remap[cr.v] != ~0u) return remap[cr.v];
            idx = remap[cr.v] = uint32_t(mesh.positions.size());
        } else {
            auto [it, inserted] = map.try_emplace(Key{cr.v, cr.vt, cr.vn}, uint32_t(mesh.positions.size()));
            if (!inserted) return it->second;
            idx = it->second;
        }
        mesh.positions.push_back(d.v[cr.v]);
        mesh.colors.push_back(d.vc[cr.v]);
        mesh.uv0.push_back(cr.vt != ~0u ? d.vt[cr.vt] : sg::vec2(0.0f));
        mesh.normals.push_back(cr.vn != ~0u ? d.vn[cr.vn] : sg::vec3(0.0f));
        hasUv |= cr.vt != ~0u;
        hasN &= cr.vn != ~0u;
        return idx;
    };
    std::vector<uint32_t> tri;
    for (uint32_t fi : faceIds) {
        ctx.poll(++done, 0.7f, 0.25f, d.faces.size());
        const ObjFace& f = d.faces[fi];
        tri.clear();
        for (uint32_t k = 0; k < f.count; ++k) tri.push_back(vertexOf(d.corners[f.first + k]));
        addPolygon(ctx, mesh, tri);
    }
    if (!hasUv) mesh.uv0.clear();
    if (!hasN) mesh.normals.clear();
    if (!d.anyColor) mesh.colors.clear();
    return mesh;
}

// The faces as one mesh per material group, in material order (faces without usemtl first,
// with the implicit texture material when there is one, else the default (-1)).
void addObjFaceMeshes(const fs::path& path, const ObjData& d, const ObjMaterials& mats, Ctx& ctx, std::vector<std::pair<sg::Mesh, int>>& parts) {
    std::vector<std::vector<uint32_t>> byMaterial(mats.materials.size() + 1);   // slot 0 = default
    for (size_t fi = 0; fi < d.faces.size(); ++fi) {
        int fm = d.faces[fi].material >= 0 ? d.faces[fi].material : mats.implicitMat;
        byMaterial[size_t(fm + 1)].push_back(uint32_t(fi));
    }
    size_t done = 0;
    for (size_t g = 0; g < byMaterial.size(); ++g) {
        if (byMaterial[g].empty()) continue;
        const int mat = int(g) - 1;
        sg::Mesh mesh = buildObjGroupMesh(d, byMaterial[g], ctx, done);
        mesh.name = mat >= 0 ? mats.materials[size_t(mat)].name : path.stem().string();
        parts.push_back({std::move(mesh), mat});
    }
}

// The `l` segments as one line mesh holding only the vertices they use.
void addObjLineMesh(const fs::path& path, const ObjData& d, std::vector<std::pair<sg::Mesh, int>>& parts) {
    sg::Mesh lines;
    lines.mode = sg::PrimitiveMode::Lines;
    lines.name = path.stem().string() + " lines";
    std::vector<uint32_t> remap(d.v.size(), ~0u);
    for (uint32_t i : d.linePoly) {
        if (remap[i] == ~0u) {
            remap[i] = uint32_t(lines.positions.size());
            lines.positions.push_back(d.v[i]);
            if (d.anyColor) lines.colors.push_back(d.vc[i]);
        }
        lines.indices.push_back(remap[i]);
    }
    parts.push_back({std::move(lines), -1});
}

// A point cloud over all (good) vertices: the `p` elements, or every vertex when nothing else
// was drawn.
void addObjPointMesh(const fs::path& path, const ObjData& d, std::vector<std::pair<sg::Mesh, int>>& parts) {
    sg::Mesh pts;
    pts.mode = sg::PrimitiveMode::Points;
    pts.name = path.stem().string() + " points";
    pts.positions = d.v;
    if (d.anyColor) pts.colors = d.vc;
    if (!d.vn.empty() && d.vn.size() == d.v.size()) pts.normals = d.vn;
    if (d.pointList.empty()) {
        for (size_t i = 0; i < d.v.size(); ++i)
            if (!d.bad[i]) pts.indices.push_back(uint32_t(i));
    } else {
        pts.indices = d.pointList;
    }
    dropBadVertices(pts, d.bad);
    parts.push_back({std::move(pts), -1});
}

LoadResult loadObj(const fs::path& path, const std::string& text, Ctx& ctx) {
    const std::string file = fileNameOf(path);
    ConfinedDir dir(path.parent_path().empty() ? fs::path(".") : path.parent_path());
    const ObjData d = parseObjText(text, ctx);
    if (d.v.empty()) throw Fail{"no vertices"};
    if (d.dropped) ctx.warnings.push_back(file + ": " + std::to_string(d.dropped) + " faces/lines with missing or out-of-range indices dropped");
    if (d.malformedLines) ctx.warnings.push_back(file + ": " + std::to_string(d.malformedLines) + " malformed vertex lines (zero used)");
    warnBadVertices(ctx, file, d.bad.count, d.v.size(), d.bad.faces, d.bad.lines);

    ObjMaterials mats = resolveObjMaterials(path, dir, d, ctx, file);
    std::vector<std::pair<sg::Mesh, int>> parts;
    addObjFaceMeshes(path, d, mats, ctx, parts);
    if (!d.linePoly.empty()) addObjLineMesh(path, d, parts);
    // Vertices only (or explicit `p` elements): a point cloud.
    if (parts.empty() || !d.pointList.empty()) addObjPointMesh(path, d, parts);
    LoadResult r;
    r.scene = makeScene(path, parts, std::move(mats.materials), std::move(mats.textures));
    return r;
}

// ---- 5. OFF -------------------------------------------------------------------------------
// The next token, skipping comments (# to end of line).
std::string_view offToken(Cursor& c) {
    for (;;) {
        c.skipWs();
        if (c.p < c.end && *c.p == '#') {
            c.skipLine();
            continue;
        }
        return c.anyToken();
    }
}

struct OffHeader {
    bool hasTex = false, hasColor = false, hasNormal = false;
    uint64_t nv = 0, nf = 0;
};

// The keyword ([ST][C][N][4][n]OFF, optionally glued to the counts line) and the counts, which
// are checked against the bytes left (each vertex needs at least "0 0 0\n", each face
// "3 0 1 2\n") so that they are safe to reserve.
OffHeader parseOffHeader(Cursor& c) {
    OffHeader h;
    const std::string_view head = offToken(c);
    if (head.size() < 3 || head.substr(head.size() - 3) != "OFF") throw Fail{"not an OFF file (no OFF header)"};
    const std::string_view prefix = head.substr(0, head.size() - 3);
    for (size_t i = 0; i < prefix.size(); ++i) {
        if (prefix.substr(i, 2) == "ST") {
            h.hasTex = true;
            ++i;
        } else if (prefix[i] == 'C')
            h.hasColor = true;
        else if (prefix[i] == 'N')
            h.hasNormal = true;
        else
            throw Fail{"unsupported OFF variant '" + std::string(head) + "' (4D, nD and binary OFF are not supported)"};
    }
    uint64_t ne;
    const std::string_view t1 = offToken(c);
    if (t1 == "BINARY") throw Fail{"binary OFF is not supported"};
    if (!toUint64(t1, h.nv) || !toUint64(offToken(c), h.nf) || !toUint64(offToken(c), ne))
        throw Fail{"malformed OFF header (expected vertex, face and edge counts)"};
    const uint64_t remaining = uint64_t(c.end - c.p);
    uint64_t need = 0, needF = 0;
    if (h.nv > kMaxVertices) throw Fail{"header claims " + std::to_string(h.nv) + " vertices (budget " + std::to_string(kMaxVertices) + ")"};
    if (__builtin_mul_overflow(h.nv, uint64_t(6), &need) || need > remaining + 1)
        throw Fail{"header claims " + std::to_string(h.nv) + " vertices but the file has only " + std::to_string(remaining) + " bytes left"};
    if (__builtin_mul_overflow(h.nf, uint64_t(8), &needF) || need + needF > remaining + 1 + 8)
        throw Fail{"header claims " + std::to_string(h.nf) + " faces but the file has only " + std::to_string(remaining) + " bytes left"};
    return h;
}

// A vertex colour: r g b [a] up to the end of the line, 0..1 floats or 0..255 integers.
sg::vec4 readOffColor(Cursor& c) {
    float col[4] = {1, 1, 1, 1};
    int n = 0;
    while (n < 4 && !c.atLineEnd()) {
        if (!toFloat(c.token(), col[n])) break;
        ++n;
    }
    const bool ints = n >= 3 && (col[0] > 1 || col[1] > 1 || col[2] > 1);
    sg::vec4 cv(col[0], col[1], col[2], n == 4 ? col[3] : (ints ? 255.0f : 1.0f));
    return ints ? cv / 255.0f : cv;
}

// The vertices with the attributes the header names (progress 0..0.5); non-finite or absurd
// positions are marked in `bad`. False when the file ends (or a coordinate is malformed) first.
bool readOffVertices(Cursor& c, const OffHeader& h, sg::Mesh& mesh, BadVertices& bad, Ctx& ctx) {
    mesh.positions.reserve(size_t(h.nv));
    const size_t perVertexExtra = (h.hasNormal ? 3 : 0) + (h.hasTex ? 2 : 0);
    for (uint64_t i = 0; i < h.nv; ++i) {
        ctx.poll(size_t(i), 0.0f, 0.5f, size_t(h.nv));
        sg::vec3 p;
        const std::string_view x = offToken(c), y = offToken(c), z = offToken(c);
        const Coord k = parsePosition(x, y, z, p);
        if (k == Coord::Malformed) return false;
        if (k == Coord::Bad) bad.mark(mesh.positions.size());
        mesh.positions.push_back(p);
        float extra[5];
        for (size_t k = 0; k < perVertexExtra; ++k) toFloat(offToken(c), extra[k]);
        if (h.hasNormal) mesh.normals.push_back({extra[0], extra[1], extra[2]});
        if (h.hasTex) mesh.uv0.push_back({extra[h.hasNormal ? 3 : 0], extra[h.hasNormal ? 4 : 1]});
        if (h.hasColor) mesh.colors.push_back(readOffColor(c));
    }
    return true;
}

// The faces (progress 0.5..0.95), triangulated; a face with an index out of range or fewer
// than 3 corners is counted in `dropped`, one using a bad vertex in bad.faces. False when the
// file ends first.
bool readOffFaces(Cursor& c, const OffHeader& h, sg::Mesh& mesh, BadVertices& bad, Ctx& ctx, size_t& facesRead, size_t& dropped) {
    std::vector<uint32_t> poly;
    for (uint64_t f = 0; f < h.nf; ++f) {
        ctx.poll(size_t(f), 0.5f, 0.45f, size_t(h.nf));
        uint64_t k;
        if (!toUint64(offToken(c), k)) return false;
        if (k > 1'000'000) throw Fail{"face " + std::to_string(f) + " claims " + std::to_string(k) + " corners"};
        poly.clear();
        bool ok = true;
        for (uint64_t j = 0; j < k; ++j) {
            int64_t idx;
            if (!toInt64(offToken(c), idx)) return false;
            if (idx < 0 || uint64_t(idx) >= mesh.positions.size())
                ok = false;
            else
                poly.push_back(uint32_t(idx));
        }
        while (!c.atLineEnd()) c.token();   // per-face colour
        ++facesRead;
        if (!ok || k < 3) {
            ++dropped;
            continue;
        }
        if (bad.anyOf(poly)) {
            ++bad.faces;
            continue;
        }
        ctx.countTriangles(k - 2);
        addPolygon(ctx, mesh, poly);
    }
    return true;
}

LoadResult loadOff(const fs::path& path, const std::string& text, Ctx& ctx) {
    const std::string file = fileNameOf(path);
    Cursor c{text.data(), text.data() + text.size()};
    const OffHeader h = parseOffHeader(c);
    sg::Mesh mesh;
    mesh.name = path.stem().string();
    size_t facesRead = 0, dropped = 0;
    BadVertices bad;
    if (!readOffVertices(c, h, mesh, bad, ctx) || !readOffFaces(c, h, mesh, bad, ctx, facesRead, dropped))
        ctx.warnings.push_back(file + ": file is truncated: read " + std::to_string(mesh.positions.size()) + " of " + std::to_string(h.nv) +
                               " vertices and " + std::to_string(facesRead) + " of " + std::to_string(h.nf) + " faces");
    if (dropped) ctx.warnings.push_back(file + ": " + std::to_string(dropped) + " faces with out-of-range indices or fewer than 3 corners dropped");
    warnBadVertices(ctx, file, bad.count, mesh.positions.size(), bad.faces);
    dropBadVertices(mesh, bad);
    return singleMeshScene(path, std::move(mesh));
}

// ---- 6. PLY -------------------------------------------------------------------------------
enum class PlyType : uint8_t { I8, U8, I16, U16, I32, U32, F32, F64, Invalid };
PlyType plyType(std::string_view s) {
    if (s == "char" || s == "int8") return PlyType::I8;
    if (s == "uchar" || s == "uint8") return PlyType::U8;
    if (s == "short" || s == "int16") return PlyType::I16;
    if (s == "ushort" || s == "uint16") return PlyType::U16;
    if (s == "int" || s == "int32") return PlyType::I32;
    if (s == "uint" || s == "uint32") return PlyType::U32;
    if (s == "float" || s == "float32") return PlyType::F32;
    if (s == "double" || s == "float64") return PlyType::F64;
    return PlyType::Invalid;
}
size_t plySize(PlyType t) {
    switch (t) {
    case PlyType::I8:
    case PlyType::U8: return 1;
    case PlyType::I16:
    case PlyType::U16: return 2;
    case PlyType::I32:
    case PlyType::U32:
    case PlyType::F32: return 4;
    case PlyType::F64: return 8;
    default: return 0;
    }
}
struct PlyProperty {
    std::string name;
    PlyType type = PlyType::F32;
    bool list = false;
    PlyType countType = PlyType::U8;
};
struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> props;
};

struct PlyReader {
    const unsigned char* p;
    const unsigned char* end;
    int format;   // 0 ascii, 1 LE, 2 BE
    Cursor text{nullptr, nullptr};

    // Bytes of data left to read.
    uint64_t left() const { return format == 0 ? uint64_t(text.end - text.p) : uint64_t(end - p); }

    // Reads one scalar; false at end of data / malformed. Always inlined: it runs per value.
    [[gnu::always_inline]] bool read(PlyType t, double& out) {
        if (format == 0) {
            std::string_view tok = text.anyToken();
            return toDouble(tok, out);
        }
        size_t n = plySize(t);
        if (size_t(end - p) < n) return false;
        unsigned char b[8];
        std::memcpy(b, p, n);
        p += n;
        if (format == 2) std::reverse(b, b + n);
        switch (t) {
        case PlyType::I8: out = double(int8_t(b[0])); break;
        case PlyType::U8: out = double(b[0]); break;
        case PlyType::I16: {
            int16_t v;
            std::memcpy(&v, b, 2);
            out = v;
            break;
        }
        case PlyType::U16: {
            uint16_t v;
            std::memcpy(&v, b, 2);
            out = v;
            break;
        }
        case PlyType::I32: {
            int32_t v;
            std::memcpy(&v, b, 4);
            out = v;
            break;
        }
        case PlyType::U32: {
            uint32_t v;
            std::memcpy(&v, b, 4);
            out = v;
            break;
        }
        case PlyType::F32: {
            float v;
            std::memcpy(&v, b, 4);
            out = v;
            break;
        }
        case PlyType::F64: {
            double v;
            std::memcpy(&v, b, 8);
            out = v;
            break;
        }
        default: return false;
        }
        return true;
    }
};

// A parsed PLY header: format, elements in file order, and where the body starts.
struct PlyHeader {
    int format = -1;   // 0 ascii, 1 LE, 2 BE
    std::vector<PlyElement> elements;
    size_t bodyStart = 0;
};

// Header lines end in \n, \r\n or \r alone (Box.ply). Throws Fail on a missing magic, format
// or end_header and on malformed element/property lines.
PlyHeader parsePlyHeader(const std::string& data) {
    PlyHeader h;
    size_t& pos = h.bodyStart;
    auto nextLine = [&](std::string& line) -> bool {
        if (pos >= data.size()) return false;
        size_t e = data.find_first_of("\r\n", pos);
        if (e == std::string::npos) {
            line = data.substr(pos);
            pos = data.size();
            return true;
        }
        line = data.substr(pos, e - pos);
        pos = e + 1;
        if (data[e] == '\r' && pos < data.size() && data[pos] == '\n') ++pos;
        return true;
    };
    std::string line;
    if (!nextLine(line) || line.substr(0, 3) != "ply") throw Fail{"not a PLY file (no 'ply' magic)"};
    bool endHeader = false;
    size_t headerLines = 0;
    while (nextLine(line)) {
        if (++headerLines > 100000) throw Fail{"PLY header too long"};
        Cursor c{line.data(), line.data() + line.size()};
        std::string_view key = c.token();
        if (key == "format") {
            std::string_view f = c.token();
            h.format = f == "ascii" ? 0 : f == "binary_little_endian" ? 1 : f == "binary_big_endian" ? 2 : -1;
            if (h.format < 0) throw Fail{"unknown PLY format '" + std::string(f) + "'"};
        } else if (key == "element") {
            PlyElement e;
            e.name = std::string(c.token());
            if (!toUint64(c.token(), e.count)) throw Fail{"malformed element line '" + line + "'"};
            h.elements.push_back(std::move(e));
        } else if (key == "property") {
            if (h.elements.empty()) throw Fail{"property before any element"};
            PlyProperty pr;
            std::string_view t = c.token();
            if (t == "list") {
                pr.list = true;
                pr.countType = plyType(c.token());
                pr.type = plyType(c.token());
                if (pr.countType == PlyType::Invalid || pr.countType == PlyType::F32 || pr.countType == PlyType::F64)
                    throw Fail{"invalid list count type in '" + line + "'"};
            } else {
                pr.type = plyType(t);
            }
            if (pr.type == PlyType::Invalid) throw Fail{"unknown property type in '" + line + "'"};
            pr.name = std::string(c.token());
            h.elements.back().props.push_back(std::move(pr));
        } else if (key == "end_header") {
            endHeader = true;
            break;
        }
        // comment, obj_info: ignored
    }
    if (!endHeader) throw Fail{"PLY header has no end_header"};
    if (h.format < 0) throw Fail{"PLY header has no format line"};
    return h;
}

// Size check before allocating: every element needs at least this many bytes (ascii: 2 per
// value, binary: a list's count or a scalar), so no count exceeds what the body can hold.
void checkPlyBodySize(const PlyHeader& h, const std::string& data) {
    const uint64_t bodyBytes = data.size() - h.bodyStart;
    uint64_t need = 0;
    for (const PlyElement& e : h.elements) {
        uint64_t per = 0;
        for (const PlyProperty& pr : e.props) per += h.format == 0 ? 2 : (pr.list ? plySize(pr.countType) : plySize(pr.type));
        uint64_t bytes;
        if (per == 0) continue;
        if (__builtin_mul_overflow(per, e.count, &bytes) || __builtin_add_overflow(need, bytes, &need) || need > bodyBytes + 1)
            throw Fail{"element '" + e.name + "' claims " + std::to_string(e.count) + " entries but the file has only " + std::to_string(bodyBytes) +
                       " bytes after the header"};
    }
}

// What an element is and which of its properties hold what we read (-1: absent). Vertex
// elements: scalar position, normal, colour and UV properties; face / tristrips elements:
// the index list. Other elements are read and skipped.
struct PlyRoles {
    bool isVertex = false, isFace = false, isStrip = false;
    int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, ir = -1, ig = -1, ib = -1, ia = -1, iu = -1, iv = -1, ilist = -1;
    bool haveNormals = false, haveColors = false, haveUv = false;   // complete attributes of a vertex element
};

PlyRoles plyRoles(const PlyElement& e) {
    PlyRoles r;
    r.isVertex = e.name == "vertex";
    r.isFace = e.name == "face";
    r.isStrip = e.name == "tristrips";
    for (size_t k = 0; k < e.props.size(); ++k) {
        const std::string& n = e.props[k].name;
        int kk = int(k);
        if (r.isVertex && !e.props[k].list) {
            if (n == "x")
                r.ix = kk;
            else if (n == "y")
                r.iy = kk;
            else if (n == "z")
                r.iz = kk;
            else if (n == "nx")
                r.inx = kk;
            else if (n == "ny")
                r.iny = kk;
            else if (n == "nz")
                r.inz = kk;
            else if (n == "red" || n == "r" || n == "diffuse_red")
                r.ir = kk;
            else if (n == "green" || n == "g" || n == "diffuse_green")
                r.ig = kk;
            else if (n == "blue" || n == "b" || n == "diffuse_blue")
                r.ib = kk;
            else if (n == "alpha" || n == "a")
                r.ia = kk;
            else if (n == "s" || n == "u" || n == "texture_u" || n == "texture_s")
                r.iu = kk;
            else if (n == "t" || n == "v" || n == "texture_v" || n == "texture_t")
                r.iv = kk;
        }
        if ((r.isFace || r.isStrip) && e.props[k].list && (n == "vertex_indices" || n == "vertex_index") && r.ilist < 0) r.ilist = kk;
    }
    r.haveNormals = r.inx >= 0 && r.iny >= 0 && r.inz >= 0;
    r.haveColors = r.ir >= 0 && r.ig >= 0 && r.ib >= 0;
    r.haveUv = r.iu >= 0 && r.iv >= 0;
    return r;
}

// The mesh under construction and what the body reading keeps between elements.
struct PlyBuild {
    sg::Mesh mesh;
    BadVertices bad;                // non-finite / absurd positions (faces using them: bad.faces)
    size_t dropped = 0;             // faces / strip triangles
    std::vector<uint32_t> poly;     // scratch: one face's corners
    std::vector<double> listVals;   // the kept list of the current entry
};

// A colour channel as 0..1: 8- and 16-bit integers are scaled, other types taken as they are.
// Always inlined (per vertex and channel; GCC outlined it once split from loadPly).
[[gnu::always_inline]] inline float plyChannel(PlyType t, double d) {
    if (t == PlyType::U8 || t == PlyType::I8)
        d /= 255.0;
    else if (t == PlyType::U16 || t == PlyType::I16)
        d /= 65535.0;
    return float(std::clamp(d, 0.0, 1.0));
}

// A vertex from its property values: its position (a non-finite or absurd one is marked in
// b.bad) and the attributes the element has.
void addPlyVertex(const PlyElement& e, const PlyRoles& k, const std::vector<double>& vals, PlyBuild& b) {
    const double x = vals[size_t(k.ix)], y = vals[size_t(k.iy)], z = vals[size_t(k.iz)];
    const bool good = goodCoordinate(x) && goodCoordinate(y) && goodCoordinate(z);
    if (!good) b.bad.mark(b.mesh.positions.size());
    b.mesh.positions.push_back(good ? sg::vec3(float(x), float(y), float(z)) : sg::vec3(0.0f));
    if (k.haveNormals) b.mesh.normals.push_back({float(vals[size_t(k.inx)]), float(vals[size_t(k.iny)]), float(vals[size_t(k.inz)])});
    if (k.haveUv) b.mesh.uv0.push_back({float(vals[size_t(k.iu)]), float(vals[size_t(k.iv)])});
    if (k.haveColors) {
        auto ch = [&](int c) __attribute__((always_inline)) { return plyChannel(e.props[size_t(c)].type, vals[size_t(c)]); };
        b.mesh.colors.push_back({ch(k.ir), ch(k.ig), ch(k.ib), k.ia >= 0 ? ch(k.ia) : 1.0f});
    }
}

// A face from b.listVals: triangulated when it has >= 3 corners, all indices of vertices
// read so far; else dropped. A face using a bad vertex is dropped into b.bad.faces.
void addPlyFace(PlyBuild& b, Ctx& ctx) {
    b.poly.clear();
    bool ok = b.listVals.size() >= 3;
    for (double d : b.listVals) {
        if (!(d >= 0 && d < double(b.mesh.positions.size()))) {
            ok = false;
            break;
        }
        b.poly.push_back(uint32_t(d));
    }
    if (!ok) {
        ++b.dropped;
        return;
    }
    if (b.bad.anyOf(b.poly)) {
        ++b.bad.faces;
        return;
    }
    ctx.countTriangles(b.listVals.size() - 2);
    addPolygon(ctx, b.mesh, b.poly);
}

// Triangle strips from b.listVals: strips separated by -1; alternate winding; degenerate
// triangles skipped, triangles with an index beyond the vertices read so far dropped, those
// using a bad vertex dropped into b.bad.faces.
void addPlyStrips(PlyBuild& b, Ctx& ctx) {
    const std::vector<double>& lv = b.listVals;
    const double nv = double(b.mesh.positions.size());
    size_t start = 0;
    for (size_t j = 0; j <= lv.size(); ++j) {
        if (j < lv.size() && lv[j] >= 0) continue;
        for (size_t q = start; q + 2 < j; ++q) {
            double a = lv[q], bb = lv[q + 1], c2 = lv[q + 2];
            if (!(a < nv && bb < nv && c2 < nv)) {
                ++b.dropped;
                continue;
            }
            uint32_t ia2 = uint32_t(a), ib2 = uint32_t(bb), ic2 = uint32_t(c2);
            if (ia2 == ib2 || ib2 == ic2 || ia2 == ic2) continue;
            if (b.bad[ia2] || b.bad[ib2] || b.bad[ic2]) {
                ++b.bad.faces;
                continue;
            }
            ctx.countTriangles(1);
            if ((q - start) % 2 == 0) {
                b.mesh.indices.push_back(ia2);
                b.mesh.indices.push_back(ib2);
                b.mesh.indices.push_back(ic2);
            } else {
                b.mesh.indices.push_back(ib2);
                b.mesh.indices.push_back(ia2);
                b.mesh.indices.push_back(ic2);
            }
        }
        start = j + 1;
    }
}

// Reads list property pr of entry i of e; when keep, its values go to b.listVals. False when
// the data ends (or the count is malformed / longer than the data left). A kept list is
// limited to 64M entries (Fail).
bool readPlyList(PlyReader& rd, const PlyElement& e, const PlyProperty& pr, uint64_t i, bool keep, PlyBuild& b) {
    double cnt;
    if (!rd.read(pr.countType, cnt) || cnt < 0 || cnt > 1e9) return false;
    uint64_t n = uint64_t(cnt);
    // A list cannot be longer than the remaining data.
    if (n > rd.left()) return false;
    if (keep && n > (64u << 20))
        throw Fail{"element '" + e.name + "' " + std::to_string(i) + " has a list of " + std::to_string(n) + " entries (limit 64M)"};
    if (keep) b.listVals.resize(size_t(n));
    for (uint64_t j = 0; j < n; ++j) {
        double d;
        if (!rd.read(pr.type, d)) return false;
        if (keep) b.listVals[size_t(j)] = d;
    }
    return true;
}

// Reads entry i of element e (values into vals) and adds what it holds to the mesh: a face or
// strips as soon as their index list is read, a vertex once all its properties are. False
// when the data ends within the entry.
bool readPlyEntry(PlyReader& rd, const PlyElement& e, const PlyRoles& k, uint64_t i, std::vector<double>& vals, PlyBuild& b, Ctx& ctx) {
    for (size_t p = 0; p < e.props.size(); ++p) {
        const PlyProperty& pr = e.props[p];
        if (!pr.list) {
            if (!rd.read(pr.type, vals[p])) return false;
            continue;
        }
        const bool keep = int(p) == k.ilist;
        if (!readPlyList(rd, e, pr, i, keep, b)) return false;
        if (!keep) continue;
        if (k.isFace)
            addPlyFace(b, ctx);
        else if (k.isStrip)
            addPlyStrips(b, ctx);
    }
    if (k.isVertex) addPlyVertex(e, k, vals, b);
    return true;
}

// Reads element e's entries (progress 0..0.95); readOf gets the number read completely.
// False when the file ends within the element.
bool readPlyElement(PlyReader& rd, const PlyElement& e, const std::string& data, PlyBuild& b, Ctx& ctx, uint64_t& readOf) {
    const PlyRoles k = plyRoles(e);
    if (k.isVertex) {
        if (e.count > kMaxVertices)
            throw Fail{"element 'vertex' claims " + std::to_string(e.count) + " entries (budget " + std::to_string(kMaxVertices) + ")"};
        if (k.ix < 0 || k.iy < 0 || k.iz < 0) throw Fail{"vertex element has no x, y, z properties"};
        b.mesh.positions.reserve(size_t(e.count));
    }
    // An element without properties holds no data whatever its count (found by fuzzing:
    // "element x 3000000000000001839" with no properties spun for hours).
    if (e.props.empty()) return true;
    std::vector<double> vals(e.props.size());
    readOf = 0;
    for (uint64_t i = 0; i < e.count; ++i) {
        ctx.poll(size_t(i), 0.0f, 0.95f, 0);
        if ((i & (kPoll - 1)) == 0) {
            size_t used = rd.format == 0 ? size_t(rd.text.p - data.data()) : size_t(rd.p - reinterpret_cast<const unsigned char*>(data.data()));
            ctx.progress.set(0.95f * float(double(used) / double(data.size())));
        }
        if (!readPlyEntry(rd, e, k, i, vals, b, ctx)) return false;
        readOf = i + 1;
    }
    return true;
}

LoadResult loadPly(const fs::path& path, const std::string& data, Ctx& ctx) {
    const std::string file = fileNameOf(path);
    const PlyHeader h = parsePlyHeader(data);
    checkPlyBodySize(h, data);   // element counts are safe to reserve by from here on
    const size_t pos = h.bodyStart;
    PlyReader rd{reinterpret_cast<const unsigned char*>(data.data()) + pos, reinterpret_cast<const unsigned char*>(data.data()) + data.size(),
                 h.format};
    rd.text = Cursor{data.data() + pos, data.data() + data.size()};

    PlyBuild b;
    b.mesh.name = path.stem().string();
    uint64_t readOf = 0;
    for (const PlyElement& e : h.elements) {
        if (!readPlyElement(rd, e, data, b, ctx, readOf)) {
            ctx.warnings.push_back(file + ": file is truncated in element '" + e.name + "' (" + std::to_string(readOf) + " of " +
                                   std::to_string(e.count) + " read)");
            break;
        }
    }
    if (b.dropped)
        ctx.warnings.push_back(file + ": " + std::to_string(b.dropped) + " faces with out-of-range indices or fewer than 3 corners dropped");
    warnBadVertices(ctx, file, b.bad.count, b.mesh.positions.size(), b.bad.faces);
    dropBadVertices(b.mesh, b.bad);
    return singleMeshScene(path, std::move(b.mesh));
}

// ---- 7. STL -------------------------------------------------------------------------------
// Welds corners with bit-identical positions (STL stores a triangle soup).
void weldAndAdd(sg::Mesh& mesh, std::unordered_map<uint64_t, std::vector<uint32_t>>& buckets, const sg::vec3& p) {
    uint32_t b[3];
    std::memcpy(b, &p, 12);
    uint64_t h = (uint64_t(b[0]) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(b[1]) * 0xC2B2AE3D27D4EB4Full) ^ (uint64_t(b[2]) * 0x165667B19E3779F9ull);
    auto& list = buckets[h];
    for (uint32_t i : list)
        if (std::memcmp(&mesh.positions[i], &p, 12) == 0) {
            mesh.indices.push_back(i);
            return;
        }
    list.push_back(uint32_t(mesh.positions.size()));
    mesh.indices.push_back(uint32_t(mesh.positions.size()));
    mesh.positions.push_back(p);
}

LoadResult loadStl(const fs::path& path, const std::string& data, Ctx& ctx) {
    const std::string file = fileNameOf(path);
    sg::Mesh mesh;
    mesh.name = path.stem().string();
    std::unordered_map<uint64_t, std::vector<uint32_t>> buckets;
    bool binary = false;
    uint32_t n = 0;
    size_t badFacets = 0;   // facets with a non-finite or absurd corner
    if (data.size() >= 84) {
        std::memcpy(&n, data.data() + 80, 4);
        binary = 84 + 50ull * n == data.size();
        if (!binary) {
            // Not an exact binary size: ASCII if it looks like text starting with "solid".
            size_t s = data.find_first_not_of(" \t\r\n");
            bool text =
                s != std::string::npos && data.compare(s, 5, "solid") == 0 &&
                std::none_of(data.begin(), data.begin() + std::ptrdiff_t(std::min<size_t>(data.size(), 512)), [](char c) { return c == '\0'; });
            binary = !text;
        }
    }
    if (binary) {
        uint64_t fits = (data.size() - 84) / 50;
        if (n != fits) {
            ctx.warnings.push_back(file + ": header claims " + std::to_string(n) + " triangles but the file holds " + std::to_string(fits) +
                                   (n > fits ? " (truncated)" : " (extra data ignored)"));
            n = uint32_t(std::min<uint64_t>(n, fits));
        }
        ctx.countTriangles(n);
        mesh.positions.reserve(n);   // at most 3n after welding, typically n/2
        mesh.indices.reserve(size_t(n) * 3);
        buckets.reserve(size_t(n));
        size_t badCorners = 0;
        for (uint32_t i = 0; i < n; ++i) {
            ctx.poll(i, 0.0f, 0.95f, n);
            const char* f = data.data() + 84 + size_t(i) * 50;
            float fl[9];
            std::memcpy(fl, f + 12, 36);
            sg::vec3 v[3] = {{fl[0], fl[1], fl[2]}, {fl[3], fl[4], fl[5]}, {fl[6], fl[7], fl[8]}};
            const size_t bad = size_t(!goodPosition(v[0])) + !goodPosition(v[1]) + !goodPosition(v[2]);
            if (bad) {
                badCorners += bad;
                ++badFacets;
                continue;
            }
            for (auto& p : v) weldAndAdd(mesh, buckets, p + sg::vec3(0.0f));   // +0 turns -0 into +0
        }
        warnBadVertices(ctx, file, badCorners, 3 * size_t(n), badFacets);
    } else {
        if (data.size() < 5) throw Fail{"file too short to be STL"};
        Cursor c{data.data(), data.data() + data.size()};
        std::string_view first = c.anyToken();
        if (first != "solid") throw Fail{"not an STL file (neither binary nor starting with 'solid')"};
        sg::vec3 tri[3];
        Coord worst = Coord::Ok;   // of the facet's corners so far
        int k = 0;
        size_t malformed = 0, badCorners = 0, count = 0;
        while (!c.atEnd()) {
            std::string_view t = c.anyToken();
            if (t != "vertex") continue;
            ctx.poll(++count, 0.0f, 0.0f, 0);
            if ((count & (kPoll - 1)) == 0) ctx.progress.set(0.95f * float(double(c.p - data.data()) / double(data.size())));
            const std::string_view x = c.anyToken(), y = c.anyToken(), z = c.anyToken();
            const Coord q = parsePosition(x, y, z, tri[k++]);
            malformed += q == Coord::Malformed;
            badCorners += q == Coord::Bad;
            if (q == Coord::Malformed || (q == Coord::Bad && worst == Coord::Ok)) worst = q;
            if (k < 3) continue;
            k = 0;
            badFacets += worst == Coord::Bad;
            if (std::exchange(worst, Coord::Ok) != Coord::Ok) continue;
            ctx.countTriangles(1);
            for (auto& p : tri) weldAndAdd(mesh, buckets, p + sg::vec3(0.0f));
        }
        if (k != 0) ctx.warnings.push_back(file + ": file ends inside a facet (truncated?)");
        if (malformed) ctx.warnings.push_back(file + ": " + std::to_string(malformed) + " malformed vertex lines; their facets dropped");
        warnBadVertices(ctx, file, badCorners, count, badFacets);
    }
    if (mesh.indices.empty())
        throw Fail{badFacets ? "no triangles: every facet has a non-finite corner or one with a |coordinate| > 1e30" : "no triangles"};
    std::vector<std::pair<sg::Mesh, int>> parts;
    parts.push_back({std::move(mesh), -1});
    LoadResult r;
    r.scene = makeScene(path, parts, {}, {});
    return r;
}

}   // namespace

// ---- 8. loadMeshFile ----------------------------------------------------------------------
LoadResult loadMeshFile(const fs::path& path, const LoadOptions& options) {
    LoadResult result;
    const std::string file = fileNameOf(path);
    std::string ext = lower(path.extension().string());
    std::string data;
    std::string err = readFileLimited(path, kMaxFileBytes, data);
    if (!err.empty()) {
        result.error = err;
        return result;
    }
    Progress progress{options};
    Ctx ctx{path, progress, {}, 0};
    try {
        if (data.empty()) throw Fail{"empty file"};
        if (data.size() >= 2 && ((uint8_t(data[0]) == 0xFE && uint8_t(data[1]) == 0xFF) || (uint8_t(data[0]) == 0xFF && uint8_t(data[1]) == 0xFE)))
            throw Fail{"UTF-16 text is not supported (save the file as UTF-8/ASCII)"};
        progress.set(0.0f);
        if (ext == ".obj")
            result = loadObj(path, data, ctx);
        else if (ext == ".off")
            result = loadOff(path, data, ctx);
        else if (ext == ".ply")
            result = loadPly(path, data, ctx);
        else if (ext == ".stl")
            result = loadStl(path, data, ctx);
        else
            throw Fail{"unsupported mesh format '" + ext + "'"};
    } catch (const Fail& f) {
        result = {};
        // Quoted file text may hold control bytes: keep the error one printable line.
        std::string why = f.why.size() > 300 ? f.why.substr(0, 300) + "..." : f.why;
        for (char& ch : why)
            if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = '?';
        result.error = file + ": " + why;
        return result;
    } catch (const std::bad_alloc&) {
        result = {};
        result.error = file + ": out of memory";
        return result;
    } catch (const std::exception& e) {
        result = {};
        result.error = file + ": " + e.what();
        return result;
    }
    for (auto& w : ctx.warnings) result.warnings.push_back(std::move(w));
    progress.set(1.0f);
    return result;
}

}   // namespace assets::detail
