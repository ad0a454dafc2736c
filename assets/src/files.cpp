// files.cpp - safe file access (see files.h): writeFileAtomic (temporary file beside the
// target, fsync, then link() where it must not overwrite or rename() where it may, then fsync
// of the folder), readFileLimited (regular files only, opened non-blocking so a FIFO cannot
// hang it, within a byte budget), readFully, and uniquePath (name-1.ext, name-2.ext, ... so
// that a new file never replaces another).
#include "assets/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>
#include <random>

namespace fs = std::filesystem;

namespace assets {

namespace {
std::string sysError(const fs::path& p, const std::string& what) { return p.string() + ": " + what + ": " + std::strerror(errno); }
}   // namespace

std::string writeFileAtomic(const fs::path& path, std::string_view bytes, bool overwrite) {
    if (path.empty()) return "(empty path): no file name given";
    std::error_code ec;
    fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    if (!fs::is_directory(dir, ec)) return path.string() + ": folder " + dir.string() + " does not exist";
    auto st = fs::symlink_status(path, ec);
    if (!ec && fs::exists(st)) {
        if (!overwrite) return path.string() + ": file exists (use overwrite to replace it)";
        if (!fs::is_regular_file(st)) return path.string() + ": exists and is not a regular file";
    }
    // Temporary file beside the target so rename() stays on one file system (atomic).
    std::random_device rd;
    fs::path tmp = dir / ("." + path.filename().string() + ".tmp" + std::to_string(rd() % 1000000));
    int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) return sysError(path, "cannot create temporary file");
    size_t done = 0;
    while (done < bytes.size()) {
        ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (w < 0) {
            if (errno == EINTR) continue;
            std::string err = sysError(path, "write failed");
            ::close(fd);
            ::unlink(tmp.c_str());
            return err;
        }
        done += size_t(w);
    }
    if (::fsync(fd) != 0) {
        std::string err = sysError(path, "fsync failed");
        ::close(fd);
        ::unlink(tmp.c_str());
        return err;
    }
    ::close(fd);
    if (!overwrite) {
        // link() fails if the target appeared meanwhile: never replace a file we were not allowed to.
        if (::link(tmp.c_str(), path.c_str()) != 0) {
            std::string err = errno == EEXIST ? path.string() + ": file exists (use overwrite to replace it)" : sysError(path, "cannot create file");
            ::unlink(tmp.c_str());
            return err;
        }
        ::unlink(tmp.c_str());
    } else if (::rename(tmp.c_str(), path.c_str()) != 0) {
        std::string err = sysError(path, "cannot replace file");
        ::unlink(tmp.c_str());
        return err;
    }
    // Make the directory entry durable too.
    int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
    return {};
}

std::string readFileLimited(const fs::path& path, uint64_t maxBytes, std::string& out) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) return sysError(path, "cannot open");
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
        std::string e = sysError(path, "cannot stat");
        ::close(fd);
        return e;
    }
    if (!S_ISREG(st.st_mode)) {
        ::close(fd);
        return path.string() + ": not a regular file";
    }
    if (uint64_t(st.st_size) > maxBytes) {
        ::close(fd);
        return path.string() + ": file too large (" + std::to_string(st.st_size) + " bytes, limit " + std::to_string(maxBytes) + ")";
    }
    out.resize(size_t(st.st_size));
    out.resize(readFully(fd, out.data(), out.size()));
    ::close(fd);
    return {};
}

size_t readFully(int fd, void* buffer, size_t n) {
    auto* p = static_cast<char*>(buffer);
    size_t done = 0;
    while (done < n) {
        ssize_t r = ::read(fd, p + done, n - done);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) break;
        done += size_t(r);
    }
    return done;
}

fs::path uniquePath(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(path, ec))) return path;
    fs::path stem = path.stem(), ext = path.extension(), dir = path.parent_path();
    for (int i = 1; i < 1000000; ++i) {
        fs::path p = dir / (stem.string() + "-" + std::to_string(i) + ext.string());
        if (!fs::exists(fs::symlink_status(p, ec))) return p;
    }
    return path;
}

}   // namespace assets
