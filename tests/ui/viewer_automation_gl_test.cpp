// viewer_automation_gl_test.cpp - the real viewer window under Xvfb, driven by automation
// scripts (ui/src/automation.cpp) whose `print` output is checked line by line: edits, undo
// and redo through keys, the Edit menu and script commands with the dirty flag following;
// File > Open with the unsaved-changes question answered; `view` doing what the View menu
// does; the diagnostic views offered and drawn by capability; screenshots as shown and the
// export from the window; bad commands failing the script.
#include "assets/aov_io.h"
#include "assets/demo.h"
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "test_support.h"
#include "ui/viewer_state.h"
#include "viewer_process.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

namespace fs = std::filesystem;

namespace {

struct ScriptRun {
    int rc = -1;
    std::vector<std::string> out;   // what `print` wrote, "viewer: " removed; a tree is one entry
    std::string log;                // stderr
};

// "viewer: tree" and the node lines after it become one entry "tree\n<line>\n<line>...".
std::vector<std::string> parseOutput(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    bool inTree = false;
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("viewer: ", 0) == 0) {
            out.push_back(line.substr(8));
            inTree = line == "viewer: tree";
        } else if (inTree) {
            out.back() += "\n" + line;
        }
    }
    return out;
}

// A folder with demo.json (the demo scene) and small.json (a root with one child).
fs::path sceneFolder(const std::string& name) {
    fs::path dir = testing_support::outputDir("ui") / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    EXPECT_EQ(assets::saveSceneJson(assets::makeDemoScene(), dir / "demo.json", true), "");
    sg::Scene small;
    small.name = "small";
    small.addNode("only child");
    EXPECT_EQ(assets::saveSceneJson(small, dir / "small.json", true), "");
    return dir;
}

ScriptRun runScript(const fs::path& dir, const std::string& script, const std::string& args = "demo.json", const std::string& screen = "") {
    ScriptRun r;
    r.rc = viewer_test::runViewer(dir, script, args, /*separateStdout=*/true, screen);
    r.out = parseOutput(viewer_test::readLog(dir, "out.txt"));
    r.log = viewer_test::readLog(dir);
    return r;
}

bool treeHas(const std::string& tree, const std::string& name) { return tree.find("\n  " + name + "\n") != std::string::npos; }

std::string dump(const ScriptRun& r) {
    std::string s = "exit code " + std::to_string(r.rc) + "\n--- stdout entries:\n";
    for (const std::string& o : r.out) s += o + "\n";
    return s + "--- stderr:\n" + r.log;
}

}   // namespace

TEST(ViewerAutomationGLTest, EditsUndoAndRedoMoveTheDirtyFlag) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_undo");
    ScriptRun r = runScript(dir,
                            "wait\n"
                            "print dirty\n"   // 0
                            "select crate\n"
                            "set material.kd 0.1\n"
                            "print dirty\n"   // 1
                            "print undo\n"    // 2
                            "key ctrl+z\n"
                            "print dirty\n"   // 3
                            "print undo\n"    // 4
                            "key Delete\n"
                            "print tree\n"    // 5
                            "print dirty\n"   // 6
                            "undo\n"
                            "print tree\n"        // 7
                            "print selection\n"   // 8
                            "print dirty\n"       // 9
                            "key ctrl+shift+z\n"
                            "print tree\n"        // 10
                            "print selection\n"   // 11
                            "key ctrl+z\n"
                            "key ctrl+y\n"
                            "print tree\n"   // 12
                            "set fog.mode linear\n"
                            "set fog.end 1\n"   // refused: end <= start
                            "print undo\n"      // 13, 14: the refusal comes first
                            "print status\n"    // 15
                            "quit\n");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 16u) << dump(r);
    EXPECT_EQ(r.out[0], "dirty no");
    EXPECT_EQ(r.out[1], "dirty yes");
    EXPECT_EQ(r.out[2], "undo Edit material crate | redo -");
    EXPECT_EQ(r.out[3], "dirty no") << "undone back to the loaded scene";
    EXPECT_EQ(r.out[4], "undo - | redo Edit material crate");
    EXPECT_FALSE(treeHas(r.out[5], "crate")) << r.out[5];
    EXPECT_TRUE(treeHas(r.out[5], "sheared crate")) << r.out[5];
    EXPECT_EQ(r.out[6], "dirty yes");
    EXPECT_TRUE(treeHas(r.out[7], "crate")) << r.out[7];
    EXPECT_EQ(r.out[7].find("  room"), r.out[7].find("\n  ") + 1) << "crate back in its place, after room:\n" << r.out[7];
    EXPECT_LT(r.out[7].find("  crate\n"), r.out[7].find("  sheared crate\n"));
    EXPECT_EQ(r.out[8], "selection crate");
    EXPECT_EQ(r.out[9], "dirty no");
    EXPECT_FALSE(treeHas(r.out[10], "crate")) << r.out[10];
    EXPECT_EQ(r.out[11], "selection -");
    EXPECT_FALSE(treeHas(r.out[12], "crate")) << "ctrl+z then ctrl+y: deleted again\n" << r.out[12];
    EXPECT_EQ(r.out[13].rfind("set fog.end: refused: ", 0), 0u) << r.out[13];
    EXPECT_NE(r.out[13].find("end > start"), std::string::npos) << r.out[13];
    EXPECT_EQ(r.out[14], "undo Change fog.mode | redo -");
    EXPECT_EQ(r.out[15].rfind("status Setting refused", 0), 0u) << r.out[15];
}

