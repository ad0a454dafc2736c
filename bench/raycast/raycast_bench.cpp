// raycast_bench.cpp - our BVH4/BVH8 traversal vs Embree 3 on the same scenes and the same rays.
//
//   ./build/release/bench/raycast/bench_raycast            # full run (sphere grids 10k/100k/1M + bunny)
//   ./build/release/bench/raycast/bench_raycast --quick    # < 1 minute: fewer repetitions, 640x360 rays
//   options: --scene NAME (run one scene), --testdata DIR, --rays CLASS (only that ray class's
//   throughput, e.g. for valgrind --tool=callgrind --toggle-collect='*TriangleBvh::intersect*'
//   --toggle-collect=rtcIntersect1), --build-only (only the 1-thread
//   builds, ours and Embree alternating --reps N times, medians; also for profilers, e.g.
//   valgrind --tool=callgrind --toggle-collect='rnd::rt::TriangleBvh::build*'), --pairs N (ours/Embree
//   alternations per ray measure), --leaf-packets N / --trav-cost X (our build options, for
//   trying other trees; default TriangleBvh::defaultOptions()), --tile WxH (pixels per packet
//   in the packet measures, default 4x4, at most 64)
//
// Prints one line per scene and measure:
//   bench: scene=<name> what=<metric> ours=<x> ref=<y> ratio=<ours/ref>
// Metrics: build_1t / build_2t (Mtris/s; ours binned SAH BVH8 (AVX2) or BVH4, Embree RTC_BUILD_QUALITY_MEDIUM),
// primary / shadow / incoherent / incoherent_occluded rays on 1 and 2 threads (Mrays/s; our
// TriangleBvh::intersect / occluded vs rtcIntersect1 / rtcOccluded1, one ray at a time, FTZ/DAZ
// on), and agreement_* (% of rays where both agree: same hit/miss, and for hits the same
// primitive - or the same distance for ties on shared edges - and distance within 1e-4 relative).
// Embree runs on two devices, its default ISA (AVX-512 where the CPU has it) and "isa=avx2" (the
// ISA of our kernels): each ray measure is ours against the faster of the two pass by pass
// (what=<measure>), and against each (<measure>_vs_default_isa, <measure>_vs_avx2).
// Ray throughput: ours and the Embree calls run in turn 3 (--quick) or 5 times per measure;
// ours/ref are the medians, ratio the median of the per-pass ratios (robust to the machine's drift).
// Timing: 1-thread figures (rays and build) use the thread's CPU clock (the machine is shared; wall time would
// count other people's work), 2-thread figures use wall time. Builds: medians of 3 (--quick) or 5
// alternating runs; 1-thread builds run inside a 1-thread TBB arena (see measureBuilds: before
// that, Embree's threads=1 build borrowed idle TBB workers and was timed on one thread while
// using two). BENCH_DEBUG=1 prints each 1-thread build's thread CPU, wall and process CPU time.
// Packet measures (primary_packet_*, shadow_packet_*): the same camera rays ordered by pixel
// tiles (--tile), each tile one TriangleBvh::intersectPacket, against Embree's 16-wide packets
// on the same tiles (rtcIntersect16 with RTC_INTERSECT_CONTEXT_FLAG_COHERENT; a tile of more
// than 16 rays as several) on both devices, the faster counting (what=primary_packet_Nt_Mrays/s;
// _vs_embree16_default_isa, _vs_embree16_avx2 each), and against rtcIntersect1 on the same rays
// in the same order (_vs_embree1); shadow rays of a tile's hits one occludedPacket against
// rtcOccluded16 (coherent) and rtcOccluded1 alike. agreement_*_packet_vs_single_pct: packet
// results identical to our single rays; agreement_*_embree16_pct: Embree's packets against our
// single rays.
// Ray classes: primary = 1280x720 pinhole camera rays; shadow = from each primary hit toward a
// point light; incoherent = from each primary hit in a random cosine-weighted hemisphere
// direction about the geometric normal.
#include "raycast/bvh.h"

#include "scenegraph/mesh.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

using namespace sg;
using rnd::rt::Ray;
using rnd::rt::TriangleBvh;
using rnd::rt::TriHit;

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

void setFtzDaz() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

struct Scene {
    std::string name;
    std::vector<vec3> pos;
    std::vector<uint32_t> idx;
    vec3 eye, target, light;
    size_t tris() const { return idx.size() / 3; }
};

void append(Scene& s, const Mesh& m, const mat4& world) {
    uint32_t base = uint32_t(s.pos.size());
    for (const vec3& p : m.positions) s.pos.push_back(vec3(world * vec4(p, 1.0f)));
    for (uint32_t i : m.indices) s.idx.push_back(base + i);
}

// n x n spheres (slices x stacks each) on a tessellated ground.
Scene sphereGrid(const std::string& name, int n, int slices, int groundSub) {
    Scene s;
    s.name = name;
    Mesh sphere = primitives::uvSphere(0.4f, slices, slices / 2);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) append(s, sphere, glm::translate(mat4(1.0f), vec3(i - 0.5f * (n - 1), 0.4f, j - 0.5f * (n - 1))));
    append(s, primitives::plane(0.5f * n + 2.0f, groundSub), mat4(1.0f));
    float e = float(n);
    s.eye = vec3(0.35f * e, 0.45f * e + 1.0f, 0.75f * e + 1.0f);
    s.target = vec3(0, 0, 0);
    s.light = vec3(-0.5f * e, 1.0f * e, 0.3f * e);
    return s;
}

