// bvh.cpp - BVH4 construction (binned SAH, top-down, oneTBB tasks for big subtrees) and the
// triangle packet tests.
//
// Sections: PrimRef + binning, node building, Bvh4::build, TriangleBvh, brute force.
//
// Build: every primitive becomes a PrimRef (box + id). A node starts with its whole range as
// one child and repeatedly splits the child with the largest surface area (binned SAH over all
// three axes, 16 bins (32 for big ranges), cost counted in blocks of 4 primitives since leaves
// are 4-packets) until it has W (4 or 8) children or none has more than maxLeafSize
// primitives. Then each child of <= maxLeafSize primitives becomes a leaf; so does one of up to
// maxLeafBlocks blocks whose SAH cost as one leaf (halfArea * blocks) is no more than that of
// its best split plus a node visit (traversalCost * halfArea): Embree's leaf rule, deciding
// whether a child gets a node of its own. Every other child becomes an inner node, recursively.
#include "raycast/bvh.h"
#include "raycast/bvh_binning.h"
#include "renderers/debug_switches.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_group.h>

#include <immintrin.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <memory>

namespace rnd::rt {

using sg::vec3;
using namespace binning;

namespace {

struct HugeDeleter {
    size_t bytes;
    void operator()(void* p) const noexcept { hugeFree(p, bytes); }
};

// --- node building ----------------------------------------------------------------------------

// A leaf as the builder makes it: refs[first, first + count). Inner nodes refer to leaves as
// kLeafBit | leaf index; the callers turn that into their own leaf encoding afterwards
// (Bvh4: primitive range, TriangleBvh: packet range).
struct LeafRec {
    uint32_t first, count;
};

template <int W>
struct Builder {
    using Node = NodeW<W>;
    PrimRef* refs;
    Node* nodes;
    LeafRec* leaves;
    std::atomic<uint32_t> nodeCount{0};
    std::atomic<uint32_t> leafCount{0};
    std::atomic<bool> spawned{false};   // subtrees built by tasks interleave their nodes
    int nbins, leafSize;
    // Ranges of more than leafSize but at most maxLeaf primitives become one leaf of several
    // blocks when the SAH says so: halfArea * blocks <= travCost * halfArea + split cost
    // (a node visit costs travCost block tests). maxLeaf == leafSize: always split.
    int maxLeaf;
    float travCost;
    bool parallel;

    static void setEmpty(Node& n, int i) {
        n.b[0][i] = n.b[2][i] = n.b[4][i] = std::numeric_limits<float>::infinity();
        n.b[1][i] = n.b[3][i] = n.b[5][i] = -std::numeric_limits<float>::infinity();
        n.child[i] = Node4::kEmpty;
    }
    static void setBounds(Node& n, int i, const Box& b) {
        alignas(16) float lo[4], hi[4];
        _mm_store_ps(lo, b.lo);
        _mm_store_ps(hi, b.hi);
        n.b[0][i] = lo[0];
        n.b[1][i] = hi[0];
        n.b[2][i] = lo[1];
        n.b[3][i] = hi[1];
        n.b[4][i] = lo[2];
        n.b[5][i] = hi[2];
    }
    uint32_t makeLeaf(const Range& r) {
        const uint32_t i = leafCount.fetch_add(1, std::memory_order_relaxed);
        leaves[i] = {r.begin, r.count()};
        return Node4::kLeafBit | i;
    }

    // A child range under construction: whether it stays a leaf, and its split when the
    // leaf test already computed it.
    struct Kid {
        Range r, a, b;
        float cost = 0;   // of the split a, b
        bool leaf = false, hasSplit = false;
    };
    // Whether a child that is not split within its parent becomes a leaf: always at <= leafSize
    // primitives; up to maxLeaf when the SAH prefers one leaf to a node of its own (Embree's
    // rule: halfArea * blocks <= travCost * halfArea + split cost). Keeps the split it computed.
    void decide(Kid& k, bool forceMedian) {
        const uint32_t n = k.r.count();
        k.leaf = n <= uint32_t(leafSize);
        if (k.leaf || n > uint32_t(maxLeaf)) return;
        ensureSplit(k, forceMedian);
        const float area = k.r.bounds.halfArea();
        k.leaf = area * float(blocks(n, leafSize)) <= travCost * area + k.cost;
    }

