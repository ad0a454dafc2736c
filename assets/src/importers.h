// importers.h - internal: the format-specific loaders behind loadScene().
#pragma once

#include "assets/scene_io.h"

namespace assets::detail {

LoadResult loadGltf(const std::filesystem::path& path, const LoadOptions& options);
LoadResult loadMeshFile(const std::filesystem::path& path, const LoadOptions& options);   // obj/off/ply/stl

}   // namespace assets::detail
