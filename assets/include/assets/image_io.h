// image_io.h - PNG/JPEG decoding (stb_image, restricted) and PNG encoding (zlib).
#pragma once

#include "scenegraph/mesh.h"

#include <filesystem>
#include <string>

namespace assets {

constexpr int kMaxImageDimension = 16384;   // decoding and encoding cap (stb's int overflow)

struct ImageLoad {
    std::shared_ptr<sg::Texture> texture;   // null on error
    std::string error;
};
// Decodes PNG or JPEG bytes (magic bytes checked, dimension cap) into an RGBA8 texture.
ImageLoad decodeImage(const void* data, size_t size, const std::string& nameForErrors);
ImageLoad loadImage(const std::filesystem::path& path);

// Encodes RGBA8 (rows top to bottom) as PNG and writes it atomically. "" on success.
std::string writePng(const std::filesystem::path& path, int width, int height, const uint8_t* rgba, bool overwrite);
std::string encodePng(int width, int height, const uint8_t* rgba, std::string& out);

}   // namespace assets
