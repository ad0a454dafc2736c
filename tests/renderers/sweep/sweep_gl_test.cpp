// sweep_gl_test.cpp - every model in shared/testdata (glTF, OBJ, PLY, OFF, STL; not the invalid
// ones) rendered by gl, raster and raycast at 320x180 with shadows off and AA off, compared
// pairwise:
//   gl ~ raster:      mean |difference| <= 1/255 and >= 99.5% of pixels within 3/255;
//   raster ~ raycast: >= 99% of pixels within 4/255.
// One test per model. Models that differ for a documented reason are listed in kKnown with
// the reason; such a model is still rendered and compared, must still load and render in every
// backend, and the test fails if it starts to agree (so the list only shrinks). Files the
// loaders must refuse (kRefused) are checked for their one-line error instead. Images and a
// line per model (sweep.md) go to test-output/sweep/.
#include "assets/scene_io.h"
#include "renderers/renderer.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

namespace fs = std::filesystem;

namespace {

constexpr int W = 320, H = 180;

// Models whose backends differ for a documented reason (README, known limitations).
const std::map<std::string, std::string> kKnown = {};
// Files every loader must refuse, with (part of) the one-line reason.
const std::map<std::string, std::string> kRefused = {
    {"meshes/assimp/OBJ/box_UTF16BE.obj", "box_UTF16BE.obj: UTF-16 text is not supported"},
};

std::vector<std::string> models() {
    std::vector<std::string> out;
    const fs::path root = testing_support::testdataDir();
    std::error_code ec;
    if (!fs::is_directory(root, ec)) return {"(testdata missing)"};
    for (auto it = fs::recursive_directory_iterator(root, ec); it != fs::recursive_directory_iterator(); it.increment(ec)) {
        if (ec) break;
        const fs::path& p = it->path();
        std::string rel = fs::relative(p, root, ec).generic_string();
        if (rel.find("invalid") != std::string::npos) continue;
        std::string lower = rel;
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        if (lower.find("embedded") != std::string::npos || !it->is_regular_file(ec)) continue;
        std::string ext = p.extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        if (ext == ".gltf" || ext == ".glb" || ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".stl") out.push_back(rel);
    }
    std::sort(out.begin(), out.end());
    return out.empty() ? std::vector<std::string>{"(no models)"} : out;
}

std::string testName(const std::string& rel) {
    std::string n;
    for (char c : rel) n += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    return n;
}

class Sweep : public ::testing::TestWithParam<std::string> {};

TEST_P(Sweep, BackendsAgree) {
    ASSERT_TRUE(testing_support::requireTestdata());
    const std::string rel = GetParam();
    ASSERT_NE(rel, "(no models)") << "no models under " << testing_support::testdataDir();
    assets::LoadResult r = assets::loadScene(testing_support::testdataDir() / rel);
    if (auto refused = kRefused.find(rel); refused != kRefused.end()) {
        EXPECT_FALSE(r.scene) << rel << " loads now: remove it from kRefused and check its images";
        EXPECT_NE(r.error.find(refused->second), std::string::npos) << r.error;
        EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
        return;
    }
    ASSERT_TRUE(r.scene) << rel << ": " << r.error;
    r.scene->settings.shadows = false;
    r.scene->settings.aa = sg::AAMode::None;
    const sg::FrameInput frame = sg::flatten(*r.scene, float(W) / float(H));
    std::map<std::string, rnd::Framebuffer> img;
    const std::string stem = testName(rel);
    for (const std::string b : {"gl", "raster", "raycast"}) {
        std::string err;
        auto renderer = rnd::makeRenderer(b, &err);
        ASSERT_TRUE(renderer) << err;
        rnd::RenderStats st = renderer->render(frame, W, H, img[b]);
        ASSERT_TRUE(st.ok) << rel << ": " << b << ": " << st.error;
        testing_support::writeImage(img[b], "sweep", stem + "-" + b);
    }
    const testing_support::ImageTolerance same = testing_support::agreementTolerance(testing_support::Agreement::SameMethod);
    const testing_support::ImageTolerance across = testing_support::agreementTolerance(testing_support::Agreement::AcrossMethods);
    const rnd::ImageDiff a = rnd::compareImages(img["gl"], img["raster"], same.channelTolerance);
    const rnd::ImageDiff c = rnd::compareImages(img["raster"], img["raycast"], across.channelTolerance);
    const bool agree = a.meanAbs <= same.maxMeanAbs && a.fractionWithin >= same.minFractionWithin && c.fractionWithin >= across.minFractionWithin;
    char line[512];
    std::snprintf(line, sizeof line, "| %s | %.3f | %.2f%% | %.2f%% | %s |", rel.c_str(), a.meanAbs, 100.0 * a.fractionWithin,
                  100.0 * c.fractionWithin, agree ? "ok" : "differs");
    std::printf("sweep: %s\n", line);
    std::ofstream(testing_support::outputDir("sweep") / (stem + ".md")) << line << "\n";
    auto known = kKnown.find(rel);
    if (known != kKnown.end()) {
        EXPECT_FALSE(agree) << rel << " now agrees: remove it from kKnown (" << known->second << ")";
        return;
    }
    EXPECT_LE(a.meanAbs, same.maxMeanAbs) << rel << ": gl ~ raster mean " << a.meanAbs << "/255";
    EXPECT_GE(a.fractionWithin, same.minFractionWithin) << rel << ": gl ~ raster within 3/255 " << 100.0 * a.fractionWithin << "%";
    EXPECT_GE(c.fractionWithin, across.minFractionWithin) << rel << ": raster ~ raycast within 4/255 " << 100.0 * c.fractionWithin << "%";
    if (!agree) {
        testing_support::writeImage(rnd::diffImage(img["gl"], img["raster"], 3), "sweep", stem + "-diff-gl-raster");
        testing_support::writeImage(rnd::diffImage(img["raster"], img["raycast"], 4), "sweep", stem + "-diff-raster-raycast");
    }
}

INSTANTIATE_TEST_SUITE_P(Testdata, Sweep, ::testing::ValuesIn(models()), [](const auto& info) { return testName(info.param); });

}   // namespace
