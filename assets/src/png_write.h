// png_write.h - PNG files from raw pixels, deflated with zlib: the one PNG encoder (RGBA8 in
// image_io.cpp, 16-bit grey ids in aov_io.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace assets::detail {

// Appends to `out` the PNG of `height` rows of `rowBytes` bytes each (top row first, `stride`
// bytes apart), of pixels `bytesPerPixel` bytes wide, with IHDR's `bitDepth` and `colourType`
// (6 = RGBA, 0 = grey). Rows use PNG's "Up" filter (the difference to the row above: renders
// and id images are mostly runs that repeat down the image) and zlib's default level: 3-5x
// faster than stb_image_write's encoder on 1280x720 renders, in 35-70% of its bytes
// (docs/benchmarks.md). "" or the reason.
std::string encodePngRows(int width, int height, int bitDepth, int colourType, int bytesPerPixel, const uint8_t* pixels, size_t stride,
                          std::string& out);

}   // namespace assets::detail