// Minimal OBJ reader: v and f (polygons fan-triangulated; v, v/vt, v//vn, v/vt/vn; negative
// indices). Returns false with a message on failure.
bool readObj(const std::string& path, Scene& s, std::string& err) {
    std::ifstream in(path);
    if (!in) {
        err = path + ": cannot open";
        return false;
    }
    std::string line;
    std::vector<uint32_t> face;
    while (std::getline(in, line)) {
        if (line.size() < 2) continue;
        if (line[0] == 'v' && line[1] == ' ') {
            vec3 p;
            if (std::sscanf(line.c_str() + 2, "%f %f %f", &p.x, &p.y, &p.z) == 3) s.pos.push_back(p);
        } else if (line[0] == 'f' && line[1] == ' ') {
            std::istringstream ls(line.substr(2));
            std::string tok;
            face.clear();
            while (ls >> tok) {
                long v = std::strtol(tok.c_str(), nullptr, 10);
                if (v < 0) v = long(s.pos.size()) + v + 1;
                if (v < 1 || size_t(v) > s.pos.size()) {
                    err = path + ": face index out of range";
                    return false;
                }
                face.push_back(uint32_t(v - 1));
            }
            for (size_t k = 2; k < face.size(); ++k) s.idx.insert(s.idx.end(), {face[0], face[k - 1], face[k]});
        }
    }
    if (s.idx.empty()) {
        err = path + ": no faces";
        return false;
    }
    return true;
}

Scene bunny(const std::string& testdata, std::string& err) {
    Scene s;
    s.name = "bunny";
    if (!readObj(testdata + "/meshes/common-3d-test-models/stanford-bunny/stanford-bunny.obj", s, err)) return s;
    Aabb b;
    for (const vec3& p : s.pos) b.extend(p);
    vec3 c = b.center();
    float r = glm::length(b.extent());
    s.eye = c + vec3(0.3f, 0.25f, 1.0f) * r;
    s.target = c;
    s.light = c + vec3(-1.0f, 2.0f, 1.0f) * r;
    return s;
}

struct RaySet {
    std::vector<Ray> rays;
};

// --- Embree wrapper -----------------------------------------------------------------------------
// Two devices per thread count take part in the ray measures: Embree's default ISA (AVX-512 on a
// CPU that has it) and "isa=avx2" (the ISA our kernels use); the faster of the two is the reference.
struct Embree {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    explicit Embree(int threads, const std::string& config = "") {
        std::string cfg = "threads=" + std::to_string(threads);
        if (!config.empty()) cfg += "," + config;
        // BENCH_EMBREE_CONFIG appends to Embree's device configuration (e.g. verbose=2).
        if (const char* extra = std::getenv("BENCH_EMBREE_CONFIG")) cfg += std::string(",") + extra;
        device = rtcNewDevice(cfg.c_str());
    }
    ~Embree() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
    double build(const Scene& s) {
        if (scene) rtcReleaseScene(scene);
        auto t0 = Clock::now();
        scene = rtcNewScene(device);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_MEDIUM);
        float* v = (float*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, s.pos.size());
        std::memcpy(v, s.pos.data(), s.pos.size() * 12);
        unsigned* ix = (unsigned*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, s.tris());
        std::memcpy(ix, s.idx.data(), s.idx.size() * 4);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(scene);
        return seconds(t0, Clock::now());
    }
    void intersect(const Ray& r, TriHit& h) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh;
        rh.ray.org_x = r.org.x;
        rh.ray.org_y = r.org.y;
        rh.ray.org_z = r.org.z;
        rh.ray.dir_x = r.dir.x;
        rh.ray.dir_y = r.dir.y;
        rh.ray.dir_z = r.dir.z;
        rh.ray.tnear = r.tmin;
        rh.ray.tfar = r.tmax;
        rh.ray.mask = ~0u;
        rh.ray.flags = 0;
        rh.ray.time = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &ctx, &rh);
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            h.t = rh.ray.tfar;
            h.prim = rh.hit.primID;
            h.b1 = rh.hit.u;
            h.b2 = rh.hit.v;
        } else
            h = TriHit();
    }
    bool occluded(const Ray& r) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRay ray;
        ray.org_x = r.org.x;
        ray.org_y = r.org.y;
        ray.org_z = r.org.z;
        ray.dir_x = r.dir.x;
        ray.dir_y = r.dir.y;
        ray.dir_z = r.dir.z;
        ray.tnear = r.tmin;
        ray.tfar = r.tmax;
        ray.mask = ~0u;
        ray.flags = 0;
        ray.time = 0;
        rtcOccluded1(scene, &ctx, &ray);
        return ray.tfar < 0;
    }
    // Up to 16 rays as one rtcIntersect16 / rtcOccluded16 (lanes n..15 inactive), with the
    // coherent flag: Embree's best case for camera rays of a 4x4 tile and their shadow rays.
    template <typename R16>
    static void load16(const Ray* r, int n, R16& q, int* valid) {
        for (int i = 0; i < 16; ++i) {
            valid[i] = i < n ? -1 : 0;
            const Ray& a = r[i < n ? i : 0];
            q.org_x[i] = a.org.x;
            q.org_y[i] = a.org.y;
            q.org_z[i] = a.org.z;
            q.dir_x[i] = a.dir.x;
            q.dir_y[i] = a.dir.y;
            q.dir_z[i] = a.dir.z;
            q.tnear[i] = a.tmin;
            q.tfar[i] = a.tmax;
            q.mask[i] = ~0u;
            q.flags[i] = 0;
            q.time[i] = 0;
        }
    }
    // A context for rays of one tile (RTC_INTERSECT_CONTEXT_FLAG_COHERENT).
    static RTCIntersectContext coherentContext() {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        return ctx;
    }
    void intersect16(const Ray* r, int n, TriHit* h) const {
        RTCIntersectContext ctx = coherentContext();
        alignas(64) int valid[16];
        RTCRayHit16 rh;
        load16(r, n, rh.ray, valid);
        for (int i = 0; i < 16; ++i) {
            rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, scene, &ctx, &rh);
        for (int i = 0; i < n; ++i)
            if (rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID) {
                h[i].t = rh.ray.tfar[i];
                h[i].prim = rh.hit.primID[i];
                h[i].b1 = rh.hit.u[i];
                h[i].b2 = rh.hit.v[i];
            } else
                h[i] = TriHit();
    }
    void occluded16(const Ray* r, int n, uint8_t* occ) const {
        RTCIntersectContext ctx = coherentContext();
        alignas(64) int valid[16];
        RTCRay16 q;
        load16(r, n, q, valid);
        rtcOccluded16(valid, scene, &ctx, &q);
        for (int i = 0; i < n; ++i) occ[i] = q.tfar[i] < 0;
    }
    // A packet of any size as packets of 16.
    void intersectN(const Ray* r, int n, TriHit* h) const {
        for (int i = 0; i < n; i += 16) intersect16(r + i, std::min(16, n - i), h + i);
    }
    void occludedN(const Ray* r, int n, uint8_t* occ) const {
        for (int i = 0; i < n; i += 16) occluded16(r + i, std::min(16, n - i), occ + i);
    }
};