TEST(ViewerAutomationGLTest, ClicksReachTheTreeAndTheEditMenu) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_click");
    ScriptRun r = runScript(dir,
                            "wait\n"
                            "click tree/crate\n"
                            "print selection\n"   // 0
                            "key Delete\n"
                            "print tree\n"   // 1
                            "click menu/edit\n"
                            "click edit/undo\n"
                            "print tree\n"             // 2
                            "print dirty\n"            // 3
                            "click viewport 40 40\n"   // a click on empty space in the 3D viewport: no edit, selection cleared (picking)
                            "wait\n"
                            "print selection\n"   // 4
                            "window-shot undone.png\n"
                            "quit\n");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 6u) << dump(r);   // + "wrote undone.png"
    EXPECT_EQ(r.out[0], "selection crate");
    EXPECT_FALSE(treeHas(r.out[1], "crate"));
    EXPECT_TRUE(treeHas(r.out[2], "crate")) << r.out[2];
    EXPECT_EQ(r.out[3], "dirty no");
    EXPECT_EQ(r.out[4], "selection -");
}

TEST(ViewerAutomationGLTest, OpenAsksAboutUnsavedChangesAndAnswersWork) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_open");
    {
        std::ofstream out(dir / "broken.json");
        out << "{ \"nodes\": [";
    }
    ScriptRun r = runScript(dir,
                            "wait\n"
                            "set shading flat\n"
                            "open small.json\n"
                            "answer cancel\n"
                            "wait\n"
                            "print tree\n"    // 0: still the demo
                            "print dirty\n"   // 1
                            "print undo\n"    // 2
                            "open small.json\n"
                            "answer discard\n"
                            "wait\n"
                            "print tree\n"    // 3: the small scene
                            "print dirty\n"   // 4
                            "print undo\n"    // 5: a new document has no history
                            "set shading flat\n"
                            "open broken.json\n"   // asks; discard; the load fails
                            "answer discard\n"
                            "wait\n"
                            "print tree\n"    // 6: still the small scene, edits kept
                            "print dirty\n"   // 7
                            "print undo\n"    // 8
                            "quit\n");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 9u) << dump(r);
    EXPECT_TRUE(treeHas(r.out[0], "crate")) << r.out[0];
    EXPECT_EQ(r.out[1], "dirty yes");
    EXPECT_EQ(r.out[2], "undo Change shading | redo -");
    EXPECT_EQ(r.out[3], "tree\nroot\n  only child");
    EXPECT_EQ(r.out[4], "dirty no");
    EXPECT_EQ(r.out[5], "undo - | redo -");
    EXPECT_EQ(r.out[6], "tree\nroot\n  only child");
    EXPECT_EQ(r.out[7], "dirty yes") << "a failed load keeps the edits and the flag";
    EXPECT_EQ(r.out[8], "undo Change shading | redo -") << "... and the history";
}

// Nothing on disk is replaced without a question, driven as a user does: Save As onto an earlier
// scene asks (Cancel keeps it, Replace writes it); Ctrl+S on an imported file opens Save As
// instead of writing NAME.obj.json beside it; Ctrl+S on the document's own .json just saves.
TEST(ViewerAutomationGLTest, SaveAsAndCtrlSNeverReplaceAFileWithoutAsking) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_save");
    {
        std::ofstream out(dir / "tri.obj");
        out << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    }
    {
        std::ofstream out(dir / "tri.obj.json");
        out << "an earlier scene";
    }
    auto text = [&](const std::string& name) {
        std::ifstream in(dir / name, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string small = text("small.json");
    ScriptRun r = runScript(dir,
                            "wait\n"
                            "set shading flat\n"
                            "save-as small.json\n"
                            "print popup\n"   // 0: the replace question
                            "answer cancel\n"
                            "frames 2\n"
                            "print popup\n"   // 1
                            "print dirty\n"   // 2: not saved
                            "save-as small.json\n"
                            "answer replace\n"
                            "frames 2\n"
                            "print dirty\n"   // 3: saved over small.json, now the document
                            "set shading gouraud\n"
                            "key ctrl+s\n"   // the document's own .json: no question
                            "frames 2\n"
                            "print popup\n"   // 4
                            "print dirty\n"   // 5
                            "open tri.obj\n"
                            "wait\n"
                            "set shading flat\n"
                            "key ctrl+s\n"   // an import: Save As opens, nothing written
                            "frames 2\n"
                            "print popup\n"   // 6
                            "print dirty\n"   // 7
                            "key Escape\n"
                            "frames 2\n"
                            "print popup\n"   // 8
                            "quit\n",
                            "demo.json");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 9u) << dump(r);
    EXPECT_EQ(r.out[0], "popup yes");
    EXPECT_EQ(r.out[1], "popup no");
    EXPECT_EQ(r.out[2], "dirty yes");
    EXPECT_EQ(r.out[3], "dirty no");
    EXPECT_EQ(r.out[4], "popup no");
    EXPECT_EQ(r.out[5], "dirty no");
    EXPECT_EQ(r.out[6], "popup yes") << "Ctrl+S on an import opens Save As";
    EXPECT_EQ(r.out[7], "dirty yes");
    EXPECT_EQ(r.out[8], "popup no");
    EXPECT_EQ(text("tri.obj.json"), "an earlier scene");
    EXPECT_NE(text("small.json"), small);
    EXPECT_NE(text("small.json").find("gouraud"), std::string::npos) << "Ctrl+S wrote the document's own file";
}

