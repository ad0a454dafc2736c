// image_io.cpp - decoding with stb_image (limited to PNG and JPEG with a dimension cap; Debian's
// libstb ships the implementation, so this file only includes the header); encoding with our
// PNG writer on zlib (png_write.h).
#include "assets/image_io.h"

#include "assets/files.h"
#include "png_write.h"

#include <stb_image.h>

#include <cstring>

namespace assets {

namespace {
bool isPng(const unsigned char* d, size_t n) {
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    return n >= 8 && std::memcmp(d, sig, 8) == 0;
}
std::string failureReason() {
    const char* why = stbi_failure_reason();
    return why ? std::string(why) : std::string("corrupt data");
}
bool isJpeg(const unsigned char* d, size_t n) { return n >= 3 && d[0] == 0xFF && d[1] == 0xD8 && d[2] == 0xFF; }
}   // namespace

ImageLoad decodeImage(const void* data, size_t size, const std::string& name) {
    ImageLoad r;
    auto* d = static_cast<const unsigned char*>(data);
    if (size > size_t(INT32_MAX)) {
        r.error = name + ": image data too large";
        return r;
    }
    if (!isPng(d, size) && !isJpeg(d, size)) {
        r.error = name + ": not a PNG or JPEG image";
        return r;
    }
    int w = 0, h = 0, comp = 0;
    // Check the header's dimensions before decoding anything. PNG: IHDR width/height are the
    // big-endian words at bytes 16..23 (read directly: stb's own "too large" message is vague).
    if (isPng(d, size) && size >= 24) {
        auto be32 = [&](size_t o) { return uint32_t(d[o]) << 24 | uint32_t(d[o + 1]) << 16 | uint32_t(d[o + 2]) << 8 | d[o + 3]; };
        uint32_t pw = be32(16), ph = be32(20);
        if (pw > uint32_t(kMaxImageDimension) || ph > uint32_t(kMaxImageDimension)) {
            r.error =
                name + ": image is " + std::to_string(pw) + "x" + std::to_string(ph) + ", limit " + std::to_string(kMaxImageDimension) + " per side";
            return r;
        }
        // Every chunk must fit in the data: stb_image grows its IDAT buffer to a chunk's claimed
        // length before reading it (found by fuzzing: a 76-byte PNG asked for 2 GB).
        for (size_t o = 8; o + 8 <= size;) {
            const uint32_t len = be32(o);
            if (uint64_t(len) + 12 > size - o) {
                r.error = name + ": corrupt PNG: a chunk claims " + std::to_string(len) + " bytes but only " + std::to_string(size - o) + " remain";
                return r;
            }
            if (std::memcmp(d + o + 4, "IEND", 4) == 0) break;
            o += size_t(len) + 12;
        }
    }
    if (!stbi_info_from_memory(d, int(size), &w, &h, &comp)) {
        r.error = name + ": cannot read image header (" + failureReason() + ")";
        return r;
    }
    if (w <= 0 || h <= 0 || w > kMaxImageDimension || h > kMaxImageDimension) {
        r.error = name + ": image is " + std::to_string(w) + "x" + std::to_string(h) + ", limit " + std::to_string(kMaxImageDimension) + " per side";
        return r;
    }
    unsigned char* pixels = stbi_load_from_memory(d, int(size), &w, &h, &comp, 4);
    if (!pixels) {
        r.error = name + ": cannot decode image (" + failureReason() + ")";
        return r;
    }
    auto t = std::make_shared<sg::Texture>();
    t->name = name;
    t->width = w;
    t->height = h;
    t->rgba.assign(pixels, pixels + size_t(w) * h * 4);
    stbi_image_free(pixels);
    r.texture = std::move(t);
    return r;
}

ImageLoad loadImage(const std::filesystem::path& path) {
    std::string bytes;
    std::string err = readFileLimited(path, 256ull << 20, bytes);
    if (!err.empty()) return {nullptr, err};
    ImageLoad r = decodeImage(bytes.data(), bytes.size(), path.string());
    if (r.texture) r.texture->sourcePath = path.string();
    return r;
}

std::string encodePng(int w, int h, const uint8_t* rgba, std::string& out) {
    if (w <= 0 || h <= 0) return "image has no pixels";
    if (w > kMaxImageDimension || h > kMaxImageDimension)
        return "image is " + std::to_string(w) + "x" + std::to_string(h) + ", limit " + std::to_string(kMaxImageDimension) + " per side";
    out.clear();
    return detail::encodePngRows(w, h, 8, 6, 4, rgba, size_t(w) * 4, out);
}

std::string writePng(const std::filesystem::path& path, int w, int h, const uint8_t* rgba, bool overwrite) {
    std::string bytes;
    std::string err = encodePng(w, h, rgba, bytes);
    if (!err.empty()) return path.string() + ": " + err;
    return writeFileAtomic(path, bytes, overwrite);
}

}   // namespace assets
