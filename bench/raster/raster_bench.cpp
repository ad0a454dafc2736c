// raster_bench.cpp - frame time of our CPU rasterizer ("raster") vs a minimal GL program on
// Mesa llvmpipe (min_gl.h: one VBO, the same Phong + linear fog, one glReadPixels; submitted
// two ways: as the scene comes, and fair: indexed, nearest first, culled as ours) and vs our GL
// backend on llvmpipe; same scene, camera, size and thread count.
//
//   cmake --build build/release -j2 --target bench_raster
//   ./build/release/bench/raster/bench_raster [--quick] [--threads 2] [--frames 15]
//        [--size 1280x720] [--shading phong|gouraud|flat] [--fog on|off] [--culling auto|on|off] [--scenes a,b,...]
//        [--no-gl | --gl-only [--gl-side ours|minimal]] [--mesh FILE ...]
//
// Prints one line per scene and metric:
//   bench: scene=<name> what=<metric> ours=<x> ref=<y> ratio=<ours/ref>
// metrics (medians of warm frames):
//   ms_fair     wall ms per frame, raster vs the minimal GL program submitted fairly (Order::Fair:
//               indexed, clusters of triangles nearest first, back faces culled where ours culls
//               them; the goal: ratio <= 0.5)
//   ms          the same against the minimal GL program as it first was (Order::Scene: one
//               unindexed glDrawArrays in the scene's order, far geometry first in the grids)
//   ms_best     raster vs the faster of the two submissions (per scene, by their medians): on
//               some scenes (the bunny) the indexed draw is not the faster one on llvmpipe
//   ref_fair    the two minimal programs: Order::Scene's ms (ours=) vs Order::Fair's (ref=); ratio =
//               how much faster llvmpipe is when fed fairly
// ms, ms_fair, ms_best, ref_fair, cpu_ms, cpu_ms_fair and scaling come from the same rounds: one
// frame of ours on --threads, one on 1 thread, one of each minimal program, --frames times.
//   ms_gl       wall ms per frame, raster vs our GL backend
//   gl_ms       wall ms per frame, our GL backend vs the minimal GL program (goal: ratio <= 1.3)
//   gl_cpu_ms   process CPU ms per frame, our GL backend vs the minimal GL program
//   cpu_ms      process CPU ms per frame (all threads), raster vs the minimal GL program (Order::Scene)
//   cpu_ms_fair the same against Order::Fair
//   mpix_s      fill rate: covered pixels per wall second / 1e6 (ratio = ref time / ours)
//   mpix_s_thread  the same per thread, ours vs the minimal GL program
//   scaling     ours: ms on 1 thread (ours=) vs on --threads (ref=); ratio = the speed-up; the
//               frames of the two alternate (one on 1 thread, one on --threads, ...), so a
//               change in the machine's load falls on both
//   cold_ms     ours: the first frame of a new renderer (ours=) vs a warm one (ref=), into a new image
//   cold_reused_ms  the same into an image of the right size that it already had (as the window's
//               RenderSlot gives a renderer after a backend switch): the renderer's own cold cost
//               without the first touch of the image's pages
//   pbr_ms      ours: the frame with the pbr model and the default environment (ours=) vs Phong (ref=;
//               the goal: ratio <= 1.5)
//   shadow_ms   ours: the frame lit by one sun with shadows (a 2048 map, PCF 3 x 3; ours=) vs the
//               same frame without (ref=; the goal: ratio <= 1.5). The other rows are without
//               shadows (the minimal GL program has none). Scene demo (the bundled demo, only
//               when named in --scenes) gets this row alone.
//   floor_shade the lighting kernel alone (raster_shading.h's shadeBatch on as many fragments as
//               the scene covers, same lights; ours=) vs the whole raster frame (ref=)
//   floor_shade_scaling  the same kernel on 1 thread (ours=) vs on --threads (ref=), ratio =
//               its speed-up: what a compute-bound SIMD loop gets from the extra threads now
//               (below floor_cpu where the cores share execution units, e.g. SMT siblings)
// and per run: what=prefilter_ms: building an environment light from a 2048x1024 image on
// --threads (goal: under 1000 ms); what=floor_bw: memory bandwidth (GB/s, read + write of a 256 MiB
// copy) on 1 thread (ours=) and on --threads (ref=); what=floor_cpu: a fixed arithmetic loop
// per thread, ms on 1 thread (ours=) and on --threads (ref=), ratio = the speed-up this machine
// gives right now (below --threads when other work shares the cores: no renderer scales better).
// Scenes: mesh10k / mesh100k / mesh1M (one mesh: a uv-sphere grid and its ground plane merged
// into a single draw, one point light), spheres10k / spheres100k / spheres1M (the same kind of
// grid as instances of one sphere mesh, plus a ground plane and a directional light) and bunny
// (stanford-bunny.obj from shared/testdata, read by a tiny OBJ reader below). --mesh FILE (any
// number) adds a scene of that mesh file, read by the viewer's importer and framed like the
// bunny, named after the file (with --scenes NAME,... selecting the built-in ones: --scenes none
// runs only the files).
// LP_NUM_THREADS is set before any GL context is created; tbb is limited to the same count.
// --culling auto|on|off: RenderSettings::culling of every scene (the scenes' materials are
// double-sided, so with auto nothing is culled; on: ours and the fair minimal program cull back faces).
// --quick: fewer frames and 960x540 (finishes well under a minute). --no-gl: raster only (for
// profiling it, e.g. perf record ... bench_raster --no-gl --scenes mesh1M). --ours-only N: only
// N warm frames of ours per scene (after a cold one), nothing printed: a profile of the frame alone
// (perf record -g bench_raster --no-gl --ours-only 100 --scenes mesh10k). --gl-only: our GL
// backend and the minimal GL program only (gl_ms, gl_cpu_ms and the image check); with
// --gl-side ours|minimal only one of them runs, for a profiler to count one side's instructions
// (valgrind --tool=callgrind bench_raster --gl-only --gl-side ours --frames N: the difference
// between two frame counts is the cost of those frames).
#include "assets/demo.h"
#include "assets/scene_io.h"
#include "bench_scenes.h"
#include "min_gl.h"
#include "raster/raster_shading.h"
#include "renderers/environment.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "scenegraph/scene.h"
#include "scenegraph/setting_names.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#ifndef VIEWER_TESTDATA_DIR
#define VIEWER_TESTDATA_DIR "../shared/testdata"
#endif

