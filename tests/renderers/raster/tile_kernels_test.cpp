// tile_kernels_test.cpp - the CPU rasterizer's vectorised tile kernels (raster/tile_kernels.h)
// against the scalar loops they replace, bit for bit: the depth-tested coverage of an opaque
// triangle (forEachCoveredPixel with the renderer's depth test) and the preparation of a run of
// plain fragments (the renderer's scalar prepareSimple). The kernels run with the instruction set
// the process picks (AVX2 where the CPU has it); CTest runs this binary a second time with
// VIEWER_RASTER_SSE=1 for the SSE2 kernels (raster_tile_kernels_sse2).
#include "raster/tile_kernels.h"
#include "raster/raster_core.h"
#include "raster/simd.h"
#include "renderers/shading.h"
#include "renderers/srgb_encoder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

using namespace rnd::raster;
using rnd::SrgbEncoder;
using rnd::srgbEncoder;
using sg::vec3;

namespace {

constexpr int W = 1280, H = 720;
constexpr size_t kTileValues = size_t(kTileSize) * kTileSize + kTilePad;

// The scalar loop: forEachCoveredPixel with the renderer's depth test (LESS on the window z
// clamped to [0, 1]).
void rasterizeScalar(const TriCoverage& s, const TriPlanes& pl, uint32_t id, int tx0, int ty0, int x0, int y0, int x1, int y1, float* depth,
                     uint32_t* ids) {
    forEachCoveredPixel(s, x0, y0, x1, y1, [&](int i, int j) {
        float z = pl.zRef + pl.zdx * float(i - s.minX) + pl.zdy * float(j - s.minY);
        z = std::clamp(z, 0.0f, 1.0f);
        const size_t p = size_t(j - ty0) * kTileSize + size_t(i - tx0);
        if (z < depth[p]) {
            depth[p] = z;
            ids[p] = id;
        }
    });
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) { return std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0; }

// The part [rx0, rx1] x [ry0, ry1] of the tile at (tx0, ty0) that triangle s's bbox covers, as
// the renderer clips it; false when empty.
bool tileRect(const TriCoverage& s, int tx0, int ty0, int& rx0, int& ry0, int& rx1, int& ry1) {
    rx0 = std::max(tx0, int(s.minX));
    rx1 = std::min(std::min(tx0 + kTileSize, W) - 1, int(s.maxX));
    ry0 = std::max(ty0, int(s.minY));
    ry1 = std::min(std::min(ty0 + kTileSize, H) - 1, int(s.maxY));
    return rx0 <= rx1 && ry0 <= ry1;
}

// The scalar loop and rasterizeOpaque, each on its own copy of the tile buffers (depth, ids):
// success when the depths are the same bits and the ids the same everywhere, the slack included.
// `depthOut` and `idsOut` get the kernel's buffers.
testing::AssertionResult kernelMatchesScalar(const TriCoverage& s, const TriPlanes& pl, uint32_t id, int tx0, int ty0,
                                             const std::vector<float>& depth, const std::vector<uint32_t>& ids,
                                             std::vector<float>* depthOut = nullptr, std::vector<uint32_t>* idsOut = nullptr) {
    int rx0, ry0, rx1, ry1;
    if (!tileRect(s, tx0, ty0, rx0, ry0, rx1, ry1)) return testing::AssertionFailure() << "the triangle misses the tile";
    std::vector<float> depthA = depth, depthB = depth;
    std::vector<uint32_t> idsA = ids, idsB = ids;
    rasterizeScalar(s, pl, id, tx0, ty0, rx0, ry0, rx1, ry1, depthA.data(), idsA.data());
    rasterizeOpaque(s, pl, id, tx0, ty0, rx0, ry0, rx1, ry1, depthB.data(), idsB.data());
    if (depthOut) *depthOut = depthB;
    if (idsOut) *idsOut = idsB;
    if (!sameBits(depthA, depthB)) return testing::AssertionFailure() << "depths differ";
    if (idsA != idsB) return testing::AssertionFailure() << "ids differ";
    return testing::AssertionSuccess();
}

}   // namespace

