// Placeholder: the native JSON format lands in the next commit.
#include "assets/scene_io.h"

namespace assets {
LoadResult loadSceneJson(const std::filesystem::path& path) { LoadResult r; r.error = path.string() + ": JSON scenes not built yet"; return r; }
LoadResult parseSceneJson(std::string_view, const std::filesystem::path& path) { return loadSceneJson(path); }
std::string serializeSceneJson(const sg::Scene&) { return "{}"; }
std::string saveSceneJson(const sg::Scene&, const std::filesystem::path& path, bool) { return path.string() + ": not built yet"; }
}  // namespace assets