using namespace sg;

namespace {

// Minimal OBJ reader for the bench only: "v x y z" and "f a b c ..." (fan), 1-based or
// negative indices, ignoring texture/normal references.
bool readObj(const std::string& path, Mesh& m) {
    std::ifstream in(path);
    if (!in) return false;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::string tag;
        ls >> tag;
        if (tag == "v") {
            vec3 p;
            ls >> p.x >> p.y >> p.z;
            m.positions.push_back(p);
        } else if (tag == "f") {
            std::vector<uint32_t> f;
            std::string tok;
            while (ls >> tok) {
                long i = std::strtol(tok.c_str(), nullptr, 10);
                if (i < 0) i = long(m.positions.size()) + i + 1;
                if (i < 1) return false;
                f.push_back(uint32_t(i - 1));
            }
            for (size_t k = 1; k + 1 < f.size(); ++k) m.indices.insert(m.indices.end(), {f[0], f[k], f[k + 1]});
        }
    }
    for (uint32_t i : m.indices)
        if (i >= m.positions.size()) return false;
    m.computeNormals();
    return !m.indices.empty();
}

using bench::addGridCameraAndKey;
using bench::BenchScene;
using bench::fileScene;
using bench::meshScene;
using bench::singleMesh;
using bench::sphereGrid;

bool bunnyScene(BenchScene& b) {
    auto m = std::make_shared<Mesh>();
    std::string path = std::string(VIEWER_TESTDATA_DIR) + "/meshes/common-3d-test-models/stanford-bunny/stanford-bunny.obj";
    if (const char* env = std::getenv("VIEWER_TESTDATA")) path = std::string(env) + "/meshes/common-3d-test-models/stanford-bunny/stanford-bunny.obj";
    if (!readObj(path, *m)) {
        std::fprintf(stderr, "bench: %s: cannot read (skipping the bunny scene)\n", path.c_str());
        return false;
    }
    b = meshScene("bunny", m);
    return true;
}

