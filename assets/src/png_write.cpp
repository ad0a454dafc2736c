// png_write.cpp - see png_write.h.
#include "png_write.h"

#include <zlib.h>

#include <vector>

namespace assets::detail {

namespace {

void putBE32(std::string& out, uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(char((v >> s) & 0xff));
}

void chunk(std::string& out, const char type[4], const unsigned char* data, size_t size) {
    putBE32(out, uint32_t(size));
    uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(type), 4);
    out.append(type, 4);
    if (size) {
        crc = crc32_z(crc, data, size);
        out.append(reinterpret_cast<const char*>(data), size);
    }
    putBE32(out, uint32_t(crc));
}

}   // namespace

std::string encodePngRows(int width, int height, int bitDepth, int colourType, int bytesPerPixel, const uint8_t* pixels, size_t stride,
                          std::string& out) {
    if (width <= 0 || height <= 0 || !pixels) return "image has no pixels";
    const size_t rowBytes = size_t(width) * size_t(bytesPerPixel);
    out.append("\x89PNG\r\n\x1a\n", 8);
    unsigned char ihdr[13] = {};
    for (int k = 0; k < 4; ++k) {
        ihdr[k] = static_cast<unsigned char>(uint32_t(width) >> (24 - 8 * k));
        ihdr[4 + k] = static_cast<unsigned char>(uint32_t(height) >> (24 - 8 * k));
    }
    ihdr[8] = static_cast<unsigned char>(bitDepth);
    ihdr[9] = static_cast<unsigned char>(colourType);   // compression 0 (deflate), filter method 0, no interlace
    chunk(out, "IHDR", ihdr, sizeof ihdr);

    // One IDAT: its length is filled in once the rows are deflated straight into `out`, one
    // filtered row at a time (no second copy of the image).
    const size_t idat = out.size();
    out.append("\0\0\0\0IDAT", 8);
    z_stream zs{};
    if (deflateInit(&zs, Z_DEFAULT_COMPRESSION) != Z_OK) return "PNG compression failed";
    constexpr size_t kStep = 1 << 16;
    auto pump = [&](int flush) {   // zlib's usual loop: until deflate leaves output space unused
        int rc = Z_OK;
        do {
            const size_t at = out.size();
            out.resize(at + kStep);
            zs.next_out = reinterpret_cast<Bytef*>(&out[at]);
            zs.avail_out = uInt(kStep);
            rc = deflate(&zs, flush);
            out.resize(at + kStep - zs.avail_out);
            if (rc == Z_STREAM_ERROR) return false;
        } while (zs.avail_out == 0);
        return flush != Z_FINISH || rc == Z_STREAM_END;
    };
    // Each row: a filter-type byte (2 = Up), then each byte minus the one above it.
    std::vector<unsigned char> line(rowBytes + 1);
    line[0] = 2;
    bool ok = true;
    for (int j = 0; j < height && ok; ++j) {
        const uint8_t* row = pixels + size_t(j) * stride;
        if (j == 0) {
            for (size_t i = 0; i < rowBytes; ++i) line[1 + i] = row[i];
        } else {
            const uint8_t* up = row - stride;
            for (size_t i = 0; i < rowBytes; ++i) line[1 + i] = static_cast<unsigned char>(row[i] - up[i]);
        }
        zs.next_in = line.data();
        zs.avail_in = uInt(line.size());
        ok = pump(Z_NO_FLUSH);
    }
    ok = ok && pump(Z_FINISH);
    deflateEnd(&zs);
    if (!ok) return "PNG compression failed";
    const size_t size = out.size() - idat - 8;
    for (int k = 0; k < 4; ++k) out[idat + size_t(k)] = char((size >> (24 - 8 * k)) & 0xff);
    putBE32(out, uint32_t(crc32_z(0L, reinterpret_cast<const Bytef*>(out.data() + idat + 4), size + 4)));
    chunk(out, "IEND", nullptr, 0);
    return {};
}

}   // namespace assets::detail
