// cli_overlay_test.cpp - `viewer render|compare ... --overlay LIST [--select NODE]` through the
// real executable (CPU rasterizer only: no GL needed): overlays change the image, and bad
// values give a one-line error naming the valid overlays, before anything is rendered.
#include "assets/image_io.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;

namespace {

using ViewerRun = testing_support::ProgramRun;
ViewerRun runViewer(const std::string& args) { return testing_support::runProgram(VIEWER_EXE, args); }

std::vector<uint8_t> renderDemo(const fs::path& out, const std::string& extra) {
    ViewerRun r = runViewer("render demo --backend raster --size 160x90 --overwrite --out \"" + out.string() + "\" " + extra);
    EXPECT_EQ(r.status, 0) << r.output;
    assets::ImageLoad img = assets::loadImage(out);
    EXPECT_TRUE(img.texture) << img.error;
    return img.texture ? img.texture->rgba : std::vector<uint8_t>{};
}

}   // namespace

TEST(CliOverlayTest, OverlaysChangeTheImage) {
    const fs::path dir = testing_support::outputDir("cli-overlay");
    const std::vector<uint8_t> plain = renderDemo(dir / "plain.png", "");
    const std::vector<uint8_t> grid = renderDemo(dir / "grid.png", "--overlay grid,axes,lights,cameras,bounds");
    const std::vector<uint8_t> sel = renderDemo(dir / "selection.png", "--overlay selection --select turntable");
    ASSERT_EQ(plain.size(), grid.size());
    EXPECT_NE(plain, grid);
    EXPECT_NE(plain, sel);
}

TEST(CliOverlayTest, BadValuesGiveOneLineErrors) {
    const fs::path dir = testing_support::outputDir("cli-overlay");
    const std::string out = " --size 16x9 --overwrite --out \"" + (dir / "bad.png").string() + "\"";
    const std::string cmp = " --size 16x9 --out \"" + (dir / "cmp").string() + "\"";
    struct Case {
        std::string args, says;
    } cases[] = {
        {"render demo --overlay gird" + out, "'gird' is not one of grid, axes, lights, cameras, bounds, selection"},
        {"render demo --overlay grid," + out, "expected a comma-separated list of grid, axes"},
        {"render demo --overlay selection" + out, "--overlay selection: name the node with --select NODE"},
        {"render demo --select nope --overlay selection" + out, "--select 'nope': no node of that name"},
        {"compare demo --overlay axes,gird" + cmp, "'gird' is not one of grid, axes"},
    };
    for (const Case& c : cases) {
        ViewerRun r = runViewer(c.args);
        EXPECT_NE(r.status, 0) << c.args;
        EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << c.args << "\n" << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "cmp")) << "compare checks --overlay before making its folder";
}
