// import_bench.cpp - importer scale benchmark (a harness, not Google Benchmark: each load is
// seconds long and the interesting number is peak memory).
//   bench_import [--keep] [--only nodes|tris|meshes] [--dir DIR]
// Generates into a temp folder (removed afterwards unless --keep):
//   nodes-1M.gltf : 1,000,001 nodes (root -> 1000 groups -> 999 boxes each), all
//                   instancing one 12-triangle box, TRS transforms
//   tris-10M.gltf : one grid mesh of 2237 x 2237 vertices = 9,999,392 triangles (uint32
//                   indices, float positions; no normals, so they are computed)
// and loads each with assets::loadScene in a forked child, reporting wall and CPU time (the
// machine is shared: CPU time is the steadier number) and the child's peak RSS growth
// (VmHWM minus VmRSS at the start of the load) as
//   bench: scene=<name> what=load_{wall_s,cpu_s,peak_rss_growth_mb} ours=<x>
// (and input_mb, nodes, unique_triangles)
// The glTF files are also parsed by tinygltf alone (TinyGLTF::LoadASCIIFromFile into its Model,
// nothing else; another forked child), the floor under our importer, which is built on it:
//   bench: scene=<name> what=tinygltf_alone_<metric> ours=<x>
// With testdata present it also times the largest real meshes (igea.ply, bunny OBJ/STL).
#include "assets/scene_io.h"

#include <tiny_gltf.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

long statusKb(const char* key) {
    std::ifstream f("/proc/self/status");
    std::string line;
    size_t n = std::strlen(key);
    while (std::getline(f, line))
        if (line.compare(0, n, key) == 0) return std::atol(line.c_str() + n + 1);
    return -1;
}
void writeFile(const fs::path& p, const void* data, size_t n) {
    FILE* f = std::fopen(p.c_str(), "wb");
    if (!f) {
        std::perror(p.c_str());
        std::exit(1);
    }
    std::fwrite(data, 1, n, f);
    std::fclose(f);
}

// A 12-triangle box (24 vertices would be nicer; 8 shared corners are enough here).
void writeBox(const fs::path& dir) {
    float p[24] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
    uint16_t i[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
    std::string b(reinterpret_cast<const char*>(p), sizeof p);
    b.append(reinterpret_cast<const char*>(i), sizeof i);
    writeFile(dir / "box.bin", b.data(), b.size());
}

// 1 root group -> 1000 groups -> 999 boxes each (1 + 1000 + 999000 = 1,000,001 nodes).
void genNodes(const fs::path& dir) {
    writeBox(dir);
    std::string j;
    j.reserve(80u << 20);
    j += "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"box.bin\",\"byteLength\":168}],"
         "\"bufferViews\":[{\"buffer\":0,\"byteLength\":96},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":72}],"
         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":8,\"type\":\"VEC3\",\"min\":[-1,-1,-1],\"max\":[1,1,1]},"
         "{\"bufferView\":1,\"componentType\":5123,\"count\":36,\"type\":\"SCALAR\"}],"
         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
         "\"scenes\":[{\"nodes\":[0]}],\"scene\":0,\"nodes\":[{\"name\":\"root\",\"children\":[";
    const int groups = 1000, per = 999;
    for (int g = 0; g < groups; ++g) {
        if (g) j += ',';
        j += std::to_string(1 + g);
    }
    j += "]}";
    int next = 1 + groups;
    char buf[160];
    for (int g = 0; g < groups; ++g) {
        j += ",{\"translation\":[" + std::to_string(g % 40 * 60) + ",0," + std::to_string(g / 40 * 60) + "],\"children\":[";
        for (int c = 0; c < per; ++c) {
            if (c) j += ',';
            j += std::to_string(next + c);
        }
        j += "]}";
        next += per;
    }
    for (int g = 0; g < groups; ++g)
        for (int c = 0; c < per; ++c) {
            std::snprintf(buf, sizeof buf, ",{\"mesh\":0,\"translation\":[%d,%d,0],\"scale\":[0.4,0.4,0.4]}", c % 32 * 2, c / 32 * 2);
            j += buf;
        }
    j += "]}";
    writeFile(dir / "nodes-1M.gltf", j.data(), j.size());
}

