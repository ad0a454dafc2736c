// raycast_frame_bench.cpp - our ray caster's whole frame (the "raycast" backend through
// rnd::Renderer::render, shadows on) against the minimal Embree renderer of min_embree.h on the
// same scene, camera, size and thread count: what a user waits for, against what Embree alone
// makes of the same image.
//
//   cmake --build build/release -j2 --target bench_raycast_frame
//   ./build/release/bench/raycast/bench_raycast_frame [--threads 2] [--frames 7] [--size 1280x720]
//        [--scenes demo,bunny,igea,mesh1M] [--png DIR] [--testdata DIR] [--ours-only N] [--avx2-only]
//        [--nearest-textures]
//
// --nearest-textures: min_embree samples colour textures at level 0, nearest texel (the
// reference as first written), not filtered with the pixel's footprint as ours (the default).
// --ours-only N: only N warm frames of ours per scene, nothing printed (for profilers:
// perf record -g bench_raycast_frame --scenes bunny --ours-only 20).
// Prints one line per scene and metric:
//   bench: scene=<name> what=<metric> ours=<x> ref=<y> ratio=<ours/ref>
// metrics (wall ms per frame, medians; the goal: frame_ms ratio <= 1.0):
//   frame_ms                 warm frames (our BVHs kept between frames, Embree's scene built
//                            once): ours against the faster of min_embree on Embree's default ISA
//                            and on "isa=avx2", frame by frame (ratio: the median of the rounds')
//   frame_ms_vs_default_isa  the same against the default ISA alone
//   frame_ms_vs_avx2         against isa=avx2 alone
//   frame_ms_vs_instanced    against min_embree with two levels as ours (each mesh once in its
//                            own space, each draw an Embree instance; default ISA): not the
//                            goal's reference, what instancing costs Embree itself
//   cold_ms                  the first frame of a new renderer (ours: its BVH builds included)
//                            against min_embree's setup (world-space copy, tessellation, Embree
//                            build) plus its first frame, default ISA
// Rounds alternate: one frame of ours, one of each min_embree, --frames times after a warm-up
// frame each, so that the machine's drift falls on all three. A "#" line per scene gives the
// image agreement (mean absolute difference per channel, % of pixels within 8 of ours); --png
// DIR writes both images (DIR/<scene>_ours.png, DIR/<scene>_min_embree.png).
// Scenes: demo (the bundled demo: analytic shapes, which min_embree draws as the rasterizers'
// tessellation; textured floor and crates), demo_tessellated (by name only: the demo with its
// analytic shapes given to both renderers as those triangles, so that what is left between them
// is the triangle scene's work), bunny and igea (mesh
// files from the test data on a ground plane with a point light, framed like bench_raster's
// bunny), mesh1M (bench_raster's mesh1M: 22 x 22 uv-spheres and a ground plane merged into one
// mesh, 988k triangles); and by name only: spheres1M (bench_raster's: 32 x 32 instances of one
// 1k-triangle sphere) and tiny (48 x 48 instances of a 36-triangle sphere: many small instances
// under each packet). TBB is limited to --threads, Embree's devices get threads=N.
// A min_embree call that has not returned after 120 s ends the run with a message (exit code 3):
// Embree 3.13's AVX-512 packet kernels never return from some rtcOccluded16 calls on AMD Zen 5;
// --avx2-only then runs min_embree on isa=avx2 alone (frame_ms_vs_default_isa is not printed).
#include "assets/demo.h"
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "bench_scenes.h"
#include "min_embree.h"
#include "renderers/draw_list.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"
#include "scenegraph/scene.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#ifndef VIEWER_TESTDATA_DIR
#define VIEWER_TESTDATA_DIR "../shared/testdata"
#endif

using namespace sg;

