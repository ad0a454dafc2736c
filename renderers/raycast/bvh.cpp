// bvh.cpp - BVH4 construction (binned SAH, top-down, oneTBB tasks for big subtrees) and the
// triangle packet tests.
//
// Sections: PrimRef + binning, node building, Bvh4::build, TriangleBvh, brute force.
//
// Build: every primitive becomes a PrimRef (box + id). A node starts with its whole range as
// one child and repeatedly splits the child with the largest surface area (binned SAH over all
// three axes, 16 bins, cost counted in blocks of 4 primitives since leaves are 4-packets) until
// it has 4 children or none can be split. Ranges of <= maxLeafSize primitives become leaves.
#include "raycast/bvh.h"

#include <tbb/task_group.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/blocked_range.h>

#include <xmmintrin.h>
#include <emmintrin.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <memory>

namespace rnd::rt {

using sg::vec3;

namespace {

// --- PrimRef + binning ----------------------------------------------------------------------

struct alignas(16) PrimRef {
    __m128 lo, hi;   // lo.w holds the primitive id (bit pattern)
    uint32_t id() const { uint32_t i; float f = _mm_cvtss_f32(_mm_shuffle_ps(lo, lo, _MM_SHUFFLE(3, 3, 3, 3))); std::memcpy(&i, &f, 4); return i; }
    __m128 center2() const { return _mm_add_ps(lo, hi); }   // 2 x centroid
};

inline PrimRef makeRef(const vec3& mn, const vec3& mx, uint32_t id) {
    float f;
    std::memcpy(&f, &id, 4);
    return {_mm_setr_ps(mn.x, mn.y, mn.z, f), _mm_setr_ps(mx.x, mx.y, mx.z, 0.0f)};
}

struct Box {
    __m128 lo = _mm_set1_ps(std::numeric_limits<float>::infinity());
    __m128 hi = _mm_set1_ps(-std::numeric_limits<float>::infinity());
    void extend(__m128 l, __m128 h) { lo = _mm_min_ps(lo, l); hi = _mm_max_ps(hi, h); }
    void extend(const Box& b) { extend(b.lo, b.hi); }
    float halfArea() const {
        alignas(16) float e[4];
        _mm_store_ps(e, _mm_sub_ps(hi, lo));
        if (e[0] < 0 || e[1] < 0 || e[2] < 0) return 0.0f;
        return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
    }
};

struct Range {
    uint32_t begin = 0, end = 0;
    Box bounds;      // of the primitives
    Box centroids;   // of 2 x centroids
    uint32_t count() const { return end - begin; }
};

// Bounds and centroid bounds of refs[begin, end).
void computeBounds(const PrimRef* refs, Range& r) {
    Box b, c;
    for (uint32_t i = r.begin; i < r.end; ++i) {
        b.extend(refs[i].lo, refs[i].hi);
        __m128 cc = refs[i].center2();
        c.extend(cc, cc);
    }
    // lo.w contains ids: clear it so bounds stay meaningful in xyz (w is ignored anyway).
    r.bounds = b;
    r.centroids = c;
}

constexpr int kMaxBins = 32;

inline int blocks(uint32_t n, int leafSize) { return int((n + uint32_t(leafSize) - 1) / uint32_t(leafSize)); }

// Splits r into l and rr (binned SAH); returns false when r should stay a leaf.
bool splitRange(PrimRef* refs, const Range& r, Range& l, Range& rr, int nbins, int leafSize, bool forceMedian) {
    const uint32_t n = r.count();
    alignas(16) float cmin[4], cmax[4];
    _mm_store_ps(cmin, r.centroids.lo);
    _mm_store_ps(cmax, r.centroids.hi);
    float ext[3] = {cmax[0] - cmin[0], cmax[1] - cmin[1], cmax[2] - cmin[2]};

    int bestAxis = -1, bestPos = 0;
    float bestCost = std::numeric_limits<float>::infinity();
    float scale[3];
    if (!forceMedian) {
        Box bins[3][kMaxBins];
        uint32_t counts[3][kMaxBins] = {};
        for (int a = 0; a < 3; ++a) scale[a] = ext[a] > 0 ? float(nbins) * 0.99999f / ext[a] : 0.0f;
        const __m128 sc = _mm_setr_ps(scale[0], scale[1], scale[2], 0.0f);
        const __m128 cm = r.centroids.lo;
        const __m128i maxBin = _mm_set1_epi32(nbins - 1);
        for (uint32_t i = r.begin; i < r.end; ++i) {
            const PrimRef& p = refs[i];
            __m128i bi = _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(p.center2(), cm), sc));
            // clamp to [0, nbins-1] (SSE2 has no min_epi32: compare and blend)
            __m128i gt = _mm_cmpgt_epi32(bi, maxBin);
            bi = _mm_or_si128(_mm_and_si128(gt, maxBin), _mm_andnot_si128(gt, bi));
            bi = _mm_and_si128(bi, _mm_cmpgt_epi32(bi, _mm_set1_epi32(-1)));
            alignas(16) int b[4];
            _mm_store_si128(reinterpret_cast<__m128i*>(b), bi);
            bins[0][b[0]].extend(p.lo, p.hi); ++counts[0][b[0]];
            bins[1][b[1]].extend(p.lo, p.hi); ++counts[1][b[1]];
            bins[2][b[2]].extend(p.lo, p.hi); ++counts[2][b[2]];
        }
        for (int a = 0; a < 3; ++a) {
            if (!(ext[a] > 0)) continue;
            float rightArea[kMaxBins];
            uint32_t rightCount[kMaxBins];
            Box acc;
            uint32_t cnt = 0;
            for (int i = nbins - 1; i > 0; --i) {
                acc.extend(bins[a][i]);
                cnt += counts[a][i];
                rightArea[i] = acc.halfArea();
                rightCount[i] = cnt;
            }
            acc = Box();
            cnt = 0;
            for (int i = 1; i < nbins; ++i) {
                acc.extend(bins[a][i - 1]);
                cnt += counts[a][i - 1];
                if (cnt == 0 || rightCount[i] == 0) continue;
                float cost = acc.halfArea() * float(blocks(cnt, leafSize)) + rightArea[i] * float(blocks(rightCount[i], leafSize));
                if (cost < bestCost) { bestCost = cost; bestAxis = a; bestPos = i; }
            }
        }
    }

