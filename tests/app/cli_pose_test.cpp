// cli_pose_test.cpp - `viewer render SCENE --time SECONDS [--animation N]` through the real
// executable (ray caster and CPU rasterizer only: no GL needed): a skinned sample posed at two times gives two different images, a
// morphed one too, and bad values give one-line errors (non-finite or non-numeric time, clip
// out of range, a file without animations). Needs ../shared/testdata.
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

using testing_support::quoted;
fs::path sample(const std::string& rel) { return testing_support::testdataDir() / "gltf" / rel; }

// Renders `file` with the ray caster at --time t into dir/name.png; returns the image's bytes.
std::vector<uint8_t> renderAt(const fs::path& file, const std::string& t, const fs::path& dir, const std::string& name) {
    fs::path out = dir / (name + ".png");
    ViewerRun r = runViewer("render " + quoted(file) + " --backend raycast --size 96x72 --overwrite --time " + t + " --out " + quoted(out));
    EXPECT_EQ(r.status, 0) << r.output;
    assets::ImageLoad img = assets::loadImage(out);
    EXPECT_TRUE(img.texture) << img.error;
    return img.texture ? img.texture->rgba : std::vector<uint8_t>{};
}

}   // namespace

TEST(CliPoseTest, TimePosesSkinsAndMorphs) {
    ASSERT_TRUE(testing_support::requireTestdata());
    fs::path dir = testing_support::outputDir("cli-pose");
    for (const char* rel : {"CesiumMan/glTF/CesiumMan.gltf", "AnimatedMorphCube/glTF/AnimatedMorphCube.gltf"}) {
        SCOPED_TRACE(rel);
        std::string stem = fs::path(rel).stem().string();
        std::vector<uint8_t> a = renderAt(sample(rel), "0", dir, stem + "-t0");
        std::vector<uint8_t> b = renderAt(sample(rel), "1.0", dir, stem + "-t1");
        ASSERT_EQ(a.size(), b.size());
        EXPECT_NE(a, b) << "--time 0 and --time 1 gave the same image";
        // --animation 0 is the default clip: the same image as without it.
        std::vector<uint8_t> c = renderAt(sample(rel), "1.0 --animation 0", dir, stem + "-t1-clip0");
        EXPECT_EQ(b, c);
    }
}

TEST(CliPoseTest, BadTimesAndClipsAreOneLineErrors) {
    ASSERT_TRUE(testing_support::requireTestdata());
    fs::path out = testing_support::outputDir("cli-pose") / "never.png";
    const std::string man = quoted(sample("CesiumMan/glTF/CesiumMan.gltf"));
    struct Case {
        std::string args, message;
    };
    const Case cases[] = {
        {man + " --time nan", "--time 'nan': expected a finite number of seconds"},
        {man + " --time inf", "--time 'inf': expected a finite number of seconds"},
        {man + " --time 1e300", "--time '1e300': expected a finite number of seconds"},
        {man + " --time 2s", "--time '2s': expected a finite number of seconds"},
        {man + " --time 1 --animation 1", "--animation 1: "},
        {man + " --animation -1", "--animation -1: "},
        {quoted(sample("Box/glTF/Box.gltf")) + " --time 1", "has no animations"},
    };
    for (const Case& c : cases) {
        ViewerRun r = runViewer("render " + c.args + " --backend raster --size 8x8 --overwrite --out " + quoted(out));
        EXPECT_NE(r.status, 0) << c.args;
        size_t at = r.output.find("viewer: error: ");
        ASSERT_NE(at, std::string::npos) << c.args << "\n" << r.output;
        std::string line = r.output.substr(at);
        EXPECT_NE(line.find(c.message), std::string::npos) << c.args << "\n" << r.output;
        EXPECT_EQ(line.find('\n'), line.size() - 1) << "one line: " << line;
    }
    EXPECT_FALSE(fs::exists(out));
}
