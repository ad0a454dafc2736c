// huge_pages.h - memory for big arrays straight from the operating system, with transparent
// huge pages asked for. A first touch of fresh memory costs a page fault per 4 KB page, and on a
// virtual machine that is microseconds each: a cold frame (`viewer render`, the first frame after
// a backend switch) spent a third of its time faulting in shadow maps and triangle set-ups. From
// 4 MB up these come from a 2 MB aligned anonymous mapping with MADV_HUGEPAGE (Linux's
// transparent huge pages in their default "madvise" mode: 512 times fewer faults), as Embree
// does for its BVHs; the mapping goes back to the system when freed.
#pragma once

#include <cstddef>
#include <new>
#include <utility>
#include <vector>

namespace rnd {

// An anonymous mapping of at least `bytes` (2 MB aligned with huge pages asked for from 4 MB up,
// not under AddressSanitizer); pageFree must get the same size. Throws std::bad_alloc.
void* pageAlloc(size_t bytes);
void pageFree(void* p, size_t bytes) noexcept;
// pageAlloc from 4 MB up (outside AddressSanitizer, which watches operator new's blocks only),
// operator new (64-byte aligned) below; hugeFree must get the size given to hugeAlloc.
void* hugeAlloc(size_t bytes);
void hugeFree(void* p, size_t bytes) noexcept;

// A std::vector allocator on hugeAlloc. resize() and emplace_back() with no arguments
// default-initialise (no zero fill): for arrays whose every element is written before it is
// read, the first write then faults the page in, on whichever thread fills it.
template <class T>
struct HugePageAllocator {
    using value_type = T;
    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>&) {}
    T* allocate(size_t n) { return static_cast<T*>(hugeAlloc(n * sizeof(T))); }
    void deallocate(T* p, size_t n) noexcept { hugeFree(p, n * sizeof(T)); }
    template <class U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... A>
    void construct(U* p, A&&... a) {
        ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
    }
    template <class U>
    bool operator==(const HugePageAllocator<U>&) const {
        return true;
    }
};
template <class T>
using HugeVector = std::vector<T, HugePageAllocator<T>>;

}   // namespace rnd
