// off.cpp - OFF ([ST][C][N]OFF, ASCII): the header's counts checked against the file size before
// anything is reserved, vertices with optional normals, texture coordinates and colours, faces
// triangulated; truncation and dropped faces reported as warnings.
#include "mesh_internal.h"

namespace fs = std::filesystem;

namespace assets::detail::meshfile {

namespace {

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

}   // namespace

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

}   // namespace assets::detail::meshfile