void genTris(const fs::path& dir) {
    const uint32_t n = 2237;   // vertices per side
    std::vector<float> pos(size_t(n) * n * 3);
    for (uint32_t y = 0; y < n; ++y)
        for (uint32_t x = 0; x < n; ++x) {
            float* p = &pos[(size_t(y) * n + x) * 3];
            p[0] = float(x) / float(n - 1) * 2 - 1;
            p[1] = 0.05f * std::sin(float(x) * 0.05f) * std::cos(float(y) * 0.05f);
            p[2] = float(y) / float(n - 1) * 2 - 1;
        }
    std::vector<uint32_t> idx;
    idx.reserve(size_t(n - 1) * (n - 1) * 6);
    for (uint32_t y = 0; y + 1 < n; ++y)
        for (uint32_t x = 0; x + 1 < n; ++x) {
            uint32_t a = y * n + x, b = a + 1, c = a + n, d = c + 1;
            idx.insert(idx.end(), {a, c, b, b, c, d});
        }
    size_t pb = pos.size() * 4, ib = idx.size() * 4;
    {
        FILE* f = std::fopen((dir / "grid.bin").c_str(), "wb");
        std::fwrite(pos.data(), 1, pb, f);
        std::fwrite(idx.data(), 1, ib, f);
        std::fclose(f);
    }
    std::string j =
        "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"grid.bin\",\"byteLength\":" + std::to_string(pb + ib) +
        "}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":" +
        std::to_string(pb) + "},{\"buffer\":0,\"byteOffset\":" + std::to_string(pb) + ",\"byteLength\":" + std::to_string(ib) +
        "}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":" +
        std::to_string(size_t(n) * n) +
        ",\"type\":\"VEC3\",\"min\":[-1,-1,-1],\"max\":[1,1,1]},{\"bufferView\":1,\"componentType\":5125,\"count\":" + std::to_string(idx.size()) +
        ",\"type\":\"SCALAR\"}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
        "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}";
    writeFile(dir / "tris-10M.gltf", j.data(), j.size());
}