TEST(ViewerAutomationGLTest, ViewCommandDoesWhatTheViewMenuDoes) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_view");
    std::string script = "frames 2\n";
    for (const char* mode : {"split", "split3", "difference", "single"})
        script +=
            std::string("view single\nview ") + mode + "\nprint compare\nview single\nclick menu/view\nclick view/" + mode + "\nprint compare\n";
    ScriptRun r = runScript(dir, script + "quit\n");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 8u) << dump(r);
    for (size_t i = 0; i < 8; i += 2) EXPECT_EQ(r.out[i], r.out[i + 1]) << "`view` vs the View menu";
    EXPECT_EQ(r.out[0].rfind("compare split ", 0), 0u) << r.out[0];
    EXPECT_EQ(r.out[2].rfind("compare split3 ", 0), 0u) << r.out[2];
    EXPECT_EQ(r.out[4].rfind("compare difference ", 0), 0u) << r.out[4];
}

// View > Diagnostic view offers a view only where a shown backend can make it (from the
// capabilities): overdraw with the rasterizer, cost with the ray caster, and a click on a
// greyed-out entry changes nothing. In the three-way split each backend's legend says what its
// image shows: the counts where it has them, and that it cannot make the view where it has not.
// The same for the shadow-map view (the rasterizers'), whose legends compare with the rays.
TEST(ViewerAutomationGLTest, OverdrawAndCostViewsFollowTheCapabilities) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_diagnostic");
    const std::string script =
        "wait\nbackend raster\nframes 2\nclick menu/view\nclick view/diagnostic\nclick diagnostic/overdraw\nprint view\n"
        "backend raycast\nframes 2\nclick menu/view\nclick view/diagnostic\nclick diagnostic/cost\nprint view\n"
        "diagnostic overdraw\nview split3\nframes 3\nwait\nframes 5\nwait\nframes 5\nprint compare\nprint legend\n"
        "diagnostic cost\nframes 3\nwait\nframes 5\nwait\nframes 5\nprint legend\n"
        "set shadows on\ndiagnostic shadow-map\nframes 3\nwait\nframes 5\nwait\nframes 5\nprint legend\n"
        "view single\nbackend raycast\ndiagnostic shaded\nframes 2\nclick menu/view\nclick view/diagnostic\nclick diagnostic/overdraw\nprint "
        "view\nquit\n";
    ScriptRun r = runScript(dir, script);
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 13u) << dump(r);
    EXPECT_EQ(r.out[0], "view single overdraw");
    EXPECT_EQ(r.out[1], "view single cost");
    EXPECT_EQ(r.out[2].rfind("compare split3 ", 0), 0u) << r.out[2];
    // "legend BACKEND TEXT" lines, one per shown backend (in the split's order): by backend.
    auto legends = [&](size_t first) {
        std::map<std::string, std::string> m;
        for (size_t i = first; i < first + 3; ++i) {
            const std::string& line = r.out[i];
            const size_t sp = line.find(' ', 7);
            if (line.rfind("legend ", 0) == 0 && sp != std::string::npos) m[line.substr(7, sp - 7)] = line.substr(sp + 1);
        }
        return m;
    };
    std::map<std::string, std::string> od = legends(3), cost = legends(6), maps = legends(9);
    ASSERT_EQ(od.size(), 3u) << dump(r);
    ASSERT_EQ(cost.size(), 3u) << dump(r);
    EXPECT_EQ(od["gl"].rfind("overdraw (fragments per pixel", 0), 0u) << od["gl"];
    EXPECT_EQ(od["raster"].rfind("overdraw (fragments per pixel", 0), 0u) << od["raster"];
    EXPECT_EQ(od["raycast"], "overdraw: the raycast backend cannot make this view (showing the shaded image)");
    EXPECT_EQ(cost["gl"], "cost: the gl backend cannot make this view (showing the shaded image)");
    EXPECT_EQ(cost["raster"], "cost: the raster backend cannot make this view (showing the shaded image)");
    EXPECT_EQ(cost["raycast"].rfind("cost (BVH nodes visited + triangles tested", 0), 0u) << cost["raycast"];
    // The shadow-map view: the rasterizers' maps against the ray caster's rays, which agree on the
    // demo but for a few edge pixels; the ray caster has no map to show.
    for (const char* b : {"gl", "raster"}) {
        const std::string& m = maps[b];
        EXPECT_EQ(m.rfind("shadow-map: light 0 (", 0), 0u) << b << ": " << m;
        const size_t red = m.find("(red: acne, edge spill) "), blue = m.find("(blue: leak, peter-panning) ");
        ASSERT_NE(red, std::string::npos) << b << ": no comparison: " << m;
        ASSERT_NE(blue, std::string::npos) << m;
        EXPECT_LT(std::stod(m.substr(red + 24)), 1.0) << m;
        EXPECT_LT(std::stod(m.substr(blue + 28)), 1.0) << m;
    }
    EXPECT_EQ(maps["raycast"], "shadow-map: the raycast backend cannot make this view (showing the shaded image)");
    EXPECT_EQ(r.out[12], "view single shaded") << "overdraw is greyed out for the ray caster alone";
}