    uint32_t mid;
    if (bestAxis >= 0) {
        const float cm = cmin[bestAxis], s = scale[bestAxis];
        const int a = bestAxis, pos = bestPos;
        PrimRef* m = std::partition(refs + r.begin, refs + r.end, [&](const PrimRef& p) {
            alignas(16) float c[4];
            _mm_store_ps(c, p.center2());
            int b = std::min(int((c[a] - cm) * s), nbins - 1);
            return b < pos;
        });
        mid = uint32_t(m - refs);
        if (mid == r.begin || mid == r.end) mid = r.begin + n / 2;   // numerical corner case
    } else {
        // All centroids coincide (or median forced): split by order along the widest axis.
        int a = ext[0] >= ext[1] ? (ext[0] >= ext[2] ? 0 : 2) : (ext[1] >= ext[2] ? 1 : 2);
        mid = r.begin + n / 2;
        if (ext[a] > 0)
            std::nth_element(refs + r.begin, refs + mid, refs + r.end, [a](const PrimRef& x, const PrimRef& y) {
                alignas(16) float cx[4], cy[4];
                _mm_store_ps(cx, x.center2());
                _mm_store_ps(cy, y.center2());
                return cx[a] < cy[a];
            });
    }
    l.begin = r.begin; l.end = mid;
    rr.begin = mid; rr.end = r.end;
    computeBounds(refs, l);
    computeBounds(refs, rr);
    return true;
}

// --- node building ----------------------------------------------------------------------------

struct Builder {
    PrimRef* refs;
    Node4* nodes;
    std::atomic<uint32_t> nodeCount{0};
    int nbins, leafSize;
    bool parallel;

    static void setEmpty(Node4& n, int i) {
        n.b[0][i] = n.b[2][i] = n.b[4][i] = std::numeric_limits<float>::infinity();
        n.b[1][i] = n.b[3][i] = n.b[5][i] = -std::numeric_limits<float>::infinity();
        n.child[i] = Node4::kEmpty;
    }
    static void setBounds(Node4& n, int i, const Box& b) {
        alignas(16) float lo[4], hi[4];
        _mm_store_ps(lo, b.lo);
        _mm_store_ps(hi, b.hi);
        n.b[0][i] = lo[0]; n.b[1][i] = hi[0];
        n.b[2][i] = lo[1]; n.b[3][i] = hi[1];
        n.b[4][i] = lo[2]; n.b[5][i] = hi[2];
    }
    static uint32_t leafRef(const Range& r) { return Node4::kLeafBit | (r.begin << 3) | r.count(); }

