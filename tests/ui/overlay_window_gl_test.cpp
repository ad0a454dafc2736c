// overlay_window_gl_test.cpp - View > Overlays in the real viewer window under Xvfb, driven by
// the automation's `overlay LIST|none` (the menu's toggles): the shown image gains the
// overlays and loses them again, the grid on top shows over the objects that hide it otherwise,
// and a bad name stops the script with a one-line error.
#include "assets/image_io.h"
#include "test_support.h"
#include "viewer_process.h"

#include <gtest/gtest.h>

#include <cstring>

namespace fs = std::filesystem;

namespace {

// Pixels whose RGB differ between two window shots of the same size (-1: unreadable).
long differingPixels(const fs::path& a, const fs::path& b) {
    assets::ImageLoad ia = assets::loadImage(a), ib = assets::loadImage(b);
    if (!ia.texture || !ib.texture || ia.texture->rgba.size() != ib.texture->rgba.size()) return -1;
    long n = 0;
    for (size_t k = 0; k < ia.texture->rgba.size(); k += 4) n += std::memcmp(&ia.texture->rgba[k], &ib.texture->rgba[k], 3) != 0;
    return n;
}

}   // namespace

TEST(OverlayWindowGLTest, MenuTogglesDrawAndRemoveOverlays) {
    ASSERT_TRUE(viewer_test::haveXvfb()) << "xvfb-run is needed to run the viewer window";
    const fs::path dir = testing_support::outputDir("overlay-window");
    fs::remove_all(dir);
    fs::create_directories(dir);
    // The first `wait` lets the GL backend draw the first frame, as every window test does:
    // switching to a CPU backend before any GL frame makes LeakSanitizer report 240 bytes held
    // by a library unloaded at exit (Mesa's, by the look of it; see docs/testing.md).
    const int rc = viewer_test::runViewer(dir,
                                          "wait\nbackend raster\nwait\nwindow-shot plain.png\n"
                                          "overlay grid,axes,bounds,lights\nframes 3\nwait\nwindow-shot on.png\n"
                                          "overlay grid-on-top,axes,bounds,lights\nframes 3\nwait\nwindow-shot top.png\n"
                                          "overlay none\nframes 3\nwait\nwindow-shot off.png\n"
                                          "overlay gird\nquit\n");
    const std::string log = viewer_test::readLog(dir);
    EXPECT_EQ(rc, 2) << "the bad name stops the script\n" << log;
    EXPECT_NE(log.find("overlay gird: --overlay: 'gird' is not one of grid, axes, lights, cameras, bounds, selection"), std::string::npos) << log;
    const long on = differingPixels(dir / "plain.png", dir / "on.png"), off = differingPixels(dir / "plain.png", dir / "off.png");
    std::printf("[overlay] window: %ld pixels changed with overlays on, %ld after turning them off\n", on, off);
    EXPECT_GT(on, 3000);
    EXPECT_GE(off, 0);
    EXPECT_LT(off, 500) << "only the status bar's frame rate may change";
    // Grid on top: the grid lines the demo's objects hid come into view over them.
    const long top = differingPixels(dir / "on.png", dir / "top.png");
    std::printf("[overlay] window: %ld pixels changed with the grid on top\n", top);
    EXPECT_GT(top, 700);
}