TEST(ViewerAutomationGLTest, BadCommandsFailTheScript) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_bad");
    for (const auto& [line, message] : std::vector<std::pair<std::string, std::string>>{{"answer discard", "no question is pending"},
                                                                                        {"set no.such.setting 1", "unknown setting"},
                                                                                        {"key ctrl+nokey", "unknown key"},
                                                                                        {"select nobody", "no node of that name"},
                                                                                        {"print everything", "expected dirty"},
                                                                                        {"click nowhere/at all", "no widget of that name"}}) {
        SCOPED_TRACE(line);
        ScriptRun r = runScript(dir, "frames 1\n" + line + "\nprint dirty\nquit\n");
        EXPECT_EQ(r.rc, 2) << dump(r);
        EXPECT_NE(r.log.find(message), std::string::npos) << dump(r);
        EXPECT_TRUE(r.out.empty()) << "stopped at the bad line\n" << dump(r);
    }
}

// Started from raster the difference view compares raster with another
// backend; split3 started from raycast shows three different ones; each view keeps its own
// choice; the figures are written one way (and only say 100% when every pixel is within).
TEST(ViewerAutomationGLTest, ComparisonDefaultsCompareDifferentBackendsAndEachViewKeepsItsOwn) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_compare");
    ScriptRun r = runScript(dir,
                            "wait\n"
                            "backend raster\n"
                            "view difference\n"
                            "print compare\n"   // 0
                            "wait\n"
                            "print diff\n"   // 1
                            "window-shot difference.png\n"
                            "backend raycast\n"
                            "view split3\n"
                            "print compare\n"   // 3
                            "view difference\n"
                            "print compare\n"   // 4
                            "view split\n"
                            "print compare\n"   // 5
                            "quit\n");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 6u) << dump(r);
    EXPECT_EQ(r.out[0], "compare difference raster gl");
    EXPECT_EQ(r.out[1].rfind("diff |raster - gl|   mean ", 0), 0u) << r.out[1];
    EXPECT_EQ(r.out[1].find("identical"), std::string::npos) << r.out[1];
    size_t pct = r.out[1].find("within 8: ");
    ASSERT_NE(pct, std::string::npos) << r.out[1];
    std::string within = r.out[1].substr(pct + 10);
    EXPECT_TRUE(within == "100%" || (within.size() >= 5 && within[within.size() - 4] == '.' && within.back() == '%')) << within;
    EXPECT_EQ(r.out[3], "compare split3 raycast gl raster");
    EXPECT_EQ(r.out[4], "compare difference raster gl") << "the difference view kept its own pair";
    EXPECT_EQ(r.out[5], "compare split raycast gl") << "the split view kept its own";
}

// File > New (Ctrl+N) then Add > Sphere gives a lit sphere in view
// (the new scene has a light and a camera); a refused value's message leaves the status bar
// once the value is valid.
TEST(ViewerAutomationGLTest, NewSceneThenAddSphereAndRefusalsThatClear) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_new_scene");
    ScriptRun r = runScript(dir,
                            "wait\n"
                            "key ctrl+n\n"
                            "print tree\n"   // 0
                            "click tree/addButton\n"
                            "click add/Sphere\n"
                            "print tree\n"    // 1
                            "print dirty\n"   // 2
                            "wait\n"
                            "window-shot new-sphere.png\n"   // 3
                            "set fog.mode linear\n"
                            "set fog.end 1\n"   // 4: refused
                            "print status\n"    // 5
                            "set fog.end 50\n"
                            "print status\n"   // 6
                            "quit\n");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 7u) << dump(r);
    EXPECT_EQ(r.out[0], "tree\nroot\n  light\n  default camera");
    EXPECT_EQ(r.out[1], "tree\nroot\n  light\n  default camera\n  sphere");
    EXPECT_EQ(r.out[2], "dirty yes");
    EXPECT_EQ(r.out[4].rfind("set fog.end: refused", 0), 0u) << r.out[4];
    EXPECT_NE(r.out[5].find("Setting refused"), std::string::npos) << r.out[5];
    EXPECT_EQ(r.out[6].find("refused"), std::string::npos) << r.out[6];
}

