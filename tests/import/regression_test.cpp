// Every input a fuzzer ever crashed on stays here (tests/import/regressions) and must load
// into valid meshes or fail with a one-line error naming the file.
#include "assets/scene_io.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace fs = std::filesystem;

TEST(FuzzRegressionTest, CrashInputsLoadValidMeshesOrFailClearly) {
    fs::path dir = fs::path(VIEWER_SOURCE_DIR) / "tests/import/regressions";
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        if (!e.is_regular_file()) continue;
        ++files;
        SCOPED_TRACE(e.path().filename().string());
        assets::LoadResult r = assets::loadScene(e.path());
        if (!r.scene) {
            EXPECT_NE(r.error.find(e.path().filename().string()), std::string::npos) << r.error;
            continue;
        }
        for (const auto& m : r.scene->meshes) EXPECT_EQ(m->validate(), "") << m->name;
    }
    EXPECT_GT(files, 0);
}
