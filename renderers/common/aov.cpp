// aov.cpp - the AOVs' names (the one table of them) and AovSet's helpers (see aov.h).
#include "renderers/aov.h"

#include <array>
#include <utility>

namespace rnd {

namespace {

constexpr std::array<std::pair<Aov, std::string_view>, kAovCount> kNames = {{{Aov::Depth, "depth"},
                                                                             {Aov::Visibility, "visibility"},
                                                                             {Aov::Overdraw, "overdraw"},
                                                                             {Aov::TraversalCost, "cost"},
                                                                             {Aov::Normal, "normal"},
                                                                             {Aov::Id, "id"}}};

}   // namespace

std::string_view nameOf(Aov aov) {
    for (const auto& [a, n] : kNames)
        if (a == aov) return n;
    return "?";
}

bool parseAov(std::string_view name, Aov& out) {
    for (const auto& [a, n] : kNames)
        if (n == name) {
            out = a;
            return true;
        }
    return false;
}

std::vector<Aov> AovSet::list() const {
    std::vector<Aov> out;
    for (Aov a : kAllAovs)
        if (has(a)) out.push_back(a);
    return out;
}

std::vector<std::string_view> AovSet::names() const {
    std::vector<std::string_view> out;
    for (Aov a : list()) out.push_back(nameOf(a));
    return out;
}

AovSet renderedAovs(AovSet aovs) {
    AovSet out = aovs.without(Aov::Normal).without(Aov::Id);
    if (aovs.has(Aov::Normal) || aovs.has(Aov::Id)) out.add(Aov::Visibility);
    return out;
}

}   // namespace rnd
