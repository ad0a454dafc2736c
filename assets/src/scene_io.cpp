// scene_io.cpp - the one entry point for opening a scene file (see scene_io.h):
// checkSceneFile() (exists, not a folder, a supported extension), then loadScene() hands the
// file by extension to the JSON reader, the glTF importer or the mesh importers and applies the
// scene defaults to whatever loaded, so every format opens alike.
#include "assets/scene_io.h"

#include "importers.h"

#include "scenegraph/scene_defaults.h"

#include <algorithm>
#include <cctype>

namespace fs = std::filesystem;

namespace assets {

std::vector<std::string> supportedSceneExtensions() { return {".json", ".gltf", ".glb", ".obj", ".off", ".ply", ".stl"}; }

namespace {
std::string lowerExtension(const fs::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}
}   // namespace

std::string checkSceneFile(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(path, ec)) return path.string() + ": no such file";
    if (fs::is_directory(path, ec)) return path.string() + ": is a folder, not a scene file";
    std::vector<std::string> exts = supportedSceneExtensions();
    std::string ext = lowerExtension(path);
    if (std::find(exts.begin(), exts.end(), ext) == exts.end()) {
        std::string list;
        for (const std::string& e : exts) list += (list.empty() ? "" : " ") + e;
        return path.string() + ": unsupported file type '" + ext + "' (supported: " + list + ")";
    }
    return {};
}

LoadResult loadScene(const fs::path& path, const LoadOptions& options) {
    LoadResult r;
    r.error = checkSceneFile(path);
    if (!r.error.empty()) return r;
    std::string ext = lowerExtension(path);
    if (ext == ".json")
        r = loadSceneJson(path);
    else if (ext == ".gltf" || ext == ".glb")
        r = detail::loadGltf(path, options);
    else
        r = detail::loadMeshFile(path, options);
    if (r.scene) sg::applySceneDefaults(*r.scene);   // the same defaults wherever a file is opened
    return r;
}

}   // namespace assets
