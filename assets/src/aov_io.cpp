// aov_io.cpp - PFM depth maps, 16-bit id PNGs and the camera sidecar (see aov_io.h).
#include "assets/aov_io.h"

#include "assets/files.h"
#include "png_write.h"

#include <stb_image.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
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

namespace {

nlohmann::json rows4(const sg::mat4& m) {
    nlohmann::json r = nlohmann::json::array();
    for (int row = 0; row < 4; ++row) r.push_back({m[0][row], m[1][row], m[2][row], m[3][row]});   // row-major
    return r;
}

nlohmann::json cameraObject(const sg::CameraModel& c, const std::string& projection) {
    using nlohmann::json;
    json cam = {{"world_to_camera", rows4(c.worldToCamera)},
                {"camera_to_world", rows4(c.cameraToWorld)},
                {"projection", projection},
                {"projection_matrix", rows4(c.projection)},
                {"near", c.zNear},
                {"far", c.zFar}};
    if (c.pinhole) {
        json K = json::array();
        for (const auto& row : c.K) K.push_back({row[0], row[1], row[2]});
        cam["K"] = K;
    } else {
        cam["K"] = nullptr;   // orthographic / oblique: no pinhole; projection_matrix maps eye to clip
    }
    return cam;
}

}   // namespace

std::string aovCameraJson(const sg::CameraModel& camera, const std::string& projection, int width, int height) {
    nlohmann::json cam = cameraObject(camera, projection);
    cam["width"] = width;
    cam["height"] = height;
    return cam.dump();
}

std::string writeAovSidecar(const fs::path& path, const AovSidecar& s, bool overwrite) {
    using nlohmann::json;
    json cam = cameraObject(s.camera, s.projection);
    json j = {{"width", s.width}, {"height", s.height}, {"backend", s.backend}, {"camera", cam}, {"files", s.files}};
    if (s.hasIds) {
        json ids = json::array();
        for (const AovInstance& i : s.ids) ids.push_back({{"id", i.id}, {"node", i.node}, {"path", i.path}});
        j["ids"] = ids;
    }
    return writeFileAtomic(path, j.dump(2) + "\n", overwrite);
}

std::string writePngGray16(const fs::path& path, int width, int height, const std::vector<uint16_t>& topDown, bool overwrite) {
    if (width <= 0 || height <= 0 || topDown.size() != size_t(width) * size_t(height)) return path.string() + ": image has no pixels";
    // PNG's 16-bit samples are big-endian (16-bit grey = colour type 0).
    std::vector<uint8_t> be(topDown.size() * 2);
    for (size_t i = 0; i < topDown.size(); ++i) {
        be[2 * i] = uint8_t(topDown[i] >> 8);
        be[2 * i + 1] = uint8_t(topDown[i] & 0xff);
    }
    std::string png;
    std::string err = detail::encodePngRows(width, height, 16, 0, 2, be.data(), size_t(width) * 2, png);
    if (!err.empty()) return path.string() + ": " + err;
    return writeFileAtomic(path, png, overwrite);
}

std::string readPngGray16(const fs::path& path, int& width, int& height, std::vector<uint16_t>& topDown) {
    std::string bytes;
    std::string err = readFileLimited(path, 1ull << 30, bytes);
    if (!err.empty()) return err;
    int w = 0, h = 0, comp = 0;
    const auto* d = reinterpret_cast<const stbi_uc*>(bytes.data());
    if (!stbi_is_16_bit_from_memory(d, int(bytes.size()))) return path.string() + ": not a 16-bit PNG";
    stbi_us* px = stbi_load_16_from_memory(d, int(bytes.size()), &w, &h, &comp, 1);
    if (!px) return path.string() + ": cannot decode PNG";
    width = w;
    height = h;
    topDown.assign(px, px + size_t(w) * size_t(h));
    stbi_image_free(px);
    return {};
}

