// aov_io.cpp - PFM depth maps, 16-bit id PNGs and the camera sidecar (see aov_io.h).
#include "assets/aov_io.h"

#include "assets/files.h"

#include <stb_image.h>
#include <stb_image_write.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <cstring>
#include <sstream>

// Part of Debian's libstb (stb_image_write's deflate), declared only in its implementation
// section of the header.
extern "C" unsigned char* stbi_zlib_compress(unsigned char* data, int data_len, int* out_len, int quality);

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
    if (s.hasIds) {
        json ids = json::array();
        for (const AovInstance& i : s.ids) ids.push_back({{"id", i.id}, {"node", i.node}, {"path", i.path}});
        j["ids"] = ids;
    }
    return writeFileAtomic(path, j.dump(2) + "\n", overwrite);
}

namespace {

uint32_t crc32(const uint8_t* p, size_t n, uint32_t crc = 0) {
    crc = ~crc;
    for (size_t i = 0; i < n; ++i) {
        crc ^= p[i];
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

void putBE32(std::string& out, uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(char((v >> s) & 0xff));
}

void chunk(std::string& out, const char type[4], const std::string& data) {
    putBE32(out, uint32_t(data.size()));
    std::string body(type, 4);
    body += data;
    out += body;
    putBE32(out, crc32(reinterpret_cast<const uint8_t*>(body.data()), body.size()));
}

}   // namespace

std::string writePngGray16(const fs::path& path, int width, int height, const std::vector<uint16_t>& topDown, bool overwrite) {
    if (width <= 0 || height <= 0 || topDown.size() != size_t(width) * size_t(height)) return path.string() + ": image has no pixels";
    // Rows: filter byte 0, then big-endian samples (PNG, 16-bit grey = colour type 0).
    std::string raw;
    raw.reserve(size_t(height) * (1 + size_t(width) * 2));
    for (int j = 0; j < height; ++j) {
        raw.push_back(0);
        for (int i = 0; i < width; ++i) {
            const uint16_t v = topDown[size_t(j) * width + i];
            raw.push_back(char(v >> 8));
            raw.push_back(char(v & 0xff));
        }
    }
    int zlen = 0;
    unsigned char* z = stbi_zlib_compress(reinterpret_cast<unsigned char*>(raw.data()), int(raw.size()), &zlen, 6);
    if (!z) return path.string() + ": PNG compression failed";
    std::string png("\x89PNG\r\n\x1a\n", 8), ihdr;
    putBE32(ihdr, uint32_t(width));
    putBE32(ihdr, uint32_t(height));
    ihdr += std::string("\x10\x00\x00\x00\x00", 5);   // depth 16, grey, deflate, filter 0, no interlace
    chunk(png, "IHDR", ihdr);
    chunk(png, "IDAT", std::string(reinterpret_cast<const char*>(z), size_t(zlen)));
    std::free(z);   // stb_image_write's default allocator
    chunk(png, "IEND", {});
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

}   // namespace assets
