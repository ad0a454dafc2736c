// import_common.h - internal helpers shared by the glTF and mesh importers:
//   * ConfinedDir: reads files named by a model (glTF buffer/image URIs, OBJ mtllib and
//     map_Kd) only from inside the model's own folder. The relative name is percent-decoded
//     and checked (no absolute path, no `..` component, no NUL); the file is opened and the
//     kernel's idea of the opened file (/proc/self/fd) must still lie inside the folder, so
//     symlinks out of the folder are refused too; only regular files are read (no FIFOs or
//     devices), up to a byte budget.
//   * Cancellation / progress polling for long loops.
//   * Default camera + light for scenes that bring none.
#pragma once

#include "assets/scene_io.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace assets::detail {

// "%2e%2e%2f" -> "../". Invalid escapes are kept literally.
std::string percentDecode(const std::string& s);

// Why a model-relative file name is refused ("" when acceptable). Checks the name as given
// and percent-decoded.
std::string checkRelativeName(const std::string& rel);

class ConfinedDir {
public:
    // `folder` is canonicalised; an error is returned by ok()/error() when that fails.
    explicit ConfinedDir(const std::filesystem::path& folder);
    bool ok() const { return m_error.empty(); }
    const std::string& error() const { return m_error; }
    const std::filesystem::path& root() const { return m_root; }
    // Reads root/rel. Returns "" or a reason (without the model's file name).
    std::string read(const std::string& rel, uint64_t maxBytes, std::vector<unsigned char>& out) const;
    // Same, for an already joined absolute path (tinygltf hands us those): it must start with
    // root + "/"; the remainder is checked like a relative name.
    std::string readAbsolute(const std::string& path, uint64_t maxBytes, std::vector<unsigned char>& out) const;
    // Relative part of an absolute path inside root, or a reason in *why.
    bool relativeOf(const std::string& path, std::string& rel, std::string* why) const;
    // "" when root/rel passes the name checks and is a regular file inside root, else why not.
    std::string probe(const std::string& rel) const;

private:
    std::filesystem::path m_root;
    std::string m_rootStr;   // with trailing '/'
    std::string m_error;
};

// Polls LoadOptions::cancel; sets progress. Cheap enough to call every few thousand items.
struct Progress {
    const LoadOptions& options;
    bool cancelled() const { return options.cancel && options.cancel->load(std::memory_order_relaxed); }
    void set(float f) const {
        if (options.progress) options.progress->store(std::clamp(f, 0.0f, 1.0f), std::memory_order_relaxed);
    }
};

// Adds a directional key light aimed at the scene from the upper front (when the scene has no
// light) and a default camera (when it has none). Returns true if a light was added.
bool addDefaultCameraAndLight(sg::Scene& scene);

// Peeks at PNG/JPEG headers for the pixel size (for budgets before decoding). false if unknown.
bool imageSize(const unsigned char* data, size_t size, int& w, int& h);

std::string fileNameOf(const std::filesystem::path& p);

}   // namespace assets::detail