    // Builds the subtree for r into node slot `index` (already allocated).
    void buildInner(uint32_t index, const Range& r, int depth) {
        Range kids[4];
        int nk = 1;
        kids[0] = r;
        bool forceMedian = depth > 40;   // keeps the depth (and traversal stack) bounded
        while (nk < 4) {
            int best = -1;
            float bestArea = -1;
            for (int i = 0; i < nk; ++i)
                if (kids[i].count() > uint32_t(leafSize)) {
                    float a = kids[i].bounds.halfArea();
                    if (a > bestArea) { bestArea = a; best = i; }
                }
            if (best < 0) break;
            Range a, b;
            splitRange(refs, kids[best], a, b, nbins, leafSize, forceMedian);
            kids[best] = a;
            kids[nk++] = b;
        }
        Node4& node = nodes[index];
        uint32_t childIndex[4];
        for (int i = 0; i < 4; ++i) {
            if (i >= nk) { setEmpty(node, i); continue; }
            setBounds(node, i, kids[i].bounds);
            if (kids[i].count() <= uint32_t(leafSize)) {
                node.child[i] = leafRef(kids[i]);
                childIndex[i] = ~0u;
            } else {
                childIndex[i] = nodeCount.fetch_add(1, std::memory_order_relaxed);
                node.child[i] = childIndex[i];
            }
        }
        bool spawn = false;
        if (parallel)
            for (int i = 0; i < nk; ++i) spawn |= childIndex[i] != ~0u && kids[i].count() > 4096;
        if (spawn) {
            tbb::task_group tg;
            for (int i = 0; i < nk; ++i)
                if (childIndex[i] != ~0u) {
                    Range k = kids[i];
                    uint32_t ci = childIndex[i];
                    tg.run([this, ci, k, depth] { buildInner(ci, k, depth + 1); });
                }
            tg.wait();
        } else {
            for (int i = 0; i < nk; ++i)
                if (childIndex[i] != ~0u) buildInner(childIndex[i], kids[i], depth + 1);
        }
    }
};

int subtreeDepth(const std::vector<Node4>& nodes, uint32_t ref) {
    if (ref & Node4::kLeafBit) return 0;
    int d = 0;
    for (uint32_t c : nodes[ref].child)
        if (c != Node4::kEmpty) d = std::max(d, subtreeDepth(nodes, c));
    return d + 1;
}

}  // namespace

// --- Bvh4::build ------------------------------------------------------------------------------

namespace detail {
// Builds from prepared refs (shared by Bvh4::build and TriangleBvh::build).
void buildFromRefs(std::vector<PrimRef>& refs, const Bvh4::BuildOptions& opt, std::vector<Node4>& outNodes,
                   std::vector<uint32_t>& outPrims, sg::Aabb& outBounds) {
    outNodes.clear();
    outPrims.clear();
    outBounds = sg::Aabb();
    const size_t n = refs.size();
    if (n == 0) return;
    const int leafSize = std::clamp(opt.maxLeafSize, 1, 4);
    const int nbins = std::clamp(opt.bins, 2, kMaxBins);

    Range root;
    root.begin = 0;
    root.end = uint32_t(n);
    if (n > 65536) {
        struct Acc { Box b, c; };
        Acc acc = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, n, 16384), Acc{},
            [&](const tbb::blocked_range<size_t>& br, Acc a) {
                for (size_t i = br.begin(); i < br.end(); ++i) {
                    a.b.extend(refs[i].lo, refs[i].hi);
                    __m128 cc = refs[i].center2();
                    a.c.extend(cc, cc);
                }
                return a;
            },
            [](Acc x, const Acc& y) { x.b.extend(y.b); x.c.extend(y.c); return x; });
        root.bounds = acc.b;
        root.centroids = acc.c;
    } else {
        computeBounds(refs.data(), root);
    }

    // Inner nodes <= primitives (every inner node has >= 2 children); +1 for a wrapped leaf.
    std::unique_ptr<Node4[]> storage(new Node4[n + 1]);
    Builder b{refs.data(), storage.get(), {}, nbins, leafSize, opt.parallel};
    b.nodeCount = 1;
    if (root.count() <= uint32_t(leafSize)) {
        Node4& r = storage[0];
        for (int i = 0; i < 4; ++i) Builder::setEmpty(r, i);
        Builder::setBounds(r, 0, root.bounds);
        r.child[0] = Builder::leafRef(root);
    } else {
        b.buildInner(0, root, 0);
    }
    const uint32_t count = b.nodeCount.load();
    outNodes.assign(storage.get(), storage.get() + count);
    outPrims.resize(n);
    for (size_t i = 0; i < n; ++i) outPrims[i] = refs[i].id();
    alignas(16) float lo[4], hi[4];
    _mm_store_ps(lo, root.bounds.lo);
    _mm_store_ps(hi, root.bounds.hi);
    outBounds = {vec3(lo[0], lo[1], lo[2]), vec3(hi[0], hi[1], hi[2])};
}
}  // namespace detail

