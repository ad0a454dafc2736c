// aov_io.h - files of the synthetic-data export (`viewer render --aov`): a depth map as a
// grey float32 PFM, the instance ids as a 16-bit grey PNG, and the JSON sidecar with the camera (K, world_to_camera in computer-vision
// axes, projection, near, far). Written atomically; an existing file is replaced only with
// overwrite. Each returns "" or a one-line error naming the file.
#pragma once

#include "scenegraph/camera_model.h"

#include <filesystem>
#include <string>
#include <vector>

namespace assets {

// Grey PFM ("Pf"), little-endian (scale -1), rows bottom to top as the format stores them;
// `topDown` holds width x height values, row 0 the image's top row.
std::string writePfm(const std::filesystem::path& path, int width, int height, const std::vector<float>& topDown, bool overwrite);
// Reads a grey PFM written by writePfm (either endianness) back into top-down rows.
std::string readPfm(const std::filesystem::path& path, int& width, int& height, std::vector<float>& topDown);

// 16-bit grey PNG (the id export: 0 background, k = instance id), rows top-down.
std::string writePngGray16(const std::filesystem::path& path, int width, int height, const std::vector<uint16_t>& topDown, bool overwrite);
// Reads a PNG written by writePngGray16 back (16-bit grey only); "" or the reason.
std::string readPngGray16(const std::filesystem::path& path, int& width, int& height, std::vector<uint16_t>& topDown);

// One instance of the id export: its id (the value in OUT.id.png), node name and path.
struct AovInstance {
    uint32_t id = 0;
    std::string node, path;
};

struct AovSidecar {
    int width = 0, height = 0;
    std::string backend;
    std::string projection;   // "perspective", "orthographic" or "oblique"
    sg::CameraModel camera;
    std::vector<std::string> files;   // the exported images, names relative to the sidecar
    std::vector<AovInstance> ids;     // written as "ids" when the id image was exported
    bool hasIds = false;
};
std::string writeAovSidecar(const std::filesystem::path& path, const AovSidecar& s, bool overwrite);
// The camera object of a sidecar, with "width" and "height" (one line of a camera list; what
// Camera > Copy camera as JSON puts on the clipboard).
std::string aovCameraJson(const sg::CameraModel& camera, const std::string& projection, int width, int height);

// A camera read back from a sidecar (its "camera" object) or from one line of a camera list:
// {"K": [[fx,s,cx],[0,fy,cy],[0,0,1]] | null, "world_to_camera": 4x4 row-major (required),
//  "camera_to_world" (its inverse; computed when absent),
//  "projection": "perspective|orthographic|oblique", "projection_matrix": 4x4 row-major,
//  "near", "far"} and optionally "width", "height" (the image it was made for; a whole sidecar
// has them next to "camera"). Without a projection matrix, K (with near and far) makes one.
struct AovCamera {
    sg::CameraModel model;   // worldToCamera, projection (matrix), K / pinhole, near, far
    std::string projection = "perspective";
    int width = 0, height = 0;   // 0 = not given
};
// `text` is one JSON object; `where` names it in errors ("cams.jsonl:3"). "" or the reason.
std::string parseAovCamera(const std::string& text, const std::string& where, AovCamera& out);
std::string readAovCamera(const std::filesystem::path& path, AovCamera& out);

}   // namespace assets
