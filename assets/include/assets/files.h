// files.h - safe file writes and confined reads.
//   * writeFileAtomic: write to a temporary file in the same folder, fsync, then rename over the
//     target, so readers see the old file or the complete new one, never a torn file. Refuses
//     to replace an existing file unless `overwrite` is set.
//   * readFileLimited: reads a regular file (no FIFOs/devices) up to a byte budget.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace assets {

// Returns an empty string on success, else a one-line error naming the file and the reason.
std::string writeFileAtomic(const std::filesystem::path& path, std::string_view bytes, bool overwrite);

// Reads a regular file of at most maxBytes. Returns an error string or "" and fills `out`.
std::string readFileLimited(const std::filesystem::path& path, uint64_t maxBytes, std::string& out);

// Reads up to n bytes from an open descriptor, retrying on EINTR and short reads; returns the
// number of bytes read (fewer at end of file or on error).
size_t readFully(int fd, void* buffer, size_t n);

// A path that does not exist yet: base + "-N" + ext with the smallest free N (N from 1), or
// `path` itself when free. Used for screenshots named without overwriting.
std::filesystem::path uniquePath(const std::filesystem::path& path);

}   // namespace assets