double median(std::vector<double> v) {
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// Process CPU time (all threads, user + system) in ms.
double cpuMs() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return (u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3;
}

struct Timing {
    double wallMs = NAN, cpuMs = NAN;   // medians per frame
};

// Median wall and CPU ms per frame of `frame` (after one warm-up frame: caches, textures, GL
// buffers); NAN when it fails. CPU time (summed over the process's threads: ours and
// llvmpipe's) is the steadier figure on a shared, loaded machine.
Timing timeFrames(const std::function<bool()>& frame, int frames) {
    if (!frame()) return {};
    std::vector<double> t, c;
    for (int i = 0; i < frames; ++i) {
        auto t0 = std::chrono::steady_clock::now();
        double c0 = cpuMs();
        frame();
        c.push_back(cpuMs() - c0);
        t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    return {median(t), median(c)};
}

Timing timeRenderer(rnd::Renderer& r, const FrameInput& f, int w, int h, int frames, rnd::Framebuffer& fb, std::string& err) {
    return timeFrames(
        [&] {
            rnd::RenderStats s = r.render(f, w, h, fb);
            if (!s.ok) err = s.error;
            return s.ok;
        },
        frames);
}

// Parallelism the machine gives this process now: a fixed amount of pure arithmetic per thread
// on 1 and on `threads` threads; returns {ms on 1 thread, ms on `threads`} (medians of 3).
// Speed-up = threads * first / second; on a machine busy with other work it is below `threads`,
// and no renderer can scale better than it.
std::pair<double, double> computeScaling(int threads) {
    auto run = [](int n) {
        std::vector<double> ms;
        for (int rep = 0; rep < 3; ++rep) {
            auto t0 = std::chrono::steady_clock::now();
            std::vector<double> sink(size_t(n) * 8);
            tbb::parallel_for(0, n, [&](int k) {
                double x = 1.0;
                for (int i = 0; i < 20000000; ++i) x = x * 1.0000001 + 1e-9;
                sink[size_t(k) * 8] = x;
            });
            ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        }
        return median(ms);
    };
    return {run(1), run(threads)};
}

// Shading-only floor: the rasterizer's lighting kernel (rnd::raster::shadeBatch, SSE2 or AVX2
// as the renderer picks it, the same lights and Phong model) on `fragments` fragments split
// over the threads, without coverage, depth, attribute interpolation or output: ms per frame
// (median of 5).
double shadeOnlyMs(const FrameInput& f, size_t fragments, int threads = 0) {
    const size_t parts = 64, per = (fragments + parts - 1) / parts;
    std::vector<rnd::raster::ShadeBatch> batches(parts);
    for (auto& b : batches) {
        b.resize(per);
        for (size_t i = 0; i < per; ++i) {
            const float u = float(i) / float(per);
            b.set(i, Material{}, vec3(u * 8.0f - 4.0f, 0.5f, u * 4.0f), glm::normalize(vec3(u - 0.5f, 1.0f, 0.3f)), vec3(0.8f, 0.3f, 0.2f),
                  f.ambientLight);
        }
    }
    std::vector<double> ms;
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));
    for (int rep = 0; rep < 5; ++rep) {
        auto t0 = std::chrono::steady_clock::now();
        tbb::parallel_for(size_t(0), parts, [&](size_t k) { rnd::raster::shadeBatch(batches[k], per, f); });
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    return median(ms);
}

// Memory bandwidth floor: GB/s of read + write of a 256 MiB buffer copied in `threads` slices
// (median of 5).
double copyBandwidth(int threads) {
    const size_t n = size_t(256) << 20;
    std::vector<char> a(n, 1), b(n, 0);
    std::vector<double> gbs;
    for (int rep = 0; rep < 5; ++rep) {
        auto t0 = std::chrono::steady_clock::now();
        tbb::parallel_for(0, threads, [&](int k) {
            size_t lo = n / threads * k, hi = k + 1 == threads ? n : n / threads * (k + 1);
            std::memcpy(b.data() + lo, a.data() + lo, hi - lo);
        });
        double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        gbs.push_back(2.0 * double(n) / s * 1e-9);
    }
    return median(gbs);
}

// Pixels not equal to the background (covered by geometry).
double coveredPixels(const rnd::Framebuffer& fb) {
    size_t n = 0;
    for (float d : fb.depth) n += d < 1.0f;
    return double(n);
}

}   // namespace

