// build_info.h - what `viewer --version` prints: the project version and the git revision it was
// built from, written into build_info.cpp at build time by cmake/BuildInfo.cmake ("unknown"
// without a git checkout; "-dirty" when tracked files differed from that revision).
#pragma once

namespace buildinfo {

extern const char* const kVersion;       // CMake project version, e.g. "0.1.0"
extern const char* const kGitRevision;   // e.g. "a33dede", "a33dede-dirty" or "unknown"

}   // namespace buildinfo
