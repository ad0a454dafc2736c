// cli_aov_gl_test.cpp - the synthetic-data export and the pixel inspector through the real
// executable: `viewer render demo --aov depth,normal,id` writes a 16-bit id image whose ids the
// sidecar names, a normal image of unit normals on exactly the covered pixels, the same ids in
// every backend; `viewer inspect demo --at X,Y` prints per backend a provenance whose terms add
// up to the pixel; bad requests get one-line errors; the diagnostic views (overdraw and cost
// included) are written with their legends, and a view the backend cannot make is refused.
#include "assets/aov_io.h"
#include "assets/image_io.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <tuple>

namespace fs = std::filesystem;

namespace {

using ViewerRun = testing_support::ProgramRun;
ViewerRun runViewer(const std::string& args, bool withStderr = true) { return testing_support::runProgram(VIEWER_EXE, args, withStderr); }

using testing_support::quoted;

struct Export {
    std::vector<uint16_t> ids;
    std::vector<uint8_t> normal;   // RGBA
    nlohmann::json side;
    int w = 0, h = 0;
};

Export exportAovs(const std::string& backend, const fs::path& dir) {
    Export e;
    const fs::path out = dir / (backend + ".png");
    ViewerRun r = runViewer("render demo --backend " + backend + " --size 160x90 --overwrite --aov depth,normal,id --out " + quoted(out));
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(assets::readPngGray16(dir / (backend + ".id.png"), e.w, e.h, e.ids), "");
    assets::ImageLoad n = assets::loadImage(dir / (backend + ".normal.png"));
    EXPECT_TRUE(n.texture) << n.error;
    if (n.texture) e.normal = n.texture->rgba;
    std::ifstream in(dir / (backend + ".json"));
    e.side = nlohmann::json::parse(in, nullptr, false);
    return e;
}

}   // namespace

TEST(CliAov, IdAndNormalImagesWithTheirSidecar) {
    const fs::path dir = testing_support::outputDir("cli-aov");
    fs::create_directories(dir);
    std::vector<Export> all;
    for (const char* b : {"gl", "raster", "raycast"}) {
        SCOPED_TRACE(b);
        Export e = exportAovs(b, dir);
        ASSERT_EQ(e.w, 160);
        ASSERT_EQ(e.h, 90);
        ASSERT_TRUE(e.side.is_object());
        ASSERT_TRUE(e.side.contains("ids"));
        EXPECT_EQ(e.side["files"], nlohmann::json({b + std::string(".depth.pfm"), b + std::string(".normal.png"), b + std::string(".id.png")}));
        std::set<uint32_t> named;
        for (const auto& i : e.side["ids"]) {
            named.insert(i["id"].get<uint32_t>());
            EXPECT_FALSE(i["node"].get<std::string>().empty());
            EXPECT_EQ(i["path"].get<std::string>().rfind('/' + i["node"].get<std::string>()),
                      i["path"].get<std::string>().size() - i["node"].get<std::string>().size() - 1);
        }
        int covered = 0;
        for (size_t k = 0; k < e.ids.size(); ++k) {
            const uint8_t* c = &e.normal[4 * k];
            if (e.ids[k] == 0) {
                EXPECT_EQ(c[0] + c[1] + c[2], 0) << "pixel " << k << ": normal where nothing was drawn";
                continue;
            }
            ++covered;
            ASSERT_TRUE(named.count(e.ids[k])) << "id " << e.ids[k] << " is not in the sidecar";
            const double x = c[0] / 127.5 - 1, y = c[1] / 127.5 - 1, z = c[2] / 127.5 - 1;
            EXPECT_NEAR(std::sqrt(x * x + y * y + z * z), 1.0, 0.03) << "pixel " << k;
        }
        EXPECT_GT(covered, 160 * 90 / 2);
        all.push_back(std::move(e));
    }
    // The backends' id images agree (edges may differ by a pixel).
    for (size_t a = 0; a < all.size(); ++a)
        for (size_t b = a + 1; b < all.size(); ++b) {
            size_t same = 0;
            for (size_t k = 0; k < all[a].ids.size(); ++k) same += all[a].ids[k] == all[b].ids[k];
            EXPECT_GE(double(same) / double(all[a].ids.size()), 0.99) << a << " vs " << b;
            EXPECT_EQ(all[a].side["ids"], all[b].side["ids"]);
        }
}

TEST(CliInspect, TermsAddUpToThePixelInEveryBackend) {
    for (const char* at : {"80,50", "30,70", "120,30", "5,5"}) {
        SCOPED_TRACE(at);
        ViewerRun r = runViewer(std::string("inspect demo --size 160x90 --at ") + at, /*withStderr=*/false);
        ASSERT_EQ(r.status, 0) << r.output;
        const nlohmann::json j = nlohmann::json::parse(r.output, nullptr, false);
        ASSERT_TRUE(j.is_object()) << r.output;
        ASSERT_EQ(j["backends"].size(), 3u);
        std::set<std::string> nodes;
        for (const auto& [name, v] : j["backends"].items()) {
            SCOPED_TRACE(name);
            ASSERT_TRUE(v.contains("rgb"));
            nodes.insert(v["node"].is_null() ? std::string("(none)") : v["node"].get<std::string>());
            if (v["node"].is_null()) continue;
            for (const char* key : {"depth", "path", "instance", "position", "normal", "terms"}) EXPECT_TRUE(v.contains(key)) << key;
            const auto& t = v["terms"];
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(t["predicted_rgb"][c].get<int>(), v["rgb"][c].get<int>(), 2) << "channel " << c;
            EXPECT_GT(v["depth"].get<double>(), 0.0);
        }
        EXPECT_EQ(nodes.size(), 1u) << "the backends name different nodes at " << at;
        EXPECT_EQ(j["differences"].size(), 3u);
    }
}