// Tells which kernels this run checks; under VIEWER_RASTER_SSE=1 they must be the SSE2 ones.
TEST(RasterTileKernelTest, InstructionSetIsTheOneAskedFor) {
    const char* e = std::getenv("VIEWER_RASTER_SSE");
    const bool forcedSse = e && e[0] == '1';
    if (forcedSse) { EXPECT_FALSE(useAvx2()); }
    RecordProperty("kernels", useAvx2() ? "avx2" : "sse2");
    std::printf("tile kernels under test: %s\n", useAvx2() ? "AVX2" : "SSE2");
}

// Random triangles from sub-pixel slivers to ones larger than the viewport (in the guard band),
// each against a tile it touches, over a depth buffer with random contents: the same depth bits
// and ids everywhere (the slack included) as the scalar loop.
TEST(RasterTileKernelTest, OpaqueCoverageMatchesTheScalarLoop) {
    std::mt19937 rng(2024);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    const float sizes[] = {1.5f, 3.0f, 7.0f, 12.0f, 40.0f, 150.0f, 700.0f, 2500.0f};
    int tested = 0, wide = 0, rejected32 = 0, clampedZ = 0;
    for (int iter = 0; iter < 6000; ++iter) {
        const float size = sizes[iter % 8];
        const float cx = -100 + (W + 200) * U(rng), cy = -100 + (H + 200) * U(rng);
        float xs[3], ys[3];
        for (int k = 0; k < 3; ++k) {
            xs[k] = cx + size * (U(rng) - 0.5f);
            ys[k] = cy + size * (U(rng) - 0.5f);
        }
        if (iter % 13 == 0) ys[1] = ys[0];   // a horizontal edge (the top-left rule)
        if (iter % 17 == 0) xs[2] = xs[0];   // a vertical one
        TriSetup ts;
        if (!setupTriangle(xs, ys, W, H, ts)) continue;
        TriCoverage cov;
        cov.set(ts);
        // Depths partly outside [0, 1] (clamped), 1/w of very different sizes (perspective).
        const float z[3] = {-0.2f + 1.4f * U(rng), -0.2f + 1.4f * U(rng), -0.2f + 1.4f * U(rng)};
        const float iw[3] = {0.05f + 4 * U(rng), 0.05f + 4 * U(rng), 0.05f + 4 * U(rng)};
        const TriPlanes pl = makeTriPlanes(ts, z, iw);
        if (!coverageFits32(cov)) {
            ++rejected32;
            continue;
        }
        // A tile the bbox touches.
        const int pi = cov.minX + int(U(rng) * float(cov.maxX - cov.minX + 1));
        const int pj = cov.minY + int(U(rng) * float(cov.maxY - cov.minY + 1));
        const int tx0 = std::min(pi, int(cov.maxX)) & ~(kTileSize - 1), ty0 = std::min(pj, int(cov.maxY)) & ~(kTileSize - 1);
        int rx0, ry0, rx1, ry1;
        if (!tileRect(cov, tx0, ty0, rx0, ry0, rx1, ry1)) continue;
        std::vector<float> depth(kTileValues), depthB;
        std::vector<uint32_t> ids(kTileValues);
        for (size_t p = 0; p < kTileValues; ++p) {
            depth[p] = p % 7 == 0 ? 1.0f : U(rng);
            ids[p] = uint32_t(rng());
        }
        ASSERT_TRUE(kernelMatchesScalar(cov, pl, uint32_t(iter), tx0, ty0, depth, ids, &depthB))
            << "iteration " << iter << ", triangle size " << size;
        ++tested;
        wide += (rx1 - rx0 >= 8 || ry1 - ry0 >= 8);
        clampedZ += std::count(depthB.begin(), depthB.end(), 0.0f) > 0;
    }
    EXPECT_GT(tested, 3000);
    EXPECT_GT(wide, 1000);       // several 8x8 blocks per triangle
    EXPECT_GT(rejected32, 50);   // the largest triangles go to the 64-bit loop
    EXPECT_GT(clampedZ, 100);    // z below 0 stored as 0
}

