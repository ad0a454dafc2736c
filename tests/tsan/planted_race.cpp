// planted_race: proof that a tsan-preset run sees races through TBB and std::thread.
// `planted_race tbb-race` and `planted_race thread-race` each plant a data race (a shared plain
// counter written from the bodies of a tbb::parallel_for, and from two std::threads); CTest
// expects ThreadSanitizer to report each one, naming the racing function. `planted_race
// tbb-clean` and `planted_race thread-clean` do the same work correctly (a parallel_reduce, an
// atomic counter) and must run without a report: with Debian's uninstrumented libtbb the clean
// parallel_for is reported too, inside TBB's partitioner, which is what this preset avoids.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

namespace {

// Work spread over TBB's threads: 64 one-item chunks, each long enough (1 ms) for the worker
// threads to wake and steal some, so that more than one thread always takes part.
constexpr int kChunks = 64;
void chunkWork() { std::this_thread::sleep_for(std::chrono::milliseconds(1)); }

std::mutex g_threadsMutex;
std::set<std::thread::id> g_threads;
void noteThread() {
    std::lock_guard lock(g_threadsMutex);
    g_threads.insert(std::this_thread::get_id());
}

// noinline: the racing functions' names appear in the report, which the test looks for.
__attribute__((noinline)) long plantedTbbRace() {
    long counter = 0;   // shared by every chunk, not atomic, not locked: the planted race
    tbb::parallel_for(tbb::blocked_range<int>(0, kChunks, 1), [&](const tbb::blocked_range<int>& r) {
        noteThread();
        chunkWork();
        for (int i = r.begin(); i != r.end(); ++i) counter = counter + i;
    });
    return counter;
}

// The clean variant also runs rounds of a parallel_for and a parallel_reduce over a vector, as the
// renderers do: with Debian's libtbb this alone gives about a hundred reports (task objects
// recycled between threads through TBB's uninstrumented allocator and scheduler).
__attribute__((noinline)) long cleanTbb() {
    std::vector<float> v(1 << 16, 1.0f);
    double total = 0.0;
    for (int round = 0; round < 200; ++round) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, v.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) v[i] = v[i] * 0.5f + 1.0f;
        });
        total += tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, v.size()), 0.0,
            [&](const tbb::blocked_range<size_t>& r, double s) {
                for (size_t i = r.begin(); i != r.end(); ++i) s += v[i];
                return s;
            },
            [](double a, double b) { return a + b; });
    }
    if (total <= 0.0) return -1;
    return tbb::parallel_reduce(
        tbb::blocked_range<int>(0, kChunks, 1), 0L,
        [](const tbb::blocked_range<int>& r, long sum) {
            noteThread();
            chunkWork();
            for (int i = r.begin(); i != r.end(); ++i) sum += i;
            return sum;
        },
        [](long a, long b) { return a + b; });
}

__attribute__((noinline)) long plantedThreadRace() {
    long counter = 0;   // written by both threads without synchronisation: the planted race
    auto work = [&counter] {
        noteThread();
        for (int i = 0; i < 1000; ++i) counter = counter + 1;
    };
    std::thread a(work), b(work);
    a.join();
    b.join();
    return counter;
}

__attribute__((noinline)) long cleanThread() {
    std::atomic<long> counter = 0;
    auto work = [&counter] {
        noteThread();
        for (int i = 0; i < 1000; ++i) counter.fetch_add(1, std::memory_order_relaxed);
    };
    std::thread a(work), b(work);
    a.join();
    b.join();
    return counter.load();
}

}   // namespace

int main(int argc, char** argv) {
    const char* mode = argc > 1 ? argv[1] : "";
    long result = 0;
    if (std::strcmp(mode, "tbb-race") == 0)
        result = plantedTbbRace();
    else if (std::strcmp(mode, "tbb-clean") == 0)
        result = cleanTbb();
    else if (std::strcmp(mode, "thread-race") == 0)
        result = plantedThreadRace();
    else if (std::strcmp(mode, "thread-clean") == 0)
        result = cleanThread();
    else {
        std::fprintf(stderr, "usage: planted_race tbb-race|tbb-clean|thread-race|thread-clean\n");
        return 2;
    }
    std::printf("planted_race %s: result %ld, %zu threads took part\n", mode, result, g_threads.size());
    // A run where one thread did all the work proves nothing: fail it rather than pass quietly.
    return g_threads.size() >= 2 ? 0 : 3;
}