    // Computes k's split unless it is known (kept in k for the fill loop, decide() and the
    // child's own subtree).
    void ensureSplit(Kid& k, bool forceMedian) {
        if (k.hasSplit) return;
        splitRange(refs, k.r, k.a, k.b, nbins, leafSize, forceMedian, &k.cost);
        k.hasSplit = true;
    }

    // Splits, in parallel, every child of more than 1024 primitives that has no split yet
    // (when there are two or more). None of it is speculative: a child of more than leafSize
    // primitives is split either in this node's fill loop or as the root of its own subtree,
    // which reuses the split; and the children's ranges are disjoint. Without it, filling the
    // root node of a 1M-triangle BVH8 (about 3n of binning and partitioning) ran on one
    // thread: 40 of the 163 ms of a 2-thread build.
    void presplit(Kid* kids, int nk, bool forceMedian) {
        int todo[W], nt = 0;
        for (int i = 0; i < nk; ++i)
            if (!kids[i].hasSplit && kids[i].r.count() > 1024) todo[nt++] = i;
        if (nt >= 2) tbb::parallel_for(0, nt, [&](int j) { ensureSplit(kids[todo[j]], forceMedian); });
    }

    // Builds the subtree for `root` (not a leaf; its split may already be known from the
    // parent's leaf test) into node slot `index` (already allocated).
    void buildInner(uint32_t index, const Kid& root, int depth) {
        Kid kids[W];
        int nk = 1;
        kids[0] = root;
        bool forceMedian = depth > 40;   // keeps the depth (and traversal stack) bounded
        // Fill the node: split the child with the largest surface area until there are W of
        // them or none has more than leafSize primitives. A child that would make a good leaf
        // is split too while the node has room: its pieces cost a box test each in the same
        // node visit and fewer triangle tests (Embree fills its nodes so). Against stopping at
        // SAH leaves here, 1M-triangle benchmark scene: 7.2 instead of 4.3 children per BVH8
        // node, SAH cost 18.9 instead of 23.3 (Embree's tree: 17.9), packet tests per primary
        // ray 2.1 instead of 3.4; incoherent rays ~+10%.
        while (nk < W) {
            int best = -1;
            float bestArea = -1;
            for (int i = 0; i < nk; ++i)
                if (kids[i].r.count() > uint32_t(leafSize)) {
                    float a = kids[i].r.bounds.halfArea();
                    if (a > bestArea) {
                        bestArea = a;
                        best = i;
                    }
                }
            if (best < 0) break;
            Kid& k = kids[best];
            if (!k.hasSplit && parallel) presplit(kids, nk, forceMedian);
            ensureSplit(k, forceMedian);
            const Range a = k.a, b = k.b;
            kids[best] = Kid{};
            kids[best].r = a;
            kids[nk] = Kid{};
            kids[nk].r = b;
            ++nk;
        }
        for (int i = 0; i < nk; ++i) decide(kids[i], forceMedian);
        Node& node = nodes[index];
        uint32_t childIndex[W];
        for (int i = 0; i < W; ++i) {
            if (i >= nk) {
                setEmpty(node, i);
                continue;
            }
            setBounds(node, i, kids[i].r.bounds);
            if (kids[i].leaf) {
                node.child[i] = makeLeaf(kids[i].r);
                childIndex[i] = ~0u;
            } else {
                childIndex[i] = nodeCount.fetch_add(1, std::memory_order_relaxed);
                node.child[i] = childIndex[i];
            }
        }
        // Tasks for children of more than 1024 primitives (a few hundred microseconds of work):
        // with 4096, a 10k-triangle mesh, whose root splits into 8 children of ~1250, was built
        // on one thread only (2-thread build 0.9x Embree's; now 1.3x).
        bool spawn = false;
        if (parallel)
            for (int i = 0; i < nk; ++i) spawn |= childIndex[i] != ~0u && kids[i].r.count() > 1024;
        if (spawn) {
            spawned.store(true, std::memory_order_relaxed);
            tbb::task_group tg;
            for (int i = 0; i < nk; ++i)
                if (childIndex[i] != ~0u) {
                    const Kid k = kids[i];
                    const uint32_t ci = childIndex[i];
                    tg.run([this, ci, k, depth] { buildInner(ci, k, depth + 1); });
                }
            tg.wait();
        } else {
            for (int i = 0; i < nk; ++i)
                if (childIndex[i] != ~0u) buildInner(childIndex[i], kids[i], depth + 1);
        }
    }
};

template <int W>
int subtreeDepth(const std::vector<NodeW<W>>& nodes, uint32_t ref) {
    if (ref & Node4::kLeafBit) return 0;
    int d = 0;
    for (uint32_t c : nodes[ref].child)
        if (c != Node4::kEmpty) d = std::max(d, subtreeDepth(nodes, c));
    return d + 1;
}

}   // namespace

// --- Bvh4::build ------------------------------------------------------------------------------

namespace detail {
// Builds from prepared refs (shared by Bvh4::build and TriangleBvh::build).
template <int W, class NodeVec>
// Leaves come out as kLeafBit | index into outLeaves.
void buildFromRefs(PrimRef* refs, size_t n, const Bvh4::BuildOptions& opt, int maxLeaf, NodeVec& outNodes, std::vector<uint32_t>& outPrims,
                   std::vector<LeafRec>& outLeaves, sg::Aabb& outBounds) {
    outNodes.clear();
    outPrims.clear();
    outLeaves.clear();
    outBounds = sg::Aabb();
    if (n == 0) return;
    const int leafSize = std::clamp(opt.maxLeafSize, 1, 4);
    const int nbins = std::clamp(opt.bins, 2, kMaxBins);

    Range root;
    root.begin = 0;
    root.end = uint32_t(n);
    if (n > 65536) {
        struct Acc {
            Box b, c;
        };
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
            [](Acc x, const Acc& y) {
                x.b.extend(y.b);
                x.c.extend(y.c);
                return x;
            });
        root.bounds = acc.b;
        root.centroids = acc.c;
    } else {
        computeBounds(refs, root);
    }