// The 32-bit limit is safe right at its edge: triangles whose edge steps sit just below the
// bound (|a| + |b| up to 2^30 / (7 kSub) fixed-point units), in every tile they touch.
TEST(RasterTileKernelTest, OpaqueCoverageAtThe32BitLimit) {
    std::mt19937 rng(77);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    int tested = 0;
    const float limitPx = float((int64_t(1) << 30) / (7 * kSub)) / kSub;   // |dx| + |dy| in pixels
    for (int iter = 0; iter < 40; ++iter) {
        // A long thin triangle whose longest edge has |dx| + |dy| just under the limit.
        const float len = limitPx * (0.97f + 0.029f * U(rng));
        const float t = U(rng);
        const float dx = len * t, dy = len * (1 - t);
        const float ax = -600 + 200 * U(rng), ay = -600 + 200 * U(rng);
        float xs[3] = {ax, ax + dx, ax + dx * 0.5f + 30 * U(rng)};
        float ys[3] = {ay, ay + dy, ay + dy * 0.5f - 30 - 30 * U(rng)};
        TriSetup ts;
        if (!setupTriangle(xs, ys, W, H, ts)) continue;
        TriCoverage cov;
        cov.set(ts);
        if (!coverageFits32(cov)) continue;
        const float z[3] = {0.3f, 0.6f, 0.9f}, iw[3] = {1, 0.5f, 0.25f};
        const TriPlanes pl = makeTriPlanes(ts, z, iw);
        const std::vector<float> depth(kTileValues, 1.0f);
        const std::vector<uint32_t> ids(kTileValues, 0xFFFFFFFFu);
        for (int ty0 = 0; ty0 < H; ty0 += kTileSize)
            for (int tx0 = 0; tx0 < W; tx0 += kTileSize) {
                int rx0, ry0, rx1, ry1;
                if (!tileRect(cov, tx0, ty0, rx0, ry0, rx1, ry1)) continue;
                std::vector<uint32_t> idsB;
                ASSERT_TRUE(kernelMatchesScalar(cov, pl, 5, tx0, ty0, depth, ids, nullptr, &idsB))
                    << "iteration " << iter << " tile " << tx0 << "," << ty0;
                tested += std::count(idsB.begin(), idsB.end(), 5u) > 0;
            }
    }
    EXPECT_GT(tested, 100);
}

// Large triangles whose part inside the viewport is a few pixels (a corner or an edge of the
// image): their bbox is clipped to the viewport and small, but their edge functions are not.
TEST(RasterTileKernelTest, OpaqueCoverageOfLargeTrianglesClippedToASmallCorner) {
    std::mt19937 rng(8);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    int tested = 0;
    for (int iter = 0; iter < 400; ++iter) {
        // Right angle a few pixels inside the bottom-left (or top-right) corner, the other two
        // vertices far outside the image: the bbox clipped to the viewport is a few pixels, the
        // edges are hundreds of pixels long (up to ~1150: the 32-bit path).
        const float far = 150 + 400 * U(rng), reach = 2 + 5 * U(rng);
        float xs[3] = {-far, reach, reach}, ys[3] = {reach, reach, -far};
        if (iter % 2) {
            for (int k = 0; k < 3; ++k) {
                xs[k] = W - xs[k];
                ys[k] = H - ys[k];
            }
        }
        xs[1] += U(rng);
        ys[2] += U(rng);
        TriSetup ts;
        if (!setupTriangle(xs, ys, W, H, ts)) continue;
        TriCoverage cov;
        cov.set(ts);
        if (!coverageFits32(cov)) continue;
        const float z[3] = {0.2f, 0.5f, 0.7f}, iw[3] = {1, 1, 1};
        const TriPlanes pl = makeTriPlanes(ts, z, iw);
        // The tile of the image corner the triangle reaches.
        const int tx0 = iter % 2 ? (W - 1) & ~(kTileSize - 1) : 0, ty0 = iter % 2 ? (H - 1) & ~(kTileSize - 1) : 0;
        int rx0, ry0, rx1, ry1;
        if (!tileRect(cov, tx0, ty0, rx0, ry0, rx1, ry1)) continue;
        std::vector<uint32_t> idsB;
        ASSERT_TRUE(kernelMatchesScalar(cov, pl, 9, tx0, ty0, std::vector<float>(kTileValues, 1.0f), std::vector<uint32_t>(kTileValues, 0xFFFFFFFFu),
                                        nullptr, &idsB))
            << "iteration " << iter << ", bbox " << cov.minX << ".." << cov.maxX << " x " << cov.minY << ".." << cov.maxY;
        tested += std::count(idsB.begin(), idsB.end(), 9u) > 0;
    }
    EXPECT_GT(tested, 300);
}

