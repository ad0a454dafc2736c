// camera_jobs.cpp - planCameraJobs(), applyCameraJob() (see camera_jobs.h).
#include "camera_jobs.h"

#include "assets/files.h"
#include "scenegraph/camera_model.h"
#include "scenegraph/setting_names.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace cli {

namespace fs = std::filesystem;

namespace {

bool parseSizeText(const std::string& s, int& w, int& h) {
    char x = 0, tail = 0;
    return std::sscanf(s.c_str(), "%d%c%d%c", &w, &x, &h, &tail) == 3 && (x == 'x' || x == 'X') && w > 0 && h > 0;
}

// OUT.png -> OUT_0007.png
fs::path numbered(const fs::path& out, int k) {
    char n[16];
    std::snprintf(n, sizeof n, "_%04d", k);
    fs::path p = out;
    return p.replace_filename(out.stem().string() + n + out.extension().string());
}

std::string parseShard(const std::string& s, int& i, int& n) {
    char slash = 0, tail = 0;
    if (std::sscanf(s.c_str(), "%d%c%d%c", &i, &slash, &n, &tail) != 3 || slash != '/' || n < 1 || i < 0 || i >= n)
        return "--shard '" + s + "': expected I/N with 0 <= I < N";
    return {};
}

std::string readCameraList(const fs::path& path, std::vector<assets::AovCamera>& cams) {
    std::string text;
    std::string err = assets::readFileLimited(path, 256u << 20, text);
    if (!err.empty()) return err;
    std::istringstream in(text);
    int line = 0;
    for (std::string l; std::getline(in, l);) {
        ++line;
        if (l.find_first_not_of(" \t\r") == std::string::npos) continue;
        assets::AovCamera c;
        err = assets::parseAovCamera(l, path.string() + ":" + std::to_string(line), c);
        if (!err.empty()) return err;
        cams.push_back(std::move(c));
    }
    if (cams.empty()) return path.string() + ": no cameras (one JSON object per line)";
    return {};
}

}   // namespace

std::string planCameraJobs(const RenderArgs& a, std::vector<CameraJob>& jobs) {
    jobs.clear();
    int w = 1280, h = 720;
    if (!a.size.empty() && !parseSizeText(a.size, w, h)) return "--size '" + a.size + "': expected WIDTHxHEIGHT, e.g. 1280x720";
    const int exclusive = int(!a.cameraJson.empty()) + int(!a.cameras.empty()) + int(a.turntable > 0);
    if (exclusive > 1) return "--camera-json, --cameras and --turntable choose the camera each; give one of them";
    if (a.turntable < 0 || a.turntable > 100000) return "--turntable " + std::to_string(a.turntable) + ": expected 1..100000 frames";
    int shardI = 0, shardN = 1;
    if (!a.shard.empty()) {
        std::string err = parseShard(a.shard, shardI, shardN);
        if (!err.empty()) return err;
    }
    auto sized = [&](CameraJob& j) {
        j.width = w;
        j.height = h;
        if (a.size.empty() && j.camera && j.camera->width > 0 && j.camera->height > 0) {
            j.width = j.camera->width;
            j.height = j.camera->height;
        }
    };
    std::vector<CameraJob> all;
    if (!a.cameras.empty()) {
        std::vector<assets::AovCamera> cams;
        std::string err = readCameraList(a.cameras, cams);
        if (!err.empty()) return err;
        for (size_t k = 0; k < cams.size(); ++k) all.push_back(CameraJob{int(k), numbered(a.out, int(k)), 0, 0, cams[k], 0.0f});
    } else if (a.turntable > 0) {
        for (int k = 0; k < a.turntable; ++k)
            all.push_back(CameraJob{k, numbered(a.out, k), 0, 0, std::nullopt, 360.0f * float(k) / float(a.turntable)});
    } else {
        CameraJob j{-1, a.out, 0, 0, std::nullopt, 0.0f};
        if (!a.cameraJson.empty()) {
            assets::AovCamera c;
            std::string err = assets::readAovCamera(a.cameraJson, c);
            if (!err.empty()) return err;
            j.camera = c;
        }
        all.push_back(std::move(j));
    }
    if (!a.shard.empty() && all.size() == 1 && all[0].index < 0) return "--shard needs several frames (--cameras or --turntable)";
    for (CameraJob& j : all) {
        if (j.index >= 0 && j.index % shardN != shardI) continue;
        sized(j);
        jobs.push_back(std::move(j));
    }
    return {};
}

std::string applyCameraJob(const RenderArgs& a, const CameraJob& job, sg::FrameInput& frame) {
    const float aspect = float(job.width) / float(job.height);
    if (job.camera) {
        const assets::AovCamera& c = *job.camera;
        if (c.width > 0 && c.height > 0 && std::fabs(float(c.width) / float(c.height) - aspect) > 1e-3f * aspect)
            return "the camera was made for " + std::to_string(c.width) + "x" + std::to_string(c.height) + " and cannot render " +
                   std::to_string(job.width) + "x" + std::to_string(job.height) + " unchanged (another aspect ratio)";
        sg::ProjectionType type = sg::ProjectionType::Perspective;
        sg::parseName(c.projection, type);
        frame.camera = sg::frameCameraFromModel(c.model, type, aspect, frame.camera.focusDistance);
    }
    if (job.turntableDeg != 0.0f) {
        const sg::FrameCamera& cam = frame.camera;
        const sg::vec3 forward = -sg::vec3(cam.viewInverse[2]);
        const sg::vec3 pivot = cam.eye + forward * cam.focusDistance;
        const sg::mat4 spin = glm::translate(sg::mat4(1.0f), pivot) * glm::rotate(sg::mat4(1.0f), glm::radians(job.turntableDeg), sg::vec3(0, 1, 0)) *
                              glm::translate(sg::mat4(1.0f), -pivot);
        frame.camera = sg::makeFrameCamera(spin * cam.viewInverse, cam.projection, aspect, cam.focusDistance);
    }
    if (!a.intrinsics.empty()) {
        double fx = 0, fy = 0, cx = 0, cy = 0;
        char tail = 0;
        if (std::sscanf(a.intrinsics.c_str(), "%lf,%lf,%lf,%lf%c", &fx, &fy, &cx, &cy, &tail) != 4)
            return "--intrinsics '" + a.intrinsics + "': expected fx,fy,cx,cy (pixels)";
        sg::Projection p;
        std::string err;
        if (!sg::projectionFromIntrinsics(fx, fy, cx, cy, job.width, job.height, frame.camera.projection.zNear, frame.camera.projection.zFar, p,
                                          &err))
            return "--intrinsics: " + err;
        frame.camera = sg::makeFrameCamera(frame.camera.viewInverse, p, aspect, frame.camera.focusDistance);
    }
    return {};
}

}   // namespace cli