    // Inner nodes <= primitives (every inner node has >= 2 children); +1 for a wrapped leaf.
    const size_t storageBytes = (n + 1) * sizeof(NodeW<W>);
    std::unique_ptr<NodeW<W>[], HugeDeleter> storage(static_cast<NodeW<W>*>(hugeAlloc(storageBytes)), HugeDeleter{storageBytes});
    // Leaves <= primitives.
    const size_t leafBytes = n * sizeof(LeafRec);
    std::unique_ptr<LeafRec[], HugeDeleter> leaves(static_cast<LeafRec*>(hugeAlloc(leafBytes)), HugeDeleter{leafBytes});
    Builder<W> b{
        refs, storage.get(), leaves.get(), {}, {}, {}, nbins, leafSize, std::max(maxLeaf, leafSize), std::max(opt.traversalCost, 0.0f), opt.parallel};
    b.nodeCount = 1;
    if (root.count() <= uint32_t(leafSize)) {
        NodeW<W>& r = storage[0];
        for (int i = 0; i < W; ++i) Builder<W>::setEmpty(r, i);
        Builder<W>::setBounds(r, 0, root.bounds);
        r.child[0] = b.makeLeaf(root);
    } else {
        typename Builder<W>::Kid rootKid;
        rootKid.r = root;
        b.buildInner(0, rootKid, 0);
    }
    const uint32_t count = b.nodeCount.load();
    // Layout: each node's inner children side by side (the traversal tests a node's child
    // boxes at once and then usually visits siblings next), groups in depth-first order. A
    // serial build allocates exactly so (measured on 1M triangles, 1 thread: coherent rays
    // ~8-15% faster than a plain depth-first preorder); subtrees built by parallel tasks
    // interleave, so those are laid out again in the same order.
    if (!b.spawned.load()) {
        outNodes.assign(storage.get(), storage.get() + count);
    } else {
        outNodes.resize(count);
        std::vector<uint32_t> newIndex(count, ~0u);
        std::vector<uint32_t> stack{0};
        newIndex[0] = 0;
        uint32_t next = 1;
        // Pass 1: number the children of each node together, visiting nodes depth first.
        while (!stack.empty()) {
            uint32_t old = stack.back();
            stack.pop_back();
            const NodeW<W>& nd = storage[old];
            for (int i = 0; i < W; ++i) {
                uint32_t c = nd.child[i];
                if (c != NodeBits::kEmpty && !(c & NodeBits::kLeafBit)) newIndex[c] = next++;
            }
            for (int i = W - 1; i >= 0; --i) {
                uint32_t c = nd.child[i];
                if (c != NodeBits::kEmpty && !(c & NodeBits::kLeafBit)) stack.push_back(c);
            }
        }
        // Pass 2: copy and remap child links.
        for (uint32_t old = 0; old < count; ++old) {
            if (newIndex[old] == ~0u) continue;
            NodeW<W> nd = storage[old];
            for (int i = 0; i < W; ++i) {
                uint32_t c = nd.child[i];
                if (c != NodeBits::kEmpty && !(c & NodeBits::kLeafBit)) nd.child[i] = newIndex[c];
            }
            outNodes[newIndex[old]] = nd;
        }
        outNodes.resize(next);
    }
    outLeaves.assign(leaves.get(), leaves.get() + b.leafCount.load());
    outPrims.resize(n);
    auto copyIds = [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) outPrims[i] = refs[i].id();
    };
    if (opt.parallel && n > 65536)
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16384), [&](const tbb::blocked_range<size_t>& r) { copyIds(r.begin(), r.end()); });
    else
        copyIds(0, n);
    alignas(16) float lo[4], hi[4];
    _mm_store_ps(lo, root.bounds.lo);
    _mm_store_ps(hi, root.bounds.hi);
    outBounds = {vec3(lo[0], lo[1], lo[2]), vec3(hi[0], hi[1], hi[2])};
}
}   // namespace detail