namespace {

// The renderer's scalar preparation of a plain fragment (prepareSimple with baryAt), written out.
struct PreparedRef {
    vec3 pos, n;
    float fog;
};
PreparedRef prepareScalar(const PlainTri& t, bool fog, int i, int j) {
    const TriPlanes& pl = *t.pl;
    const float di = float(i - t.minX), dj = float(j - t.minY);
    float u[3], sum = 0;
    for (int q = 0; q < 3; ++q) {
        u[q] = pl.uRef[q] + pl.udx[q] * di + pl.udy[q] * dj;
        sum += u[q];
    }
    const float invSum = sum != 0 ? 1.0f / sum : 0.0f;
    float b[3];
    for (int q = 0; q < 3; ++q) b[q] = u[q] * invSum;
    vec3 bo;
    if (t.cb)
        bo = b[0] * (*t.cb)[0] + b[1] * (*t.cb)[1] + b[2] * (*t.cb)[2];
    else if (!t.swapped)
        bo = vec3(b[0], b[1], b[2]);
    else
        bo = vec3(b[0], b[2], b[1]);
    PreparedRef r;
    r.pos = bo[0] * t.p[0] + bo[1] * t.p[1] + bo[2] * t.p[2];
    if (t.faceNormal) {
        r.n = t.n[0];
    } else {
        vec3 n = bo[0] * t.n[0] + bo[1] * t.n[1] + bo[2] * t.n[2];
        const float len = glm::length(n);
        r.n = len > 0 ? n / len : vec3(0, 0, 1);
    }
    r.fog = fog ? glm::length(bo[0] * t.pe[0] + bo[1] * t.pe[1] + bo[2] * t.pe[2]) : 0.0f;
    return r;
}

bool sameFloat(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}   // namespace

// Runs of every length at unaligned starts, clipped and whole triangles, both setup orders, flat
// and interpolated normals (a zero normal among them), with and without fog: each slot of the run
// holds the scalar code's bits, and nothing before the run or past its vector slack is touched.
TEST(RasterTileKernelTest, PlainFragmentsMatchTheScalarFormula) {
    std::mt19937 rng(31);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f), P(0.0f, 1.0f);
    const size_t slots = 200;
    int checked = 0;
    for (int iter = 0; iter < 3000; ++iter) {
        // A triangle with a perspective 1/w, set up as the renderer sets it up.
        const float cx = 40 + 1200 * P(rng), cy = 40 + 640 * P(rng), size = 4 + 60 * P(rng);
        float xs[3], ys[3];
        for (int k = 0; k < 3; ++k) {
            xs[k] = cx + size * U(rng);
            ys[k] = cy + size * U(rng);
        }
        TriSetup ts;
        if (!setupTriangle(xs, ys, W, H, ts)) continue;
        const float z[3] = {P(rng), P(rng), P(rng)};
        const float iw[3] = {0.1f + P(rng), 0.1f + 3 * P(rng), 0.1f + 9 * P(rng)};
        const TriPlanes pl = makeTriPlanes(ts, z, iw);
        std::array<vec3, 3> clipBary;
        PlainTri t;
        t.pl = &pl;
        t.minX = ts.minX;
        t.minY = ts.minY;
        t.swapped = ts.order[1] != 1;
        if (iter % 3 == 0) {   // a clipped piece: its vertices' weights of the input corners
            for (auto& c : clipBary) {
                const float a = P(rng), b = P(rng) * (1 - a);
                c = vec3(a, b, 1 - a - b);
            }
            t.cb = &clipBary;
        }
        for (int q = 0; q < 3; ++q) {
            t.p[q] = vec3(5 * U(rng), 5 * U(rng), 5 * U(rng));
            t.pe[q] = vec3(5 * U(rng), 5 * U(rng), -1 - 20 * P(rng));
            t.n[q] = glm::normalize(vec3(U(rng), U(rng), U(rng)) + vec3(0, 0, 0.1f));
        }
        if (iter % 29 == 0) t.n[1] = t.n[2] = -t.n[0];   // normals that cancel somewhere
        t.faceNormal = iter % 4 == 1;
        t.slot = int32_t(iter % 5);
        const bool fog = iter % 2 == 0;
        // Fragments: pixels of the tile at (x0, y0) around the triangle (outside it too: the
        // planes extrapolate, and a run's slack lanes read whatever follows).
        const int tx0 = std::max(0, int(cx) - 32) & ~(kTileSize - 1), ty0 = std::max(0, int(cy) - 32) & ~(kTileSize - 1);
        std::vector<uint16_t> fragPixel(slots + 8);
        for (auto& p : fragPixel) p = uint16_t(rng() % (kTileSize * kTileSize));
        ShadeBatch batch;
        batch.resize(slots);
        const float sentinel = -12345.0f;
        for (auto* v : {&batch.px, &batch.py, &batch.pz, &batch.nx, &batch.ny, &batch.nz}) std::fill(v->begin(), v->end(), sentinel);
        std::fill(batch.mat.begin(), batch.mat.end(), -7);
        std::vector<float> fogDist(slots + ShadeBatch::kSlack, sentinel);
        const size_t k = rng() % 100, count = 1 + rng() % 60;
        preparePlainRun(t, fog, fragPixel.data(), tx0, ty0, k, count, BatchOut(batch), fogDist.data());
        for (size_t s = 0; s < slots; ++s) {
            const bool inRun = s >= k && s < k + count;
            if (!inRun) {   // before the run or past its slack: untouched
                if (s < k || s >= k + count + 7) {
                    ASSERT_EQ(batch.px[s], sentinel) << "slot " << s << " outside run " << k << "+" << count;
                    ASSERT_EQ(batch.mat[s], -7);
                    ASSERT_EQ(fogDist[s], sentinel);
                }
                continue;
            }
            const int p = fragPixel[s];
            const PreparedRef r = prepareScalar(t, fog, tx0 + p % kTileSize, ty0 + p / kTileSize);
            const float got[7] = {batch.px[s], batch.py[s], batch.pz[s], batch.nx[s], batch.ny[s], batch.nz[s], fogDist[s]};
            const float want[7] = {r.pos.x, r.pos.y, r.pos.z, r.n.x, r.n.y, r.n.z, r.fog};
            for (int c = 0; c < 7; ++c)
                ASSERT_TRUE(sameFloat(got[c], want[c]))
                    << "iteration " << iter << " slot " << s << " value " << c << ": " << got[c] << " vs " << want[c];
            ASSERT_EQ(batch.mat[s], t.slot);
            ++checked;
        }
    }
    EXPECT_GT(checked, 50000);
}