void Bvh4::build(const vec3* boxMin, const vec3* boxMax, size_t n, const BuildOptions& opt) {
    std::vector<PrimRef> refs;
    refs.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        const vec3 &mn = boxMin[i], &mx = boxMax[i];
        if (!(mn.x <= mx.x && mn.y <= mx.y && mn.z <= mx.z) || !sg::isFinite(mn) || !sg::isFinite(mx)) continue;
        refs.push_back(makeRef(mn, mx, uint32_t(i)));
    }
    detail::buildFromRefs(refs, opt, m_nodes, m_primIndex, m_bounds);
}

int Bvh4::depth() const { return m_nodes.empty() ? 0 : subtreeDepth(m_nodes, 0); }

namespace {
inline void setLane(TriPacket4& p, int k, const vec3& p0, const vec3& p1, const vec3& p2);
}

// --- TriangleBvh ------------------------------------------------------------------------------

void TriangleBvh::build(const vec3* pos, const uint32_t* idx, size_t triCount, const Bvh4::BuildOptions& opt) {
    std::vector<PrimRef> refs(triCount);
    std::atomic<size_t> valid{0};
    std::vector<uint8_t> ok(triCount);
    auto makeRange = [&](size_t b, size_t e) {
        for (size_t t = b; t < e; ++t) {
            const vec3 &p0 = pos[idx[3 * t]], &p1 = pos[idx[3 * t + 1]], &p2 = pos[idx[3 * t + 2]];
            vec3 mn = glm::min(p0, glm::min(p1, p2)), mx = glm::max(p0, glm::max(p1, p2));
            ok[t] = sg::isFinite(mn) && sg::isFinite(mx);
            refs[t] = makeRef(mn, mx, uint32_t(t));
        }
    };
    if (opt.parallel && triCount > 65536)
        tbb::parallel_for(tbb::blocked_range<size_t>(0, triCount, 16384),
                          [&](const tbb::blocked_range<size_t>& r) { makeRange(r.begin(), r.end()); });
    else
        makeRange(0, triCount);
    // Drop non-finite triangles (keeps the tree sane on bad input).
    size_t w = 0;
    for (size_t t = 0; t < triCount; ++t)
        if (ok[t]) refs[w++] = refs[t];
    refs.resize(w);
    (void)valid;

    std::vector<uint32_t> prims;
    detail::buildFromRefs(refs, opt, m_bvh.m_nodes, m_bvh.m_primIndex, m_bvh.m_bounds);
    // One packet per leaf; rewrite leaf refs to packet indices.
    m_packets.clear();
    m_packets.reserve(w / 2 + 1);
    for (Node4& n : m_bvh.m_nodes)
        for (uint32_t& c : n.child) {
            if (c == Node4::kEmpty || !(c & Node4::kLeafBit)) continue;
            uint32_t first = (c & ~Node4::kLeafBit) >> 3, count = c & 7u;
            TriPacket4 p{};
            for (uint32_t k = 0; k < 4; ++k) {
                if (k >= count) { p.prim[k] = ~0u; continue; }
                uint32_t t = m_bvh.m_primIndex[first + k];
                setLane(p, int(k), pos[idx[3 * t]], pos[idx[3 * t + 1]], pos[idx[3 * t + 2]]);
                p.prim[k] = t;
            }
            c = Node4::kLeafBit | (uint32_t(m_packets.size()) << 3) | count;
            m_packets.push_back(p);
        }
}