double cpuSeconds() {
    struct rusage ru {};
    getrusage(RUSAGE_SELF, &ru);
    return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// Runs `load` in a forked child, so that its peak RSS (VmHWM) belongs to this load alone, and
// prints its wall and CPU time and peak RSS growth as <prefix>wall_s, <prefix>cpu_s and
// <prefix>peak_rss_growth_mb. `load` returns "" (then prints its own figures with `report`)
// or an error, printed as <prefix>error. True when the child succeeded.
template <class Load>
bool inChild(const std::string& name, const std::string& prefix, Load&& load) {
    std::fflush(stdout);
    pid_t pid = fork();
    if (pid < 0) {
        std::perror("fork");
        return false;
    }
    if (pid > 0) {
        int status = 0;
        waitpid(pid, &status, 0);
        return WIFEXITED(status) && WEXITSTATUS(status) == 0;
    }
    const long rssBefore = statusKb("VmRSS:");
    const double cpu0 = cpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    std::function<void()> report;
    const std::string err = load(report);
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = cpuSeconds() - cpu0;
    const long hwm = statusKb("VmHWM:");
    if (!err.empty()) {
        std::printf("bench: scene=%s what=%serror ours=\"%s\"\n", name.c_str(), prefix.c_str(), err.c_str());
        std::fflush(stdout);
        _exit(1);
    }
    std::printf("bench: scene=%s what=%swall_s ours=%.3f\n", name.c_str(), prefix.c_str(), dt);
    std::printf("bench: scene=%s what=%scpu_s ours=%.3f\n", name.c_str(), prefix.c_str(), cpu);
    std::printf("bench: scene=%s what=%speak_rss_growth_mb ours=%.1f\n", name.c_str(), prefix.c_str(), double(hwm - rssBefore) / 1024.0);
    if (report) report();
    std::fflush(stdout);
    _exit(0);
}

// Our importer (assets::loadScene) on `file`.
bool measure(const std::string& name, const fs::path& file, uint64_t extraBytes = 0) {
    assets::LoadResult r;
    return inChild(name, "load_", [&](std::function<void()>& report) {
        r = assets::loadScene(file);
        if (!r.scene) return r.error;
        report = [&] {
            size_t tris = 0;
            for (const auto& m : r.scene->meshes) tris += m->triangleCount();
            std::printf("bench: scene=%s what=input_mb ours=%.1f\n", name.c_str(), double(fs::file_size(file) + extraBytes) / 1048576.0);
            std::printf("bench: scene=%s what=nodes ours=%zu\n", name.c_str(), r.scene->nodeCount());
            std::printf("bench: scene=%s what=unique_triangles ours=%zu\n", name.c_str(), tris);
        };
        return std::string();
    });
}

// tinygltf alone on a .gltf: the parse our importer starts with, the floor under it.
bool measureTinygltf(const std::string& name, const fs::path& file) {
    tinygltf::Model model;
    return inChild(name, "tinygltf_alone_", [&](std::function<void()>&) {
        tinygltf::TinyGLTF loader;
        std::string err, warn;
        return loader.LoadASCIIFromFile(&model, &err, &warn, file.string()) ? std::string() : err.empty() ? std::string("failed") : err;
    });
}

}   // namespace

int main(int argc, char** argv) {
    bool keep = false;
    std::string only;
    fs::path dir;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--keep")
            keep = true;
        else if (a == "--only" && i + 1 < argc)
            only = argv[++i];
        else if (a == "--dir" && i + 1 < argc)
            dir = argv[++i];
        else {
            std::fprintf(stderr, "usage: bench_import [--keep] [--only nodes|tris|meshes] [--dir DIR]\n");
            return 2;
        }
    }
    if (dir.empty()) dir = fs::temp_directory_path() / ("bench_import_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    bool ok = true;
    auto gen = [&](const char* what, auto&& f) {
        auto t0 = std::chrono::steady_clock::now();
        f(dir);
        std::printf("bench: scene=%s what=generate_s ours=%.3f\n", what,
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    };
    if (only.empty() || only == "nodes") {
        gen("gltf-1M-nodes", genNodes);
        ok &= measure("gltf-1M-nodes", dir / "nodes-1M.gltf");
        ok &= measureTinygltf("gltf-1M-nodes", dir / "nodes-1M.gltf");
        if (!keep) fs::remove(dir / "nodes-1M.gltf");
    }
    if (only.empty() || only == "tris") {
        gen("gltf-10M-tris", genTris);
        ok &= measure("gltf-10M-tris", dir / "tris-10M.gltf", fs::file_size(dir / "grid.bin"));
        ok &= measureTinygltf("gltf-10M-tris", dir / "tris-10M.gltf");
        if (!keep) fs::remove(dir / "grid.bin");
    }
    if (only.empty() || only == "meshes") {
        fs::path td = fs::path(VIEWER_TESTDATA_DIR) / "meshes";
        const std::pair<const char*, const char*> real[] = {
            {"igea.ply", "common-3d-test-models/igea/igea.ply"},
            {"bunny.obj", "common-3d-test-models/stanford-bunny/stanford-bunny.obj"},
            {"bunny.stl", "draco-testdata/STL/bunny.stl"},
            {"SheenCloth.glb", "../gltf/SheenCloth/glTF-Binary/SheenCloth.glb"},
        };
        for (const auto& [name, rel] : real)
            if (fs::exists(td / rel)) ok &= measure(name, td / rel);
    }
    if (!keep) fs::remove_all(dir);
    return ok ? 0 : 1;
}
