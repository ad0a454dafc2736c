// files_test.cpp - safe file writes and reads (assets/files.h) and PNG output: atomic writes
// that refuse to overwrite unless asked and leave the old file or the complete new one on a
// full disk, in a read-only folder or when the writer is killed; a clear error for a missing
// folder; limited reads that refuse devices and large files; unique names; PNG round trips
// and the size caps.
#include "assets/files.h"
#include "assets/image_io.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <csignal>
#include <cstdio>
#include <fstream>

namespace fs = std::filesystem;

TEST(FilesTest, AtomicWriteCreatesAndRefusesToOverwrite) {
    fs::path dir = testing_support::outputDir("files") / "atomic";
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::path f = dir / "a.txt";
    EXPECT_EQ(assets::writeFileAtomic(f, "one", false), "");
    EXPECT_NE(assets::writeFileAtomic(f, "two", false), "");
    std::string content;
    EXPECT_EQ(assets::readFileLimited(f, 100, content), "");
    EXPECT_EQ(content, "one");
    EXPECT_EQ(assets::writeFileAtomic(f, "two", true), "");
    EXPECT_EQ(assets::readFileLimited(f, 100, content), "");
    EXPECT_EQ(content, "two");
}

TEST(FilesTest, MissingFolderGivesAClearError) {
    std::string err = assets::writeFileAtomic("/nonexistent-folder/x.png", "data", false);
    EXPECT_NE(err.find("/nonexistent-folder"), std::string::npos) << err;
    err = assets::writeFileAtomic("/proc/self/new-file", "data", false);   // not creatable, even as root
    EXPECT_NE(err, "");
}

// A full disk, simulated with a file-size limit (works as root too): the write fails with a
// clear error, the old file stays intact and no temporary file is left behind.
TEST(FilesTest, FullDiskKeepsTheOldFile) {
    fs::path dir = testing_support::outputDir("files") / "fulldisk";
    fs::remove_all(dir);
    fs::create_directories(dir);
    ASSERT_EQ(assets::writeFileAtomic(dir / "old.txt", "old", false), "");
    struct rlimit saved {};
    getrlimit(RLIMIT_FSIZE, &saved);
    auto oldHandler = signal(SIGXFSZ, SIG_IGN);
    struct rlimit small = saved;
    small.rlim_cur = 4096;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
    std::string err = assets::writeFileAtomic(dir / "old.txt", std::string(1 << 20, 'n'), true);
    setrlimit(RLIMIT_FSIZE, &saved);
    signal(SIGXFSZ, oldHandler);
    EXPECT_NE(err.find("old.txt"), std::string::npos) << err;
    std::string content;
    assets::readFileLimited(dir / "old.txt", 100, content);
    EXPECT_EQ(content, "old");
    int files = 0;
    for (auto& e : fs::directory_iterator(dir)) {
        (void)e;
        ++files;
    }
    EXPECT_EQ(files, 1);
}

// A read-only folder: the replacement cannot be created, the error names the file, the old file
// stays. Root ignores folder permissions, so as root the write runs in a child process that
// has dropped to the unprivileged uid 65534 first.
TEST(FilesTest, ReadOnlyFolderKeepsTheOldFile) {
    fs::path dir = testing_support::outputDir("files") / "readonly";
    ::chmod(dir.c_str(), 0755);   // an earlier run that stopped half way
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path f = dir / "old.txt";
    ASSERT_EQ(assets::writeFileAtomic(f, "old", false), "");
    ASSERT_EQ(::chmod(dir.c_str(), 0555), 0);
    std::string err;
    if (::geteuid() == 0) {
        int fds[2];
        ASSERT_EQ(::pipe(fds), 0);
        pid_t pid = ::fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            ::close(fds[0]);
            if (::setgid(65534) != 0 || ::setuid(65534) != 0) _exit(2);
            std::string e = assets::writeFileAtomic(f, "new", true);
            ssize_t w = ::write(fds[1], e.data(), e.size());
            _exit(w == ssize_t(e.size()) ? 0 : 3);
        }
        ::close(fds[1]);
        char buf[1024];
        ssize_t r;
        while ((r = ::read(fds[0], buf, sizeof buf)) > 0) err.append(buf, size_t(r));
        ::close(fds[0]);
        int status = 0;
        ::waitpid(pid, &status, 0);
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "child status " << status;
    } else {
        err = assets::writeFileAtomic(f, "new", true);
    }
    ::chmod(dir.c_str(), 0755);
    EXPECT_NE(err.find("old.txt"), std::string::npos) << err;
    EXPECT_EQ(err.find('\n'), std::string::npos) << err;
    std::printf("  read-only folder -> %s\n", err.c_str());
    std::string content;
    EXPECT_EQ(assets::readFileLimited(f, 100, content), "");
    EXPECT_EQ(content, "old");
    int files = 0;
    for (auto& e : fs::directory_iterator(dir)) {
        (void)e;
        ++files;
    }
    EXPECT_EQ(files, 1);
}

TEST(FilesTest, ReadLimitedRefusesDevicesAndLargeFiles) {
    std::string out;
    EXPECT_NE(assets::readFileLimited("/dev/zero", 1 << 20, out).find("not a regular file"), std::string::npos);
    fs::path f = testing_support::outputDir("files") / "big.bin";
    std::ofstream(f) << std::string(1000, 'x');
    EXPECT_NE(assets::readFileLimited(f, 100, out).find("too large"), std::string::npos);
}