namespace {
// Moller-Trumbore on 4 triangles at once (seeds 2.4), rewritten with the precomputed normal
// N = e1 x e2 and s = o - p0, R = s x d (scalar triple products):
//   det = -d.N,  b1 = e2.R / det,  b2 = -e1.R / det,  t = s.N / det.
// Division-free: the comparisons use the sign-adjusted numerators against |det|; only lanes
// that hit are divided. Returns the lane mask of hits in (tmin, tmax) and their t, b1, b2.
inline int intersectPacket(const TriPacket4& p, const __m128 o[3], const __m128 d[3], __m128 tmin, __m128 tmax,
                           __m128& tOut, __m128& uOut, __m128& vOut) {
    const __m128 nx = _mm_load_ps(p.n[0]), ny = _mm_load_ps(p.n[1]), nz = _mm_load_ps(p.n[2]);
    const __m128 sx = _mm_sub_ps(o[0], _mm_load_ps(p.v0[0]));
    const __m128 sy = _mm_sub_ps(o[1], _mm_load_ps(p.v0[1]));
    const __m128 sz = _mm_sub_ps(o[2], _mm_load_ps(p.v0[2]));
    // det = -d.N
    __m128 det = _mm_add_ps(_mm_add_ps(_mm_mul_ps(d[0], nx), _mm_mul_ps(d[1], ny)), _mm_mul_ps(d[2], nz));
    det = _mm_xor_ps(det, _mm_set1_ps(-0.0f));
    const __m128 sign = _mm_and_ps(det, _mm_set1_ps(-0.0f));
    const __m128 absDet = _mm_xor_ps(det, sign);
    // R = s x d
    const __m128 rx = _mm_sub_ps(_mm_mul_ps(sy, d[2]), _mm_mul_ps(sz, d[1]));
    const __m128 ry = _mm_sub_ps(_mm_mul_ps(sz, d[0]), _mm_mul_ps(sx, d[2]));
    const __m128 rz = _mm_sub_ps(_mm_mul_ps(sx, d[1]), _mm_mul_ps(sy, d[0]));
    __m128 U = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_load_ps(p.e2[0]), rx), _mm_mul_ps(_mm_load_ps(p.e2[1]), ry)),
                          _mm_mul_ps(_mm_load_ps(p.e2[2]), rz));
    __m128 V = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_load_ps(p.e1[0]), rx), _mm_mul_ps(_mm_load_ps(p.e1[1]), ry)),
                          _mm_mul_ps(_mm_load_ps(p.e1[2]), rz));
    V = _mm_xor_ps(V, _mm_set1_ps(-0.0f));
    __m128 T = _mm_add_ps(_mm_add_ps(_mm_mul_ps(sx, nx), _mm_mul_ps(sy, ny)), _mm_mul_ps(sz, nz));
    U = _mm_xor_ps(U, sign);
    V = _mm_xor_ps(V, sign);
    T = _mm_xor_ps(T, sign);
    const __m128 zero = _mm_setzero_ps();
    __m128 ok = _mm_cmpneq_ps(det, zero);
    ok = _mm_and_ps(ok, _mm_cmpge_ps(U, zero));
    ok = _mm_and_ps(ok, _mm_cmpge_ps(V, zero));
    ok = _mm_and_ps(ok, _mm_cmple_ps(_mm_add_ps(U, V), absDet));
    ok = _mm_and_ps(ok, _mm_cmpgt_ps(T, _mm_mul_ps(absDet, tmin)));
    ok = _mm_and_ps(ok, _mm_cmplt_ps(T, _mm_mul_ps(absDet, tmax)));
    int mask = _mm_movemask_ps(ok);
    if (mask) {
        const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), absDet);
        tOut = _mm_mul_ps(T, inv);
        uOut = _mm_mul_ps(U, inv);
        vOut = _mm_mul_ps(V, inv);
        // Division rounding may push t to tmax: re-check on the divided values.
        mask &= _mm_movemask_ps(_mm_and_ps(_mm_cmplt_ps(tOut, tmax), _mm_cmpgt_ps(tOut, tmin)));
    }
    return mask;
}

