// scenegraph_bench.cpp - world-matrix update and flatten() cost for 10k / 100k / 1M nodes.
//   build/release/bench/scenegraph/bench_scenegraph [--benchmark_filter=...]
// Trees: "random" = each node under a uniformly random earlier node (random recursive tree:
// random branching, depth ~ ln n), "chain" = one node under the previous (depth n).
// Cases: full update after touching the root, update after editing one leaf, flatten().
// The per_node counter is time per node of the scene ("3.2n" = 3.2 ns): wall time for the
// full updates, CPU time otherwise.
#include "scenegraph/frame.h"

#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <random>

namespace {

using namespace sg;

struct BenchScene {
    Scene scene;
    NodeId leaf = kNoNode;
};

// Builds (once per size and shape) a scene with n nodes besides the root; every 8th node
// carries a mesh instance, and there is one camera and one light, so flatten() has work.
BenchScene& benchScene(size_t n, bool chain) {
    static std::map<std::pair<size_t, bool>, std::unique_ptr<BenchScene>> cache;
    auto& slot = cache[{n, chain}];
    if (slot) return *slot;
    slot = std::make_unique<BenchScene>();
    Scene& s = slot->scene;
    s.meshes.push_back(std::make_shared<Mesh>(primitives::box(vec3(0.5f))));
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<NodeId> ids{s.root()};
    ids.reserve(n + 1);
    for (size_t i = 0; i < n; ++i) {
        NodeId parent = chain ? ids.back() : ids[rng() % ids.size()];
        Payload p;
        if (i % 8 == 0) p = MeshInstance{0, -1};
        NodeId id = s.addNode({}, parent, std::move(p));
        LocalTransform lt = LocalTransform::fromTRS(vec3(u(rng), u(rng), u(rng)) * (chain ? 1e-3f : 1.0f), quat(1, 0, 0, 0), vec3(1.0f));
        lt.setEulerDegrees(vec3(10 * u(rng), 10 * u(rng), 10 * u(rng)));
        s.setLocal(id, lt);
        ids.push_back(id);
    }
    NodeId cam = s.addNode("camera", s.root(), Camera{});
    s.lookAt(cam, vec3(0, 0, 20), vec3(0));
    s.activeCamera = cam;
    s.addNode("light", s.root(), Light{});
    // A leaf: the last node added has no children.
    slot->leaf = ids.back();
    s.updateWorld();
    return *slot;
}

void setPerNode(benchmark::State& st, size_t nodes) {
    // Seconds per node: printed as e.g. "3.2n" = 3.2 ns per node.
    st.counters["per_node"] = benchmark::Counter(double(nodes) * double(st.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    st.counters["nodes"] = double(nodes);
}

void BM_FullUpdate(benchmark::State& st, bool chain) {
    BenchScene& b = benchScene(size_t(st.range(0)), chain);
    Scene& s = b.scene;
    LocalTransform rootLocal = s.node(s.root()).local;
    size_t updated = 0;
    for (auto _ : st) {
        rootLocal.translation.x += 1e-6f;
        s.setLocal(s.root(), rootLocal);   // dirties everything
        updated = s.updateWorld();
        benchmark::DoNotOptimize(updated);
    }
    setPerNode(st, updated);
}

void BM_LeafUpdate(benchmark::State& st, bool chain) {
    BenchScene& b = benchScene(size_t(st.range(0)), chain);
    Scene& s = b.scene;
    LocalTransform lt = s.node(b.leaf).local;
    size_t updated = 0;
    for (auto _ : st) {
        lt.translation.x += 1e-6f;
        s.setLocal(b.leaf, lt);
        updated = s.updateWorld();
        benchmark::DoNotOptimize(updated);
    }
    st.counters["updated"] = double(updated);
}

void BM_Flatten(benchmark::State& st, bool chain) {
    BenchScene& b = benchScene(size_t(st.range(0)), chain);
    size_t draws = 0;
    for (auto _ : st) {
        FrameInput f = flatten(b.scene, 16.0f / 9.0f);
        draws = f.meshes.size();
        benchmark::DoNotOptimize(f);
    }
    setPerNode(st, b.scene.nodeCount());
    st.counters["draws"] = double(draws);
}

// Full updates of >= 32k nodes run on several threads: "Time" is wall time, "CPU" the whole
// process's CPU time (all threads), per_node uses wall time.
BENCHMARK_CAPTURE(BM_FullUpdate, random, false)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK_CAPTURE(BM_FullUpdate, chain, true)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK_CAPTURE(BM_LeafUpdate, random, false)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kNanosecond);
BENCHMARK_CAPTURE(BM_LeafUpdate, chain, true)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kNanosecond);
BENCHMARK_CAPTURE(BM_Flatten, random, false)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

}   // namespace

BENCHMARK_MAIN();