int main(int argc, char** argv) {
    bool quick = false, noGl = false, glOnly = false;
    int threads = 2, frames = 15, w = 1280, h = 720, oursOnly = 0;
    std::string shading = "phong", fog = "on", only, glSide = "both";
    CullMode culling = CullMode::Auto;   // --culling: RenderSettings::culling of every scene (ours and the fair minimal program)
    std::vector<std::string> meshFiles;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
        if (a == "--quick")
            quick = true;
        else if (a == "--no-gl")
            noGl = true;
        else if (a == "--gl-only")
            glOnly = true;
        else if (a == "--gl-side")
            glSide = next();
        else if (a == "--threads")
            threads = std::max(1, std::atoi(next().c_str()));
        else if (a == "--frames")
            frames = std::max(1, std::atoi(next().c_str()));
        else if (a == "--ours-only")
            oursOnly = std::max(1, std::atoi(next().c_str()));
        else if (a == "--size")
            std::sscanf(next().c_str(), "%dx%d", &w, &h);
        else if (a == "--shading")
            shading = next();
        else if (a == "--fog")
            fog = next();
        else if (a == "--culling") {
            if (!sg::parseName(next(), culling)) {
                std::fprintf(stderr, "bench: --culling wants %s\n", sg::nameList<CullMode>().c_str());
                return 2;
            }
        } else if (a == "--scenes")
            only = next();
        else if (a == "--mesh")
            meshFiles.push_back(next());
        else {
            std::fprintf(stderr, "bench: unknown argument %s\n", a.c_str());
            return 2;
        }
    }
    if (quick) {
        frames = std::min(frames, 5);
        if (w == 1280 && h == 720) {
            w = 960;
            h = 540;
        }
    }
    // Same thread count for both: llvmpipe reads LP_NUM_THREADS when the context is created.
    setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), 1);
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

    std::string err;
    auto ours = rnd::makeRenderer("raster", &err);
    if (!ours) {
        std::fprintf(stderr, "bench: %s\n", err.c_str());
        return 1;
    }
    auto glBackend = noGl ? nullptr : rnd::makeRenderer("gl", &err);

    std::vector<BenchScene> scenes;
    auto want = [&](const std::string& n) { return only.empty() || ("," + only + ",").find("," + n + ",") != std::string::npos; };
    if (want("mesh10k")) scenes.push_back(singleMesh("mesh10k", 4, 22, 32));
    if (want("mesh100k")) scenes.push_back(singleMesh("mesh100k", 10, 30, 64));
    if (want("mesh1M")) scenes.push_back(singleMesh("mesh1M", 22, 46, 64));
    if (want("spheres10k")) scenes.push_back(sphereGrid("spheres10k", 4, 24));
    if (want("spheres100k")) scenes.push_back(sphereGrid("spheres100k", 10, 32));
    if (want("spheres1M")) scenes.push_back(sphereGrid("spheres1M", 32, 32));
    if (want("bunny")) {
        BenchScene b;
        if (bunnyScene(b)) scenes.push_back(std::move(b));
    }
    if (!only.empty() && want("demo")) scenes.push_back({"demo", assets::makeDemoScene(), 0});
    for (const std::string& file : meshFiles) {
        BenchScene b;
        if (!fileScene(file, b)) return 1;
        scenes.push_back(std::move(b));
    }

    std::printf("# raster vs minimal GL and gl backend (llvmpipe): %dx%d, %d threads, shading=%s fog=%s, median of %d frames\n", w, h, threads,
                shading.c_str(), fog.c_str(), frames);
    if (glOnly && !glBackend) {
        std::fprintf(stderr, "bench: --gl-only without a GL backend: %s\n", err.c_str());
        return 1;
    }
    if (!glOnly && oursOnly == 0) {
        const double bw1 = copyBandwidth(1), bwN = copyBandwidth(threads);
        std::printf("bench: scene=all what=floor_bw ours=%.2f ref=%.2f ratio=%.3f\n", bw1, bwN, bwN / bw1);
        const auto [cpu1, cpuN] = computeScaling(threads);
        std::printf("bench: scene=all what=floor_cpu ours=%.2f ref=%.2f ratio=%.3f\n", cpu1, cpuN, threads * cpu1 / cpuN);
        // Image-based light: building the environment (resample, SH, GGX prefilter) from a
        // 2048x1024 equirectangular image on --threads, against the 1 s goal.
        {
            const std::vector<float> img = rnd::defaultEnvironmentImage(2048, 1024);
            std::vector<double> ms;
            for (int i = 0; i < 3; ++i) {
                auto t0 = std::chrono::steady_clock::now();
                rnd::EnvironmentMap map("bench", 2048, 1024, img.data());
                ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            }
            std::printf("bench: scene=all what=prefilter_ms ours=%.2f ref=1000 ratio=%.3f\n", median(ms), median(ms) / 1000.0);
        }
    }
    for (BenchScene& b : scenes) {
        parse(shading, b.scene.settings.shading);
        b.scene.settings.culling = culling;
        b.scene.settings.fog = fog == "on" ? FogMode::Linear : FogMode::Off;
        b.scene.settings.fogStart = 2.0f;
        b.scene.settings.fogEnd = 60.0f;
        b.scene.settings.shadows = false;
        FrameInput f = flatten(b.scene, float(w) / h);
        const char* sceneName = b.name.c_str();
        if (oursOnly > 0) {   // a profiler's run: only our frames (one cold, then warm ones)
            rnd::Framebuffer fb;
            for (int i = 0; i <= oursOnly; ++i) ours->render(f, w, h, fb);
            continue;
        }
        // Shadows: the scene lit by one sun (the first light's radiance) with and without them.
        auto shadowRow = [&] {
            FrameInput off = f;
            sg::DrawLight sun;
            sun.type = LightType::Directional;
            sun.direction = glm::normalize(vec3(-0.4f, -1.0f, -0.3f));
            sun.radiance = f.lights.empty() ? vec3(1.0f) : f.lights.front().radiance;
            off.lights = {sun};
            FrameInput on = off;
            on.settings.shadows = true;
            on.settings.shadowMapSize = 2048;
            on.settings.shadowFilter = sg::ShadowFilter::Pcf;
            on.settings.shadowPcfSize = 3;
            rnd::Framebuffer fbS;
            std::string es;
            const Timing tOff = timeRenderer(*ours, off, w, h, frames, fbS, es), tOn = timeRenderer(*ours, on, w, h, frames, fbS, es);
            if (!es.empty()) std::fprintf(stderr, "bench: raster shadows failed on %s: %s\n", sceneName, es.c_str());
            std::printf("bench: scene=%s what=shadow_ms ours=%.2f ref=%.2f ratio=%.3f\n", sceneName, tOn.wallMs, tOff.wallMs,
                        tOn.wallMs / tOff.wallMs);
            std::fflush(stdout);
        };
        if (b.name == "demo") {   // analytic shapes: the minimal GL program does not draw them
            if (!glOnly) shadowRow();
            continue;
        }
        rnd::Framebuffer fbO, fbG;
        std::string eo, eg;
        Timing r, rf;
        std::vector<uint8_t> rgba, rgbaFair;   // the minimal GL programs' images, rows bottom to top
        // Fraction of pixels whose channels all lie within 8 of a minimal GL image's.
        auto closeToMinimal = [&](const rnd::Framebuffer& fb, const std::vector<uint8_t>* image = nullptr) {
            const std::vector<uint8_t>& rgba_ = image ? *image : rgba;
            size_t close = 0;
            if (rgba_.size() == fb.color.size())
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) {
                        const uint8_t* a = fb.pixel(x, h - 1 - y);
                        const uint8_t* c = &rgba_[(size_t(y) * w + x) * 4];
                        close += std::abs(a[0] - c[0]) <= 8 && std::abs(a[1] - c[1]) <= 8 && std::abs(a[2] - c[2]) <= 8;
                    }
            return 100.0 * double(close) / (double(w) * h);
        };
        const char* n = b.name.c_str();
        if (glOnly) {
            // Our GL backend, then the minimal GL program (each owns its context); the ratio
            // of the two medians, taken seconds apart, is the figure to compare.
            Timing g = glSide == "minimal" ? Timing{} : timeRenderer(*glBackend, f, w, h, frames, fbG, eg);
            if (glSide == "ours") continue;
            bench::MinimalGl mgl;
            if (std::string em = mgl.setup(f, w, h); !em.empty()) {
                std::fprintf(stderr, "bench: minimal GL failed on %s: %s\n", n, em.c_str());
                continue;
            }
            r = timeFrames(
                [&] {
                    mgl.render(rgba);
                    return true;
                },
                frames);
            if (!eg.empty()) std::fprintf(stderr, "bench: gl failed on %s: %s\n", n, eg.c_str());
            std::printf("bench: scene=%s what=gl_ms ours=%.2f ref=%.2f ratio=%.3f\n", n, g.wallMs, r.wallMs, g.wallMs / r.wallMs);
            std::printf("bench: scene=%s what=gl_cpu_ms ours=%.2f ref=%.2f ratio=%.3f\n", n, g.cpuMs, r.cpuMs, g.cpuMs / r.cpuMs);
            std::printf("# %s: %zu triangles, %.2f%% of our GL backend's pixels within 8 of the minimal GL image\n", n, b.triangles,
                        closeToMinimal(fbG));
            std::fflush(stdout);
            continue;
        }
        // Cold: the first frame of a new renderer (no caches, buffers sized on the way).
        double cold = NAN;
        rnd::Framebuffer fbCold;
        {
            auto fresh = rnd::makeRenderer("raster", &err);
            auto t0 = std::chrono::steady_clock::now();
            rnd::Framebuffer& fb = fbCold;
            if (fresh && fresh->render(f, w, h, fb).ok)
                cold = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        }
        double coldReused = NAN;
        {
            auto fresh = rnd::makeRenderer("raster", &err);
            auto t0 = std::chrono::steady_clock::now();
            if (fresh && fresh->render(f, w, h, fbCold).ok)
                coldReused = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        }
        // The minimal GL programs (both submissions), each in its own context.
        bench::MinimalGl mgl, fair;
        std::string em = noGl ? "skipped (--no-gl)" : mgl.setup(f, w, h);
        if (em.empty()) em = fair.setup(f, w, h, bench::MinimalGl::Order::Fair);
        const bool minimal = em.empty();
        std::string fairInfo;
        if (minimal) {
            char buf[160];
            std::snprintf(buf, sizeof buf, "minimal GL: %zu vertices unindexed, fair %zu vertices indexed in %zu draw(s)", mgl.vertices(),
                          fair.vertices(), fair.draws());
            fairInfo = buf;
        } else if (!noGl) {
            std::fprintf(stderr, "bench: minimal GL failed on %s: %s\n", b.name.c_str(), em.c_str());
        }
        // Rounds after a warm-up frame of each: ours on --threads, ours on 1 thread (when
        // --threads > 1), the minimal program in the scene's order, the fair one; so that the
        // machine's drift falls on all of them alike.
        Timing o, o1;
        {
            std::vector<double> tN, cN, t1, tS, cS, tF, cF;
            auto timed = [&](const std::function<void()>& fn, std::vector<double>& t, std::vector<double>* cpu) {
                auto t0 = std::chrono::steady_clock::now();
                const double c0 = cpuMs();
                fn();
                if (cpu) cpu->push_back(cpuMs() - c0);
                t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            };
            auto ourFrame = [&] {
                rnd::RenderStats st = ours->render(f, w, h, fbO);
                if (!st.ok) eo = st.error;
            };
            ourFrame();
            if (minimal) {
                mgl.render(rgba);
                fair.render(rgbaFair);
            }
            for (int i = 0; i < frames; ++i) {
                timed(ourFrame, tN, &cN);
                if (threads > 1) {
                    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
                    timed(ourFrame, t1, nullptr);
                }
                if (!minimal) continue;
                mgl.activate();   // the context switch outside the timed frame
                timed([&] { mgl.render(rgba); }, tS, &cS);
                fair.activate();
                timed([&] { fair.render(rgbaFair); }, tF, &cF);
            }
            o = {median(tN), median(cN)};
            o1 = {median(t1), NAN};
            if (minimal) {
                r = {median(tS), median(cS)};
                rf = {median(tF), median(cF)};
            }
        }
        Timing g = glBackend ? timeRenderer(*glBackend, f, w, h, frames, fbG, eg) : Timing{};
        if (!eo.empty()) std::fprintf(stderr, "bench: raster failed on %s: %s\n", b.name.c_str(), eo.c_str());
        if (!eg.empty()) std::fprintf(stderr, "bench: gl failed on %s: %s\n", b.name.c_str(), eg.c_str());
        const double to = o.wallMs, tr = r.wallMs, cov = coveredPixels(fbO);
        std::printf("bench: scene=%s what=ms_fair ours=%.2f ref=%.2f ratio=%.3f\n", n, to, rf.wallMs, to / rf.wallMs);
        std::printf("bench: scene=%s what=ms ours=%.2f ref=%.2f ratio=%.3f\n", n, to, tr, to / tr);
        std::printf("bench: scene=%s what=ms_best ours=%.2f ref=%.2f ratio=%.3f\n", n, to, std::min(tr, rf.wallMs), to / std::min(tr, rf.wallMs));
        std::printf("bench: scene=%s what=ref_fair ours=%.2f ref=%.2f ratio=%.3f\n", n, tr, rf.wallMs, tr / rf.wallMs);
        std::printf("bench: scene=%s what=ms_gl ours=%.2f ref=%.2f ratio=%.3f\n", n, to, g.wallMs, to / g.wallMs);
        std::printf("bench: scene=%s what=cpu_ms ours=%.2f ref=%.2f ratio=%.3f\n", n, o.cpuMs, r.cpuMs, o.cpuMs / r.cpuMs);
        std::printf("bench: scene=%s what=cpu_ms_fair ours=%.2f ref=%.2f ratio=%.3f\n", n, o.cpuMs, rf.cpuMs, o.cpuMs / rf.cpuMs);
        std::printf("bench: scene=%s what=mpix_s ours=%.1f ref=%.1f ratio=%.3f\n", n, cov / (to * 1e3), cov / (tr * 1e3), tr / to);
        std::printf("bench: scene=%s what=mpix_s_thread ours=%.1f ref=%.1f ratio=%.3f\n", n, cov / (to * 1e3) / threads, cov / (tr * 1e3) / threads,
                    tr / to);
        if (threads > 1) std::printf("bench: scene=%s what=scaling ours=%.2f ref=%.2f ratio=%.3f\n", n, o1.wallMs, to, o1.wallMs / to);
        const double shadeMs = shadeOnlyMs(f, size_t(cov));
        std::printf("bench: scene=%s what=floor_shade ours=%.2f ref=%.2f ratio=%.3f\n", n, shadeMs, to, shadeMs / to);
        if (threads > 1) {
            const double shade1 = shadeOnlyMs(f, size_t(cov), 1), shadeN = shadeOnlyMs(f, size_t(cov), threads);
            std::printf("bench: scene=%s what=floor_shade_scaling ours=%.2f ref=%.2f ratio=%.3f\n", n, shade1, shadeN, shade1 / shadeN);
        }
        std::printf("bench: scene=%s what=cold_ms ours=%.2f ref=%.2f ratio=%.3f\n", n, cold, to, cold / to);
        std::printf("bench: scene=%s what=cold_reused_ms ours=%.2f ref=%.2f ratio=%.3f\n", n, coldReused, to, coldReused / to);
        {
            // The pbr model lit by the default environment (image-based light) vs the same frame in Phong.
            FrameInput fp = f;
            fp.settings.reflection = ReflectionModel::Pbr;
            fp.settings.environment = "default";
            rnd::Framebuffer fbP;
            std::string ep;
            const Timing p = timeRenderer(*ours, fp, w, h, frames, fbP, ep);
            if (!ep.empty()) std::fprintf(stderr, "bench: raster pbr failed on %s: %s\n", n, ep.c_str());
            std::printf("bench: scene=%s what=pbr_ms ours=%.2f ref=%.2f ratio=%.3f\n", n, p.wallMs, to, p.wallMs / to);
        }
        shadowRow();
        std::printf(
            "# %s: %zu triangles, %.0f covered pixels, %.2f%% of pixels within 8 of the minimal GL image (%.2f%% of the fair one's), warm "
            "frame %s the first; %s\n",
            n, b.triangles, cov, closeToMinimal(fbO), closeToMinimal(fbO, &rgbaFair), fbCold.color == fbO.color ? "identical to" : "DIFFERS from",
            fairInfo.c_str());
        std::fflush(stdout);
    }
    return 0;
}
