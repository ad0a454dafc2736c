// soak_gl_test.cpp - hours of use, compressed: the real window under Xvfb runs a long script
// (backends switched, orbits, edits and undo, picks, diagnostic views, loads that fail or are
// cancelled while an edit is unsaved) and then a randomised script from a fixed seed. The
// viewer must not crash or hang, the unsaved edit must survive to the end, and the resident
// memory must stay flat after warm-up (within 10%).
#include "assets/demo.h"
#include "assets/scene_io.h"
#include "test_support.h"
#include "viewer_process.h"

#include <gtest/gtest.h>

#include <fstream>

#include <algorithm>
#include <random>
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

fs::path folder(const std::string& name) {
    fs::path dir = testing_support::outputDir("ui") / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    EXPECT_EQ(assets::saveSceneJson(assets::makeDemoScene(), dir / "demo.json", true), "");
    std::ofstream(dir / "broken.obj") << "this is not an obj file\nf 1 2 3 4 5\n";   // opens, then fails to load
    return dir;
}

const char* const kBackends[] = {"gl", "raster", "raycast"};
const char* const kDiagnostics[] = {"shaded", "depth", "normal", "id", "uv", "triangles", "overdraw", "cost"};
const char* const kViews[] = {"single", "split", "split3", "difference"};

}   // namespace

TEST(SoakGLTest, LongSessionKeepsTheEditAndItsMemoryFlat) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    const fs::path dir = folder("soak");
    std::ostringstream s;
    // Shadows on: a click asks the pixel inspector for each backend's shadows, and GL's are read
    // from its maps in the worker's context (asked on the UI thread, they once made the renderer
    // drop every object of that context, about 10 MB a click).
    s << "wait\nset shadows on\nselect crate\nset material.kd 0.33\nprint dirty\n";
#if defined(__SANITIZE_ADDRESS__)
    // AddressSanitizer keeps freed memory in quarantine (256 MB), so resident memory says
    // nothing about leaks there (LeakSanitizer checks those at exit); a shorter session keeps
    // the run bounded.
    const int rounds = 18;
    const bool checkMemory = false;
    std::printf("soak: AddressSanitizer build: %d rounds, resident memory not compared (quarantine)\n", rounds);
#else
    const int rounds = 48;
    const bool checkMemory = true;
#endif
    for (int r = 0; r < rounds; ++r) {
        s << "backend " << kBackends[r % 3] << "\n";
        s << "orbit " << (r % 2 ? 25 : -18) << " " << (r % 5) - 2 << "\n";
        s << "frames 3\n";
        // Selected right before the edit: a click's pick resolves when its image arrives, which may
        // be after a later `select` (the edit and the select run in the same step, no frame between).
        s << "select crate\nset material.ks 0.1" << (r % 9) + 1 << "\nundo\n";   // 0.11 .. 0.19: never the crate's own 0.2 (a no-op set adds no step)
        s << "diagnostic " << kDiagnostics[r % 8] << "\n";
        s << "view " << kViews[r % 4] << "\nframes 2\n";
        s << "click viewport " << 200 + (r * 37) % 300 << " " << 150 + (r * 53) % 300 << "\nframes 2\nselect crate\n";
        if (r % 6 == 0) s << "open broken.obj\nanswer discard\nwait load\n";   // a failed load with an unsaved edit
        if (r % 6 == 3) s << "open demo.json\nanswer cancel\n";                // a cancelled one
        if (r % 6 == 5) s << "frames 3\nprint memory\n";
    }
    s << "wait\nprint dirty\nprint undo\nquit\n";
    const int rc = viewer_test::runViewer(dir, s.str(), "demo.json", /*separateStdout=*/true);
    const std::vector<std::string> out = printed(viewer_test::readLog(dir, "out.txt"));
    const std::string log = viewer_test::readLog(dir);
    ASSERT_EQ(rc, 0) << log;
    ASSERT_GE(out.size(), 3u) << log;
    EXPECT_EQ(out.front(), "dirty yes");
    EXPECT_EQ(out[out.size() - 2], "dirty yes") << "the unsaved edit was lost";
    EXPECT_NE(out.back().find("undo "), std::string::npos);
    std::vector<long> rss;
    for (const std::string& o : out)
        if (long kb = 0; std::sscanf(o.c_str(), "memory %ld kB", &kb) == 1) rss.push_back(kb);
    ASSERT_EQ(rss.size(), size_t(rounds / 6)) << log;
    std::string samples;
    for (long kb : rss) samples += " " + std::to_string(kb / 1024) + " MB";
    std::printf("soak: resident memory every 6 rounds:%s\n", samples.c_str());
    // Warm-up: 30 rounds (every backend, view and diagnostic has been shown in every
    // combination, each slot has its buffers); after it, resident memory stays within 10%.
    // (Measured over 150 rounds: 373 MB, a step to 418 MB by round 30, 446 MB at round 150.)
    if (!checkMemory) return;
    const long warm = *std::max_element(rss.begin(), rss.begin() + 5);
    for (size_t i = 5; i < rss.size(); ++i) EXPECT_LE(rss[i], warm + warm / 10) << "resident memory grew: sample " << i << " of " << rss.size();
}