// F12 right after an orbit (a real drag) in the split and difference views
// saves every shown backend; the status line names each file, with the absolute folder once.
// (GL used to be lost: after an orbit in the difference view its texture was deleted while the
// frame's UI still drew it; the GL error that left in the window's context stayed there, in
// whatever view came next, until a GL screenshot read it as its own failure.)
TEST(ViewerAutomationGLTest, ScreenshotAfterAnOrbitSavesEveryShownBackend) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    const std::pair<std::string, std::string> cases[] = {
        {"split", "view split\n"}, {"difference", "view difference\n"}, {"difference_then_split", "view difference\n"}};
    for (const auto& [name, view] : cases) {
        SCOPED_TRACE(name);
        fs::path dir = sceneFolder("automation_shot_" + name);
        std::string thenSplit = name == "difference_then_split" ? "view split\n" : "";
        ScriptRun r =
            runScript(dir, "wait\n" + view + "wait\ndrag 100 100 260 140\n" + thenSplit + "print compare\nkey F12\nwait\nprint status\nquit\n");
        ASSERT_EQ(r.rc, 0) << dump(r);
        ASSERT_EQ(r.out.size(), 2u) << dump(r);
        std::istringstream compare(r.out[0]);
        std::string word, mode;
        compare >> word >> mode;
        std::vector<std::string> files;
        for (std::string b; compare >> b;) files.push_back("screenshot-" + b + ".png");
        ASSERT_EQ(files.size(), 2u) << r.out[0];
        std::sort(files.begin(), files.end());   // the status lists them by backend name
        EXPECT_EQ(r.out[1], "status Saved 2 screenshots in " + fs::canonical(dir).string() + ": " + files[0] + ", " + files[1]) << dump(r);
        for (const std::string& f : files) EXPECT_TRUE(fs::exists(dir / f)) << f;
        EXPECT_EQ(r.log.find("OpenGL error"), std::string::npos) << dump(r);
    }
}

// Right after a load the viewport shows nothing of the previous scene: no
// image (it says "rendering...") and no figures, in the single and the split view; once
// rendered, the new scene's.
TEST(ViewerAutomationGLTest, AfterALoadNothingOfThePreviousSceneIsShown) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_load_clears");
    ScriptRun r = runScript(dir,
                            "wait\n"
                            "view split\n"
                            "wait\n"
                            "stats\n"   // 0, 1: the demo
                            "open small.json\n"
                            "wait load\n"
                            "stats\n"   // 2, 3: right after the load
                            "window-shot loaded.png\n"
                            "wait\n"
                            "stats\n"   // 5, 6: the small scene (no geometry)
                            "quit\n");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 7u) << dump(r);
    for (int i : {0, 1}) EXPECT_EQ(r.out[size_t(i)].find(", 0 triangles"), std::string::npos) << "the demo has triangles: " << r.out[size_t(i)];
    for (int i : {2, 3}) {
        EXPECT_EQ(r.out[size_t(i)].rfind("stats ", 0), 0u) << r.out[size_t(i)];
        EXPECT_NE(r.out[size_t(i)].find(": no image yet"), std::string::npos) << r.out[size_t(i)];
    }
    for (int i : {5, 6}) EXPECT_NE(r.out[size_t(i)].find("level 1: "), std::string::npos) << r.out[size_t(i)];
    for (int i : {5, 6}) EXPECT_NE(r.out[size_t(i)].find(", 0 triangles"), std::string::npos) << r.out[size_t(i)];
}

