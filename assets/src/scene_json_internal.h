// scene_json_internal.h - what the native scene file's reader (scene_json_read.cpp) and writer
// (scene_json_write.cpp) share: the limits on what a file may hold, the names of a material's
// uv1 map bits, and base64 for embedded PNGs. The format itself is described in scene_json.cpp.
#pragma once

#include "scenegraph/material.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace assets::scene_json {

inline constexpr uint64_t kMaxFileBytes = 1ull << 30;   // 1 GiB of JSON
inline constexpr int kMaxNesting = 64;                  // our format needs < 10
inline constexpr size_t kMaxNodes = 20'000'000;
inline constexpr size_t kMaxVertices = 100'000'000;
inline constexpr size_t kMaxIndices = 300'000'000;
inline constexpr size_t kMaxGridValues = 512ull * 512 * 512;
inline constexpr size_t kMaxMorphTargets = 4096;

// The names of sg::Material's map bits in "uv1Maps".
struct MapBitName {
    const char* name;
    uint8_t bit;
};
inline constexpr MapBitName kMapBitNames[] = {{"emissive", sg::Material::EmissiveMap},
                                              {"occlusion", sg::Material::OcclusionMap},
                                              {"metallicRoughness", sg::Material::MetallicRoughnessMap},
                                              {"normal", sg::Material::NormalMap}};
inline const MapBitName* findMapBit(const std::string& name) {
    for (const MapBitName& e : kMapBitNames)
        if (name == e.name) return &e;
    return nullptr;
}

std::string base64Encode(std::string_view in);
// False on a character outside the alphabet; stops at the first '='.
bool base64Decode(std::string_view in, std::string& out);

}   // namespace assets::scene_json