double threadCpuSeconds() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// Runs fn(i) for i in [0, n) on `threads` threads, repeated until minSeconds; returns Mrays/s.
// One thread: timed by the thread's CPU clock (this machine is shared, so wall time includes
// other people's work); two threads: wall time.
// grain: items per task on two threads (packets: fewer, bigger items).
double measure(size_t n, int threads, double minSeconds, const std::function<void(size_t, size_t)>& fn, size_t grain = 1024) {
    tbb::task_arena arena(threads);
    size_t total = 0;
    if (threads == 1) {
        setFtzDaz();
        double c0 = threadCpuSeconds(), el = 0;
        do {
            fn(0, n);
            total += n;
            el = threadCpuSeconds() - c0;
        } while (el < minSeconds);
        return double(total) / el * 1e-6;
    }
    auto t0 = Clock::now();
    double el = 0;
    do {
        {
            arena.execute([&] {
                tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain), [&](const tbb::blocked_range<size_t>& r) {
                    setFtzDaz();
                    fn(r.begin(), r.end());
                });
            });
        }
        total += n;
        el = seconds(t0, Clock::now());
    } while (el < minSeconds);
    return double(total) / el * 1e-6;
}

// Median of v (sorts it); 0 for an empty v.
double median(std::vector<double>& v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Ours and the reference measured alternately `reps` times (the machine's speed drifts by
// +-10% over seconds: alternating exposes both to the same drift). Returns the medians of each
// and the median of the per-pair ratios ours_i / ref_i: each pair ran within a second, so its
// ratio is the least drift-sensitive figure (the ratio of medians mixes different moments).
struct PairResult {
    double ours, ref, ratio;
};
using RangeFn = std::function<void(size_t, size_t)>;
// fns[0] (ours) and references fns[1..] measured in turn `reps` times: Mrays/s per function and pass.
struct SetResult {
    std::vector<std::vector<double>> mrays;   // [function][pass]
    // Ours against the best of the references in `refs` (indices into fns) pass by pass: the
    // median of those references' best Mrays/s and of ours / that best.
    PairResult against(std::initializer_list<size_t> refs) const {
        std::vector<double> o = mrays[0], r, q;
        for (size_t i = 0; i < mrays[0].size(); ++i) {
            double best = 0;
            for (size_t k : refs) best = std::max(best, mrays[k][i]);
            r.push_back(best);
            q.push_back(mrays[0][i] / best);
        }
        return {median(o), median(r), median(q)};
    }
};
SetResult measureSet(size_t n, int threads, double minSeconds, int reps, const std::vector<RangeFn>& fns, size_t grain = 1024) {
    SetResult s;
    s.mrays.resize(fns.size());
    for (int i = 0; i < reps; ++i)
        for (size_t k = 0; k < fns.size(); ++k) s.mrays[k].push_back(measure(n, threads, minSeconds, fns[k], grain));
    return s;
}
PairResult measurePair(size_t n, int threads, double minSeconds, int reps, const RangeFn& ours, const RangeFn& ref, size_t grain = 1024) {
    return measureSet(n, threads, minSeconds, reps, {ours, ref}, grain).against({1});
}

// ratio < 0: ours / ref.
void line(const std::string& scene, const std::string& what, double ours, double ref, double ratio = -1) {
    const char* fmt = what.rfind("agreement", 0) == 0 ? "bench: scene=%s what=%s ours=%.4f ref=%.4f ratio=%.5f\n"
                                                      : "bench: scene=%s what=%s ours=%.4g ref=%.4g ratio=%.3f\n";
    if (ratio < 0) ratio = ref > 0 ? ours / ref : 0.0;
    std::printf(fmt, scene.c_str(), what.c_str(), ours, ref, ratio);
    std::fflush(stdout);
}

bool sameHit(const TriHit& a, const TriHit& b) {
    if (a.valid() != b.valid()) return false;
    if (!a.valid()) return true;
    float tol = 1e-4f * std::max(1.0f, a.t);
    if (std::abs(a.t - b.t) > tol) return false;
    return a.prim == b.prim || std::abs(a.t - b.t) <= 1e-6f * std::max(1.0f, a.t);
}

// Build times (seconds, medians over `reps`, the builders alternating). One thread: ours with
// parallel=false and Embree's threads=1 device, each inside a 1-thread task arena and timed by
// the thread's CPU clock. (Without the arena Embree's "threads=1" build borrows idle TBB workers
// left by an earlier parallel build: process CPU twice its wall time, an inflated reference.)
// Two threads: wall time.
struct BuildTimes {
    double ours1 = 0, ref1 = 0, ours2 = 0, ref2 = 0;
};
// Our build options: TriangleBvh::defaultOptions() unless --leaf-packets / --trav-cost say otherwise.
rnd::rt::Bvh4::BuildOptions g_options = TriangleBvh::defaultOptions();
int g_tileW = 4, g_tileH = 4;   // --tile WxH: pixels per packet (at most 64)
int g_pairs = 0;                // --pairs: ours/Embree alternations per ray measure (0: 3 quick, 5 full)
// --against LEAF,COST: the throughput reference is our own traversal on a second tree built
// with these maxLeafBlocks / traversalCost, alternated with the first in one process (tree
// tuning: differences of 1-2% that separate runs against Embree cannot resolve).
bool g_againstTree = false;
rnd::rt::Bvh4::BuildOptions g_againstOptions = TriangleBvh::defaultOptions();

BuildTimes measureBuilds(const Scene& s, TriangleBvh& bvh, int reps, bool twoThreads = true) {
    rnd::rt::Bvh4::BuildOptions single = g_options;
    single.parallel = false;
    std::vector<double> o1, r1, o2, r2;
    Embree e1(1), e2(2);
    tbb::task_arena one(1), two(2);
    auto cpu = [&](const std::function<void()>& fn) {
        double c = 0;
        one.execute([&] {
            timespec p0, p1;
            clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &p0);
            auto w0 = Clock::now();
            double c0 = threadCpuSeconds();
            fn();
            c = threadCpuSeconds() - c0;
            clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &p1);
            if (std::getenv("BENCH_DEBUG"))
                std::printf("  1t build: thread cpu %.1f ms, wall %.1f ms, process cpu %.1f ms\n", c * 1e3, seconds(w0, Clock::now()) * 1e3,
                            (p1.tv_sec - p0.tv_sec) * 1e3 + (p1.tv_nsec - p0.tv_nsec) * 1e-6);
        });
        return c;
    };
    for (int r = 0; r < reps; ++r) {
        o1.push_back(cpu([&] { bvh.build(s.pos.data(), s.idx.data(), s.tris(), single); }));
        r1.push_back(cpu([&] { e1.build(s); }));
        if (!twoThreads) continue;
        two.execute([&] {
            auto t1 = Clock::now();
            bvh.build(s.pos.data(), s.idx.data(), s.tris(), g_options);
            o2.push_back(seconds(t1, Clock::now()));
        });
        r2.push_back(e2.build(s));
    }
    return {median(o1), median(r1), median(o2), median(r2)};
}