void Bvh4::build(const vec3* boxMin, const vec3* boxMax, size_t n, const BuildOptions& opt) {
    if (n >= (size_t(1) << 28)) n = 0;   // leaf references hold (first << 3) in 31 bits
    std::vector<PrimRef> refs;
    refs.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        const vec3 &mn = boxMin[i], &mx = boxMax[i];
        if (!(mn.x <= mx.x && mn.y <= mx.y && mn.z <= mx.z) || !sg::isFinite(mn) || !sg::isFinite(mx)) continue;
        refs.push_back(makeRef(mn, mx, uint32_t(i)));
    }
    // Leaves of up to 7 primitives (the count has 3 bits).
    const int leafSize = std::clamp(opt.maxLeafSize, 1, 4);
    const int maxLeaf = std::min(leafSize * std::max(opt.maxLeafBlocks, 1), 7);
    std::vector<LeafRec> leaves;
    detail::buildFromRefs<4>(refs.data(), refs.size(), opt, maxLeaf, m_nodes, m_primIndex, leaves, m_bounds);
    for (Node4& nd : m_nodes)
        for (uint32_t& c : nd.child)
            if (c != NodeBits::kEmpty && (c & NodeBits::kLeafBit)) {
                const LeafRec& l = leaves[c & ~NodeBits::kLeafBit];
                c = NodeBits::kLeafBit | (l.first << 3) | l.count;
            }
}