// Every float from 2^-14 to 1 (the range the encoder's buckets cover, and a little below it),
// plus values outside [0, 1], NaN and infinities, through the output kernel without fog: the
// byte SrgbEncoder::operator() gives (which is rnd::toByteSRGB's), in each of R, G and B.
TEST(RasterTileKernelTest, OutputEncodesEveryFloatLikeTheScalarEncoder) {
    const SrgbEncoder& enc = srgbEncoder();
    constexpr size_t kBatch = 4096;
    std::vector<float> r(kBatch + 8), g(kBatch + 8), b(kBatch + 8), fogDist(kBatch + 8, 0.0f);
    std::vector<uint16_t> fragPixel(kBatch + 8);
    for (size_t i = 0; i < kBatch + 8; ++i) fragPixel[i] = uint16_t(i % kBatch);
    std::vector<uint32_t> color(kBatch);
    auto check = [&](size_t n, const char* what) {
        // G and B get the values in another order, so that each lane sees different buckets.
        for (size_t i = 0; i < n; ++i) {
            g[i] = r[n - 1 - i];
            b[i] = r[(i * 7) % n];
        }
        writeFragments(r.data(), g.data(), b.data(), fogDist.data(), fragPixel.data(), n, LinearFog{}, enc, color.data());
        for (size_t i = 0; i < n; ++i) {
            const uint32_t want = uint32_t(enc(r[i])) | uint32_t(enc(g[i])) << 8 | uint32_t(enc(b[i])) << 16 | 0xFF000000u;
            if (color[i] != want) {
                ADD_FAILURE() << what << ": " << r[i] << " (bits " << std::hex << *reinterpret_cast<const uint32_t*>(&r[i]) << ") gives " << color[i]
                              << ", want " << want;
                return false;
            }
        }
        return true;
    };
    size_t mismatchToByte = 0;
    uint32_t bits = 0x38800000u;        // 2^-14
    const uint32_t end = 0x3F800000u;   // 1.0
    while (bits <= end) {
        size_t n = 0;
        for (; n < kBatch && bits <= end; ++n, ++bits) std::memcpy(&r[n], &bits, 4);
        for (size_t i = 0; i < n; ++i) mismatchToByte += enc(r[i]) != rnd::toByteSRGB(r[i]);
        ASSERT_TRUE(check(n, "float in [2^-14, 1]"));
    }
    EXPECT_EQ(mismatchToByte, 0u) << "SrgbEncoder and rnd::toByteSRGB disagree";
    const float specials[] = {0.0f,
                              -0.0f,
                              -1.0f,
                              1e-30f,
                              0x1p-13f,
                              1.0f,
                              1.0000001f,
                              2.0f,
                              1e30f,
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::quiet_NaN(),
                              0x1p-20f,
                              0.5f};
    size_t n = 0;
    for (float v : specials) r[n++] = v;
    EXPECT_TRUE(check(n, "special value"));
}

