#include "test_support.h"

#include "assets/image_io.h"

#include <algorithm>
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

}   // namespace testing_support
