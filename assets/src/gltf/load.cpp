// load.cpp - the glTF importer's entry point, detail::loadGltf: reads the file (size limit) and,
// for GLB, its header; checks the JSON's size and nesting depth before tinygltf's recursive
// parser sees it; runs tinygltf with our file-system callbacks (reads confined to the model's
// folder) and an image callback that keeps the encoded bytes; then checks the required
// extensions, validates the model and converts it (convertModel).
#include "gltf_internal.h"
#include "importers.h"

#include "assets/files.h"

#if defined(__GLIBC__)
#include <malloc.h>   // malloc_trim
#endif

#include <string_view>

namespace fs = std::filesystem;

namespace assets::detail::gltf {

namespace {

// Gives the heap's free pages back to the system. tinygltf's JSON tree is millions of small
// blocks; freed, they stay in the heap (resident) while the scene's big arrays come from new
// pages: at 1M nodes the load's peak was tinygltf's parse peak plus the whole scene.
void releaseFreedMemory() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

void addRefusal(Ctx& c, const std::string& why) {
    if (std::find(c.refused.begin(), c.refused.end(), why) == c.refused.end()) c.refused.push_back(why);
}

bool fsFileExists(const std::string& path, void* ud) {
    Ctx& c = *static_cast<Ctx*>(ud);
    std::string rel;
    // tinygltf also tries "./name" (the working directory): refused silently, the model-folder
    // attempt already recorded why the name was not found.
    if (!c.dir.relativeOf(path, rel, nullptr)) return false;
    std::string why = c.dir.probe(rel);
    if (!why.empty()) addRefusal(c, why);
    return why.empty();
}
std::string fsExpand(const std::string& path, void*) { return path; }   // no ~ or $VAR expansion
bool fsRead(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* ud) {
    Ctx& c = *static_cast<Ctx*>(ud);
    std::string why = c.dir.readAbsolute(path, kMaxResourceBytes, *out);
    if (!why.empty()) {
        addRefusal(c, why);
        if (err) *err = why;
        return false;
    }
    return true;
}
bool fsWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err = "writing is disabled";
    return false;
}

// Keeps the encoded bytes; decoding happens after validation, for used images only.
bool storeImage(tinygltf::Image* image, const int idx, std::string*, std::string*, int, int, const unsigned char* bytes, int size, void* ud) {
    Ctx& c = *static_cast<Ctx*>(ud);
    size_t n = size > 0 ? size_t(size) : 0;
    if (image->bufferView >= 0) {
        // tinygltf checked the view and buffer indices but not the byte range.
        const tinygltf::Model& m = *c.model;
        const auto& bv = m.bufferViews[size_t(image->bufferView)];
        const auto& buf = m.buffers[size_t(bv.buffer)];
        if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset) {
            c.imageWarnings.push_back("image " + std::to_string(idx) + ": bufferView " + std::to_string(image->bufferView) +
                                      " exceeds its buffer; texture skipped");
            return true;
        }
        bytes = buf.data.data() + bv.byteOffset;
        n = bv.byteLength;
    }
    if (!bytes || n == 0) {
        c.imageWarnings.push_back("image " + std::to_string(idx) + ": no data; texture skipped");
        return true;
    }
    c.imageBytes[idx].assign(bytes, bytes + n);
    return true;
}

// Maximum nesting of {} / [] outside strings; stops counting past `limit`.
size_t jsonDepth(const char* s, size_t n, size_t limit) {
    size_t depth = 0, maxDepth = 0;
    bool inString = false;
    for (size_t i = 0; i < n; ++i) {
        char ch = s[i];
        if (inString) {
            if (ch == '\\')
                ++i;
            else if (ch == '"')
                inString = false;
        } else if (ch == '"') {
            inString = true;
        } else if (ch == '{' || ch == '[') {
            if (++depth > maxDepth) {
                maxDepth = depth;
                if (maxDepth > limit) return maxDepth;
            }
        } else if (ch == '}' || ch == ']') {
            if (depth > 0) --depth;
        }
    }
    return maxDepth;
}