// Packet lane k from triangle p0, p1, p2.
inline void setLane(TriPacket4& p, int k, const vec3& p0, const vec3& p1, const vec3& p2) {
    vec3 e1 = p1 - p0, e2 = p2 - p0, n = glm::cross(e1, e2);
    for (int a = 0; a < 3; ++a) { p.v0[a][k] = p0[a]; p.e1[a][k] = e1[a]; p.e2[a][k] = e2[a]; p.n[a][k] = n[a]; }
}
}  // namespace

bool TriangleBvh::intersect(const Ray& ray, TriHit& hit) const {
    if (m_bvh.empty()) return false;
    const __m128 o[3] = {_mm_set1_ps(ray.org.x), _mm_set1_ps(ray.org.y), _mm_set1_ps(ray.org.z)};
    const __m128 d[3] = {_mm_set1_ps(ray.dir.x), _mm_set1_ps(ray.dir.y), _mm_set1_ps(ray.dir.z)};
    const __m128 tmin = _mm_set1_ps(ray.tmin);
    float tmax = ray.tmax;
    bool found = false;
    const TriPacket4* packets = m_packets.data();
    m_bvh.traverse(ray, tmax, [&](uint32_t first, uint32_t, float& tm) {
        const TriPacket4& p = packets[first];
        __m128 t, u, v;
        int mask = intersectPacket(p, o, d, tmin, _mm_set1_ps(tm), t, u, v);
        if (mask) {
            alignas(16) float ta[4], ua[4], va[4];
            _mm_store_ps(ta, t);
            _mm_store_ps(ua, u);
            _mm_store_ps(va, v);
            while (mask) {
                int k = __builtin_ctz(mask);
                mask &= mask - 1;
                if (ta[k] < tm) {
                    tm = ta[k];
                    hit.t = ta[k];
                    hit.prim = p.prim[k];
                    hit.b1 = ua[k];
                    hit.b2 = va[k];
                    found = true;
                }
            }
        }
        return false;
    });
    return found;
}

bool TriangleBvh::occluded(const Ray& ray) const {
    if (m_bvh.empty()) return false;
    const __m128 o[3] = {_mm_set1_ps(ray.org.x), _mm_set1_ps(ray.org.y), _mm_set1_ps(ray.org.z)};
    const __m128 d[3] = {_mm_set1_ps(ray.dir.x), _mm_set1_ps(ray.dir.y), _mm_set1_ps(ray.dir.z)};
    const __m128 tmin = _mm_set1_ps(ray.tmin), tmaxV = _mm_set1_ps(ray.tmax);
    float tmax = ray.tmax;
    bool hitAny = false;
    const TriPacket4* packets = m_packets.data();
    m_bvh.traverse<true>(ray, tmax, [&](uint32_t first, uint32_t, float&) {
        __m128 t, u, v;
        if (intersectPacket(packets[first], o, d, tmin, tmaxV, t, u, v)) { hitAny = true; return true; }
        return false;
    });
    return hitAny;
}

// --- brute force ------------------------------------------------------------------------------

bool intersectBruteForce(const vec3* pos, const uint32_t* idx, size_t triCount, const Ray& ray, TriHit& hit) {
    const __m128 o[3] = {_mm_set1_ps(ray.org.x), _mm_set1_ps(ray.org.y), _mm_set1_ps(ray.org.z)};
    const __m128 d[3] = {_mm_set1_ps(ray.dir.x), _mm_set1_ps(ray.dir.y), _mm_set1_ps(ray.dir.z)};
    bool found = false;
    float tmax = ray.tmax;
    for (size_t t = 0; t < triCount; ++t) {
        TriPacket4 p{};
        setLane(p, 0, pos[idx[3 * t]], pos[idx[3 * t + 1]], pos[idx[3 * t + 2]]);
        __m128 tv, u, v;
        int mask = intersectPacket(p, o, d, _mm_set1_ps(ray.tmin), _mm_set1_ps(tmax), tv, u, v) & 1;
        if (mask) {
            alignas(16) float ta[4], ua[4], va[4];
            _mm_store_ps(ta, tv);
            _mm_store_ps(ua, u);
            _mm_store_ps(va, v);
            tmax = ta[0];
            hit.t = ta[0];
            hit.prim = uint32_t(t);
            hit.b1 = ua[0];
            hit.b2 = va[0];
            found = true;
        }
    }
    return found;
}

}  // namespace rnd::rt
