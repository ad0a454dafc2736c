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

class GlBaselineGLTest : public ::testing::TestWithParam<std::string> {};

TEST_P(GlBaselineGLTest, MatchesBaseline) {
    const std::string name = GetParam();
    auto r = rnd::makeGlRenderer();
    rnd::Framebuffer actual;
    rnd::RenderStats st = r->render(test_scenes::baselineFrame(name, kWidth, kHeight), kWidth, kHeight, actual);
    ASSERT_TRUE(st.ok) << st.error;

    EXPECT_TRUE(testing_support::matchesGlBaseline(actual, name));
}

INSTANTIATE_TEST_SUITE_P(Scenes, GlBaselineGLTest, ::testing::ValuesIn(test_scenes::baselineNames()),
                         [](const ::testing::TestParamInfo<std::string>& i) { return i.param; });

}   // namespace