// rayClass: "" for all three ray classes, else only that one's throughput (profiling).
void runScene(const Scene& s, bool quick, const std::string& rayClass) {
    const double minT = quick ? 0.0 : 0.25;
    const int reps = g_pairs > 0 ? g_pairs : quick ? 3 : 5;   // alternating ours/Embree passes per measure (medians)
    const int W = quick ? 640 : 1280, H = quick ? 360 : 720;
    // --- build --------------------------------------------------------------------------
    TriangleBvh bvh;
    const BuildTimes bt = measureBuilds(s, bvh, quick ? 3 : 5);
    const double oursB1 = bt.ours1, refB1 = bt.ref1, oursB2 = bt.ours2, refB2 = bt.ref2;
    const double mt = double(s.tris()) * 1e-6;
    line(s.name, "build_1t_Mtris/s", mt / oursB1, mt / refB1);
    line(s.name, "build_2t_Mtris/s", mt / oursB2, mt / refB2);
    std::printf("bench: scene=%s info tris=%zu build_ms ours_1t=%.2f embree_1t=%.2f ours_2t=%.2f embree_2t=%.2f bvh_MB=%.1f\n", s.name.c_str(),
                s.tris(), oursB1 * 1e3, refB1 * 1e3, oursB2 * 1e3, refB2 * 1e3, bvh.memoryBytes() / 1048576.0);
    {
        const TriangleBvh::Stats st = bvh.stats();
        std::printf(
            "bench: scene=%s info width=%d nodes=%zu children_per_node=%.2f leaves=%zu packets=%zu tris_per_packet=%.2f "
            "depth=%d sah=%.2f (nodes %.2f, leaves %.2f)\n",
            s.name.c_str(), bvh.width(), st.nodes, st.nodes ? double(st.childSlots) / double(st.nodes) : 0.0, st.leaves, st.packets,
            st.packets ? double(st.lanes) / double(st.packets) : 0.0, st.depth, st.sahNodes + st.sahLeaves, st.sahNodes, st.sahLeaves);
    }

    // --- rays (ours traced on the tree of the last, parallel, build: what the renderer uses)
    Embree e1(1), e2(2), e1a(1, "isa=avx2"), e2a(2, "isa=avx2");
    e1.build(s);
    e1a.build(s);
    auto build2 = [&] {   // the 2-thread devices' scenes, when first needed
        if (!e2.scene) e2.build(s);
        if (!e2a.scene) e2a.build(s);
    };
    mat4 view = glm::lookAt(s.eye, s.target, vec3(0, 1, 0));
    mat4 proj = glm::perspective(radians(45.0f), float(W) / H, 0.01f, 1000.0f);
    mat4 inv = glm::inverse(proj * view);
    std::vector<Ray> primary(size_t(W) * H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            vec4 a = inv * vec4(2.0f * (x + 0.5f) / W - 1, 2.0f * (y + 0.5f) / H - 1, -1, 1);
            vec4 b = inv * vec4(2.0f * (x + 0.5f) / W - 1, 2.0f * (y + 0.5f) / H - 1, 1, 1);
            Ray r;
            r.org = s.eye;
            r.dir = glm::normalize(vec3(b) / b.w - vec3(a) / a.w);
            primary[size_t(y) * W + x] = r;
        }
    std::vector<TriHit> hits(primary.size()), refHits(primary.size());
    for (size_t i = 0; i < primary.size(); ++i) {
        bvh.intersect(primary[i], hits[i]);
        e1.intersect(primary[i], refHits[i]);
    }
    // Secondary rays from the (Embree) primary hits so both trace exactly the same rays.
    std::vector<Ray> shadow, incoherent;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> U(0, 1);
    for (size_t i = 0; i < primary.size(); ++i) {
        const TriHit& h = refHits[i];
        if (!h.valid()) continue;
        const Ray& pr = primary[i];
        vec3 p = pr.org + h.t * pr.dir;
        const vec3 &p0 = s.pos[s.idx[3 * h.prim]], &p1 = s.pos[s.idx[3 * h.prim + 1]], &p2 = s.pos[s.idx[3 * h.prim + 2]];
        vec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
        if (glm::dot(n, pr.dir) > 0) n = -n;
        float eps = 1e-4f * (1.0f + glm::length(p));
        Ray sr;
        sr.org = p + eps * n;
        vec3 toL = s.light - sr.org;
        sr.tmax = glm::length(toL);
        sr.dir = toL / sr.tmax;
        sr.tmax *= 0.9999f;
        shadow.push_back(sr);
        // cosine-weighted hemisphere about n
        float r1 = U(rng), r2 = U(rng);
        float phi = 2 * kPi * r1, sr2 = std::sqrt(r2);
        vec3 t = std::abs(n.x) > 0.5f ? glm::normalize(glm::cross(n, vec3(0, 1, 0))) : glm::normalize(glm::cross(n, vec3(1, 0, 0)));
        vec3 bt = glm::cross(n, t);
        Ray ir;
        ir.org = sr.org;
        ir.dir = glm::normalize(std::cos(phi) * sr2 * t + std::sin(phi) * sr2 * bt + std::sqrt(std::max(0.0f, 1 - r2)) * n);
        incoherent.push_back(ir);
    }

    // Agreement.
    auto agreeClosest = [&](const std::vector<Ray>& rays) {
        size_t ok = 0;
        for (const Ray& r : rays) {
            TriHit a, b;
            bvh.intersect(r, a);
            e1.intersect(r, b);
            ok += sameHit(a, b);
        }
        return 100.0 * double(ok) / double(std::max<size_t>(rays.size(), 1));
    };
    size_t shOk = 0;
    for (const Ray& r : shadow) shOk += bvh.occluded(r) == e1.occluded(r);
    line(s.name, "agreement_primary_pct", agreeClosest(primary), 100.0);
    line(s.name, "agreement_shadow_pct", 100.0 * double(shOk) / double(std::max<size_t>(shadow.size(), 1)), 100.0);
    line(s.name, "agreement_incoherent_pct", agreeClosest(incoherent), 100.0);
    size_t ioOk = 0;
    for (const Ray& r : incoherent) ioOk += bvh.occluded(r) == e1.occluded(r);
    line(s.name, "agreement_incoherent_occluded_pct", 100.0 * double(ioOk) / double(std::max<size_t>(incoherent.size(), 1)), 100.0);

    // Throughput.
    TriangleBvh treeB;
    if (g_againstTree) {
        treeB.build(s.pos.data(), s.idx.data(), s.tris(), g_againstOptions);
        const TriangleBvh::Stats st = treeB.stats();
        std::printf(
            "bench: scene=%s info reference = our tree B (leaf packets %d, visit cost %.2f): nodes=%zu leaves=%zu sah=%.2f "
            "(nodes %.2f, leaves %.2f)\n",
            s.name.c_str(), g_againstOptions.maxLeafBlocks, g_againstOptions.traversalCost, st.nodes, st.leaves, st.sahNodes + st.sahLeaves,
            st.sahNodes, st.sahLeaves);
    }
    std::vector<TriHit> out(std::max(primary.size(), incoherent.size()));
    std::vector<uint8_t> occ(shadow.size());
    struct Cls {
        const char* name;
        const std::vector<Ray>* rays;
        bool shadow;
    };
    // incoherent_occluded: the incoherent rays as occlusion queries (any hit, no tmax).
    const Cls classes[4] = {
        {"primary", &primary, false}, {"shadow", &shadow, true}, {"incoherent", &incoherent, false}, {"incoherent_occluded", &incoherent, true}};
    for (const Cls& c : classes) {
        if (!rayClass.empty() && rayClass != c.name) continue;
        const std::vector<Ray>& rays = *c.rays;
        for (int threads : {1, 2}) {
            if (threads == 2) build2();
            const Embree& E = threads == 1 ? e1 : e2;
            const Embree& EA = threads == 1 ? e1a : e2a;
            const std::string what = std::string(c.name) + "_" + std::to_string(threads) + "t_Mrays/s";
            if (g_againstTree) {
                PairResult m;
                if (c.shadow)
                    m = measurePair(
                        rays.size(), threads, minT, reps,
                        [&](size_t b, size_t e) {
                            for (size_t i = b; i < e; ++i) occ[i] = bvh.occluded(rays[i]);
                        },
                        [&](size_t b, size_t e) {
                            for (size_t i = b; i < e; ++i) occ[i] = treeB.occluded(rays[i]);
                        });
                else
                    m = measurePair(
                        rays.size(), threads, minT, reps,
                        [&](size_t b, size_t e) {
                            for (size_t i = b; i < e; ++i) bvh.intersect(rays[i], out[i]);
                        },
                        [&](size_t b, size_t e) {
                            for (size_t i = b; i < e; ++i) treeB.intersect(rays[i], out[i]);
                        });
                line(s.name, what, m.ours, m.ref, m.ratio);
                continue;
            }
            // Ours, Embree's default ISA, Embree's AVX2 kernels, in turn.
            SetResult m;
            if (c.shadow) {
                auto embree = [&](const Embree& X) -> RangeFn {
                    return [&](size_t b, size_t e) {
                        for (size_t i = b; i < e; ++i) occ[i] = X.occluded(rays[i]);
                    };
                };
                m = measureSet(rays.size(), threads, minT, reps,
                               {[&](size_t b, size_t e) {
                                    for (size_t i = b; i < e; ++i) occ[i] = bvh.occluded(rays[i]);
                                },
                                embree(E), embree(EA)});
            } else {
                auto embree = [&](const Embree& X) -> RangeFn {
                    return [&](size_t b, size_t e) {
                        for (size_t i = b; i < e; ++i) X.intersect(rays[i], out[i]);
                    };
                };
                m = measureSet(rays.size(), threads, minT, reps,
                               {[&](size_t b, size_t e) {
                                    for (size_t i = b; i < e; ++i) bvh.intersect(rays[i], out[i]);
                                },
                                embree(E), embree(EA)});
            }
            const PairResult best = m.against({1, 2}), def = m.against({1}), avx2 = m.against({2});
            line(s.name, what, best.ours, best.ref, best.ratio);
            line(s.name, what + "_vs_default_isa", def.ours, def.ref, def.ratio);
            line(s.name, what + "_vs_avx2", avx2.ours, avx2.ref, avx2.ratio);
        }
    }
    if (g_againstTree || rayClass == "incoherent") return;

    // --- packets: the same camera rays in pixel tiles of g_tileW x g_tileH, each tile one packet
    // (TriangleBvh::intersectPacket) against Embree's rtcIntersect1 on the same rays in the same
    // order; shadow rays of a tile's hits (to the one point light) one packet
    // (occludedPacket) against rtcOccluded1.
    std::vector<Ray> tiled;
    std::vector<std::pair<uint32_t, uint32_t>> primaryPk, shadowPk;   // (first ray, count)
    std::vector<Ray> shadowT;
    for (int ty = 0; ty < H; ty += g_tileH)
        for (int tx = 0; tx < W; tx += g_tileW) {
            const uint32_t first = uint32_t(tiled.size()), firstS = uint32_t(shadowT.size());
            for (int y = ty; y < std::min(ty + g_tileH, H); ++y)
                for (int x = tx; x < std::min(tx + g_tileW, W); ++x) {
                    const Ray& pr = primary[size_t(y) * W + x];
                    tiled.push_back(pr);
                    const TriHit& h = refHits[size_t(y) * W + x];
                    if (!h.valid()) continue;
                    // The shadow ray of the single-ray measure above, for this pixel.
                    vec3 p = pr.org + h.t * pr.dir;
                    const vec3 &p0 = s.pos[s.idx[3 * h.prim]], &p1 = s.pos[s.idx[3 * h.prim + 1]], &p2 = s.pos[s.idx[3 * h.prim + 2]];
                    vec3 nrm = glm::normalize(glm::cross(p1 - p0, p2 - p0));
                    if (glm::dot(nrm, pr.dir) > 0) nrm = -nrm;
                    float eps = 1e-4f * (1.0f + glm::length(p));
                    Ray sr;
                    sr.org = p + eps * nrm;
                    vec3 toL = s.light - sr.org;
                    sr.tmax = glm::length(toL);
                    sr.dir = toL / sr.tmax;
                    sr.tmax *= 0.9999f;
                    shadowT.push_back(sr);
                }
            primaryPk.push_back({first, uint32_t(tiled.size()) - first});
            if (shadowT.size() > firstS) shadowPk.push_back({firstS, uint32_t(shadowT.size()) - firstS});
        }
    // Agreement: packet vs Embree (as above) and packet vs our single rays (must be 100%).
    {
        std::vector<TriHit> ph(tiled.size());
        std::vector<uint8_t> po(shadowT.size());
        for (const auto& [b, c] : primaryPk) bvh.intersectPacket(&tiled[b], int(c), ~uint64_t(0), &ph[b]);
        for (const auto& [b, c] : shadowPk) {
            const uint64_t m = bvh.occludedPacket(&shadowT[b], int(c), ~uint64_t(0));
            for (uint32_t i = 0; i < c; ++i) po[b + i] = (m >> i) & 1;
        }
        size_t okE = 0, okS = 0, shE = 0, shS = 0, ties = 0;
        for (size_t i = 0; i < tiled.size(); ++i) {
            TriHit a, b;
            bvh.intersect(tiled[i], a);
            e1.intersect(tiled[i], b);
            okE += sameHit(ph[i], b);
            const bool same =
                ph[i].valid() == a.valid() && (!a.valid() || (ph[i].t == a.t && ph[i].prim == a.prim && ph[i].b1 == a.b1 && ph[i].b2 == a.b2));
            okS += same;
            // An exact tie (two triangles at the same t, e.g. a ray through a shared edge): either may be kept.
            ties += !same && ph[i].valid() && a.valid() && ph[i].t == a.t;
            if (!same && std::getenv("BENCH_DEBUG"))
                std::printf("bench: packet differs: ray %zu t %.9g / %.9g prim %u / %u\n", i, double(ph[i].t), double(a.t), ph[i].prim, a.prim);
        }
        for (size_t i = 0; i < shadowT.size(); ++i) {
            shE += bool(po[i]) == e1.occluded(shadowT[i]);
            shS += bool(po[i]) == bvh.occluded(shadowT[i]);
        }
        // Embree's 16-wide packets against our single rays (the same check as Embree's single rays above).
        std::vector<TriHit> eh(tiled.size());
        std::vector<uint8_t> eo(shadowT.size());
        for (const auto& [b, c] : primaryPk) e1.intersectN(&tiled[b], int(c), &eh[b]);
        for (const auto& [b, c] : shadowPk) e1.occludedN(&shadowT[b], int(c), &eo[b]);
        size_t e16 = 0, e16s = 0;
        for (size_t i = 0; i < tiled.size(); ++i) {
            TriHit a;
            bvh.intersect(tiled[i], a);
            e16 += sameHit(a, eh[i]);
        }
        for (size_t i = 0; i < shadowT.size(); ++i) e16s += bool(eo[i]) == bvh.occluded(shadowT[i]);
        const double np = double(std::max<size_t>(tiled.size(), 1)), ns = double(std::max<size_t>(shadowT.size(), 1));
        line(s.name, "agreement_primary_packet_pct", 100.0 * double(okE) / np, 100.0);
        line(s.name, "agreement_shadow_packet_pct", 100.0 * double(shE) / ns, 100.0);
        line(s.name, "agreement_primary_packet_vs_single_pct", 100.0 * double(okS) / np, 100.0);
        std::printf("bench: scene=%s info packet hits differing from single rays: %zu, all exact ties (same t): %s\n", s.name.c_str(),
                    tiled.size() - okS, ties == tiled.size() - okS ? "yes" : "no");
        line(s.name, "agreement_shadow_packet_vs_single_pct", 100.0 * double(shS) / ns, 100.0);
        line(s.name, "agreement_primary_embree16_pct", 100.0 * double(e16) / np, 100.0);
        line(s.name, "agreement_shadow_embree16_pct", 100.0 * double(e16s) / ns, 100.0);
    }
    std::vector<TriHit> outT(tiled.size());
    std::vector<uint8_t> occT(shadowT.size());
    for (int cls = 0; cls < 2; ++cls) {
        const bool sh = cls == 1;
        if (!rayClass.empty() && rayClass != (sh ? "shadow" : "primary")) continue;
        const auto& pk = sh ? shadowPk : primaryPk;
        const std::vector<Ray>& rays = sh ? shadowT : tiled;
        const double perPacket = double(rays.size()) / double(std::max<size_t>(pk.size(), 1));
        for (int threads : {1, 2}) {
            if (threads == 2) build2();
            const Embree& E = threads == 1 ? e1 : e2;
            const Embree& EA = threads == 1 ? e1a : e2a;
            // Ours, Embree's 16-wide coherent packets (default ISA, AVX2), its single rays, in turn.
            SetResult m;
            if (sh) {
                auto packet16 = [&](const Embree& X) -> RangeFn {
                    return [&](size_t b, size_t e) {
                        for (size_t k = b; k < e; ++k) X.occludedN(&rays[pk[k].first], int(pk[k].second), &occT[pk[k].first]);
                    };
                };
                m = measureSet(pk.size(), threads, minT, reps,
                               {[&](size_t b, size_t e) {
                                    for (size_t k = b; k < e; ++k) {
                                        const uint64_t o = bvh.occludedPacket(&rays[pk[k].first], int(pk[k].second), ~uint64_t(0));
                                        occT[pk[k].first] = uint8_t(o);
                                    }
                                },
                                packet16(E), packet16(EA),
                                [&](size_t b, size_t e) {
                                    for (size_t k = b; k < e; ++k)
                                        for (uint32_t i = pk[k].first; i < pk[k].first + pk[k].second; ++i) occT[i] = E.occluded(rays[i]);
                                }},
                               16);
            } else {
                auto packet16 = [&](const Embree& X) -> RangeFn {
                    return [&](size_t b, size_t e) {
                        for (size_t k = b; k < e; ++k) X.intersectN(&rays[pk[k].first], int(pk[k].second), &outT[pk[k].first]);
                    };
                };
                m = measureSet(pk.size(), threads, minT, reps,
                               {[&](size_t b, size_t e) {
                                    for (size_t k = b; k < e; ++k)
                                        bvh.intersectPacket(&rays[pk[k].first], int(pk[k].second), ~uint64_t(0), &outT[pk[k].first]);
                                },
                                packet16(E), packet16(EA),
                                [&](size_t b, size_t e) {
                                    for (size_t k = b; k < e; ++k)
                                        for (uint32_t i = pk[k].first; i < pk[k].first + pk[k].second; ++i) E.intersect(rays[i], outT[i]);
                                }},
                               16);
            }
            const std::string what = std::string(sh ? "shadow" : "primary") + "_packet_" + std::to_string(threads) + "t_Mrays/s";
            const PairResult best = m.against({1, 2}), def = m.against({1}), avx2 = m.against({2}), single = m.against({3});
            line(s.name, what, best.ours * perPacket, best.ref * perPacket, best.ratio);
            line(s.name, what + "_vs_embree16_default_isa", def.ours * perPacket, def.ref * perPacket, def.ratio);
            line(s.name, what + "_vs_embree16_avx2", avx2.ours * perPacket, avx2.ref * perPacket, avx2.ratio);
            line(s.name, what + "_vs_embree1", single.ours * perPacket, single.ref * perPacket, single.ratio);
        }
    }
}

}   // namespace