// Linear fog in the output kernel: the renderer's scalar formula (vis clamped to [0, 1]) on each
// channel before encoding, distances before the start, inside and past the end.
TEST(RasterTileKernelTest, OutputAppliesLinearFogLikeTheScalarFormula) {
    const SrgbEncoder& enc = srgbEncoder();
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> P(0.0f, 1.0f);
    const size_t n = 1003;
    std::vector<float> r(n + 8), g(n + 8), b(n + 8), dist(n + 8);
    std::vector<uint16_t> fragPixel(n + 8);
    for (size_t i = 0; i < n + 8; ++i) {
        r[i] = 1.2f * P(rng);
        g[i] = P(rng);
        b[i] = P(rng) * P(rng);
        dist[i] = 60.0f * P(rng);
        fragPixel[i] = uint16_t((i * 37) % 4096);
    }
    LinearFog fog;
    fog.on = true;
    fog.end = 40.0f;
    fog.range = 40.0f - 5.0f;
    fog.color = vec3(0.6f, 0.7f, 0.8f);
    std::vector<uint32_t> color(4096, 0);
    writeFragments(r.data(), g.data(), b.data(), dist.data(), fragPixel.data(), n, fog, enc, color.data());
    for (size_t i = 0; i < n; ++i) {
        const float vis = std::clamp((fog.end - dist[i]) / fog.range, 0.0f, 1.0f);
        const vec3 c = vis * vec3(r[i], g[i], b[i]) + (1.0f - vis) * fog.color;
        const uint32_t want = uint32_t(enc(c.x)) | uint32_t(enc(c.y)) << 8 | uint32_t(enc(c.z)) << 16 | 0xFF000000u;
        ASSERT_EQ(color[fragPixel[i]], want) << "fragment " << i << " at distance " << dist[i];
    }
}