// On a 1366x768 screen the window opens inside the work area, sized from it;
// it reopens at the size it had (remembered in the config folder); a remembered rectangle too
// big or off the screen, or a window.txt that does not parse, still gives a window that fits;
// a run sized by --window-size is not remembered.
TEST(ViewerAutomationGLTest, WindowFitsASmallScreenAndRemembersItsSize) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_window");
    auto fits = [](const std::string& line) {
        int x, y, w, h, ax, ay, aw, ah;
        if (std::sscanf(line.c_str(), "window %d %d %d %d in work area %d %d %d %d", &x, &y, &w, &h, &ax, &ay, &aw, &ah) != 8) return false;
        return x >= ax && y >= ay && x + w <= ax + aw && y + h <= ay + ah && w >= aw / 2 && h >= ah / 2;
    };
    const std::string screen = "1366x768x24";
    ScriptRun first = runScript(dir, "frames 2\nprint window\nresize 900 600\nprint window\nquit\n", "demo.json", screen);
    ASSERT_EQ(first.rc, 0) << dump(first);
    ASSERT_EQ(first.out.size(), 2u) << dump(first);
    EXPECT_TRUE(fits(first.out[0])) << first.out[0];
    EXPECT_NE(first.out[0].find(" in work area 0 0 1366 768"), std::string::npos) << first.out[0];
    EXPECT_NE(first.out[1].find(" 900 600 in"), std::string::npos) << first.out[1];

    ScriptRun second = runScript(dir, "frames 2\nprint window\nquit\n", "demo.json", screen);
    ASSERT_EQ(second.rc, 0) << dump(second);
    ASSERT_EQ(second.out.size(), 1u) << dump(second);
    EXPECT_EQ(second.out[0], first.out[1]) << "reopened where and as big as it was";

    ScriptRun sized = runScript(dir, "frames 2\nresize 700 500\nquit\n", "demo.json --window-size 800x600", screen);
    ASSERT_EQ(sized.rc, 0) << dump(sized);
    ScriptRun third = runScript(dir, "frames 2\nprint window\nquit\n", "demo.json", screen);
    ASSERT_EQ(third.out.size(), 1u) << dump(third);
    EXPECT_EQ(third.out[0], first.out[1]) << "a run sized by --window-size is not remembered";

    for (const char* remembered : {"-500 -300 3000 2000\n", "not a rectangle\n"}) {
        SCOPED_TRACE(remembered);
        std::ofstream(dir / "config" / "sceneviewer" / "window.txt") << remembered;
        ScriptRun r = runScript(dir, "frames 2\nprint window\nquit\n", "demo.json", screen);
        ASSERT_EQ(r.rc, 0) << dump(r);
        ASSERT_EQ(r.out.size(), 1u) << dump(r);
        EXPECT_TRUE(fits(r.out[0])) << r.out[0];
        if (std::string(remembered).rfind("not", 0) == 0) { EXPECT_NE(r.log.find("window.txt: expected"), std::string::npos) << dump(r); }
    }
}

// A file camera far from its model with a focus distance in front of itself (as glTF files
// have): the orbit pivot is on the model, so an orbit keeps it in view; keypad 7 looks down,
// keypad 5 switches to orthographic; the panels follow the window and Viewport only hides them.
TEST(ViewerAutomationGLTest, OrbitStaysOnTheModelAndTheLayoutFollowsTheWindow) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_orbit");
    {
        sg::Scene s;
        sg::ImplicitShape box;
        box.type = sg::ImplicitType::Box;
        box.halfExtents = sg::vec3(50.0f);
        s.addNode("engine", s.root(), sg::ImplicitPayload{box, -1});
        sg::Camera cam;
        cam.focusDistance = 5.0f;   // 5 units ahead of a camera 1500 away
        cam.projection.zNear = 1.0f;
        cam.projection.zFar = 5000.0f;
        sg::NodeId c = s.addNode("file camera", s.root(), cam);
        sg::LocalTransform t;
        t.translation = sg::vec3(0.0f, 0.0f, 1500.0f);
        s.setLocal(c, t);
        s.activeCamera = c;
        ASSERT_EQ(assets::saveSceneJson(s, dir / "far.json", true), "");
    }
    auto camera = [](const std::string& line, sg::vec3& eye, sg::vec3& centre, std::string& proj) {
        char name[64] = {};
        const bool ok = std::sscanf(line.c_str(), "camera eye %f %f %f centre %f %f %f up %*f %*f %*f projection %63s", &eye.x, &eye.y, &eye.z,
                                    &centre.x, &centre.y, &centre.z, name) == 7;
        proj = name;
        return ok;
    };
    auto viewport = [](const std::string& line, int& x, int& y, int& w, int& h) {
        return std::sscanf(line.c_str(), "viewport %d %d %d %d", &x, &y, &w, &h) == 4;
    };
    ScriptRun r = runScript(dir,
                            "wait\n"
                            "print camera\n"   // 0: pivot on the model
                            "drag 300 300 340 300\n"
                            "print camera\n"   // 1: orbited about it
                            "key kp7\n"
                            "print camera\n"   // 2: top view
                            "key kp5\n"
                            "print camera\n"     // 3: orthographic
                            "print viewport\n"   // 4
                            "print window\n"     // 8 (printed here; the index below)
                            "panels hide\n"
                            "print viewport\n"   // 5: the whole width
                            "panels show\n"
                            "resize 800 500\n"
                            "print viewport\n"   // 6
                            "resize 1366 700\n"
                            "print viewport\n"   // 7
                            "quit\n",
                            "far.json", "1366x768x24");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 9u) << dump(r);
    int winX, winY, winW = 0, winH;
    ASSERT_EQ(std::sscanf(r.out[5].c_str(), "window %d %d %d %d", &winX, &winY, &winW, &winH), 4) << r.out[5];
    r.out.erase(r.out.begin() + 5);
    sg::vec3 eye, centre;
    std::string proj;
    ASSERT_TRUE(camera(r.out[0], eye, centre, proj)) << r.out[0];
    EXPECT_LT(glm::length(centre), 1.0f) << "the pivot is on the model, not 5 units ahead of the camera: " << r.out[0];
    EXPECT_NEAR(glm::length(eye - centre), 1500.0f, 1.0f) << r.out[0];
    ASSERT_TRUE(camera(r.out[1], eye, centre, proj)) << r.out[1];
    EXPECT_LT(glm::length(centre), 1.0f) << r.out[1];
    EXPECT_GT(std::abs(eye.x), 50.0f) << "the drag orbited: " << r.out[1];
    ASSERT_TRUE(camera(r.out[2], eye, centre, proj)) << r.out[2];
    EXPECT_GT(eye.y - centre.y, 0.99f * glm::length(eye - centre)) << "keypad 7 looks down from above: " << r.out[2];
    ASSERT_TRUE(camera(r.out[3], eye, centre, proj)) << r.out[3];
    EXPECT_EQ(proj, "orthographic") << r.out[3];
    int x, y, w, h;
    ASSERT_TRUE(viewport(r.out[4], x, y, w, h)) << r.out[4];
    EXPECT_GE(w, winW / 2) << "the viewport keeps at least half the width: " << r.out[4];
    ASSERT_TRUE(viewport(r.out[5], x, y, w, h)) << r.out[5];
    EXPECT_EQ(x, 0);
    EXPECT_EQ(w, winW) << "Viewport only: " << r.out[5];
    ASSERT_TRUE(viewport(r.out[6], x, y, w, h)) << r.out[6];
    EXPECT_GE(w, 400) << "800 px wide window: " << r.out[6];
    int w7;
    ASSERT_TRUE(viewport(r.out[7], x, y, w7, h)) << r.out[7];
    EXPECT_GE(w7, 1366 / 2) << "grown back, the panels follow: " << r.out[7];
    EXPECT_LE(w7, 1366 * 3 / 4) << "grown back, the panels take their share again: " << r.out[7];
}

