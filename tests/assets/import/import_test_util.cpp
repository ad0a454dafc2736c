// import_test_util.cpp - the importer tests' helpers (see import_test_util.h): triangle counts
// (unique and drawn), payload counts, a timed load with a hang guard, a fresh scratch folder
// and text files written into it.
#include "import_test_util.h"

#include "test_support.h"

#include <fstream>

namespace import_test {

size_t uniqueTriangles(const sg::Scene& s) {
    size_t n = 0;
    for (const auto& m : s.meshes) n += m->triangleCount();
    return n;
}
size_t drawnTriangles(const sg::Scene& s) {
    size_t n = 0;
    for (sg::NodeId id : s.depthFirstOrder())
        if (auto* mi = std::get_if<sg::MeshInstance>(&s.node(id).payload))
            if (mi->mesh >= 0 && size_t(mi->mesh) < s.meshes.size()) n += s.meshes[size_t(mi->mesh)]->triangleCount();
    return n;
}
size_t countPayload(const sg::Scene& s, std::string_view kind) {
    size_t n = 0;
    for (sg::NodeId id : s.depthFirstOrder())
        if (sg::payloadKind(s.node(id).payload) == kind) ++n;
    return n;
}
assets::LoadResult timedLoad(const std::filesystem::path& p, double limit, double* seconds) {
    auto t0 = std::chrono::steady_clock::now();
    assets::LoadResult r = assets::loadScene(p);
    double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (seconds) *seconds = dt;
    EXPECT_LT(dt, limit) << p << " took " << dt << " s (hang guard)";
    return r;
}
// One folder per test: CTest runs the tests of one binary as parallel processes, and a folder
// shared by two of them would be emptied by one while the other reads it.
std::filesystem::path scratchDir(const std::string& name) {
    auto d = testing_support::outputDir("import") / name;
    if (const auto* info = ::testing::UnitTest::GetInstance()->current_test_info()) d /= std::string(info->test_suite_name()) + "." + info->name();
    std::error_code ec;
    std::filesystem::remove_all(d, ec);
    std::filesystem::create_directories(d);
    return d;
}
void writeText(const std::filesystem::path& p, const std::string& text) {
    std::ofstream f(p, std::ios::binary);
    f << text;
}

}   // namespace import_test
