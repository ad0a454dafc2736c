// Placeholder until the glTF importer lands.
#include "importers.h"

namespace assets::detail {
LoadResult loadGltf(const std::filesystem::path& path, const LoadOptions&) {
    LoadResult r;
    r.error = path.string() + ": glTF import is not built yet";
    return r;
}
}  // namespace assets::detail
