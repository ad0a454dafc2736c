// interactive_bench.cpp - what the user waits for in the window after a camera move, per
// backend, on the bundled demo or a scene file, through the viewport's own code: ViewerState
// builds the frame from the orbit camera (sg::flatten, as the window does on every change) and
// a RenderSlot renders it on a worker thread, coarse to fine (GL there in its own headless
// context, as the window runs it where OpenGL is software only).
//
//   ./build/release/bench/interactive/bench_interactive [--size 960x850] [--moves 9]
//       [--backends raycast,raster,gl] [--shadows on|off] [--aa none|ssaa4|...] [--scene FILE]
//
// --scene FILE: that file (any format the viewer opens) framed as the window frames it on open.
//
// Each move is a 25-pixel orbit drag (alternately left and right, so the view stays that of
// the scene's camera give or take 12 degrees) followed by the release, as in the window:
//   coarse_ms: from the drag (frame built, request(interacting)) to the first image shown,
//              the 1/4-resolution preview;
//   full_ms:   from the release (request(not interacting)) to the final full-resolution image
//              (the preview of the view is on screen already and is not rendered again);
//   render_ms: the full image's own render time (RenderStats::milliseconds).
// One warm-up render first (acceleration structures built, textures decoded); then the medians
// over the moves. Prints `bench: scene=<demo or the file's stem> what=<metric> backend=<b> median=<ms> min=.. max=..`.
#include "assets/demo.h"
#include "assets/scene_io.h"
#include "ui/render_slot.h"
#include "ui/viewer_state.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

struct Series {
    std::vector<double> v;
    void print(const std::string& scene, const char* what, const std::string& backend) const {
        std::vector<double> s = v;
        std::sort(s.begin(), s.end());
        if (s.empty()) return;
        std::printf("bench: scene=%s what=%s backend=%s median=%.1f min=%.1f max=%.1f n=%zu\n", scene.c_str(), what, backend.c_str(), s[s.size() / 2],
                    s.front(), s.back(), s.size());
    }
};

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    size_t a = 0;
    while (a <= s.size()) {
        size_t b = s.find(',', a);
        if (b == std::string::npos) b = s.size();
        if (b > a) out.push_back(s.substr(a, b - a));
        a = b + 1;
    }
    return out;
}

}   // namespace

int main(int argc, char** argv) {
    int width = 960, height = 850, moves = 9;
    std::vector<std::string> backends = {"raycast", "raster", "gl"};
    bool shadows = true;
    std::string aa = "none", sceneFile;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "bench_interactive: %s needs a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--size") {
            if (std::sscanf(next().c_str(), "%dx%d", &width, &height) != 2 || width < 16 || height < 16) {
                std::fprintf(stderr, "bench_interactive: --size WIDTHxHEIGHT (at least 16x16)\n");
                return 2;
            }
        } else if (a == "--moves")
            moves = std::max(1, std::atoi(next().c_str()));
        else if (a == "--backends")
            backends = split(next());
        else if (a == "--shadows")
            shadows = next() != "off";
        else if (a == "--aa")
            aa = next();
        else if (a == "--scene")
            sceneFile = next();
        else {
            std::fprintf(stderr,
                         "usage: bench_interactive [--size WxH] [--moves N] [--backends a,b] [--shadows on|off] [--aa MODE] [--scene FILE]\n");
            return 2;
        }
    }
    sg::Scene scene = assets::makeDemoScene();
    std::string sceneName = "demo";
    if (!sceneFile.empty()) {
        assets::LoadResult loaded = assets::loadScene(sceneFile);
        if (!loaded.scene) {
            std::fprintf(stderr, "bench_interactive: %s: %s\n", sceneFile.c_str(), loaded.error.c_str());
            return 1;
        }
        scene = std::move(*loaded.scene);
        sceneName = std::filesystem::path(sceneFile).stem().string();
    }
    std::printf("# %s at %dx%d, %d moves, shadows %s, aa %s\n", sceneName.c_str(), width, height, moves, shadows ? "on" : "off", aa.c_str());
    for (const std::string& backend : backends) {
        ui::ViewerState st;
        st.view.viewportWidth = width;
        st.view.viewportHeight = height;
        st.setScene(scene, {});
        st.doc.scene.settings.shadows = shadows;
        if (!st.doc.scene.settings.setAA(aa)) {
            std::fprintf(stderr, "bench_interactive: unknown --aa %s\n", aa.c_str());
            return 2;
        }
        ui::RenderSlot slot(backend, ui::RenderSlot::Threading::Worker);
        // Publications, seen on the worker thread: the first after a request, and the final one.
        std::mutex mu;
        std::condition_variable cv;
        Clock::time_point t0;
        double firstMs = -1, finalMs = -1, renderMs = 0;
        int firstLevel = 0;
        slot.onPublish = [&](const rnd::Framebuffer&, const ui::SlotStatus& s) {
            std::lock_guard<std::mutex> lock(mu);
            const double ms = msSince(t0);
            if (firstMs < 0) {
                firstMs = ms;
                firstLevel = s.level;
            }
            if (s.level == 1 && !s.refining) {
                finalMs = ms;
                renderMs = s.stats.milliseconds;
            }
            cv.notify_all();
        };
        const float aspect = float(width) / float(height);
        uint64_t key = 1;
        auto run = [&](bool interacting) {
            {
                std::lock_guard<std::mutex> lock(mu);
                t0 = Clock::now();
                firstMs = finalMs = -1;
            }
            auto frame = std::make_shared<sg::FrameInput>(st.buildFrame(aspect));
            slot.request(frame, width, height, key, interacting);
            slot.waitIdle();
            slot.poll();
        };
        run(false);   // warm-up: builds, caches
        if (!slot.status().error.empty()) {
            std::printf("# %s: %s\n", backend.c_str(), slot.status().error.c_str());
            continue;
        }
        Series coarse, full, render;
        int level = 0;
        for (int m = 0; m < moves; ++m) {
            // A drag step, alternately left and right, so every view stays within 12 degrees of
            // the scene's own camera (the demo's full view, not a turned-away one).
            st.view.camera.orbit(m % 2 ? -25.0f : 25.0f, m % 2 ? -4.0f : 4.0f);
            ++key;
            run(true);
            coarse.v.push_back(firstMs);
            level = firstLevel;
            run(false);   // the release: the same view, now in full
            // Nothing published: the image after the drag was full resolution already (a fast
            // backend), so the release has nothing to wait for.
            full.v.push_back(finalMs < 0 ? 0.0 : finalMs);
            render.v.push_back(renderMs);
        }
        std::printf("# %s: the first image after a move is 1/%d resolution\n", backend.c_str(), level);
        coarse.print(sceneName, "coarse_ms", backend);
        full.print(sceneName, "full_ms", backend);
        render.print(sceneName, "render_ms", backend);
    }
    return 0;
}