TEST(FilesTest, UniquePathNeverReturnsAnExistingFile) {
    fs::path dir = testing_support::outputDir("files") / "unique";
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::path p = dir / "shot.png";
    EXPECT_EQ(assets::uniquePath(p), p);
    std::ofstream(p) << "x";
    EXPECT_EQ(assets::uniquePath(p), dir / "shot-1.png");
    std::ofstream(dir / "shot-1.png") << "x";
    EXPECT_EQ(assets::uniquePath(p), dir / "shot-2.png");
}

TEST(FilesTest, PngRoundTripAndCaps) {
    std::vector<uint8_t> px(4 * 3 * 2);
    for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t(i * 10);
    std::string png;
    ASSERT_EQ(assets::encodePng(3, 2, px.data(), png), "");
    assets::ImageLoad img = assets::decodeImage(png.data(), png.size(), "mem.png");
    ASSERT_TRUE(img.texture) << img.error;
    EXPECT_EQ(img.texture->width, 3);
    EXPECT_EQ(img.texture->rgba, px);
    EXPECT_NE(assets::encodePng(20000, 10, px.data(), png), "");   // capped before stb overflows
    // Not PNG/JPEG (a GIF header) and a PNG header claiming 65535x65535 are refused before decoding.
    std::string gif = "GIF89a\x01\x00\x01\x00";
    EXPECT_NE(assets::decodeImage(gif.data(), gif.size(), "x.gif").error.find("not a PNG or JPEG"), std::string::npos);
    std::string huge = png;
    huge[16] = huge[17] = huge[20] = huge[21] = 0;
    huge[18] = huge[19] = huge[22] = huge[23] = char(0xFF);
    assets::ImageLoad h = assets::decodeImage(huge.data(), huge.size(), "huge.png");
    EXPECT_FALSE(h.texture);
    EXPECT_NE(h.error.find("65535x65535"), std::string::npos) << h.error;
}

// An image whose deflated rows take several of the encoder's 64 KB output steps (noise does
// not compress), with runs and gradients as well: decoded back exactly, and every chunk's CRC
// right (stb_image does not check them).
TEST(FilesTest, PngOfManyOutputStepsRoundTrips) {
    const int w = 301, h = 203;
    std::vector<uint8_t> px(size_t(w) * h * 4);
    uint32_t state = 12345;
    for (size_t i = 0; i < px.size(); ++i) {
        state = state * 1664525u + 1013904223u;
        const size_t y = i / (size_t(w) * 4);
        px[i] = y < 100 ? uint8_t(state >> 24) : y < 150 ? uint8_t(i / 4 % 256) : uint8_t(7);
    }
    std::string png;
    ASSERT_EQ(assets::encodePng(w, h, px.data(), png), "");
    EXPECT_GT(png.size(), size_t(100) << 10);
    assets::ImageLoad img = assets::decodeImage(png.data(), png.size(), "noise.png");
    ASSERT_TRUE(img.texture) << img.error;
    EXPECT_EQ(img.texture->width, w);
    EXPECT_EQ(img.texture->height, h);
    EXPECT_EQ(img.texture->rgba, px);
    auto be32 = [&](size_t o) {
        return uint32_t(uint8_t(png[o])) << 24 | uint32_t(uint8_t(png[o + 1])) << 16 | uint32_t(uint8_t(png[o + 2])) << 8 | uint8_t(png[o + 3]);
    };
    auto crc = [](const char* p, size_t n) {
        uint32_t c = ~0u;
        for (size_t i = 0; i < n; ++i) {
            c ^= uint8_t(p[i]);
            for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
        }
        return ~c;
    };
    std::vector<std::string> types;
    for (size_t o = 8; o + 12 <= png.size();) {
        const size_t n = be32(o);
        ASSERT_LE(o + 12 + n, png.size());
        types.push_back(png.substr(o + 4, 4));
        EXPECT_EQ(be32(o + 8 + n), crc(png.data() + o + 4, n + 4)) << types.back();
        o += 12 + n;
    }
    EXPECT_EQ(types, (std::vector<std::string>{"IHDR", "IDAT", "IEND"}));
}

// Kill the writer at random points, many times: the target is always either the complete old
// file or the complete new one, never torn or empty.
TEST(FilesTest, KilledWriterLeavesOldOrNewFile) {
    fs::path dir = testing_support::outputDir("files") / "killed";
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::path target = dir / "scene.json";
    const std::string oldContent(200000, 'o');
    const std::string newContent(3000000, 'n');
    ASSERT_EQ(assets::writeFileAtomic(target, oldContent, false), "");
    std::srand(12345);
    int sawNew = 0;
    for (int round = 0; round < 60; ++round) {
        pid_t pid = fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            assets::writeFileAtomic(target, newContent, true);
            _exit(0);
        }
        usleep(useconds_t(std::rand() % 20000));
        kill(pid, SIGKILL);
        int status = 0;
        waitpid(pid, &status, 0);
        std::string content;
        ASSERT_EQ(assets::readFileLimited(target, 1u << 24, content), "");
        bool isOld = content == oldContent, isNew = content == newContent;
        ASSERT_TRUE(isOld || isNew) << "round " << round << ": torn file of " << content.size() << " bytes";
        if (isNew) {
            ++sawNew;
            ASSERT_EQ(assets::writeFileAtomic(target, oldContent, true), "");
        }
    }
    std::printf("[killed writer] 60 rounds, %d completed before the kill\n", sawNew);
}
