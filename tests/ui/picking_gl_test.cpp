// picking_gl_test.cpp - picking and the pixel inspector in the real window (Xvfb), through the
// automation: a click in the viewport selects the node the pixel inspector names there, in the
// split view both backends name the same node and triangle and their terms add up to their
// pixels, and a click on empty space clears the selection.
#include "assets/demo.h"
#include "assets/scene_io.h"
#include "test_support.h"
#include "viewer_process.h"

#include <gtest/gtest.h>

#include <sstream>

namespace fs = std::filesystem;

namespace {

std::vector<std::string> printed(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        if (line.rfind("viewer: ", 0) == 0) out.push_back(line.substr(8));
    return out;
}

// "pixel gl 300 420 rgb 115 60 16 node /crate triangle 8 depth 12.2 predicted 115 60 17" -> fields.
struct PixelLine {
    std::string backend, node;
    int rgb[3] = {0, 0, 0}, predicted[3] = {0, 0, 0};
    int triangle = -2;
    bool background = false;
};
PixelLine parsePixel(const std::string& line) {
    PixelLine p;
    std::istringstream in(line);
    std::string word, x, y;
    in >> word >> p.backend >> x >> y;
    while (in >> word) {
        if (word == "rgb") in >> p.rgb[0] >> p.rgb[1] >> p.rgb[2];
        if (word == "predicted") in >> p.predicted[0] >> p.predicted[1] >> p.predicted[2];
        if (word == "node") {   // the path may hold spaces ("/red sphere"): up to " triangle"
            std::string part;
            in >> p.node;
            while (in >> part && part != "triangle") p.node += " " + part;
            if (part == "triangle") in >> p.triangle;
        }
        if (word == "triangle") in >> p.triangle;
        if (word == "background") p.background = true;
    }
    return p;
}

}   // namespace

TEST(PickingGLTest, ClickSelectsWhatTheInspectorNamesInEveryBackend) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = testing_support::outputDir("ui") / "picking";
    fs::remove_all(dir);
    fs::create_directories(dir);
    ASSERT_EQ(assets::saveSceneJson(assets::makeDemoScene(), dir / "demo.json", true), "");
    const std::string script =
        "wait\nframes 10\nwait\nclick viewport 300 330\nframes 5\nwait\nprint selection\nprint pixel\n"
        "view split\nwait\nframes 10\nwait\nclick viewport 300 330\nframes 5\nwait\nprint pixel\n"
        "click viewport 12 12\nframes 3\nprint selection\nprint pixel\n"
        "diagnostic id\nframes 3\nwait\nprint view\nwindow-shot ids.png\ndiagnostic bogus\nquit\n";
    const int rc = viewer_test::runViewer(dir, script, "demo.json", /*separateStdout=*/true);
    const std::vector<std::string> out = printed(viewer_test::readLog(dir, "out.txt"));
    const std::string log = viewer_test::readLog(dir);
    EXPECT_NE(rc, 0) << "diagnostic bogus must fail the script";
    EXPECT_NE(log.find("diagnostic bogus: expected shaded, depth"), std::string::npos) << log;
    ASSERT_EQ(out.size(), 9u) << log;
    EXPECT_EQ(out[7], "view split id");
    // Single view (gl): the selection is the node the inspector names.
    ASSERT_EQ(out[0].rfind("selection ", 0), 0u);
    const std::string selected = out[0].substr(10);
    ASSERT_NE(selected, "-") << "the click at (300, 330) should hit the demo's geometry";
    const PixelLine single = parsePixel(out[1]);
    EXPECT_EQ(single.node.substr(single.node.rfind('/') + 1), selected) << out[1];
    // Split view (gl | raster): the same node and triangle, and each pixel is what its terms add up to.
    const PixelLine a = parsePixel(out[2]), b = parsePixel(out[3]);
    EXPECT_NE(a.backend, b.backend);
    EXPECT_EQ(a.node, single.node);
    EXPECT_EQ(b.node, single.node);
    EXPECT_EQ(a.triangle, b.triangle);
    for (const PixelLine* p : {&single, &a, &b})
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(p->rgb[c], p->predicted[c], 3) << p->backend << " channel " << c;
    // Empty space clears the selection.
    EXPECT_EQ(out[4], "selection -");
    EXPECT_TRUE(parsePixel(out[5]).background) << out[5];
    EXPECT_TRUE(parsePixel(out[6]).background) << out[6];
}

// Ctrl+click adds to the selection and takes out again, in the viewport and the scene tree;
// the last added is the active node (listed first); Ctrl+click on empty space changes nothing;
// Delete removes every selected node as one undo step, and Ctrl+Z brings them all back.
TEST(PickingGLTest, CtrlClickAddsAndDeleteRemovesTheWholeSelection) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = testing_support::outputDir("ui") / "picking_multi";
    fs::remove_all(dir);
    fs::create_directories(dir);
    ASSERT_EQ(assets::saveSceneJson(assets::makeDemoScene(), dir / "demo.json", true), "");
    const std::string pick = "frames 5\nwait\nprint selection\n";
    const std::string script =
        "wait\nframes 10\nwait\n"
        "click viewport 236 366\n" +
        pick +                                                  // 0: the red sphere
        "click ctrl viewport 362 434\n" + pick +                // 1: + the blue sphere
        "click ctrl tree/red sphere\n" + pick +                 // 2: - the red sphere (tree)
        "click ctrl viewport 236 366\n" + pick +                // 3: + the red sphere again
        "click ctrl viewport 12 12\n" + pick +                  // 4: empty space: unchanged
        "key Delete\nframes 2\nprint tree\nprint undo\n"        // 5, 6
        "key ctrl+z\nframes 2\nprint tree\nprint selection\n"   // 7, 8
        "click viewport 12 12\n" +
        pick +   // 9
        "quit\n";
    const int rc = viewer_test::runViewer(dir, script, "demo.json", /*separateStdout=*/true);
    const std::string log = viewer_test::readLog(dir);
    std::vector<std::string> out;   // a tree is one entry
    {
        std::istringstream in(viewer_test::readLog(dir, "out.txt"));
        bool tree = false;
        for (std::string line; std::getline(in, line);) {
            if (line.rfind("viewer: ", 0) == 0) {
                out.push_back(line.substr(8));
                tree = line == "viewer: tree";
            } else if (tree) {
                out.back() += "\n" + line;
            }
        }
    }
    ASSERT_EQ(rc, 0) << log;
    ASSERT_EQ(out.size(), 10u) << log;
    EXPECT_EQ(out[0], "selection red sphere");
    EXPECT_EQ(out[1], "selection blue sphere, red sphere");
    EXPECT_EQ(out[2], "selection blue sphere");
    EXPECT_EQ(out[3], "selection red sphere, blue sphere");
    EXPECT_EQ(out[4], "selection red sphere, blue sphere");
    EXPECT_EQ(out[5].find("sphere"), std::string::npos) << out[5];
    EXPECT_NE(out[5].find("crate"), std::string::npos) << out[5];
    EXPECT_EQ(out[6], "undo Delete 2 nodes | redo -");
    EXPECT_NE(out[7].find("  red sphere\n"), std::string::npos) << out[7];
    EXPECT_NE(out[7].find("  blue sphere\n"), std::string::npos) << out[7];
    EXPECT_EQ(out[8], "selection red sphere") << "undo brings back the active node's selection";
    EXPECT_EQ(out[9], "selection -");
}
