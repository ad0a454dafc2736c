// import_test_util.h - small helpers for the importer tests.
#pragma once

#include "assets/scene_io.h"

#include <chrono>
#include <filesystem>
#include <string>

namespace import_test {

// Unique triangles (sum over Scene::meshes) and drawn triangles (over mesh instances).
size_t uniqueTriangles(const sg::Scene& s);
size_t drawnTriangles(const sg::Scene& s);
size_t countPayload(const sg::Scene& s, std::string_view kind);   // payloadKind() name
// A load that takes longer than this has hung (a guard, not a speed test: the machine may be
// busy with other tests, or instrumented by a sanitizer; speed is measured in bench/).
constexpr double kHangGuardSeconds = 60.0;
// Loads with a time limit check: the load must finish within `limitSeconds` (hang guard).
assets::LoadResult timedLoad(const std::filesystem::path& p, double limitSeconds, double* seconds = nullptr);
// A fresh empty folder under the test output dir.
std::filesystem::path scratchDir(const std::string& name);
void writeText(const std::filesystem::path& p, const std::string& text);

}   // namespace import_test
