// stl.cpp - STL, binary (a file of exactly 84 + 50 n bytes, or anything that is not text starting
// with "solid") or ASCII: a triangle soup welded by exact position; facets with unusable corners
// dropped with one warning, a triangle count that disagrees with the file size reported.
#include "mesh_internal.h"

#include <algorithm>
#include <cstring>
#include <unordered_map>

namespace fs = std::filesystem;

namespace assets::detail::meshfile {

namespace {

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

}   // namespace

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
    return singleMeshScene(path, std::move(mesh));
}

}   // namespace assets::detail::meshfile
