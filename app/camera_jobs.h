// camera_jobs.h - the images one `viewer render` makes and the camera of each:
//   --intrinsics fx,fy,cx,cy   the scene camera's pose with the perspective whose K that is
//   --camera-json FILE         exactly the camera of a sidecar (P.json) or camera object
//   --cameras FILE.jsonl       one such camera per line: numbered frames OUT_0000.png, ...
//   --turntable N              N frames around the camera's pivot (vertical axis), numbered
//   --shard I/N                only the jobs whose number k has k mod N == I
// Frames are numbered by their place in the whole list, so shards write disjoint, stable
// names and any scheduler can spread them (Slurm arrays, Kubernetes indexed Jobs, parallel).
#pragma once

#include "assets/aov_io.h"
#include "cli.h"
#include "scenegraph/frame.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace cli {

struct CameraJob {
    int index = -1;                            // frame number (-1: a single image, OUT as given)
    std::filesystem::path out;                 // the PNG to write
    int width = 0, height = 0;                 // image size
    std::optional<assets::AovCamera> camera;   // exact camera (--camera-json, --cameras)
    float turntableDeg = 0.0f;                 // --turntable: rotation about the pivot's vertical axis
};

// The jobs of `a` (after --shard), each with its size: --size, else the camera's own size
// (--camera-json / --cameras lines that name one), else 1280x720. "" or a one-line error.
std::string planCameraJobs(const RenderArgs& a, std::vector<CameraJob>& jobs);

// Puts the job's camera (or --intrinsics, or the turntable step) into `frame`, flattened
// for the job's size. "" or a one-line error.
std::string applyCameraJob(const RenderArgs& a, const CameraJob& job, sg::FrameInput& frame);

}   // namespace cli