int Bvh4::depth() const { return m_nodes.empty() ? 0 : subtreeDepth<4>(m_nodes, 0); }

namespace {
// Packet lane k from triangle p0, p1, p2.
// noinline: the AVX2 brute force must build lanes bit-identically to the (SSE-compiled) build.
// (The builder inlines setLaneInline: it is compiled for the baseline target, so no FMA
// contraction can make the two differ.)
inline __attribute__((always_inline)) void setLaneInline(TriPacket4& p, int k, const vec3& p0, const vec3& p1, const vec3& p2) {
    vec3 e1 = p1 - p0, e2 = p2 - p0, n = glm::cross(e1, e2);
    for (int a = 0; a < 3; ++a) {
        p.v0[a][k] = p0[a];
        p.e1[a][k] = e1[a];
        p.e2[a][k] = e2[a];
        p.n[a][k] = n[a];
    }
}
}   // namespace

// Out of line for the brute-force reference of bvh_trace.cpp (see setLaneInline).
__attribute__((noinline)) void setLane(TriPacket4& p, int k, const vec3& p0, const vec3& p1, const vec3& p2) { setLaneInline(p, k, p0, p1, p2); }

namespace {
// Each leaf's triangles as consecutive packets, leaves in node order; leaf refs become
// kLeafBit | (first packet << 3) | packet count. A serial pass over the nodes numbers the
// packets (the same order as filling them one by one); the leaves are then filled in
// parallel (2-thread 1M-triangle build: this was 18 ms of serial work).
template <int W>
void makePackets(HugeVector<NodeW<W>>& nodes, const std::vector<uint32_t>& prims, const std::vector<LeafRec>& leaves, const vec3* pos,
                 const uint32_t* idx, HugeVector<TriPacket4>& packets, HugeVector<uint32_t>& ids, bool parallel) {
    std::vector<uint32_t> firstPacket(leaves.size(), ~0u);   // per leaf record (~0u: not referenced)
    uint32_t total = 0;
    for (NodeW<W>& n : nodes)
        for (uint32_t& c : n.child) {
            if (c == NodeBits::kEmpty || !(c & NodeBits::kLeafBit)) continue;
            const uint32_t leaf = c & ~NodeBits::kLeafBit;
            const uint32_t count = (leaves[leaf].count + 3) / 4;
            firstPacket[leaf] = total;
            c = NodeBits::kLeafBit | (total << 3) | count;
            total += count;
        }
    packets.resize(total);
    ids.resize(size_t(total) * 4);
    auto fill = [&](size_t begin, size_t end) {
        for (size_t leaf = begin; leaf < end; ++leaf) {
            const LeafRec& l = leaves[leaf];
            uint32_t pi = firstPacket[leaf];
            if (pi == ~0u) continue;
            for (uint32_t base = 0; base < l.count; base += 4, ++pi) {
                TriPacket4 p{};   // empty lanes stay zero: det = 0, never a hit
                for (uint32_t k = 0; k < 4; ++k) {
                    uint32_t id = ~0u;
                    if (base + k < l.count) {
                        id = prims[l.first + base + k];
                        setLaneInline(p, int(k), pos[idx[3 * id]], pos[idx[3 * id + 1]], pos[idx[3 * id + 2]]);
                    }
                    ids[4 * size_t(pi) + k] = id;
                }
                packets[pi] = p;
            }
        }
    };
    if (parallel && leaves.size() > 4096)
        tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 2048), [&](const tbb::blocked_range<size_t>& r) { fill(r.begin(), r.end()); });
    else
        fill(0, leaves.size());
}
}   // namespace

// 4 (SSE: BVH4) or 8 (AVX2+FMA: BVH8): the width of the kernels bvh_trace.cpp runs here.
int kernelWidth();

// --- TriangleBvh ------------------------------------------------------------------------------