namespace {

using bench::BenchScene;
using bench::fileScene;
using bench::singleMesh;

double median(std::vector<double> v) {
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

double timeMs(const std::function<void()>& fn) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void line(const std::string& scene, const char* what, double ours, double ref, double ratio) {
    std::printf("bench: scene=%s what=%s ours=%.2f ref=%.2f ratio=%.3f\n", scene.c_str(), what, ours, ref, ratio);
}

// Ends the process with a message when a guarded call has run longer than its limit: a library
// call that never returns cannot be stopped from inside, and a benchmark that hangs says nothing.
class Watchdog {
public:
    Watchdog()
        : m_thread([this] {
              while (!m_stop) {
                  std::this_thread::sleep_for(std::chrono::milliseconds(200));
                  const int64_t due = m_due;
                  if (due != 0 && now() > due) {
                      std::fflush(stdout);
                      std::fprintf(stderr,
                                   "bench: %s did not return within %d s; on a CPU where Embree's default ISA hangs, rerun with --avx2-only\n",
                                   m_what.load(), m_limitS.load());
                      std::_Exit(3);
                  }
              }
          }) {}
    ~Watchdog() {
        m_stop = true;
        m_thread.join();
    }
    // fn(), ended by the watchdog after `limitS` seconds; `what` names it in the message.
    void guard(const char* what, int limitS, const std::function<void()>& fn) {
        m_what = what;
        m_limitS = limitS;
        m_due = now() + int64_t(limitS) * 1000;
        fn();
        m_due = 0;
    }

private:
    static int64_t now() {
        return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
    }
    std::atomic<bool> m_stop{false};
    std::atomic<int64_t> m_due{0};
    std::atomic<const char*> m_what{""};
    std::atomic<int> m_limitS{0};
    std::thread m_thread;
};

// f with its analytic shapes replaced by their tessellation at the frame's level (the triangles
// min_embree draws for them), as meshes in world space: a shape whose faces take several
// materials (CSG) becomes one mesh per material. The same triangles on both sides, so what is
// left between the two renderers is the triangle scene's work (demo_tessellated).
FrameInput tessellated(const FrameInput& f) {
    FrameInput t = f;
    t.analytics.clear();
    rnd::TessellationCache cache;
    for (const rnd::PreparedDraw& d : rnd::prepareDraws(f, f.settings.tessellation, cache)) {
        if (!d.analytic) continue;
        DrawMesh dm;
        dm.node = d.node;
        dm.texture = d.texture;
        dm.maps = d.maps;
        dm.world = *d.world;
        dm.normal = d.normal;
        dm.mirrored = d.mirrored;
        if (!d.triangleMaterial) {
            dm.mesh = d.mesh;
            dm.material = *d.material;
            t.meshes.push_back(dm);
            continue;
        }
        for (size_t m = 0; m < d.materials->size(); ++m) {
            auto part = std::make_shared<Mesh>(*d.mesh);
            part->id = newResourceId();
            part->indices.clear();
            for (size_t tri = 0; tri < d.triangleMaterial->size(); ++tri)
                if ((*d.triangleMaterial)[tri] == m)
                    part->indices.insert(part->indices.end(), &d.mesh->indices[3 * tri], &d.mesh->indices[3 * tri + 3]);
            if (part->indices.empty()) continue;
            dm.mesh = part;
            dm.material = (*d.materials)[m];
            t.meshes.push_back(dm);
        }
    }
    return t;
}

}   // namespace

int main(int argc, char** argv) {
    int threads = 2, frames = 7, w = 1280, h = 720, oursOnly = 0;
    bool avx2Only = false, nearestTextures = false;
    std::string only = "demo,bunny,igea,mesh1M", pngDir, testdata = VIEWER_TESTDATA_DIR;
    if (const char* env = std::getenv("VIEWER_TESTDATA")) testdata = env;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
        if (a == "--threads")
            threads = std::max(1, std::atoi(next().c_str()));
        else if (a == "--frames")
            frames = std::max(1, std::atoi(next().c_str()));
        else if (a == "--size")
            std::sscanf(next().c_str(), "%dx%d", &w, &h);
        else if (a == "--scenes")
            only = next();
        else if (a == "--png")
            pngDir = next();
        else if (a == "--testdata")
            testdata = next();
        else if (a == "--ours-only")
            oursOnly = std::max(1, std::atoi(next().c_str()));
        else if (a == "--avx2-only")
            avx2Only = true;
        else if (a == "--nearest-textures")
            nearestTextures = true;
        else {
            std::fprintf(stderr,
                         "usage: %s [--threads N] [--frames N] [--size WxH] [--scenes demo,bunny,igea,mesh1M] [--png DIR] [--testdata DIR] "
                         "[--ours-only N] [--avx2-only] [--nearest-textures]\n",
                         argv[0]);
            return 2;
        }
    }
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const std::string threadsCfg = "threads=" + std::to_string(threads);
    auto want = [&](const std::string& n) { return ("," + only + ",").find("," + n + ",") != std::string::npos; };
    std::vector<BenchScene> scenes;
    if (want("demo")) scenes.push_back({"demo", assets::makeDemoScene()});
    if (want("demo_tessellated")) scenes.push_back({"demo_tessellated", assets::makeDemoScene()});
    const std::string models = testdata + "/meshes/common-3d-test-models/";
    BenchScene b;
    if (want("bunny") && fileScene(models + "stanford-bunny/stanford-bunny.obj", b, "bunny")) scenes.push_back(std::move(b));
    if (want("igea") && fileScene(models + "igea/igea.ply", b, "igea")) scenes.push_back(std::move(b));
    if (want("mesh1M")) scenes.push_back(singleMesh("mesh1M", 22, 46, 64));
    if (want("spheres1M")) scenes.push_back(bench::sphereGrid("spheres1M", 32, 32));   // 1024 instances of 1k triangles
    if (want("tiny")) scenes.push_back(bench::sphereGrid("tiny", 48, 6));              // 2304 instances of 36 triangles