int main(int argc, char** argv) {
    bool quick = false, buildOnly = false;
    int reps = 1;
    std::string only, rayClass, testdata = VIEWER_TESTDATA_DIR;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--quick")
            quick = true;
        else if (a == "--scene" && i + 1 < argc)
            only = argv[++i];
        else if (a == "--testdata" && i + 1 < argc)
            testdata = argv[++i];
        else if (a == "--build-only")
            buildOnly = true;
        else if (a == "--rays" && i + 1 < argc)
            rayClass = argv[++i];
        else if (a == "--reps" && i + 1 < argc)
            reps = std::max(1, std::atoi(argv[++i]));
        else if (a == "--tile" && i + 1 < argc) {
            if (std::sscanf(argv[++i], "%dx%d", &g_tileW, &g_tileH) != 2 || g_tileW < 1 || g_tileH < 1 || g_tileW * g_tileH > rnd::rt::kMaxPacket) {
                std::fprintf(stderr, "bench: --tile wants WxH with W*H <= %d, got '%s'\n", rnd::rt::kMaxPacket, argv[i]);
                return 2;
            }
        } else if (a == "--pairs" && i + 1 < argc)
            g_pairs = std::max(1, std::atoi(argv[++i]));
        else if (a == "--leaf-packets" && i + 1 < argc)
            g_options.maxLeafBlocks = std::clamp(std::atoi(argv[++i]), 1, 7);
        else if (a == "--trav-cost" && i + 1 < argc)
            g_options.traversalCost = std::max(0.0f, float(std::atof(argv[++i])));
        else if (a == "--against" && i + 1 < argc) {
            int leaf = 0;
            float cost = 0;
            if (std::sscanf(argv[++i], "%d,%f", &leaf, &cost) != 2 || leaf < 1 || leaf > 7 || !(cost >= 0)) {
                std::fprintf(stderr, "bench: --against wants LEAF,COST (leaf packets 1-7, visit cost >= 0), got '%s'\n", argv[i]);
                return 2;
            }
            g_againstTree = true;
            g_againstOptions.maxLeafBlocks = leaf;
            g_againstOptions.traversalCost = cost;
        } else {
            std::fprintf(stderr,
                         "usage: %s [--quick] [--scene NAME] [--testdata DIR] [--rays primary|shadow|incoherent] [--build-only [--reps N]] [--pairs "
                         "N] [--tile WxH] [--leaf-packets N] [--trav-cost X] [--against LEAF,COST]\n",
                         argv[0]);
            return 2;
        }
    }
    if (const char* env = std::getenv("VIEWER_TESTDATA")) testdata = env;
    setFtzDaz();
    struct Spec {
        std::string name;
        std::function<Scene()> make;
    };
    std::string err;
    std::vector<Spec> specs = {
        {"spheres10k", [] { return sphereGrid("spheres10k", 4, 24, 32); }},
        {"spheres100k", [] { return sphereGrid("spheres100k", 10, 32, 64); }},
        {"spheres1M", [] { return sphereGrid("spheres1M", 16, 64, 128); }},
        {"bunny", [&] { return bunny(testdata, err); }},
    };
    if (!rayClass.empty() && rayClass != "primary" && rayClass != "shadow" && rayClass != "incoherent") {
        std::fprintf(stderr, "bench: unknown ray class '%s' (primary, shadow, incoherent)\n", rayClass.c_str());
        return 2;
    }
    if (!only.empty() && std::none_of(specs.begin(), specs.end(), [&](const Spec& sp) { return sp.name == only; })) {
        std::fprintf(stderr, "bench: unknown scene '%s' (spheres10k, spheres100k, spheres1M, bunny)\n", only.c_str());
        return 2;
    }
    for (const Spec& sp : specs) {
        if (!only.empty() && sp.name != only) continue;
        Scene s = sp.make();
        if (s.idx.empty()) {
            std::fprintf(stderr, "bench: scene=%s skipped: %s\n", sp.name.c_str(), err.c_str());
            continue;
        }
        if (buildOnly) {
            TriangleBvh bvh;
            const BuildTimes bt = measureBuilds(s, bvh, reps, /*twoThreads=*/false);
            const double mt = double(s.tris()) * 1e-6;
            line(s.name, "build_1t_Mtris/s", mt / bt.ours1, mt / bt.ref1);
            continue;
        }
        runScene(s, quick, rayClass);
    }
    return 0;
}