// Random command sequences from a fixed seed (VIEWER_RANDOM_SEED overrides it; the seed is in
// every failure message): the viewer survives them and exits normally.
TEST(SoakGLTest, RandomisedScriptFromAFixedSeed) {
    if (!viewer_test::haveXvfb()) GTEST_FAIL() << "xvfb-run is missing (apt-get install xvfb): window tests cannot run";
    unsigned seed = 20261124u;
    if (const char* e = std::getenv("VIEWER_RANDOM_SEED")) seed = unsigned(std::strtoul(e, nullptr, 10));
    std::mt19937 rng(seed);
    auto pick = [&](int n) { return int(rng() % unsigned(n)); };
    // Commands that cannot fail the script by themselves (a Delete or an in-place rename would
    // make a later `select crate` name a node that is gone).
    const char* const nodes[] = {"crate", "floor", "red sphere", "torus", "carved block", "key light", "camera", "metaballs"};
    const char* const keys[] = {"ctrl+z", "ctrl+y", "ctrl+shift+z", "f", "Home", "Escape", "1", "2"};
    std::ostringstream s;
    s << "wait\n";
    int prints = 0;
#if defined(__SANITIZE_ADDRESS__)
    const int commands = 80;   // the same kinds of command, fewer: under ASan 150 took ~190 s of the viewer's 200
#else
    const int commands = 150;
#endif
    for (int i = 0; i < commands; ++i) {
        switch (pick(12)) {
        case 0: s << "backend " << kBackends[pick(3)] << "\n"; break;
        case 1: s << "view " << kViews[pick(4)] << "\n"; break;
        case 2: s << "orbit " << pick(80) - 40 << " " << pick(40) - 20 << "\n"; break;
        case 3: s << "zoom " << pick(5) - 2 << "\n"; break;
        case 4: s << "select " << nodes[pick(8)] << "\n"; break;
        case 5: s << "select crate\nset material.kd 0.1" << pick(10) << "\n"; break;
        case 6: s << (pick(2) ? "undo\n" : "redo\n"); break;
        case 7: s << "key " << keys[pick(8)] << "\n"; break;
        case 8: s << "click viewport " << pick(600) << " " << pick(600) << "\n"; break;
        case 9: s << "diagnostic " << kDiagnostics[pick(8)] << "\n"; break;
        case 10: s << "frames " << 1 + pick(4) << "\n"; break;
        default:
            s << "print dirty\n";
            ++prints;
            break;
        }
    }
    s << "wait\nprint dirty\nquit\n";
    ++prints;
    const fs::path dir = folder("random");
    const int rc = viewer_test::runViewer(dir, s.str(), "demo.json", /*separateStdout=*/true);
    const std::string log = viewer_test::readLog(dir);
    std::vector<std::string> out = printed(viewer_test::readLog(dir, "out.txt"));
    size_t dirtyLines = 0;
    for (const std::string& o : out) dirtyLines += o.rfind("dirty ", 0) == 0;
    EXPECT_EQ(rc, 0) << "seed " << seed << "\n" << log;
    EXPECT_EQ(dirtyLines, size_t(prints)) << "seed " << seed << ": the script did not run to its end\n" << log;
}
