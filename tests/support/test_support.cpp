// test_support.cpp - the tests' shared helpers (see test_support.h): test data and output
// folders, image and pixel comparisons that write actual / expected / diff PNGs on failure, the
// GL baselines (compared, or rewritten with VIEWER_ACCEPT_BASELINES=1), checker textures,
// base64, running a program, and which agreement tolerance two backends are held to.
#include "test_support.h"

#include "assets/image_io.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace fs = std::filesystem;

namespace testing_support {

fs::path testdataDir() {
    if (const char* env = std::getenv("VIEWER_TESTDATA")) return env;
    return VIEWER_TESTDATA_DIR;
}

::testing::AssertionResult requireTestdata() {
    std::error_code ec;
    if (fs::is_directory(testdataDir(), ec)) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "test data folder " << testdataDir()
                                         << " is absent: this test needs ../shared/testdata "
                                            "(or set VIEWER_TESTDATA to its location)";
}

fs::path outputDir(const std::string& suite) {
    fs::path p = fs::path(VIEWER_TEST_OUTPUT_DIR) / suite;
    std::error_code ec;
    fs::create_directories(p, ec);
    return p;
}

void writeImage(const rnd::Framebuffer& img, const std::string& suite, const std::string& name) {
    if (img.width <= 0 || img.height <= 0) return;
    fs::path p = outputDir(suite) / (name + ".png");
    assets::writePng(p, img.width, img.height, img.color.data(), true);
}

::testing::AssertionResult imagesClose(const rnd::Framebuffer& actual, const rnd::Framebuffer& expected, const ImageTolerance& tol,
                                       const std::string& suite, const std::string& name) {
    if (actual.width != expected.width || actual.height != expected.height)
        return ::testing::AssertionFailure() << name << ": size " << actual.width << "x" << actual.height << " vs expected " << expected.width << "x"
                                             << expected.height;
    rnd::ImageDiff d = rnd::compareImages(actual, expected, tol.channelTolerance);
    std::printf("[image] %s/%s: %s\n", suite.c_str(), name.c_str(), d.describe().c_str());
    if (d.meanAbs <= tol.maxMeanAbs && d.fractionWithin >= tol.minFractionWithin) return ::testing::AssertionSuccess();
    writeImage(actual, suite, name + "-actual");
    writeImage(expected, suite, name + "-expected");
    writeImage(rnd::diffImage(actual, expected, tol.channelTolerance), suite, name + "-diff");
    return ::testing::AssertionFailure() << name << ": " << d.describe() << " (allowed: mean <= " << tol.maxMeanAbs << ", within "
                                         << tol.channelTolerance << "/255 >= " << tol.minFractionWithin * 100 << "%); images written to "
                                         << outputDir(suite);
}

::testing::AssertionResult pixelsMatch(const rnd::Framebuffer& actual, const rnd::Framebuffer& expectedImage, const std::vector<PixelCheck>& checks,
                                       const std::string& suite, const std::string& name, PixelCheckSummary* summary) {
    PixelCheckSummary s;
    struct Failure {
        const PixelCheck* check;
        int diff;
    };
    std::vector<Failure> failures;
    double sum = 0;
    for (const PixelCheck& c : checks) {
        if (c.x < 0 || c.y < 0 || c.x >= actual.width || c.y >= actual.height) {
            failures.push_back({&c, 256});
            continue;
        }
        const uint8_t* p = actual.pixel(c.x, c.y);
        int worst = 0;
        for (int ch = 0; ch < 3; ++ch) {
            int d = std::abs(int(p[ch]) - int(c.expected[ch]));
            worst = std::max(worst, d);
            sum += d;
        }
        s.maxAbs = std::max(s.maxAbs, worst);
        if (worst > c.tolerance) failures.push_back({&c, worst});
    }
    s.checked = int(checks.size());
    s.failed = int(failures.size());
    s.meanAbs = checks.empty() ? 0.0 : sum / (3.0 * double(checks.size()));
    if (summary) *summary = s;
    std::printf("[pixels] %s/%s: %d checked, %d outside tolerance, max |diff| %d/255, mean %.3f/255\n", suite.c_str(), name.c_str(), s.checked,
                s.failed, s.maxAbs, s.meanAbs);
    if (checks.empty()) return ::testing::AssertionFailure() << name << ": no pixels were checked (the scene does not cover the test points)";
    if (failures.empty()) return ::testing::AssertionSuccess();

    std::sort(failures.begin(), failures.end(), [](const Failure& a, const Failure& b) { return a.diff > b.diff; });
    ::testing::AssertionResult r = ::testing::AssertionFailure();
    r << name << ": " << s.failed << " of " << s.checked << " checked pixels outside tolerance (max |diff| " << s.maxAbs << "/255); worst:";
    for (size_t i = 0; i < failures.size() && i < 8; ++i) {
        const PixelCheck& c = *failures[i].check;
        r << "\n  pixel (" << c.x << "," << c.y << "): expected (" << int(c.expected[0]) << "," << int(c.expected[1]) << "," << int(c.expected[2])
          << ") +-" << c.tolerance;
        if (c.x >= 0 && c.y >= 0 && c.x < actual.width && c.y < actual.height) {
            const uint8_t* p = actual.pixel(c.x, c.y);
            r << ", actual (" << int(p[0]) << "," << int(p[1]) << "," << int(p[2]) << ")";
        } else {
            r << ", outside the " << actual.width << "x" << actual.height << " image";
        }
    }
    // Diff of the checked pixels only: unchecked pixels take the actual value.
    rnd::Framebuffer masked = actual;
    int minTol = 255;
    for (const PixelCheck& c : checks) {
        if (c.x < 0 || c.y < 0 || c.x >= actual.width || c.y >= actual.height) continue;
        for (int ch = 0; ch < 3; ++ch) masked.pixel(c.x, c.y)[ch] = c.expected[ch];
        minTol = std::min(minTol, c.tolerance);
    }
    writeImage(actual, suite, name + "-actual");
    writeImage(expectedImage.width > 0 ? expectedImage : masked, suite, name + "-expected");
    if (masked.width > 0) writeImage(rnd::diffImage(actual, masked, minTol), suite, name + "-diff");
    r << "\n  images written to " << outputDir(suite) / name << "-{actual,expected,diff}.png";
    return r;
}

std::string base64Encode(std::string_view bytes) {
    static const char* b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string enc;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        if (i + 2 < bytes.size()) v |= uint8_t(bytes[i + 2]);
        enc += b64[(v >> 18) & 63];
        enc += b64[(v >> 12) & 63];
        enc += i + 1 < bytes.size() ? b64[(v >> 6) & 63] : '=';
        enc += i + 2 < bytes.size() ? b64[v & 63] : '=';
    }
    return enc;
}