std::string oneLine(std::string s) {
    for (char& ch : s)
        if (ch == '\n' || ch == '\r') ch = ' ';
    while (!s.empty() && s.back() == ' ') s.pop_back();
    size_t p;
    while ((p = s.find("  ")) != std::string::npos) s.replace(p, 2, "; ");
    if (s.size() > 400) s = s.substr(0, 400) + "...";
    return s;
}

// Checks the size limits and, for GLB, the header; sets `json` to the JSON text. "" or the reason.
std::string locateJson(const std::string& bytes, const fs::path& path, bool& binary, std::string_view& json) {
    binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    json = bytes;
    if (binary) {
        if (bytes.size() < 20) return "GLB file is truncated (" + std::to_string(bytes.size()) + " bytes)";
        uint32_t chunkLen = 0, chunkType = 0, total = 0;
        std::memcpy(&total, bytes.data() + 8, 4);
        std::memcpy(&chunkLen, bytes.data() + 12, 4);
        std::memcpy(&chunkType, bytes.data() + 16, 4);
        if (chunkType != 0x4E4F534Au) return "GLB: first chunk is not JSON";
        if (uint64_t(chunkLen) + 20 > bytes.size())
            return "GLB: JSON chunk length " + std::to_string(chunkLen) + " exceeds the file size " + std::to_string(bytes.size());
        if (total > bytes.size())
            return "GLB: header length " + std::to_string(total) + " exceeds the file size " + std::to_string(bytes.size()) + " (truncated file?)";
        json = std::string_view(bytes.data() + 20, chunkLen);
    } else if (path.extension() == ".glb" || path.extension() == ".GLB") {
        return "not a GLB file (no 'glTF' magic)";
    }
    if (json.size() > kMaxJsonBytes) return "JSON is " + std::to_string(json.size()) + " bytes, limit " + std::to_string(kMaxJsonBytes);
    if (jsonDepth(json.data(), json.size(), kMaxJsonDepth) > kMaxJsonDepth)
        return "JSON nesting deeper than " + std::to_string(kMaxJsonDepth) + " levels";
    if (bytes.size() > UINT32_MAX) return "file larger than 4 GB";
    return {};
}

// tinygltf parses `bytes` with our file-system and image callbacks (which confine reads to the
// file's folder and keep images undecoded). "" or the reason.
std::string parseModel(const std::string& bytes, bool binary, Ctx& ctx, tinygltf::Model& model) {
    ctx.model = &model;
    tinygltf::TinyGLTF loader;
    tinygltf::FsCallbacks cb{};
    cb.FileExists = &fsFileExists;
    cb.ExpandFilePath = &fsExpand;
    cb.ReadWholeFile = &fsRead;
    cb.WriteWholeFile = &fsWrite;
    cb.user_data = &ctx;
    loader.SetFsCallbacks(cb);
    loader.SetImageLoader(&storeImage, &ctx);
    std::string terr, twarn;
    bool ok = false;
    const std::string base = ctx.dir.root().string();
    try {
        if (binary)
            ok = loader.LoadBinaryFromMemory(&model, &terr, &twarn, reinterpret_cast<const unsigned char*>(bytes.data()), unsigned(bytes.size()),
                                             base, 0);
        else
            ok = loader.LoadASCIIFromString(&model, &terr, &twarn, bytes.data(), unsigned(bytes.size()), base, 0);
    } catch (const std::bad_alloc&) { return "out of memory while parsing"; } catch (const std::exception& e) {
        return std::string("parse error: ") + e.what();
    }
    ctx.parserWarning = oneLine(twarn);
    if (ok) return {};
    std::string why = oneLine(terr.empty() ? "tinygltf could not parse the file" : terr);
    if (!ctx.refused.empty() && why.find("File not found") != std::string::npos) return ctx.refused.front() + " (" + why + ")";
    if (!ctx.refused.empty() && why.find("read error") != std::string::npos) return ctx.refused.front();
    return why;
}

