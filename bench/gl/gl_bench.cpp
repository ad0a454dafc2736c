// gl_bench.cpp - frame times of the GL backend (headless EGL, Mesa llvmpipe here):
//   BM_GlDemo/aa         the demo scene at 1280x720, warm caches (steady state of the viewer)
//   BM_GlDemoFirstFrame  a new renderer per frame: context, shader compile, uploads, tessellation
//   BM_GlEmpty           clear + resolve + read-back only (the fixed cost of a frame)
//   BM_GlSpheres/tris    a grid of spheres with ~10k / 100k / 1M triangles, Phong + fog
// Run: build/release/bench/gl/bench_gl --benchmark_min_time=2
#include "assets/demo.h"
#include "gl/gl_renderer.h"

#include <benchmark/benchmark.h>

#include <cmath>

namespace {

constexpr int kW = 1280, kH = 720;

sg::FrameInput demoFrame(const char* aa) {
    sg::Scene s = assets::makeDemoScene();
    s.settings.setAA(aa);
    return sg::flatten(s, float(kW) / kH);
}

void renderLoop(benchmark::State& state, const sg::FrameInput& f) {
    auto r = rnd::makeGlRenderer();
    rnd::Framebuffer fb;
    auto st = r->render(f, kW, kH, fb);   // warm up: context, shaders, uploads
    if (!st.ok) {
        state.SkipWithError(st.error.c_str());
        return;
    }
    double ms = 0;
    for (auto _ : state) {
        st = r->render(f, kW, kH, fb);
        ms += st.milliseconds;
        benchmark::DoNotOptimize(fb.color.data());
    }
    state.counters["ms/frame"] = ms / double(state.iterations());
    state.counters["triangles"] = double(st.triangles);
}

void BM_GlDemo(benchmark::State& state) {
    const char* names[] = {"none", "msaa4", "ssaa2"};
    state.SetLabel(names[state.range(0)]);
    renderLoop(state, demoFrame(names[state.range(0)]));
}
BENCHMARK(BM_GlDemo)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_GlDemoFirstFrame(benchmark::State& state) {
    sg::FrameInput f = demoFrame("none");
    for (auto _ : state) {
        auto r = rnd::makeGlRenderer();
        rnd::Framebuffer fb;
        auto st = r->render(f, kW, kH, fb);
        if (!st.ok) state.SkipWithError(st.error.c_str());
    }
}
BENCHMARK(BM_GlDemoFirstFrame)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

void BM_GlEmpty(benchmark::State& state) {
    sg::FrameInput f = demoFrame("none");
    f.meshes.clear();
    f.analytics.clear();
    renderLoop(state, f);
}
BENCHMARK(BM_GlEmpty)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_GlSpheres(benchmark::State& state) {
    // n x n spheres of 2*s*(s/2) triangles filling the view.
    const int64_t target = state.range(0);
    int n = 10, slices = int(std::sqrt(double(target) / (n * n)));
    sg::Scene s;
    s.settings.fog = sg::FogMode::Linear;
    s.meshes.push_back(std::make_shared<sg::Mesh>(sg::primitives::uvSphere(0.45f, slices, slices / 2)));
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            sg::NodeId id = s.addNode("s", s.root(), sg::MeshInstance{0, -1});
            s.setLocal(id, sg::LocalTransform::fromTRS(sg::vec3(i - n / 2 + 0.5f, j - n / 2 + 0.5f, 0)));
        }
    s.addNode("light", s.root(), sg::Light{sg::LightType::Directional, sg::vec3(1.0f), 1.0f, false});
    s.addDefaultCamera();
    renderLoop(state, sg::flatten(s, float(kW) / kH));
}
BENCHMARK(BM_GlSpheres)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();

// BM_GlLayers/n/l: n full-screen quads (sorted front to back by the renderer, so the early
// depth test rejects all but the first), Phong with l lights (directional, point, spot, ...):
// the per-layer and per-light fragment cost.
void BM_GlLayers(benchmark::State& state) {
    sg::Scene s;
    s.meshes.push_back(std::make_shared<sg::Mesh>(sg::primitives::plane(20.0f, 1)));
    for (int i = 0; i < state.range(0); ++i) {
        sg::NodeId id = s.addNode("layer", s.root(), sg::MeshInstance{0, -1});
        s.setLocal(id, sg::LocalTransform::fromTRS(sg::vec3(0, 0, -5.0f + 0.1f * i), glm::angleAxis(glm::radians(90.0f), sg::vec3(1, 0, 0))));
    }
    sg::LightType types[] = {sg::LightType::Directional, sg::LightType::Point, sg::LightType::Spot};
    for (int i = 0; i < state.range(1); ++i) s.addNode("light", s.root(), sg::Light{types[i % 3], sg::vec3(1.0f), 2.0f, i % 3 == 1});
    sg::Camera cam;
    sg::NodeId c = s.addNode("camera", s.root(), cam);
    s.activeCamera = c;
    renderLoop(state, sg::flatten(s, float(kW) / kH));
}
BENCHMARK(BM_GlLayers)->Args({0, 3})->Args({1, 0})->Args({1, 1})->Args({1, 3})->Args({4, 3})->Unit(benchmark::kMillisecond)->UseRealTime();

}   // namespace

BENCHMARK_MAIN();
