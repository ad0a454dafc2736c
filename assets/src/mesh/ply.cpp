// ply.cpp - PLY (ASCII, binary little and big endian): the header (any line ends), element
// counts checked against the body size, vertex elements with positions, normals, colours and
// UVs, faces triangulated and tristrips unrolled; other elements read and skipped; a file with
// vertices only becomes a point cloud.
#include "mesh_internal.h"

#include <algorithm>
#include <cstring>

namespace fs = std::filesystem;

namespace assets::detail::meshfile {

namespace {

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

}   // namespace

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

}   // namespace assets::detail::meshfile
