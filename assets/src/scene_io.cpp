#include "assets/scene_io.h"

#include "importers.h"

#include <algorithm>
#include <cctype>

namespace fs = std::filesystem;

namespace assets {

std::vector<std::string> supportedSceneExtensions() { return {".json", ".gltf", ".glb", ".obj", ".off", ".ply", ".stl"}; }

LoadResult loadScene(const fs::path& path, const LoadOptions& options) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    std::error_code ec;
    LoadResult r;
    if (!fs::exists(path, ec)) {
        r.error = path.string() + ": no such file";
        return r;
    }
    if (fs::is_directory(path, ec)) {
        r.error = path.string() + ": is a folder, not a scene file";
        return r;
    }
    if (ext == ".json") return loadSceneJson(path);
    if (ext == ".gltf" || ext == ".glb") return detail::loadGltf(path, options);
    if (ext == ".obj" || ext == ".off" || ext == ".ply" || ext == ".stl") return detail::loadMeshFile(path, options);
    r.error = path.string() + ": unsupported file type '" + ext + "' (supported: .json .gltf .glb .obj .off .ply .stl)";
    return r;
}

}   // namespace assets