    std::printf("# raycast frame vs min_embree (Embree 3, 4x4 packets): %dx%d, %d threads, shadows on, median of %d rounds\n", w, h, threads, frames);
    if (avx2Only) std::printf("# --avx2-only: min_embree on isa=avx2 alone (Embree's default ISA left out)\n");
    // The reference's devices: Embree's default ISA (isa=avx2 with --avx2-only) and isa=avx2.
    const std::string defaultCfg = avx2Only ? threadsCfg + ",isa=avx2" : threadsCfg;
    const char* defaultName = avx2Only ? "min_embree (isa=avx2)" : "min_embree on Embree's default ISA";
    constexpr int kLimitS = 120;        // per min_embree call: a cold 1M-triangle frame takes a few seconds
    std::optional<Watchdog> watchdog;   // (not with --ours-only: no min_embree call to watch)
    if (oursOnly == 0) watchdog.emplace();
    for (BenchScene& sc : scenes) {
        sc.scene.settings.shadows = true;
        const FrameInput f =
            sc.name == "demo_tessellated" ? tessellated(flatten(sc.scene, float(w) / float(h))) : flatten(sc.scene, float(w) / float(h));
        const char* n = sc.name.c_str();
        std::string err;
        // Cold: a new renderer's first frame against min_embree's setup and first frame.
        rnd::Framebuffer fb;
        std::vector<uint8_t> img, imgA;
        auto ours = rnd::makeRenderer("raycast", &err);
        if (!ours) {
            std::fprintf(stderr, "bench: %s\n", err.c_str());
            return 1;
        }
        if (oursOnly > 0) {
            for (int i = 0; i <= oursOnly; ++i) ours->render(f, w, h, fb);
            continue;
        }
        bool ok = true;
        const double coldOurs = timeMs([&] { ok = ours->render(f, w, h, fb).ok; });
        bench::MinimalEmbree ref, refA;
        const double coldRef = timeMs([&] {
            watchdog->guard(defaultName, kLimitS, [&] {
                err = ref.setup(f, f.settings.tessellation, defaultCfg, false, nearestTextures);
                if (err.empty()) ref.render(f, w, h, img);
            });
        });
        if (!err.empty() || !ok || !(err = refA.setup(f, f.settings.tessellation, threadsCfg + ",isa=avx2", false, nearestTextures)).empty()) {
            std::fprintf(stderr, "bench: scene %s failed: %s\n", n, ok ? err.c_str() : "our render failed");
            return 1;
        }
        watchdog->guard("min_embree (isa=avx2)", kLimitS, [&] { refA.render(f, w, h, imgA); });
        // Two levels, as ours (the default ISA; isa=avx2 with --avx2-only): not the reference, what instancing costs Embree.
        bench::MinimalEmbree refI;
        std::vector<uint8_t> imgI;
        if (!(err = refI.setup(f, f.settings.tessellation, defaultCfg, true, nearestTextures)).empty()) {
            std::fprintf(stderr, "bench: scene %s failed (instanced): %s\n", n, err.c_str());
            return 1;
        }
        watchdog->guard(defaultName, kLimitS, [&] { refI.render(f, w, h, imgI); });
        // Warm frames, in rounds.
        std::vector<double> to, td, ta, ti, q, qd, qa, qi;
        for (int i = 0; i < frames; ++i) {
            to.push_back(timeMs([&] { ours->render(f, w, h, fb); }));
            watchdog->guard(defaultName, kLimitS, [&] { td.push_back(timeMs([&] { ref.render(f, w, h, img); })); });
            watchdog->guard("min_embree (isa=avx2)", kLimitS, [&] { ta.push_back(timeMs([&] { refA.render(f, w, h, imgA); })); });
            watchdog->guard(defaultName, kLimitS, [&] { ti.push_back(timeMs([&] { refI.render(f, w, h, imgI); })); });
            q.push_back(to.back() / std::min(td.back(), ta.back()));
            qd.push_back(to.back() / td.back());
            qa.push_back(to.back() / ta.back());
            qi.push_back(to.back() / ti.back());
        }
        std::vector<double> best(td.size());
        for (size_t i = 0; i < td.size(); ++i) best[i] = std::min(td[i], ta[i]);
        line(sc.name, "frame_ms", median(to), median(best), median(q));
        if (!avx2Only) line(sc.name, "frame_ms_vs_default_isa", median(to), median(td), median(qd));
        line(sc.name, "frame_ms_vs_avx2", median(to), median(ta), median(qa));
        line(sc.name, "frame_ms_vs_instanced", median(to), median(ti), median(qi));
        line(sc.name, "cold_ms", coldOurs, coldRef, coldOurs / coldRef);
        // Image agreement.
        double sum = 0;
        size_t close = 0;
        for (size_t p = 0; p + 3 < img.size() && img.size() == fb.color.size(); p += 4) {
            int worst = 0;
            for (int k = 0; k < 3; ++k) {
                const int d = std::abs(int(img[p + k]) - int(fb.color[p + k]));
                sum += d;
                worst = std::max(worst, d);
            }
            close += worst <= 8;
        }
        const double px = double(w) * h;
        std::printf(
            "# %s: %zu triangles in min_embree (ours: %zu + analytic shapes), mean |ours - min_embree| %.2f / 255 per channel, %.2f%% of pixels "
            "within 8%s\n",
            n, ref.triangles(), f.triangleCount(), sum / (3.0 * px), 100.0 * double(close) / px, img == imgA ? "" : " (the two ISAs' images differ)");
        double sumI = 0;
        for (size_t p = 0; p < img.size() && img.size() == imgI.size(); ++p)
            if (p % 4 != 3) sumI += std::abs(int(img[p]) - int(imgI[p]));
        std::printf("# %s: min_embree instanced against flat: mean difference %.3f / 255 per channel\n", n, sumI / (3.0 * px));
        if (!pngDir.empty()) {
            const std::string e1 = assets::writePng(pngDir + "/" + sc.name + "_ours.png", w, h, fb.color.data(), true);
            const std::string e2 = assets::writePng(pngDir + "/" + sc.name + "_min_embree.png", w, h, img.data(), true);
            if (!e1.empty() || !e2.empty()) std::fprintf(stderr, "bench: png: %s %s\n", e1.c_str(), e2.c_str());
        }
        std::fflush(stdout);
    }
    return 0;
}
