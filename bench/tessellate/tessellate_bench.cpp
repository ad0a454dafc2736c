// tessellate_bench.cpp - time to tessellate the demo scene's analytic drawables (what a
// rasterizer pays on the first frame or after an edit), per drawable and in total.
//   build/release/bench/tessellate/bench_tessellate
#include "renderers/tessellate.h"

#include "assets/demo.h"

#include <benchmark/benchmark.h>

namespace {

const sg::FrameInput& demoFrame() {
    static sg::Scene scene = assets::makeDemoScene();
    static sg::FrameInput f = sg::flatten(scene, 1.0f);
    return f;
}

void BM_DemoSceneTotal(benchmark::State& st) {
    const auto& f = demoFrame();
    size_t tris = 0;
    for (auto _ : st) {
        tris = 0;
        for (const auto& a : f.analytics) tris += rnd::tessellate(a, int(st.range(0))).mesh->triangleCount();
    }
    st.counters["triangles"] = double(tris);
}
BENCHMARK(BM_DemoSceneTotal)->Arg(32)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

void BM_DemoDrawable(benchmark::State& st) {
    const auto& f = demoFrame();
    const auto& a = f.analytics[size_t(st.range(0))];
    size_t tris = 0;
    for (auto _ : st) tris = rnd::tessellate(a, 64).mesh->triangleCount();
    static const char* kinds[] = {"implicit", "csg", "parametric", "grid"};
    st.SetLabel(std::string(kinds[int(a.kind)]) +
                (a.kind == sg::DrawAnalytic::Kind::Implicit ? " " + std::string(sg::toString(a.implicit.type)) : ""));
    st.counters["triangles"] = double(tris);
}
BENCHMARK(BM_DemoDrawable)->DenseRange(0, 8)->Unit(benchmark::kMillisecond);

}   // namespace

BENCHMARK_MAIN();