// The validated model -> result.scene (+ animations, warnings). "" or the reason.
std::string convertModel(tinygltf::Model& model, Ctx& ctx, const Progress& progress, const fs::path& path, LoadResult& result) {
    const std::string file = fileNameOf(path);
    Converter conv(model, ctx, progress);
    conv.file = file;
    conv.scene.name = path.stem().string();
    conv.scene.settings.reflection = sg::ReflectionModel::Pbr;   // glTF's own material model (the demo and meshes keep Phong)
    conv.textureOf.assign(model.textures.size(), {-2, -2});
    conv.decodedImage.assign(model.images.size(), nullptr);
    conv.imageTried.assign(model.images.size(), 0);
    conv.meshPrims.resize(model.meshes.size());
    conv.meshDone.assign(model.meshes.size(), 0);
    try {
        conv.convertMaterials();
        std::string ignored;
        for (const std::string& ext : model.extensionsUsed)
            if (!honouredExtension(ext)) ignored += (ignored.empty() ? "" : ", ") + ext;
        if (!ignored.empty()) conv.warnOnce("drawn without the extensions it uses that this viewer does not honour: " + ignored);
        progress.set(0.4f);
        std::string e = conv.buildNodes(chooseRoots(model, file, result));
        if (!e.empty()) return e;
        if (!(e = conv.convertSkins()).empty()) return e;
        result.animations = conv.animations();
    } catch (const std::bad_alloc&) { return "out of memory while building the scene"; }
    progress.set(0.95f);
    // The file's nodes (~480 bytes each in tinygltf) and the per-node tables are done with: free
    // them before the scene builds its caches (traversal order, world matrices), so that a file
    // of 1M nodes peaks at tinygltf's own parse peak instead of ~330 MB above it (bench_import).
    std::vector<tinygltf::Node>().swap(model.nodes);
    std::vector<std::vector<sg::NodeId>>().swap(conv.instancesOf);
    std::vector<sg::NodeId>().swap(conv.sgOf);
    releaseFreedMemory();
    addDefaultCameraAndLight(conv.scene);
    for (auto& w : conv.warnings) result.warnings.push_back(file + ": " + w);
    result.scene = std::move(conv.scene);
    return {};
}

}   // namespace

}   // namespace assets::detail::gltf

namespace assets::detail {

LoadResult loadGltf(const fs::path& path, const LoadOptions& options) {
    using namespace gltf;
    LoadResult result;
    const std::string file = fileNameOf(path);
    Progress progress{options};
    auto fail = [&](const std::string& why) {
        result.scene.reset();
        result.error = file + ": " + why;
        return std::move(result);
    };
    std::string bytes;
    if (std::string err = readFileLimited(path, kMaxFileBytes, bytes); !err.empty()) {
        result.error = err;
        return result;
    }
    if (bytes.empty()) return fail("empty file");
    progress.set(0.02f);
    bool binary = false;
    std::string_view json;
    if (std::string e = locateJson(bytes, path, binary, json); !e.empty()) return fail(e);

    Ctx ctx(path.parent_path().empty() ? fs::path(".") : path.parent_path());
    if (!ctx.dir.ok()) return fail(ctx.dir.error());
    tinygltf::Model model;
    std::string e = parseModel(bytes, binary, ctx, model);
    std::string().swap(bytes);
    if (!e.empty()) return fail(e);
    releaseFreedMemory();   // tinygltf's JSON tree is gone: give its pages back before the scene is built
    progress.set(0.3f);
    // Files we refused or could not read (images: the load goes on without them).
    for (const std::string& why : ctx.refused) result.warnings.push_back(file + ": file not read: " + why);
    if (!ctx.parserWarning.empty() && ctx.refused.empty()) result.warnings.push_back(file + ": " + ctx.parserWarning);
    for (const auto& w : ctx.imageWarnings) result.warnings.push_back(file + ": " + w);
    if (!(e = checkRequiredExtensions(model)).empty()) return fail(e);

    std::vector<std::string> vwarn;
    if (!(e = validate(model, vwarn)).empty()) return fail(e);
    for (auto& w : vwarn) result.warnings.push_back(file + ": " + w);
    if (progress.cancelled() || !(e = convertModel(model, ctx, progress, path, result)).empty()) return fail(e.empty() ? "cancelled" : e);
    progress.set(1.0f);
    return result;
}

}   // namespace assets::detail
