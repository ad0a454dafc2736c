// aov_io.cpp - PFM depth maps and the camera sidecar (see aov_io.h).
#include "assets/aov_io.h"

#include "assets/files.h"

#include <nlohmann/json.hpp>

#include <cstring>
#include <sstream>

namespace assets {

namespace fs = std::filesystem;

std::string writePfm(const fs::path& path, int width, int height, const std::vector<float>& topDown, bool overwrite) {
    if (width <= 0 || height <= 0 || topDown.size() != size_t(width) * size_t(height))
        return path.filename().string() + ": " + std::to_string(topDown.size()) + " values for a " + std::to_string(width) + "x" +
               std::to_string(height) + " image";
    std::string bytes = "Pf\n" + std::to_string(width) + " " + std::to_string(height) + "\n-1.0\n";
    const size_t header = bytes.size(), row = size_t(width) * sizeof(float);
    bytes.resize(header + row * size_t(height));
    for (int j = 0; j < height; ++j)   // PFM: bottom row first; -1.0: little-endian floats
        std::memcpy(&bytes[header + size_t(j) * row], &topDown[size_t(height - 1 - j) * size_t(width)], row);
    return writeFileAtomic(path, bytes, overwrite);
}

std::string readPfm(const fs::path& path, int& width, int& height, std::vector<float>& topDown) {
    std::string bytes;
    if (std::string e = readFileLimited(path, uint64_t(1) << 32, bytes); !e.empty()) return e;
    std::istringstream in(bytes);
    std::string magic;
    double scale = 0;
    in >> magic >> width >> height >> scale;
    const std::string name = path.filename().string();
    if (magic != "Pf" || !in || width <= 0 || height <= 0 || width > 65536 || height > 65536 || scale == 0)
        return name + ": not a grey PFM (expected 'Pf', a size and a scale)";
    in.get();   // the single whitespace before the data
    const size_t header = size_t(in.tellg()), n = size_t(width) * size_t(height);
    if (bytes.size() < header + n * sizeof(float)) return name + ": truncated PFM";
    topDown.assign(n, 0.0f);
    const bool swap = scale > 0;   // positive scale: big-endian
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) {
            uint32_t u;
            std::memcpy(&u, &bytes[header + (size_t(j) * size_t(width) + size_t(i)) * 4], 4);
            if (swap) u = __builtin_bswap32(u);
            std::memcpy(&topDown[size_t(height - 1 - j) * size_t(width) + size_t(i)], &u, 4);
        }
    return {};
}

std::string writeAovSidecar(const fs::path& path, const AovSidecar& s, bool overwrite) {
    using nlohmann::json;
    auto rows4 = [](const sg::mat4& m) {
        json r = json::array();
        for (int row = 0; row < 4; ++row) r.push_back({m[0][row], m[1][row], m[2][row], m[3][row]});   // row-major
        return r;
    };
    json cam = {{"world_to_camera", rows4(s.camera.worldToCamera)},
                {"projection", s.projection},
                {"projection_matrix", rows4(s.camera.projection)},
                {"near", s.camera.zNear},
                {"far", s.camera.zFar}};
    if (s.camera.pinhole) {
        json K = json::array();
        for (const auto& row : s.camera.K) K.push_back({row[0], row[1], row[2]});
        cam["K"] = K;
    } else {
        cam["K"] = nullptr;   // orthographic / oblique: no pinhole; projection_matrix maps eye to clip
    }
    json j = {{"width", s.width}, {"height", s.height}, {"backend", s.backend}, {"camera", cam}, {"files", s.files}};
    return writeFileAtomic(path, j.dump(2) + "\n", overwrite);
}

}   // namespace assets
