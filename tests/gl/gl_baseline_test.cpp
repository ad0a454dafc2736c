// gl_baseline_test.cpp - small (160x120) GL renders of the scenes in tests/support/test_scenes.cpp held
// against tests/baselines/gl/<name>.png with mean/fraction thresholds (never byte for byte).
// On failure the actual, expected and diff images go to build/<preset>/test-output/gl-baselines.
// VIEWER_ACCEPT_BASELINES=1 writes the baselines instead (scripts/accept-baselines.sh).
#include "assets/image_io.h"
#include "gl/gl_renderer.h"
#include "test_scenes.h"
#include "test_support.h"

#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace {

constexpr int kWidth = 160, kHeight = 120;

fs::path baselinePath(const std::string& name) { return fs::path(VIEWER_SOURCE_DIR) / "tests" / "baselines" / "gl" / (name + ".png"); }

class GlBaselineGLTest : public ::testing::TestWithParam<std::string> {};

TEST_P(GlBaselineGLTest, MatchesBaseline) {
    const std::string name = GetParam();
    auto r = rnd::makeGlRenderer();
    rnd::Framebuffer actual;
    rnd::RenderStats st = r->render(test_scenes::baselineFrame(name, kWidth, kHeight), kWidth, kHeight, actual);
    ASSERT_TRUE(st.ok) << st.error;

    fs::path path = baselinePath(name);
    const char* accept = std::getenv("VIEWER_ACCEPT_BASELINES");
    if (accept && std::string(accept) == "1") {
        std::string err = assets::writePng(path, actual.width, actual.height, actual.color.data(), true);
        ASSERT_TRUE(err.empty()) << err;
        std::printf("[baseline] wrote %s\n", path.c_str());
        return;
    }
    assets::ImageLoad load = assets::loadImage(path);
    ASSERT_TRUE(load.texture) << "baseline " << path << " missing or unreadable (" << load.error
                              << "): run scripts/accept-baselines.sh after looking at the render";
    rnd::Framebuffer expected;
    expected.resize(load.texture->width, load.texture->height);
    expected.color = load.texture->rgba;
    testing_support::ImageTolerance tol;
    tol.maxMeanAbs = 1.0;
    tol.minFractionWithin = 0.98;
    tol.channelTolerance = 8;
    EXPECT_TRUE(testing_support::imagesClose(actual, expected, tol, "gl-baselines", name));
}

INSTANTIATE_TEST_SUITE_P(Scenes, GlBaselineGLTest, ::testing::ValuesIn(test_scenes::baselineNames()),
                         [](const ::testing::TestParamInfo<std::string>& i) { return i.param; });

}   // namespace
