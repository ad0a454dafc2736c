// test_support.h - helpers shared by the tests: where test data and outputs live, and image
// comparison with tolerances that writes actual + expected + diff PNGs on failure.
#pragma once

#include "renderers/framebuffer.h"
#include "scenegraph/mesh.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace testing_support {

// ../shared/testdata (override with VIEWER_TESTDATA). Tests that need it call
// requireTestdata(), which fails the test with a clear message when the folder is absent.
std::filesystem::path testdataDir();
::testing::AssertionResult requireTestdata();
// Where tests write images (build/<preset>/test-output/<suite>/...).
std::filesystem::path outputDir(const std::string& suite);

struct ImageTolerance {
    double maxMeanAbs = 1.0;   // mean absolute difference per channel (0..255 units)
    double minFractionWithin = 0.995;
    int channelTolerance = 3;   // per-pixel tolerance for the fraction
};

// How closely two backends' images must agree, by how they make them (README: "Same scene,
// camera and settings give the same image wherever the methods agree"); every test that holds
// backends together takes its tolerance from here:
//   SameMethod:   two rasterizers (GL ~ CPU rasterizer): mean below 1/255 and >= 99.5% of pixels
//                 within 3/255 (a small, badly wrong region fails the fraction);
//   AcrossMethods: ray caster ~ a rasterizer, shadows and reflections off: >= 99% of pixels
//                 within 4/255 (silhouette pixels of tessellated vs exact surfaces may differ).
enum class Agreement { SameMethod, AcrossMethods };
inline ImageTolerance agreementTolerance(Agreement a) {
    return a == Agreement::SameMethod ? ImageTolerance{1.0, 0.995, 3} : ImageTolerance{255.0, 0.99, 4};
}
// Whether `a` and `b` are made the same way (both rasterizers) or not.
Agreement agreementBetween(const std::string& a, const std::string& b);

// Compares and reports the figures; on failure writes <name>-actual.png, <name>-expected.png
// and <name>-diff.png into outputDir(suite).
::testing::AssertionResult imagesClose(const rnd::Framebuffer& actual, const rnd::Framebuffer& expected, const ImageTolerance& tol,
                                       const std::string& suite, const std::string& name);

// A GL baseline image: tests/baselines/gl/<name>.png. Compares `actual` with it (mean <= 1,
// >= 98% of pixels within 8/255; failures write actual/expected/diff to test-output/gl-baselines),
// or writes it when VIEWER_ACCEPT_BASELINES=1 (scripts/accept-baselines.sh; look first).
::testing::AssertionResult matchesGlBaseline(const rnd::Framebuffer& actual, const std::string& name);

void writeImage(const rnd::Framebuffer& img, const std::string& suite, const std::string& name);

// One pixel held to a value computed from a formula: (x, y) with y down from the top row,
// the expected sRGB bytes and the allowed difference per channel.
struct PixelCheck {
    int x = 0, y = 0;
    uint8_t expected[3] = {0, 0, 0};
    int tolerance = 1;
};
struct PixelCheckSummary {
    int checked = 0, failed = 0, maxAbs = 0;
    double meanAbs = 0;   // over the checked pixels' channels, 0..255 units
};
// Checks `actual` at every PixelCheck; prints "[pixels] suite/name: ..." with the figures
// (into *summary when given). On failure reports the worst pixels (position, expected,
// actual) and writes <name>-actual.png, <name>-expected.png (`expectedImage`: the formula's
// whole image) and <name>-diff.png (only the checked pixels) into outputDir(suite).
::testing::AssertionResult pixelsMatch(const rnd::Framebuffer& actual, const rnd::Framebuffer& expectedImage, const std::vector<PixelCheck>& checks,
                                       const std::string& suite, const std::string& name, PixelCheckSummary* summary = nullptr);

// A size x size RGBA texture of checks x checks squares: colour a where the square's x + y is
// odd, b elsewhere (0..1, rounded to 8 bits). Default sampling settings.
std::shared_ptr<sg::Texture> checker(int size, int checks, const sg::vec3& a, const sg::vec3& b);

// A command-line run (the viewer's CLI tests): `exe args` through the shell, its exit status as
// pclose() gives it (0 = success) and its stdout, plus stderr when `withStderr`.
struct ProgramRun {
    int status = -1;
    std::string output;
};
ProgramRun runProgram(const std::string& exe, const std::string& args, bool withStderr = true);
// `p` in double quotes, for a command line.
std::string quoted(const std::filesystem::path& p);

// Standard base64 with padding (for data URIs and embedded PNGs in generated files).
std::string base64Encode(std::string_view bytes);

}   // namespace testing_support
