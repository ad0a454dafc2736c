// import_common.cpp - see import_common.h.
#include "import_common.h"

#include "assets/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

namespace fs = std::filesystem;

namespace assets::detail {

std::string fileNameOf(const fs::path& p) { return p.filename().string(); }

std::string percentDecode(const std::string& s) {
    std::string out;
    out.reserve(s.size());
    auto hex = [](char c) -> int {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
    };
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '%' && i + 2 < s.size()) {
            int a = hex(s[i + 1]), b = hex(s[i + 2]);
            if (a >= 0 && b >= 0) {
                out.push_back(char(a * 16 + b));
                i += 2;
                continue;
            }
        }
        out.push_back(s[i]);
    }
    return out;
}

namespace {
std::string checkOne(const std::string& rel) {
    if (rel.empty()) return "empty file name";
    if (rel.find('\0') != std::string::npos) return "file name contains a NUL byte";
    if (rel[0] == '/') return "absolute path '" + rel + "' is not allowed (files must lie in the model's folder)";
    if (rel.size() >= 2 && rel[1] == ':') return "drive path '" + rel + "' is not allowed";
    if (rel[0] == '~') return "home-relative path '" + rel + "' is not allowed";
    size_t start = 0;
    while (start <= rel.size()) {
        size_t end = rel.find_first_of("/\\", start);
        if (end == std::string::npos) end = rel.size();
        if (rel.compare(start, end - start, "..") == 0 && end - start == 2) return "path '" + rel + "' leaves the model's folder ('..')";
        start = end + 1;
    }
    return {};
}

std::string sysErr(const std::string& what) { return what + ": " + std::strerror(errno); }
}   // namespace

std::string checkRelativeName(const std::string& rel) {
    std::string e = checkOne(rel);
    if (!e.empty()) return e;
    std::string dec = percentDecode(rel);
    if (dec != rel) {
        e = checkOne(dec);
        if (!e.empty()) return e + " (after percent-decoding '" + rel + "')";
    }
    return {};
}

ConfinedDir::ConfinedDir(const fs::path& folder) {
    std::error_code ec;
    m_root = fs::canonical(folder.empty() ? fs::path(".") : folder, ec);
    if (ec) {
        m_error = folder.string() + ": cannot resolve folder: " + ec.message();
        return;
    }
    m_rootStr = m_root.string();
    if (m_rootStr.empty() || m_rootStr.back() != '/') m_rootStr += '/';
}

bool ConfinedDir::relativeOf(const std::string& path, std::string& rel, std::string* why) const {
    if (path.compare(0, m_rootStr.size(), m_rootStr) != 0) {
        if (why) *why = "'" + path + "' is outside the model's folder";
        return false;
    }
    rel = path.substr(m_rootStr.size());
    return true;
}

namespace {
// Opens root/rel without following the final name into a non-regular file and verifies
// where the opened file really lives. Returns fd >= 0 or -1 with *why set.
int openConfined(const fs::path& root, const std::string& rootStr, const std::string& rel, std::string* why, struct stat* stOut) {
    std::string e = checkRelativeName(rel);
    if (!e.empty()) {
        *why = e;
        return -1;
    }
    fs::path p = root / rel;
    // Resolve symlinks first (realpath opens nothing) so that a link pointing out of the
    // folder is refused without its target ever being opened.
    {
        char resolved[PATH_MAX + 1];
        if (!::realpath(p.c_str(), resolved)) {
            *why = sysErr("cannot open '" + rel + "'");
            return -1;
        }
        std::string rs(resolved);
        if (rs.compare(0, rootStr.size(), rootStr) != 0) {
            *why = "'" + rel + "' resolves to '" + rs + "', outside the model's folder";
            return -1;
        }
        p = rs;
    }
    int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
    if (fd < 0) {
        *why = sysErr("cannot open '" + rel + "'");
        return -1;
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
        *why = sysErr("cannot stat '" + rel + "'");
        ::close(fd);
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        *why = "'" + rel + "' is not a regular file";
        ::close(fd);
        return -1;
    }
    // Where does the opened file really live (symlinks resolved by the kernel)?
    char buf[PATH_MAX + 1];
    std::string link = "/proc/self/fd/" + std::to_string(fd);
    ssize_t n = ::readlink(link.c_str(), buf, PATH_MAX);
    if (n <= 0) {
        // No /proc: fall back to canonicalising the name.
        std::error_code ec;
        fs::path c = fs::canonical(p, ec);
        if (ec) {
            *why = "cannot resolve '" + rel + "'";
            ::close(fd);
            return -1;
        }
        std::string cs = c.string();
        if (cs.compare(0, rootStr.size(), rootStr) != 0) {
            *why = "'" + rel + "' resolves to '" + cs + "', outside the model's folder";
            ::close(fd);
            return -1;
        }
    } else {
        std::string real(buf, size_t(n));
        if (real.compare(0, rootStr.size(), rootStr) != 0) {
            *why = "'" + rel + "' resolves to '" + real + "', outside the model's folder";
            ::close(fd);
            return -1;
        }
    }
    *stOut = st;
    return fd;
}
}   // namespace

