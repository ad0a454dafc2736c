// builder.cpp - what the mesh importers share: number and coordinate parsing, the bad-vertex
// warning and removal, polygons triangulated into a mesh (assets/polygon.h: a fan when convex,
// ear clipping when concave), and the scene built from the parsed meshes (one node per mesh
// and material, incomplete attributes dropped, normals computed where missing, default camera
// and light).
#include "mesh_internal.h"

#include <cmath>
#include <limits>

namespace fs = std::filesystem;

namespace assets::detail::meshfile {

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

Coord parseCoordinate(std::string_view t, float& out) {
    double d;
    if (!toDouble(t, d)) return Coord::Malformed;
    if (!goodCoordinate(d)) return Coord::Bad;
    out = float(d);
    return Coord::Ok;
}
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

void warnBadVertices(Ctx& ctx, const std::string& file, size_t bad, size_t total, size_t faces, size_t lines) {
    if (!bad) return;
    auto counted = [](size_t n, const char* what) { return std::to_string(n) + " " + what + (n == 1 ? "" : "s"); };
    std::string w = file + ": dropped " + std::to_string(bad) + " of " + std::to_string(total) + " vertices (non-finite or |coordinate| > 1e30)";
    if (faces) w += " and " + counted(faces, "face");
    if (lines) w += " and " + counted(lines, "line");
    if (faces || lines) w += bad == 1 ? " that use it" : " that use them";
    ctx.warnings.push_back(std::move(w));
}

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

void addPolygon(Ctx& ctx, sg::Mesh& mesh, const std::vector<uint32_t>& corners) {
    ctx.triangulator.triangulate(mesh.positions, corners, mesh.indices);
}

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

}   // namespace assets::detail::meshfile