TEST(CliInspect, BadRequestsGetOneLineErrors) {
    struct Case {
        std::string args, message;
    };
    const fs::path dir = testing_support::outputDir("cli-aov");
    fs::create_directories(dir);
    for (const Case& c : {Case{"inspect demo --size 160x90 --at 160,10", "outside the 160x90 image"}, Case{"inspect demo --at ten,3", "expected X,Y"},
                          Case{"inspect demo --at 1,1 --backend vulkan", "expected all or one of"},
                          Case{"render demo --aov depth,albedo --out " + quoted(dir / "bad.png"), "unknown kind 'albedo'"},
                          Case{"render demo --view heat --out " + quoted(dir / "bad.png"), "--view 'heat': expected one of shaded, depth"}}) {
        ViewerRun r = runViewer(c.args);
        EXPECT_NE(r.status, 0) << c.args;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << " -> " << r.output;
        EXPECT_LE(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    }
}

TEST(AovFiles, Gray16PngRoundTrips) {
    const fs::path dir = testing_support::outputDir("cli-aov");
    fs::create_directories(dir);
    std::vector<uint16_t> v = {0, 1, 2, 300, 65535, 4096};
    ASSERT_EQ(assets::writePngGray16(dir / "g16.png", 3, 2, v, true), "");
    int w = 0, h = 0;
    std::vector<uint16_t> back;
    ASSERT_EQ(assets::readPngGray16(dir / "g16.png", w, h, back), "");
    EXPECT_EQ(w, 3);
    EXPECT_EQ(h, 2);
    EXPECT_EQ(back, v);
    EXPECT_NE(assets::writePngGray16(dir / "g16.png", 3, 2, v, false), "");   // never replaced without overwrite
}

TEST(CliView, DiagnosticViewsAreWrittenWithTheirLegend) {
    const fs::path dir = testing_support::outputDir("cli-aov");
    fs::create_directories(dir);
    for (const char* view : {"depth", "normal", "id", "uv", "triangles"}) {
        SCOPED_TRACE(view);
        const fs::path out = dir / (std::string("view-") + view + ".png");
        ViewerRun r = runViewer("render demo --backend raycast --size 96x54 --overwrite --view " + std::string(view) + " --out " + quoted(out));
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_NE(r.output.find(std::string(view) + " view: "), std::string::npos) << r.output;
        assets::ImageLoad img = assets::loadImage(out);
        ASSERT_TRUE(img.texture) << img.error;
        EXPECT_EQ(img.texture->width, 96);
    }
}

// --view overdraw (the rasterizers) and --view cost (the ray caster) write their heat maps and
// print their legends; asking a backend for a view it cannot make fails before rendering, with
// one line naming the view, the backend and the backends that can, and writes no file.
TEST(CliView, OverdrawAndCostViewsAndTheBackendsThatCannot) {
    const fs::path dir = testing_support::outputDir("cli-aov");
    fs::create_directories(dir);
    for (auto [backend, view] : {std::pair{"gl", "overdraw"}, std::pair{"raster", "overdraw"}, std::pair{"raycast", "cost"}}) {
        SCOPED_TRACE(std::string(backend) + " " + view);
        const fs::path out = dir / (std::string("view-") + view + "-" + backend + ".png");
        ViewerRun r =
            runViewer("render demo --backend " + std::string(backend) + " --size 96x54 --overwrite --view " + view + " --out " + quoted(out));
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_NE(r.output.find(std::string(view) + " view: " + view + " ("), std::string::npos) << r.output;
        assets::ImageLoad img = assets::loadImage(out);
        ASSERT_TRUE(img.texture) << img.error;
        EXPECT_EQ(img.texture->width, 96);
        EXPECT_EQ(img.texture->height, 54);
        size_t coloured = 0;   // the heat map is not the shaded image: mostly saturated colours
        for (size_t k = 0; k + 3 < img.texture->rgba.size(); k += 4) {
            const uint8_t* p = &img.texture->rgba[k];
            coloured += std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}) > 100;
        }
        EXPECT_GT(coloured, size_t(96 * 54 / 2)) << "heat-map colours";
    }
    for (auto [backend, view, can] :
         {std::tuple{"raycast", "overdraw", "gl, raster"}, std::tuple{"gl", "cost", "raycast"}, std::tuple{"raster", "cost", "raycast"}}) {
        SCOPED_TRACE(std::string(backend) + " " + view);
        const fs::path out = dir / (std::string("refused-") + view + "-" + backend + ".png");
        fs::remove(out);
        ViewerRun r =
            runViewer("render demo --backend " + std::string(backend) + " --size 96x54 --overwrite --view " + view + " --out " + quoted(out));
        EXPECT_NE(r.status, 0) << r.output;
        EXPECT_NE(
            r.output.find(std::string("--view ") + view + ": the " + backend + " backend cannot make this view (backends that can: " + can + ")"),
            std::string::npos)
            << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;
        EXPECT_FALSE(fs::exists(out));
    }
}
