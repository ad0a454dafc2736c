// scene_io.h - loading and saving scenes.
//   loadScene: by extension: .json (native scene file), .gltf/.glb, .obj/.off/.ply/.stl.
//   saveScene: the native JSON format (scene_json.cpp documents it).
// Errors are one line naming the file and the reason (for JSON: also the JSON path, e.g.
// "scene.json: /nodes/3/transform/translation: expected 3 numbers"). A failed load returns
// no scene, so the caller's current scene stays untouched.
#pragma once

#include "assets/animation.h"
#include "scenegraph/scene.h"

#include <atomic>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace assets {

struct LoadOptions {
    std::atomic<bool>* cancel = nullptr;      // polled during long loads
    std::atomic<float>* progress = nullptr;   // 0..1
};

struct LoadResult {
    std::optional<sg::Scene> scene;
    std::string error;                   // set when !scene
    std::vector<std::string> warnings;   // recoverable problems (missing texture, ...)
    // glTF only (additive): node TRS animation clips (node ids refer to *scene), the names of
    // all scenes in the file ("scene N" when unnamed) and which one was loaded (-1: none).
    std::vector<AnimationClip> animations;
    std::vector<std::string> sceneNames;
    int loadedScene = -1;
};

// The scene comes with its size-dependent defaults set (scenegraph/scene_defaults.h), so the
// window and every command show the same file the same way.
LoadResult loadScene(const std::filesystem::path& path, const LoadOptions& options = {});

// Native JSON scene file.
LoadResult loadSceneJson(const std::filesystem::path& path);
LoadResult parseSceneJson(std::string_view text, const std::filesystem::path& pathForErrors);
// Serialises the scene. Every mesh is written inline (also one that was loaded from a file
// reference) and every texture as an embedded PNG; file references are only read. Every float
// is written so that it reads back bit for bit (-0.0, denormals and the largest float included).
// A scene holding a NaN or an infinity is not serialised: "" comes back and *error (when given)
// names the first such value by its JSON path.
std::string serializeSceneJson(const sg::Scene& scene, std::string* error = nullptr);
// Writes atomically; refuses to replace an existing file unless overwrite, and refuses a scene
// with a NaN or an infinity (the file is not touched). "" on success.
std::string saveSceneJson(const sg::Scene& scene, const std::filesystem::path& path, bool overwrite);

// Which extensions loadScene understands (lower case, with dot).
std::vector<std::string> supportedSceneExtensions();
// What loadScene would refuse before reading a byte (no such file, a folder, an unsupported
// type), as its one-line error; "" when the file may be opened.
std::string checkSceneFile(const std::filesystem::path& path);

}   // namespace assets
