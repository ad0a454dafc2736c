// Placeholder until the OBJ/OFF/PLY/STL importer lands.
#include "importers.h"

namespace assets::detail {
LoadResult loadMeshFile(const std::filesystem::path& path, const LoadOptions&) {
    LoadResult r;
    r.error = path.string() + ": mesh import is not built yet";
    return r;
}
}  // namespace assets::detail