// At View > UI scale 200% (kept in the config folder) on a 1920x1080 screen the viewport still
// gets at least half the window.
TEST(ViewerAutomationGLTest, DoubleUiScaleLeavesTheViewportHalfTheWindow) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_ui_scale");
    fs::create_directories(dir / "config" / "sceneviewer");
    ASSERT_EQ(ui::saveUiScale(dir / "config" / "sceneviewer", 2.0f), "");
    EXPECT_FLOAT_EQ(ui::loadUiScale(dir / "config" / "sceneviewer"), 2.0f);
    ScriptRun r = runScript(dir, "frames 3\nprint window\nprint viewport\nquit\n", "demo.json", "1920x1080x24");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 2u) << dump(r);
    int wx, wy, ww = 0, wh, x, y, w = 0, h;
    ASSERT_EQ(std::sscanf(r.out[0].c_str(), "window %d %d %d %d", &wx, &wy, &ww, &wh), 4) << r.out[0];
    ASSERT_EQ(std::sscanf(r.out[1].c_str(), "viewport %d %d %d %d", &x, &y, &w, &h), 4) << r.out[1];
    EXPECT_GE(w, ww / 2) << r.out[1] << " in " << r.out[0];
}

// `viewer FOLDER` (or a file of an unsupported type) opens the demo instead and says why.
TEST(ViewerAutomationGLTest, APathThatCannotBeOpenedKeepsTheDemoAndSaysWhy) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_folder_arg");
    fs::create_directories(dir / "models");
    ScriptRun r = runScript(dir, "frames 2\nprint status\nprint tree\nquit\n", "models");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 2u) << dump(r);
    EXPECT_EQ(r.out[0], "status Could not open models: is a folder, not a scene file; showing the demo scene") << dump(r);
    EXPECT_TRUE(treeHas(r.out[1], "crate")) << r.out[1];
    EXPECT_NE(r.log.find("viewer: error: models: is a folder"), std::string::npos) << dump(r);
}

// Escape closes menus and dialogs: the File menu, a submenu level at a time, the
// screenshot dialog (as Cancel: nothing is taken), the unsaved-changes question (as Cancel:
// the edits stay).
TEST(ViewerAutomationGLTest, EscapeClosesMenusAndDialogs) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_escape");
    ScriptRun r = runScript(dir,
                            "frames 2\n"
                            "click menu/file\n"
                            "print popup\n"   // 0
                            "key Escape\n"
                            "print popup\n"   // 1
                            "click menu/file\n"
                            "click file/screenshotDialog\n"
                            "frames 2\n"
                            "print popup\n"   // 2
                            "key Escape\n"
                            "print popup\n"    // 3
                            "print status\n"   // 4: no screenshot taken
                            "set shading flat\n"
                            "key ctrl+n\n"
                            "print popup\n"   // 5: the unsaved-changes question
                            "key Escape\n"
                            "print popup\n"   // 6
                            "print dirty\n"   // 7
                            "quit\n");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 8u) << dump(r);
    EXPECT_EQ(r.out[0], "popup yes");
    EXPECT_EQ(r.out[1], "popup no");
    EXPECT_EQ(r.out[2], "popup yes");
    EXPECT_EQ(r.out[3], "popup no");
    EXPECT_EQ(r.out[4].find("Screenshot"), std::string::npos) << r.out[4];
    EXPECT_EQ(r.out[5], "popup yes");
    EXPECT_EQ(r.out[6], "popup no");
    EXPECT_EQ(r.out[7], "dirty yes");
    EXPECT_FALSE(fs::exists(dir / "screenshot-gl.png"));
}

