// load.cpp - the mesh importers' entry point, detail::loadMeshFile: reads the file (size limit),
// refuses empty and UTF-16 files, hands the bytes to the format's importer by extension and
// turns a Fail (one printable line), out of memory or another exception into the load's error.
#include "importers.h"
#include "mesh_internal.h"

#include "assets/files.h"

namespace fs = std::filesystem;

namespace assets::detail {

LoadResult loadMeshFile(const fs::path& path, const LoadOptions& options) {
    using namespace meshfile;
    LoadResult result;
    const std::string file = fileNameOf(path);
    std::string ext = lower(path.extension().string());
    std::string data;
    std::string err = readFileLimited(path, kMaxFileBytes, data);
    if (!err.empty()) {
        result.error = err;
        return result;
    }
    Progress progress{options};
    Ctx ctx{path, progress, {}, 0};
    try {
        if (data.empty()) throw Fail{"empty file"};
        if (data.size() >= 2 && ((uint8_t(data[0]) == 0xFE && uint8_t(data[1]) == 0xFF) || (uint8_t(data[0]) == 0xFF && uint8_t(data[1]) == 0xFE)))
            throw Fail{"UTF-16 text is not supported (save the file as UTF-8/ASCII)"};
        progress.set(0.0f);
        if (ext == ".obj")
            result = loadObj(path, data, ctx);
        else if (ext == ".off")
            result = loadOff(path, data, ctx);
        else if (ext == ".ply")
            result = loadPly(path, data, ctx);
        else if (ext == ".stl")
            result = loadStl(path, data, ctx);
        else
            throw Fail{"unsupported mesh format '" + ext + "'"};
    } catch (const Fail& f) {
        result = {};
        // Quoted file text may hold control bytes: keep the error one printable line.
        std::string why = f.why.size() > 300 ? f.why.substr(0, 300) + "..." : f.why;
        for (char& ch : why)
            if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = '?';
        result.error = file + ": " + why;
        return result;
    } catch (const std::bad_alloc&) {
        result = {};
        result.error = file + ": out of memory";
        return result;
    } catch (const std::exception& e) {
        result = {};
        result.error = file + ": " + e.what();
        return result;
    }
    for (auto& w : ctx.warnings) result.warnings.push_back(std::move(w));
    progress.set(1.0f);
    return result;
}

}   // namespace assets::detail