std::string ConfinedDir::read(const std::string& rel, uint64_t maxBytes, std::vector<unsigned char>& out) const {
    out.clear();
    if (!ok()) return m_error;
    std::string why;
    struct stat st {};
    int fd = openConfined(m_root, m_rootStr, rel, &why, &st);
    if (fd < 0) return why;
    if (uint64_t(st.st_size) > maxBytes) {
        ::close(fd);
        return "'" + rel + "' is too large (" + std::to_string(st.st_size) + " bytes, limit " + std::to_string(maxBytes) + ")";
    }
    out.resize(size_t(st.st_size));
    out.resize(readFully(fd, out.data(), out.size()));
    ::close(fd);
    return {};
}

std::string ConfinedDir::readAbsolute(const std::string& path, uint64_t maxBytes, std::vector<unsigned char>& out) const {
    std::string rel, why;
    if (!relativeOf(path, rel, &why)) return why;
    return read(rel, maxBytes, out);
}

std::string ConfinedDir::probe(const std::string& rel) const {
    if (!ok()) return m_error;
    std::string why;
    struct stat st {};
    int fd = openConfined(m_root, m_rootStr, rel, &why, &st);
    if (fd < 0) return why;
    ::close(fd);
    return {};
}

bool addDefaultCameraAndLight(sg::Scene& scene) {
    bool hasLight = false, hasCamera = false;
    for (sg::NodeId id : scene.depthFirstOrder()) {
        const auto& p = scene.node(id).payload;
        if (std::holds_alternative<sg::Light>(p)) hasLight = true;
        if (std::holds_alternative<sg::Camera>(p)) hasCamera = true;
    }
    const sg::Aabb bounds = scene.worldBounds();   // once: a light adds none (lights have no bounds)
    sg::Aabb b = bounds;
    if (b.empty()) b = {sg::vec3(-1.0f), sg::vec3(1.0f)};
    bool added = false;
    if (!hasLight) {
        // A directional key light from the upper front-left of the default camera's view
        // (a "headlight-ish" key), plus the scene's ambient term.
        sg::Light key;
        key.type = sg::LightType::Directional;
        key.color = sg::vec3(1.0f);
        key.intensity = 1.0f;
        sg::NodeId id = scene.addNode("default key light", scene.root(), key);
        sg::vec3 c = b.center();
        float r = std::max(0.5f * glm::length(b.extent()), 1e-3f);
        scene.lookAt(id, c + glm::normalize(sg::vec3(0.3f, 0.8f, 1.0f)) * (2.0f * r), c);
        added = true;
    }
    if (!hasCamera)
        scene.addDefaultCamera(bounds);
    else if (!scene.valid(scene.activeCamera))
        scene.activeCamera = scene.cameras().front();
    return added;
}

bool imageSize(const unsigned char* d, size_t n, int& w, int& h) {
    static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (n >= 24 && std::memcmp(d, png, 8) == 0 && std::memcmp(d + 12, "IHDR", 4) == 0) {
        uint32_t ww = (uint32_t(d[16]) << 24) | (uint32_t(d[17]) << 16) | (uint32_t(d[18]) << 8) | d[19];
        uint32_t hh = (uint32_t(d[20]) << 24) | (uint32_t(d[21]) << 16) | (uint32_t(d[22]) << 8) | d[23];
        if (ww > INT32_MAX || hh > INT32_MAX) return false;
        w = int(ww);
        h = int(hh);
        return true;
    }
    if (n >= 4 && d[0] == 0xFF && d[1] == 0xD8) {
        size_t i = 2;
        while (i + 4 <= n) {
            if (d[i] != 0xFF) return false;
            unsigned char m = d[i + 1];
            if (m == 0xFF) {
                ++i;
                continue;
            }
            if (m == 0xD8 || m == 0x01 || (m >= 0xD0 && m <= 0xD7)) {
                i += 2;
                continue;
            }
            size_t len = (size_t(d[i + 2]) << 8) | d[i + 3];
            if (len < 2) return false;
            bool sof = (m >= 0xC0 && m <= 0xCF) && m != 0xC4 && m != 0xC8 && m != 0xCC;
            if (sof) {
                if (i + 9 > n) return false;
                h = (int(d[i + 5]) << 8) | d[i + 6];
                w = (int(d[i + 7]) << 8) | d[i + 8];
                return true;
            }
            i += 2 + len;
        }
    }
    return false;
}

}   // namespace assets::detail
