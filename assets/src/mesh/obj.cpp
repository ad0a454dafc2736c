// obj.cpp - Wavefront OBJ with its MTL material libraries: v (with optional vertex colours), vt,
// vn, f / l / p elements (1-based or negative indices), usemtl groups -> one mesh per material,
// lines and point clouds; MTL colours, shininess, alpha and map_Kd textures read through
// ConfinedDir, and a texture beside a model without mtllib picked up by its name.
#include "mesh_internal.h"

#include "assets/image_io.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

namespace fs = std::filesystem;

namespace assets::detail::meshfile {

namespace {

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

}   // namespace

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

}   // namespace assets::detail::meshfile
