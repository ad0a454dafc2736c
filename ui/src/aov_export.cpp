// aov_export.cpp - writeAovs() and its helpers (see aov_export.h).
#include "ui/aov_export.h"

#include "assets/image_io.h"
#include "renderers/inspect.h"
#include "scenegraph/camera_model.h"
#include "scenegraph/instances.h"
#include "scenegraph/setting_names.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace fs = std::filesystem;

namespace ui {

namespace {

// P.normal.png: 0.5 n + 0.5 as 8-bit RGB (opaque), black where nothing was drawn.
std::string writeNormalImage(const fs::path& p, const sg::FrameInput& frame, const sg::InstanceTable& ids, const rnd::Framebuffer& img,
                             bool overwrite) {
    const std::vector<sg::vec3> n = rnd::normalImage(frame, ids, img);
    std::vector<uint8_t> rgba(n.size() * 4, 0);
    for (size_t k = 0; k < n.size(); ++k) {
        rgba[4 * k + 3] = 255;
        if (img.drawable[k] == 0 || glm::dot(n[k], n[k]) == 0.0f) continue;
        for (int c = 0; c < 3; ++c) rgba[4 * k + size_t(c)] = uint8_t(std::lround(std::clamp(0.5f * n[k][c] + 0.5f, 0.0f, 1.0f) * 255.0f));
    }
    return assets::writePng(p, img.width, img.height, rgba.data(), overwrite);
}

// P.id.png: the instance id of each pixel, 0 = nothing.
std::string writeIdImage(const fs::path& p, const sg::InstanceTable& ids, const rnd::Framebuffer& img, bool overwrite) {
    if (ids.node.size() > 65536) return p.string() + ": " + std::to_string(ids.node.size() - 1) + " instances do not fit a 16-bit id image";
    std::vector<uint16_t> v(img.drawable.size());
    for (size_t k = 0; k < v.size(); ++k) v[k] = uint16_t(ids.instanceOf(img.drawable[k]));
    return assets::writePngGray16(p, img.width, img.height, v, overwrite);
}

fs::path withoutExtension(fs::path p) { return p.replace_extension(); }

// "depth, normal, id": the names of the AOVs the export writes.
std::string exportedNames() {
    std::string known;
    for (rnd::Aov a : rnd::kAllAovs)
        if (aovSuffix(a)) known += (known.empty() ? "" : ", ") + std::string(rnd::nameOf(a));
    return known;
}

}   // namespace

const char* aovSuffix(rnd::Aov aov) {
    switch (aov) {
    case rnd::Aov::Depth: return ".depth.pfm";
    case rnd::Aov::Normal: return ".normal.png";
    case rnd::Aov::Id: return ".id.png";
    default: return nullptr;
    }
}

std::string parseAovList(const std::string& list, std::vector<rnd::Aov>& out) {
    out.clear();
    std::stringstream in(list);
    for (std::string k; std::getline(in, k, ',');) {
        if (k.empty()) continue;
        rnd::Aov a{};
        if (!rnd::parseAov(k, a) || !aovSuffix(a)) { return "unknown kind '" + k + "' (known: " + exportedNames() + ")"; }
        if (std::find(out.begin(), out.end(), a) == out.end()) out.push_back(a);
    }
    return {};
}

rnd::AovSet aovSetOf(const std::vector<rnd::Aov>& kinds) {
    rnd::AovSet s;
    for (rnd::Aov a : kinds) s.add(a);
    return s;
}

bool aovsNeedVisibility(const std::vector<rnd::Aov>& kinds) { return rnd::renderedAovs(aovSetOf(kinds)).has(rnd::Aov::Visibility); }

std::vector<fs::path> aovFiles(const fs::path& png, const std::vector<rnd::Aov>& kinds) {
    const std::string base = withoutExtension(png).string();
    std::vector<fs::path> files;
    for (rnd::Aov k : kinds)
        if (const char* s = aovSuffix(k)) files.push_back(base + s);
    if (!files.empty()) files.push_back(base + ".json");
    return files;
}

std::vector<assets::AovInstance> aovInstances(const sg::Scene& scene, const sg::FrameInput& frame) {
    const sg::InstanceTable ids = sg::instanceTable(frame);
    std::vector<assets::AovInstance> out;
    for (uint32_t i = 1; i < ids.node.size(); ++i) {
        const sg::NodeId n = ids.node[i];
        out.push_back({i, scene.valid(n) ? scene.node(n).name : std::string(), sg::nodePath(scene, n)});
    }
    return out;
}

std::string writeAovs(const fs::path& png, const std::vector<rnd::Aov>& kinds, const std::string& backend,
                      const std::vector<assets::AovInstance>& instances, const sg::FrameInput& frame, const rnd::Framebuffer& img, bool overwrite) {
    if (kinds.empty()) return {};
    const std::string base = withoutExtension(png).string();
    if (aovsNeedVisibility(kinds) && !img.has(rnd::Aov::Visibility))
        return base + ": the " + backend + " render has no visibility for the normal / id export";
    const sg::InstanceTable ids = sg::instanceTable(frame);
    assets::AovSidecar side;
    side.width = img.width;
    side.height = img.height;
    side.backend = backend;
    side.projection = std::string(sg::nameOf(frame.camera.projection.type));
    side.camera = sg::cameraModelOf(frame.camera, img.width, img.height);
    for (rnd::Aov k : kinds) {
        const char* suffix = aovSuffix(k);
        if (!suffix) return base + ": " + std::string(rnd::nameOf(k)) + " is not exported (known: " + exportedNames() + ")";
        const fs::path p = base + suffix;
        std::string e;
        if (k == rnd::Aov::Depth)
            e = assets::writePfm(p, img.width, img.height, sg::opticalDepthMap(frame.camera, img.width, img.height, img.depth), overwrite);
        else if (k == rnd::Aov::Normal)
            e = writeNormalImage(p, frame, ids, img, overwrite);
        else
            e = writeIdImage(p, ids, img, overwrite);
        if (!e.empty()) return e;
        side.files.push_back(p.filename().string());
        side.hasIds = side.hasIds || k == rnd::Aov::Id;
    }
    if (side.hasIds) side.ids = instances;
    return assets::writeAovSidecar(base + ".json", side, overwrite);
}

}   // namespace ui