void TriangleBvh::build(const vec3* pos, const uint32_t* idx, size_t triCount, const Bvh4::BuildOptions& opt) {
    // Leaf references hold (first << 3) in 31 bits: 2^28 primitives at most per BVH.
    if (triCount >= (size_t(1) << 28)) triCount = 0;
    // Refs without zero-filling (every slot is written), compacted in place only when some
    // triangle has a non-finite coordinate (keeps the tree sane on bad input).
    const size_t refBytes = std::max<size_t>(triCount, 1) * sizeof(PrimRef);
    std::unique_ptr<PrimRef[], HugeDeleter> refs(static_cast<PrimRef*>(hugeAlloc(refBytes)), HugeDeleter{refBytes});
    std::atomic<bool> allFinite{true};
    auto makeRange = [&](size_t b, size_t e) {
        const __m128 zero = _mm_setzero_ps();
        bool finite = true;
        for (size_t t = b; t < e; ++t) {
            const vec3 &p0 = pos[idx[3 * t]], &p1 = pos[idx[3 * t + 1]], &p2 = pos[idx[3 * t + 2]];
            __m128 a = _mm_setr_ps(p0.x, p0.y, p0.z, 0), c = _mm_setr_ps(p1.x, p1.y, p1.z, 0), d = _mm_setr_ps(p2.x, p2.y, p2.z, 0);
            __m128 mn = _mm_min_ps(a, _mm_min_ps(c, d)), mx = _mm_max_ps(a, _mm_max_ps(c, d));
            // x - x is 0 exactly for finite x (NaN otherwise); a NaN coordinate may also be
            // dropped by min/max, so check the vertices themselves.
            __m128 all = _mm_add_ps(_mm_add_ps(_mm_sub_ps(a, a), _mm_sub_ps(c, c)), _mm_sub_ps(d, d));
            finite &= _mm_movemask_ps(_mm_cmpeq_ps(all, zero)) == 0xF;
            // lo = (min.xyz, id bits): tmp = (min.z, min.z, id, id), then pick x, y from min.
            __m128 idv = _mm_castsi128_ps(_mm_cvtsi32_si128(int(uint32_t(t))));
            __m128 tmp = _mm_shuffle_ps(mn, idv, _MM_SHUFFLE(0, 0, 2, 2));
            refs[t].lo = _mm_shuffle_ps(mn, tmp, _MM_SHUFFLE(2, 0, 1, 0));
            refs[t].hi = mx;
        }
        if (!finite) allFinite.store(false, std::memory_order_relaxed);
    };
    if (opt.parallel && triCount > 65536)
        tbb::parallel_for(tbb::blocked_range<size_t>(0, triCount, 16384),
                          [&](const tbb::blocked_range<size_t>& r) { makeRange(r.begin(), r.end()); });
    else
        makeRange(0, triCount);
    size_t refCount = triCount;
    if (!allFinite.load()) {
        size_t w = 0;
        for (size_t t = 0; t < triCount; ++t)
            if (sg::isFinite(pos[idx[3 * t]]) && sg::isFinite(pos[idx[3 * t + 1]]) && sg::isFinite(pos[idx[3 * t + 2]])) refs[w++] = refs[t];
        refCount = w;
    }

    std::vector<uint32_t> prims;
    std::vector<LeafRec> leaves;
    // Leaves of up to 7 packets (the count has 3 bits).
    const int maxLeaf = 4 * std::clamp(opt.maxLeafBlocks, 1, 7);
    m_nodes4.clear();
    m_nodes8.clear();
    m_packets.clear();
    m_prims.clear();
    bool wide = kernelWidth() == 8;
    if (wide) {
        detail::buildFromRefs<8>(refs.get(), refCount, opt, maxLeaf, m_nodes8, prims, leaves, m_bounds);
        // Inner children by byte offset (see bvh.h), which must stay below the leaf bit.
        static_assert(sizeof(Node8) << 23 == size_t(1) << 31);
        if (m_nodes8.size() <= std::min<uint32_t>(opt.maxWideNodes, 1u << 23)) {
            makePackets(m_nodes8, prims, leaves, pos, idx, m_packets, m_prims, opt.parallel);
            for (Node8& nd : m_nodes8)
                for (uint32_t& c : nd.child)
                    if (c != NodeBits::kEmpty && !(c & NodeBits::kLeafBit)) c *= uint32_t(sizeof(Node8));
        } else {   // too many nodes to address that way: a BVH4 (same kernels, 4-wide nodes)
            m_nodes8 = {};
            wide = false;
        }
    }
    if (!wide) {
        detail::buildFromRefs<4>(refs.get(), refCount, opt, maxLeaf, m_nodes4, prims, leaves, m_bounds);
        makePackets(m_nodes4, prims, leaves, pos, idx, m_packets, m_prims, opt.parallel);
    }
    for (int a = 0; a < 3; ++a) m_absMax[a] = m_packets.empty() ? 0.0f : std::max(std::abs(m_bounds.min[a]), std::abs(m_bounds.max[a]));
}

