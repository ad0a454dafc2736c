// regression_test.cpp - every input a fuzzer ever crashed or hung on stays here
// (tests/assets/import/regressions) and must load into valid meshes or fail with a one-line error
// naming the file, within seconds.
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <chrono>

namespace fs = std::filesystem;

TEST(FuzzRegressionTest, CrashInputsLoadValidMeshesOrFailClearly) {
    fs::path dir = fs::path(VIEWER_SOURCE_DIR) / "tests/assets/import/regressions";
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        if (!e.is_regular_file()) continue;
        ++files;
        SCOPED_TRACE(e.path().filename().string());
        auto t0 = std::chrono::steady_clock::now();
        if (e.path().extension() == ".png") {   // the image path (textures)
            assets::ImageLoad img = assets::loadImage(e.path());
            EXPECT_FALSE(img.texture);
            EXPECT_NE(img.error.find(e.path().filename().string()), std::string::npos) << img.error;
            // These PNGs declare chunks longer than the file: refused before stb_image sizes a
            // buffer by the claim (it asked for 2 GB).
            EXPECT_NE(img.error.find("chunk claims"), std::string::npos) << img.error;
            continue;
        }
        assets::LoadResult r = assets::loadScene(e.path());
        EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0) << "hang";
        if (!r.scene) {
            EXPECT_NE(r.error.find(e.path().filename().string()), std::string::npos) << r.error;
            continue;
        }
        for (const auto& m : r.scene->meshes) EXPECT_EQ(m->validate(), "") << m->name;
    }
    EXPECT_GT(files, 0);
}
