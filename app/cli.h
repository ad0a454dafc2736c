// cli.h - the headless commands of the viewer executable.
#pragma once

#include <CLI/CLI.hpp>

#include <map>
#include <optional>
#include <string>

namespace cli {

struct RenderArgs {
    std::string scene;
    std::string out;
    std::string backend;   // "" = render: rnd::defaultRenderBackend() (gl, or raster where GL is software only)
    std::string size;      // "" = 1280x720 (render: or the --camera-json camera's own size)
    bool overwrite = false;
    int camera = -1;   // index into the scene's cameras, -1 = active
    // Overrides of the scene's own values, one per row of the parameter tables that has a
    // command-line flag (scenegraph/params.h), keyed by the row's key; unset = the scene's own.
    std::map<std::string, std::optional<std::string>> settings;     // render settings: --fog, --fog-start, ...
    std::map<std::string, std::optional<std::string>> projection;   // the camera's projection: --projection, --fovy, ...
    std::string aov;                                                // comma-separated list of extra outputs (render only): depth, normal, id
    std::string at;                                                 // inspect: pixel "X,Y" from the top-left corner
    std::string view = "shaded";                                    // render: the diagnostic view written (rnd::DiagnosticView names)
    // Cameras (app/camera_jobs.h): --intrinsics, --camera-json, --cameras, --turntable, --shard.
    std::string intrinsics, cameraJson, cameras, shard;
    int turntable = 0;
    // Pose: clip `animation` (default 0) of the file at `time` seconds (default: the clip's start).
    std::optional<std::string> time;
    std::optional<int> animation;
    // Overlays (renderers/overlay.h): --overlay LIST, and the node --select names for `selection`.
    std::string overlay, select;
};

enum class Command { Render, Compare, Inspect };
void addRenderOptions(CLI::App& cmd, RenderArgs& args, Command command);
int runRender(const RenderArgs& args);
// `viewer inspect SCENE --at X,Y [--backend NAME|all]`: one JSON object on stdout with the
// pixel's provenance in each backend (app/provenance_json.h) and their differences.
int runInspect(const RenderArgs& args);
int runCompare(const RenderArgs& args);
int runDemoShots(const std::string& outDir, const std::string& size);
int runConvert(const std::string& scene, const std::string& out, bool overwrite);
// The man page's entries for the options that come from the parameter tables (roff), which the
// build puts into docs/viewer.1 at its "@TABLE_OPTIONS@" line (packaging/manpage.cmake).
std::string manPageOptions();

}   // namespace cli