std::vector<sg::Aabb> TriangleBvh::rootChildBoxes() const {
    std::vector<sg::Aabb> out;
    auto collect = [&](const auto& root, int width) {
        for (int c = 0; c < width; ++c)
            if (root.child[c] != NodeBits::kEmpty)
                out.push_back({vec3(root.b[0][c], root.b[2][c], root.b[4][c]), vec3(root.b[1][c], root.b[3][c], root.b[5][c])});
    };
    if (!m_nodes8.empty())
        collect(m_nodes8[0], 8);
    else if (!m_nodes4.empty())
        collect(m_nodes4[0], 4);
    return out;
}

namespace {
// refScale: what an inner child reference is in units of nodes (BVH8: byte offsets).
template <int W>
void addStats(const HugeVector<NodeW<W>>& nodes, uint32_t refScale, const sg::Aabb& bounds, TriangleBvh::Stats& s) {
    s.nodes = nodes.size();
    auto halfArea = [](float dx, float dy, float dz) {
        return dx < 0 || dy < 0 || dz < 0 ? 0.0 : double(dx) * dy + double(dy) * dz + double(dz) * dx;
    };
    const sg::vec3 e = bounds.max - bounds.min;
    const double rootArea = halfArea(e.x, e.y, e.z);
    double nodeArea = rootArea, leafArea = 0;
    for (const NodeW<W>& n : nodes)
        for (int i = 0; i < W; ++i) {
            const uint32_t c = n.child[i];
            if (c == NodeBits::kEmpty) continue;
            ++s.childSlots;
            const double a = halfArea(n.b[1][i] - n.b[0][i], n.b[3][i] - n.b[2][i], n.b[5][i] - n.b[4][i]);
            if (c & NodeBits::kLeafBit) {
                s.maxLeafPackets = std::max(s.maxLeafPackets, int(c & 7u));
                ++s.leaves;
                leafArea += a * double(c & 7u);
            } else {
                nodeArea += a;
            }
        }
    if (rootArea > 0) {
        s.sahNodes = nodeArea / rootArea;
        s.sahLeaves = leafArea / rootArea;
    }
    std::vector<std::pair<uint32_t, int>> stack{{0u, 1}};
    while (!stack.empty()) {
        auto [i, d] = stack.back();
        stack.pop_back();
        s.depth = std::max(s.depth, d);
        for (uint32_t c : nodes[i].child)
            if (c != NodeBits::kEmpty && !(c & NodeBits::kLeafBit)) stack.push_back({c / refScale, d + 1});
    }
}
}   // namespace

TriangleBvh::Stats TriangleBvh::stats() const {
    Stats s;
    if (!m_nodes8.empty())
        addStats(m_nodes8, uint32_t(sizeof(Node8)), m_bounds, s);
    else if (!m_nodes4.empty())
        addStats(m_nodes4, 1, m_bounds, s);
    s.packets = m_packets.size();
    for (uint32_t id : m_prims) s.lanes += id != ~0u;
    return s;
}

}   // namespace rnd::rt