// Export from the UI and overlays in screenshots: F12 writes what the
// viewport shows (here with the axes overlay); File > Export depth, normal, id... opens the
// screenshot dialog with the export ticked, and Take writes the PNG with its depth, normal and id
// files and the camera sidecar next to it, never over an existing file. Unticking "as shown"
// writes the bare image: the two PNGs differ only by the overlay's pixels.
TEST(ViewerAutomationGLTest, ScreenshotsAsShownAndTheExportFromTheWindow) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    fs::path dir = sceneFolder("automation_export");
    ScriptRun r = runScript(dir,
                            "wait\n"
                            "overlay axes\n"
                            "wait\n"
                            "key F12\n"
                            "wait\n"
                            "print status\n"   // 0: screenshot-gl.png, as shown
                            "click menu/file\n"
                            "click file/exportDialog\n"
                            "frames 2\n"
                            "click shot/asShown\n"
                            "click shot/take\n"
                            "wait\n"
                            "print status\n"   // 1: screenshot-gl-1.png, bare, with the export
                            "quit\n");
    ASSERT_EQ(r.rc, 0) << dump(r);
    ASSERT_EQ(r.out.size(), 2u) << dump(r);
    const std::string folder = fs::canonical(dir).string();
    EXPECT_EQ(r.out[0], "status Saved screenshot-gl.png in " + folder) << dump(r);
    EXPECT_EQ(r.out[1], "status Saved screenshot-gl-1.png in " + folder + "; with depth, normal, id and the camera .json") << dump(r);
    for (const char* f : {"screenshot-gl-1.depth.pfm", "screenshot-gl-1.normal.png", "screenshot-gl-1.id.png", "screenshot-gl-1.json"})
        EXPECT_TRUE(fs::exists(dir / f)) << f;
    EXPECT_FALSE(fs::exists(dir / "screenshot-gl.json")) << "F12 before the export was ticked writes the PNG alone";

    assets::ImageLoad shown = assets::loadImage(dir / "screenshot-gl.png"), bare = assets::loadImage(dir / "screenshot-gl-1.png");
    ASSERT_TRUE(shown.texture && bare.texture) << shown.error << bare.error;
    const int w = bare.texture->width, h = bare.texture->height;
    ASSERT_EQ(shown.texture->width, w);
    ASSERT_EQ(shown.texture->height, h);
    size_t differ = 0;
    for (size_t k = 0; k < size_t(w) * h; ++k) differ += std::memcmp(&shown.texture->rgba[4 * k], &bare.texture->rgba[4 * k], 3) != 0;
    EXPECT_GT(differ, 100u) << "the axes overlay is in the as-shown screenshot";
    EXPECT_LT(differ, size_t(w) * h / 20) << "and nothing else differs much";

    int dw = 0, dh = 0, iw = 0, ih = 0;
    std::vector<float> depth;
    std::vector<uint16_t> ids;
    ASSERT_EQ(assets::readPfm(dir / "screenshot-gl-1.depth.pfm", dw, dh, depth), "");
    ASSERT_EQ(assets::readPngGray16(dir / "screenshot-gl-1.id.png", iw, ih, ids), "");
    ASSERT_EQ(std::make_pair(dw, dh), std::make_pair(w, h));
    ASSERT_EQ(std::make_pair(iw, ih), std::make_pair(w, h));
    std::ifstream in(dir / "screenshot-gl-1.json");
    nlohmann::json side = nlohmann::json::parse(in, nullptr, false);
    ASSERT_TRUE(side.is_object());
    EXPECT_EQ(side["backend"], "gl");
    EXPECT_EQ(side["width"], w);
    ASSERT_TRUE(side["ids"].is_array());
    const size_t instances = side["ids"].size();
    size_t covered = 0, agree = 0;
    for (size_t k = 0; k < ids.size(); ++k) {
        EXPECT_LE(ids[k], instances) << "pixel " << k;
        if (ids[k] == 0) continue;
        ++covered;
        agree += depth[k] > 0.0f;
    }
    EXPECT_GT(covered, size_t(w) * h / 10) << "the demo covers the image";
    EXPECT_GE(agree, covered * 99 / 100) << "depth where the id image sees geometry";
}
