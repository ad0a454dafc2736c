// viewer_gl_test.cpp - drives the real viewer window under Xvfb (xvfb-run) with an automation
// script: waits for the images, switches backends with keys 1/2/3, opens the split and
// difference views, takes offscreen backend screenshots (F12 path) and a PNG of the whole
// window, then quits. Never hangs: the viewer has its own --timeout and the command runs under
// `timeout`.
#include "assets/image_io.h"
#include "test_support.h"
#include "viewer_process.h"

#include <gtest/gtest.h>

#include <cstring>

namespace fs = std::filesystem;

using viewer_test::haveXvfb;
using viewer_test::readLog;
using viewer_test::runViewer;

namespace {

// Non-empty and not one flat colour.
::testing::AssertionResult pngHasContent(const fs::path& p) {
    if (!fs::exists(p)) return ::testing::AssertionFailure() << p << " missing";
    if (fs::file_size(p) == 0) return ::testing::AssertionFailure() << p << " empty";
    assets::ImageLoad img = assets::loadImage(p);
    if (!img.texture) return ::testing::AssertionFailure() << img.error;
    const sg::Texture& t = *img.texture;
    size_t n = size_t(t.width) * t.height;
    if (n == 0) return ::testing::AssertionFailure() << p << " has no pixels";
    size_t differing = 0;
    for (size_t i = 1; i < n; ++i)
        if (std::memcmp(&t.rgba[i * 4], &t.rgba[0], 3) != 0) ++differing;
    if (differing < n / 100) return ::testing::AssertionFailure() << p << " is (nearly) uniform";
    return ::testing::AssertionSuccess();
}

}   // namespace

TEST(ViewerGLTest, SwitchesBackendsAndTakesScreenshots) {
    if (!haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = testing_support::outputDir("ui") / "viewer_gl";
    fs::remove_all(dir);
    fs::create_directories(dir);
    int rc = runViewer(dir,
                       "wait\n"
                       "key 2\nwait\n"
                       "key 3\nwait\n"
                       "key 1\nwait\n"
                       "orbit 40 10\nwait\n"
                       "screenshot shots\n"
                       "window-shot window.png\n"
                       "view split3\nwait\n"
                       "window-shot split.png\n"
                       "view difference\nwait\n"
                       "window-shot diff.png\n"
                       "quit\n");
    ASSERT_EQ(rc, 0) << readLog(dir);
    EXPECT_TRUE(pngHasContent(dir / "window.png"));
    EXPECT_TRUE(pngHasContent(dir / "split.png"));
    EXPECT_TRUE(pngHasContent(dir / "diff.png"));
    // Config written to the per-user folder (layout).
    EXPECT_TRUE(fs::exists(dir / "config" / "sceneviewer" / "imgui.ini")) << readLog(dir);
    // Backend screenshot: written when the gl backend works, else the log says why.
    fs::path shot = dir / "shots" / "screenshot-gl.png";
    if (fs::exists(shot))
        EXPECT_TRUE(pngHasContent(shot));
    else
        EXPECT_NE(readLog(dir).find("screenshot"), std::string::npos) << readLog(dir);
}

TEST(ViewerGLTest, FailedOpenKeepsRunning) {
    if (!haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = testing_support::outputDir("ui") / "viewer_gl_badfile";
    fs::remove_all(dir);
    fs::create_directories(dir);
    int rc = runViewer(dir, "wait\nwindow-shot window.png\nquit\n", "'" + (dir / "missing.gltf").string() + "'");
    ASSERT_EQ(rc, 0) << readLog(dir);
    EXPECT_TRUE(pngHasContent(dir / "window.png"));
}
