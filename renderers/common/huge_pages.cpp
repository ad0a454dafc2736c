// huge_pages.cpp - see huge_pages.h.
#include "renderers/huge_pages.h"

#include <sys/mman.h>

#include <cstdint>

namespace rnd {

namespace {
// Under AddressSanitizer hugeAlloc takes everything from operator new, so the sanitizer keeps
// watching these buffers (it puts no redzones around mappings), and pageAlloc asks for no huge
// pages (its shadow memory would grow with them).
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif
constexpr size_t kHugeMin = size_t(4) << 20, kHugePage = size_t(2) << 20, kPage = 4096;
size_t pageRound(size_t b) { return (b + kPage - 1) & ~(kPage - 1); }
}   // namespace

void* pageAlloc(size_t bytes) {
    const size_t len = pageRound(bytes > 0 ? bytes : 1);
    if (kSanitized || len < kHugeMin) {
        void* p = ::mmap(nullptr, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED) throw std::bad_alloc();
        return p;
    }
    // Map 2 MB more than needed, keep a 2 MB aligned window, give the rest back.
    const size_t span = len + kHugePage;
    void* m = ::mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) throw std::bad_alloc();
    const uintptr_t base = reinterpret_cast<uintptr_t>(m), aligned = (base + kHugePage - 1) & ~(kHugePage - 1);
    if (aligned > base) ::munmap(m, aligned - base);
    if (base + span > aligned + len) ::munmap(reinterpret_cast<void*>(aligned + len), base + span - (aligned + len));
    ::madvise(reinterpret_cast<void*>(aligned), len, MADV_HUGEPAGE);   // advice only: may fail harmlessly
    return reinterpret_cast<void*>(aligned);
}

void pageFree(void* p, size_t bytes) noexcept {
    if (p) ::munmap(p, pageRound(bytes > 0 ? bytes : 1));
}

void* hugeAlloc(size_t bytes) {
    if (kSanitized || bytes < kHugeMin) return ::operator new(bytes, std::align_val_t(64));
    return pageAlloc(bytes);
}

void hugeFree(void* p, size_t bytes) noexcept {
    if (!p) return;
    if (kSanitized || bytes < kHugeMin)
        ::operator delete(p, std::align_val_t(64));
    else
        pageFree(p, bytes);
}

}   // namespace rnd
