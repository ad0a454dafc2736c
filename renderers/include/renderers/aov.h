// aov.h - the per-pixel outputs of a render besides its colour image (AOVs, arbitrary output
// variables) as one enum, and a small set of them. The four places that speak of them use an
// AovSet: Capabilities::aovs (what a backend can fill), RenderRequest::aovs (what a caller
// asks for), RenderConfig::aovs (what one pass of a backend fills) and Framebuffer::has()
// (what an image holds). Their names are in one table (aov.cpp): the command line, the export
// and the messages name them from it.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string_view>
#include <vector>

namespace rnd {

enum class Aov : uint8_t {
    Depth,           // Framebuffer::depth: window depth in [0,1]; every pass of every backend fills it
    Visibility,      // Framebuffer::drawable/primitive: the surface each pixel centre shows
    Overdraw,        // Framebuffer::overdraw: fragments rasterized per pixel (rasterizers)
    TraversalCost,   // Framebuffer::costNodes/costPrims: BVH work of each primary ray (ray caster)
    Normal,          // world normal per pixel, made from Visibility and the frame (inspect.h's normalImage)
    Id,              // instance id per pixel, made from Visibility (sg::instanceTable)
};
inline constexpr int kAovCount = 6;

// The AOVs, in the enum's order.
inline constexpr Aov kAllAovs[kAovCount] = {Aov::Depth, Aov::Visibility, Aov::Overdraw, Aov::TraversalCost, Aov::Normal, Aov::Id};

// "depth", "visibility", "overdraw", "cost", "normal", "id".
std::string_view nameOf(Aov aov);
// The AOV named `name` (nameOf's spelling); false for anything else.
bool parseAov(std::string_view name, Aov& out);

class AovSet {
public:
    constexpr AovSet() = default;
    constexpr AovSet(std::initializer_list<Aov> aovs) {
        for (Aov a : aovs) add(a);
    }
    constexpr bool has(Aov a) const { return (m_bits & bit(a)) != 0; }
    // Every AOV of `other` is in this set.
    constexpr bool hasAll(AovSet other) const { return (m_bits & other.m_bits) == other.m_bits; }
    constexpr bool empty() const { return m_bits == 0; }
    constexpr AovSet& add(Aov a) {
        m_bits = uint8_t(m_bits | bit(a));
        return *this;
    }
    constexpr AovSet& add(AovSet other) {
        m_bits = uint8_t(m_bits | other.m_bits);
        return *this;
    }
    constexpr AovSet& remove(Aov a) {
        m_bits = uint8_t(m_bits & ~bit(a));
        return *this;
    }
    // add(a) when `on`, else remove(a).
    constexpr AovSet& set(Aov a, bool on) { return on ? add(a) : remove(a); }
    constexpr AovSet without(Aov a) const { return AovSet(*this).remove(a); }
    constexpr bool operator==(const AovSet&) const = default;
    // The AOVs in the set, in the enum's order.
    std::vector<Aov> list() const;
    // Their names (nameOf), in the enum's order.
    std::vector<std::string_view> names() const;

private:
    static constexpr uint8_t bit(Aov a) { return uint8_t(1u << unsigned(a)); }
    uint8_t m_bits = 0;
};
static_assert(kAovCount <= 8, "AovSet holds the AOVs in 8 bits");

// The AOVs a backend fills for `aovs`: each one itself, but Normal and Id, which are made
// from the Visibility.
AovSet renderedAovs(AovSet aovs);

}   // namespace rnd
