// cli_default_backend_gl_test.cpp - the backend `viewer render` uses when none is named, through
// the real executable: gl, or the CPU rasterizer with a one-line note where OpenGL is software
// only (rnd::defaultRenderBackend); `--backend gl` renders with GL whatever GL is. The output
// line "OUT: WxH, NAME backend, ..." says which backend rendered.
//
// LIBGL_ALWAYS_SOFTWARE=1 makes Mesa's GL (the project's: libgl1-mesa-dri, libegl-mesa0) llvmpipe
// even where a GPU is, so the software case is checked on every machine.
#include "assets/image_io.h"
#include "renderers/renderer.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using testing_support::quoted;

namespace {

const std::string kNote = "rendering with the CPU rasterizer (raster backend); --backend gl forces GL";

testing_support::ProgramRun runViewer(const std::string& env, const std::string& args) {
    return testing_support::runProgram("env", env + " " + quoted(VIEWER_EXE) + " " + args);
}

std::vector<uint8_t> pixels(const fs::path& png, int w, int h) {
    assets::ImageLoad img = assets::loadImage(png);
    EXPECT_TRUE(img.texture) << img.error;
    if (!img.texture) return {};
    EXPECT_EQ(img.texture->width, w);
    EXPECT_EQ(img.texture->height, h);
    return img.texture->rgba;
}

}   // namespace

// On software GL the default is the CPU rasterizer: the note (one line, on stderr, naming what
// GL runs on) and the same image as --backend raster.
TEST(CliDefaultBackendGLTest, SoftwareGlMeansTheRasterizerWithANote) {
    const fs::path dir = testing_support::outputDir("cli-default-backend");
    const std::string size = " --size 96x54 --overwrite --out ";
    testing_support::ProgramRun r = runViewer("LIBGL_ALWAYS_SOFTWARE=1", "render demo" + size + quoted(dir / "default.png"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("viewer: note: OpenGL here is software only ("), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(kNote + "\n"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("default.png: 96x54, raster backend"), std::string::npos) << r.output;

    testing_support::ProgramRun raster = runViewer("LIBGL_ALWAYS_SOFTWARE=1", "render demo --backend raster" + size + quoted(dir / "raster.png"));
    ASSERT_EQ(raster.status, 0) << raster.output;
    EXPECT_EQ(raster.output.find("note"), std::string::npos) << "a named backend needs no note: " << raster.output;
    const std::vector<uint8_t> a = pixels(dir / "default.png", 96, 54), b = pixels(dir / "raster.png", 96, 54);
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(a, b) << "the default rendered with the CPU rasterizer";
}

// --backend gl is exactly GL, on software GL too.
TEST(CliDefaultBackendGLTest, BackendGlAlwaysRendersWithGl) {
    const fs::path dir = testing_support::outputDir("cli-default-backend");
    testing_support::ProgramRun r =
        runViewer("LIBGL_ALWAYS_SOFTWARE=1", "render demo --backend gl --size 96x54 --overwrite --out " + quoted(dir / "gl.png"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("gl.png: 96x54, gl backend"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("CPU rasterizer"), std::string::npos) << r.output;
    EXPECT_FALSE(pixels(dir / "gl.png", 96, 54).empty());
}

// Without LIBGL_ALWAYS_SOFTWARE the executable takes what the registry says here (gl on a GPU,
// the rasterizer with the note on llvmpipe), and says which.
TEST(CliDefaultBackendGLTest, DefaultIsWhatTheRegistrySays) {
    unsetenv("LIBGL_ALWAYS_SOFTWARE");   // the registry asks in this process, as the child will
    const rnd::BackendChoice choice = rnd::defaultRenderBackend();
    std::printf("[default backend here] %s%s%s\n", choice.name.c_str(), choice.note.empty() ? "" : ": ", choice.note.c_str());
    const fs::path dir = testing_support::outputDir("cli-default-backend");
    testing_support::ProgramRun r = runViewer("-u LIBGL_ALWAYS_SOFTWARE", "render demo --size 96x54 --overwrite --out " + quoted(dir / "here.png"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("here.png: 96x54, " + choice.name + " backend"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find(kNote) != std::string::npos, !choice.note.empty()) << r.output;
    if (!choice.note.empty()) { EXPECT_NE(r.output.find("viewer: note: " + choice.note + "\n"), std::string::npos) << r.output; }
    EXPECT_FALSE(pixels(dir / "here.png", 96, 54).empty());
}

TEST(CliDefaultBackendTest, HelpDescribesTheDefault) {
    testing_support::ProgramRun r = testing_support::runProgram(VIEWER_EXE, "render --help");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("Default: gl, or raster (with a note saying so) where OpenGL is software only"), std::string::npos) << r.output;
}