namespace {

bool readMatrix4(const nlohmann::json& j, sg::mat4& m) {
    if (!j.is_array() || j.size() != 4) return false;
    for (int row = 0; row < 4; ++row) {
        if (!j[size_t(row)].is_array() || j[size_t(row)].size() != 4) return false;
        for (int col = 0; col < 4; ++col) {
            const nlohmann::json& v = j[size_t(row)][size_t(col)];
            if (!v.is_number() || !std::isfinite(v.get<double>())) return false;
            m[col][row] = v.get<float>();   // row-major in the file, glm is column-major
        }
    }
    return true;
}

}   // namespace

std::string parseAovCamera(const std::string& text, const std::string& where, AovCamera& out) {
    using nlohmann::json;
    json j = json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return where + ": not a JSON object";
    AovCamera c;
    if (j.contains("width") && j["width"].is_number_integer()) c.width = j["width"].get<int>();
    if (j.contains("height") && j["height"].is_number_integer()) c.height = j["height"].get<int>();
    const json& cam = j.contains("camera") && j["camera"].is_object() ? j["camera"] : j;
    if (!cam.contains("world_to_camera") || !readMatrix4(cam["world_to_camera"], c.model.worldToCamera))
        return where + ": \"world_to_camera\" must be a 4x4 array of finite numbers";
    c.model.cameraToWorld = glm::inverse(c.model.worldToCamera);
    if (cam.contains("camera_to_world") && !readMatrix4(cam["camera_to_world"], c.model.cameraToWorld))
        return where + ": \"camera_to_world\" must be a 4x4 array of finite numbers";
    if (cam.contains("near") && cam["near"].is_number()) c.model.zNear = cam["near"].get<float>();
    if (cam.contains("far") && cam["far"].is_number()) c.model.zFar = cam["far"].get<float>();
    if (!(c.model.zNear > 0) || !(c.model.zFar > c.model.zNear) || !std::isfinite(c.model.zFar)) return where + ": needs 0 < near < far";
    if (cam.contains("projection") && cam["projection"].is_string()) c.projection = cam["projection"].get<std::string>();
    if (c.projection != "perspective" && c.projection != "orthographic" && c.projection != "oblique")
        return where + ": \"projection\" must be perspective, orthographic or oblique";
    if (cam.contains("K") && cam["K"].is_array()) {
        const json& K = cam["K"];
        if (K.size() != 3) return where + ": \"K\" must be 3x3";
        for (int r = 0; r < 3; ++r) {
            if (!K[size_t(r)].is_array() || K[size_t(r)].size() != 3) return where + ": \"K\" must be 3x3";
            for (int col = 0; col < 3; ++col) {
                if (!K[size_t(r)][size_t(col)].is_number()) return where + ": \"K\" must hold numbers";
                c.model.K[r][col] = K[size_t(r)][size_t(col)].get<double>();
            }
        }
        c.model.pinhole = true;
    }
    if (cam.contains("projection_matrix")) {
        if (!readMatrix4(cam["projection_matrix"], c.model.projection))
            return where + ": \"projection_matrix\" must be a 4x4 array of finite numbers";
    } else if (c.model.pinhole) {
        if (c.width < 1 || c.height < 1) return where + ": K without a projection matrix needs \"width\" and \"height\"";
        if (c.model.K[0][1] != 0.0) return where + ": K with skew needs a projection matrix";
        sg::Projection p;
        std::string err;
        if (!sg::projectionFromIntrinsics(c.model.K[0][0], c.model.K[1][1], c.model.K[0][2], c.model.K[1][2], c.width, c.height, c.model.zNear,
                                          c.model.zFar, p, &err))
            return where + ": " + err;
        c.model.projection = p.matrix(float(c.width) / float(c.height), 1.0f);
    } else {
        return where + ": needs \"projection_matrix\" or \"K\"";
    }
    out = c;
    return {};
}

std::string readAovCamera(const fs::path& path, AovCamera& out) {
    std::string text;
    std::string err = readFileLimited(path, 16u << 20, text);
    if (!err.empty()) return err;
    return parseAovCamera(text, path.string(), out);
}

}   // namespace assets