std::shared_ptr<sg::Texture> checker(int size, int checks, const sg::vec3& a, const sg::vec3& b) {
    auto t = std::make_shared<sg::Texture>();
    t->width = t->height = size;
    t->rgba.resize(size_t(size) * size * 4);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const bool odd = ((x * checks / size) + (y * checks / size)) % 2;
            const sg::vec3 c = odd ? a : b;
            uint8_t* p = &t->rgba[(size_t(y) * size + x) * 4];
            for (int i = 0; i < 3; ++i) p[i] = uint8_t(std::clamp(c[i], 0.0f, 1.0f) * 255.0f + 0.5f);
            p[3] = 255;
        }
    return t;
}

::testing::AssertionResult matchesGlBaseline(const rnd::Framebuffer& actual, const std::string& name) {
    const std::filesystem::path path = std::filesystem::path(VIEWER_SOURCE_DIR) / "tests" / "baselines" / "gl" / (name + ".png");
    const char* accept = std::getenv("VIEWER_ACCEPT_BASELINES");
    if (accept && std::string(accept) == "1") {
        std::string err = assets::writePng(path, actual.width, actual.height, actual.color.data(), true);
        if (!err.empty()) return ::testing::AssertionFailure() << err;
        std::printf("[baseline] wrote %s\n", path.c_str());
        return ::testing::AssertionSuccess();
    }
    assets::ImageLoad load = assets::loadImage(path);
    if (!load.texture)
        return ::testing::AssertionFailure() << "baseline " << path << " missing or unreadable (" << load.error
                                             << "): run scripts/accept-baselines.sh after looking at the render";
    rnd::Framebuffer expected;
    expected.resize(load.texture->width, load.texture->height);
    expected.color = load.texture->rgba;
    ImageTolerance tol;
    tol.maxMeanAbs = 1.0;
    tol.minFractionWithin = 0.98;
    tol.channelTolerance = 8;
    return imagesClose(actual, expected, tol, "gl-baselines", name);
}

ProgramRun runProgram(const std::string& exe, const std::string& args, bool withStderr) {
    ProgramRun r;
    const std::string cmd = testing_support::quoted(exe) + " " + args + (withStderr ? " 2>&1" : " 2>/dev/null");
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
    r.status = pclose(p);
    return r;
}

std::string quoted(const std::filesystem::path& p) { return "\"" + p.string() + "\""; }

Agreement agreementBetween(const std::string& a, const std::string& b) {
    auto rasterizes = [](const std::string& n) { return n != "raycast"; };
    return rasterizes(a) && rasterizes(b) ? Agreement::SameMethod : Agreement::AcrossMethods;
}

}   // namespace testing_support
