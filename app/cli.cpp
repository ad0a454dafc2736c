// cli.cpp - render / compare / demo-shots: everything the UI can make, made headless.
#include "cli.h"
#include "camera_jobs.h"
#include "provenance_json.h"

#include "assets/aov_io.h"
#include "assets/demo.h"
#include "assets/files.h"
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "renderers/diagnostic.h"
#include "renderers/environment.h"
#include "renderers/inspect.h"
#include "renderers/overlay.h"
#include "renderers/renderer.h"
#include "renderers/shadow_map_view.h"
#include "scenegraph/camera_model.h"
#include "scenegraph/instances.h"
#include "scenegraph/params.h"
#include "scenegraph/setting_names.h"
#include "ui/aov_export.h"
#include "ui/viewer.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace fs = std::filesystem;

namespace cli {

namespace {

int fail(const std::string& msg) {
    std::fprintf(stderr, "viewer: error: %s\n", msg.c_str());
    return 1;
}

bool parseSize(const std::string& s, int& w, int& h, std::string& err) {
    int a = 0, b = 0;
    char x = 0, extra = 0;
    if (std::sscanf(s.c_str(), "%d%c%d%c", &a, &x, &b, &extra) != 3 || (x != 'x' && x != 'X')) {
        err = "--size '" + s + "': expected WIDTHxHEIGHT, e.g. 1920x1080";
        return false;
    }
    if (a < 1 || b < 1 || a > assets::kMaxImageDimension || b > assets::kMaxImageDimension) {
        err = "--size '" + s + "': each side must be 1.." + std::to_string(assets::kMaxImageDimension);
        return false;
    }
    w = a;
    h = b;
    return true;
}

std::optional<sg::Scene> loadSceneArg(const std::string& arg, std::string& err, std::vector<assets::AnimationClip>* clips = nullptr) {
    if (arg.empty() || arg == "demo") return assets::makeDemoScene();
    assets::LoadResult r = assets::loadScene(arg);
    for (const auto& w : r.warnings) std::fprintf(stderr, "viewer: warning: %s\n", w.c_str());
    if (!r.scene) err = r.error;
    if (clips) *clips = std::move(r.animations);
    return std::move(r.scene);
}

// --time / --animation: poses the scene at that time of that clip with the function the UI's
// animation bar uses (assets::applyAnimation; skins and morphs follow in flatten). "" or an error.
std::string applyPose(const RenderArgs& a, const std::vector<assets::AnimationClip>& clips, sg::Scene& scene) {
    if (!a.time && !a.animation) return {};
    double seconds = 0.0;
    if (a.time) {
        const char* s = a.time->c_str();
        char* end = nullptr;
        seconds = std::strtod(s, &end);
        if (a.time->empty() || *end != '\0' || !std::isfinite(seconds) || !std::isfinite(float(seconds)))
            return "--time '" + *a.time + "': expected a finite number of seconds";
    }
    if (clips.empty()) return std::string(a.time ? "--time" : "--animation") + ": " + a.scene + " has no animations";
    const int n = a.animation.value_or(0);
    if (n < 0 || size_t(n) >= clips.size())
        return "--animation " + std::to_string(n) + ": " + a.scene + " has " + std::to_string(clips.size()) + " animation(s) (0.." +
               std::to_string(clips.size() - 1) + ")";
    const assets::AnimationClip& clip = clips[size_t(n)];
    float t = a.time ? float(seconds) : clip.start;
    if (t < clip.start || t > clip.duration)
        std::fprintf(stderr, "viewer: note: --time %g is outside clip %d '%s' (%g..%g s): posed at the nearest end\n", seconds, n, clip.name.c_str(),
                     double(clip.start), double(clip.duration));
    assets::applyAnimation(scene, clip, t);
    return {};
}

// The option a table row has on the command line ("--fog-start").
template <class T>
std::string flagOf(const sg::Param<T>& p) {
    return "--" + std::string(p.flag);
}

// Applies the rows of T's table that were given on the command line to `object`, in table
// order. "" or the first error ("--fog: 'fgo' is not one of off, linear, exp, exp2").
template <class T>
std::string applyTableOverrides(const std::map<std::string, std::optional<std::string>>& given, T& object) {
    for (const sg::Param<T>& p : sg::params<T>()) {
        auto it = given.find(std::string(p.key));
        if (it == given.end() || !it->second) continue;
        if (std::string err = sg::setParamFromText(object, p, *it->second); !err.empty())
            return flagOf(p) + err.substr(std::min(err.size(), p.key.size()));
    }
    return {};
}

bool anyGiven(const std::map<std::string, std::optional<std::string>>& given) {
    return std::any_of(given.begin(), given.end(), [](const auto& kv) { return kv.second.has_value(); });
}

// Whether --projection names the isometric preset (the projection row takes it as orthographic).
bool isometricAsked(const RenderArgs& a) {
    auto it = a.projection.find("type");
    if (it == a.projection.end() || !it->second) return false;
    std::string err;
    const std::optional<sg::ParamValue> v = sg::parseParamText(sg::ParamKind::Choice, *it->second, err);
    sg::AxonometricPreset preset;
    return v && sg::parseName(std::get<std::string>(*v), preset);
}

// --projection isometric: camera `id` turned to look along the isometric direction
// (sg::isometricViewDirection) at its pivot - its focus distance ahead - from as far. A camera
// that was perspective (`before`) keeps the size of its view at the pivot, d tan(fovy / 2), as
// the window's perspective / orthographic switch does, unless --ortho-half-height is given.
void turnIsometric(sg::Scene& scene, sg::NodeId id, sg::ProjectionType before, bool halfHeightGiven) {
    const sg::mat4 world = scene.world(id);
    auto& cam = std::get<sg::Camera>(scene.editPayload(id));
    const float d = cam.focusDistance > 0.0f && std::isfinite(cam.focusDistance) ? cam.focusDistance : 1.0f;
    const sg::vec3 eye(world[3]), forward = glm::normalize(-sg::vec3(world[2]));
    const sg::vec3 pivot = eye + d * forward;
    if (before == sg::ProjectionType::Perspective && !halfHeightGiven)
        cam.projection.orthoHalfHeight = std::max(d * std::tan(sg::radians(cam.projection.fovyDeg) * 0.5f), 1e-6f);
    scene.lookAt(id, pivot - d * sg::isometricViewDirection(), pivot);
}

// Applies command-line overrides to the scene's settings and camera. Returns "" or an error.
std::string applyOverrides(const RenderArgs& a, sg::Scene& scene) {
    sg::RenderSettings& s = scene.settings;
    if (std::string err = applyTableOverrides(a.settings, s); !err.empty()) return err;
    std::string err = s.validate();
    if (!err.empty()) return "invalid settings: " + err;
    // An environment file that cannot be read is refused here, not rendered without it.
    if (s.reflection == sg::ReflectionModel::Pbr && s.environment != "none" && s.environment != "default") {
        std::string why;
        rnd::environmentFor(s, &why);
        if (!why.empty()) return "--environment " + why;
    }

    std::vector<sg::NodeId> cams = scene.cameras();
    if (a.camera >= 0) {
        if (size_t(a.camera) >= cams.size())
            return "--camera " + std::to_string(a.camera) + ": the scene has " + std::to_string(cams.size()) + " camera(s)";
        scene.activeCamera = cams[a.camera];
    }
    if (anyGiven(a.projection)) {
        if (!scene.valid(scene.activeCamera) || !std::holds_alternative<sg::Camera>(scene.node(scene.activeCamera).payload)) {
            if (cams.empty())
                scene.addDefaultCamera();
            else
                scene.activeCamera = cams.front();
        }
        auto& cam = std::get<sg::Camera>(scene.editPayload(scene.activeCamera));
        const sg::ProjectionType before = cam.projection.type;
        if (std::string e = applyTableOverrides(a.projection, cam.projection); !e.empty()) return e;
        if (!(cam.projection.zNear < cam.projection.zFar)) return "--near / --far: the camera needs near < far";
        if (isometricAsked(a)) {
            auto given = a.projection.find("orthoHalfHeight");
            turnIsometric(scene, scene.activeCamera, before, given != a.projection.end() && given->second.has_value());
        }
    }
    return {};
}

struct Shot {
    std::string backend;
    rnd::Framebuffer image;
    rnd::RenderStats stats;
    std::unique_ptr<rnd::Renderer> renderer;   // kept for questions about the frame (lightVisibility)
};

Shot renderWith(const std::string& backend, const sg::FrameInput& frame, int w, int h, const rnd::RenderRequest& request = {}) {
    Shot shot;
    shot.backend = backend;
    std::string err;
    auto r = rnd::makeRenderer(backend, &err);
    if (!r) {
        shot.stats.error = err;
        return shot;
    }
    auto t0 = std::chrono::steady_clock::now();
    shot.stats = r->render(frame, w, h, shot.image, nullptr, request);
    shot.renderer = std::move(r);
    if (shot.stats.milliseconds == 0)
        shot.stats.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    // Never a silent substitution: what the backend did not honour as asked, one line each.
    if (shot.stats.ok) {
        for (const std::string& n : shot.stats.config.notes) std::fprintf(stderr, "viewer: note: %s: %s\n", backend.c_str(), n.c_str());
        for (const std::string& u : shot.stats.config.unsupported)
            if (u != "shadows" && u != "reflections")   // on by default, drawn only by backends that say so
                std::fprintf(stderr, "viewer: note: %s does not draw %s\n", backend.c_str(), u.c_str());
    }
    return shot;
}

// --overlay / --select into the options for `scene`: the names, the selected node and the
// scene's cameras as gizmos. "" or a one-line error.
std::string overlayOptions(const RenderArgs& a, const sg::Scene& scene, float aspect, rnd::OverlayOptions& o) {
    std::string err;
    if (a.overlay.empty() && a.select.empty()) return {};
    if (!a.overlay.empty() && !rnd::parseOverlayList(a.overlay, o, err)) return err;
    const sg::NodeId id = a.select.empty() ? sg::kNoNode : scene.findByName(a.select);
    if (!a.select.empty() && id == sg::kNoNode) return "--select '" + a.select + "': no node of that name in " + a.scene;
    if (o.selection && id == sg::kNoNode) return "--overlay selection: name the node with --select NODE";
    rnd::setSceneOverlayInputs(scene, {id}, aspect, o);
    return {};
}

}   // namespace

namespace {

// "Backend: gl, raster or raycast", then one line per backend.
std::string backendHelp() {
    std::string out = "Backend: " + rnd::rendererNameList("or");
    for (const rnd::BackendInfo& b : rnd::backends()) out += "\n  " + std::string(b.name) + "  " + std::string(b.help);
    return out;
}

// Help for a table row: its help line, the range or the choices (one line each).
template <class T>
std::string optionHelp(const sg::Param<T>& p) {
    std::string out(p.help);
    switch (p.kind) {
    case sg::ParamKind::Bool: out += ": on, off"; break;
    case sg::ParamKind::Int:
    case sg::ParamKind::Float: out += " (" + sg::formatParamValue(float(p.min)) + ".." + sg::formatParamValue(float(p.max)) + ")"; break;
    case sg::ParamKind::Color: out += ": r,g,b"; break;
    case sg::ParamKind::Text: break;
    case sg::ParamKind::Choice: {
        size_t width = 0;
        for (const sg::ParamChoice& c : p.choices) width = std::max(width, c.name.size());
        for (const sg::ParamChoice& c : p.choices)
            out += "\n  " + std::string(c.name) + std::string(width + 2 - c.name.size(), ' ') + std::string(c.help);
        break;
    }
    }
    return out;
}

// One option per row of T's table that has a flag; the text lands in given[KEY].
template <class T>
void addTableOptions(CLI::App& cmd, std::map<std::string, std::optional<std::string>>& given) {
    for (const sg::Param<T>& p : sg::params<T>())
        if (!p.flag.empty()) cmd.add_option(flagOf(p), given[std::string(p.key)], optionHelp(p));
}

}   // namespace

namespace {

// Roff text: '-' as "\-" (a minus, as man pages write options), a leading '.' or '\'' escaped.
std::string roff(std::string_view text) {
    std::string out;
    for (char c : text) {
        if (c == '-')
            out += "\\-";
        else if (c == '\\')
            out += "\\e";
        else
            out += c;
    }
    if (!out.empty() && (out[0] == '.' || out[0] == '\'')) out = "\\&" + out;
    return out;
}

template <class T>
void printManOptions(std::string& out) {
    for (const sg::Param<T>& p : sg::params<T>()) {
        if (p.flag.empty()) continue;
        const char* arg = p.kind == sg::ParamKind::Bool    ? nullptr
                          : p.kind == sg::ParamKind::Int   ? " N"
                          : p.kind == sg::ParamKind::Float ? " X"
                          : p.kind == sg::ParamKind::Color ? " R,G,B"
                          : p.kind == sg::ParamKind::Text  ? " TEXT"
                                                           : " NAME";
        out += ".TP\n";
        out += arg ? ".BI " + roff(flagOf(p)) + " \"" + arg + "\"\n" : ".BR " + roff(flagOf(p)) + " \" on|off\"\n";
        out += roff(p.help);
        if (p.kind == sg::ParamKind::Int || p.kind == sg::ParamKind::Float)
            out += ", " + roff(sg::formatParamValue(float(p.min))) + " to " + roff(sg::formatParamValue(float(p.max)));
        if (p.kind == sg::ParamKind::Color) out += " (linear, three numbers)";
        out += p.kind == sg::ParamKind::Choice ? ":\n" : ".\n";
        for (size_t i = 0; i < p.choices.size(); ++i)
            out += ".B " + roff(p.choices[i].name) + "\n(" + roff(p.choices[i].help) + ")" + (i + 1 < p.choices.size() ? ",\n" : ".\n");
    }
}

}   // namespace

std::string manPageOptions() {
    std::string out;
    printManOptions<sg::RenderSettings>(out);
    printManOptions<sg::Projection>(out);
    return out;
}

void addRenderOptions(CLI::App& cmd, RenderArgs& a, Command command) {
    cmd.add_option("scene", a.scene, "Scene file (.json .gltf .glb .obj .off .ply .stl) or 'demo'")->required();
    if (command == Command::Compare) {
        cmd.add_option("--out", a.out, "Output folder (created if missing)")->required();
    } else if (command == Command::Inspect) {
        cmd.add_option("--at", a.at, "Pixel X,Y (from the top-left corner of the image)")->required();
        cmd.add_option("--backend", a.backend, "Backend: " + rnd::rendererNameList("or") + " (or all)")->capture_default_str();
    } else {
        cmd.add_option("--out", a.out, "Output PNG file")->required();
        cmd.add_option("--backend", a.backend,
                       backendHelp() +
                           "\nDefault: gl, or raster (with a note saying so) where OpenGL is software only "
                           "(Mesa llvmpipe, no GPU) or cannot render; --backend gl always renders with GL");
        cmd.add_option("--aov", a.aov,
                       "Also write, next to OUT.png, any of: depth (OUT.depth.pfm, float32 depth along the optical axis, 0 = nothing), "
                       "normal (OUT.normal.png, world normal as 0.5 n + 0.5, black = nothing), id (OUT.id.png, 16-bit instance id, 0 = "
                       "nothing); always with the sidecar OUT.json (K, world_to_camera, projection, near, far, ids)");
        cmd.add_option("--cameras", a.cameras, "Render one frame per line of this JSON-lines file of cameras: OUT_0000.png, OUT_0001.png, ...");
        cmd.add_option("--turntable", a.turntable, "Render N frames around the camera's pivot: OUT_0000.png, ...");
        cmd.add_option("--shard", a.shard, "Render only frames k with k mod N == I (I/N), for a scheduler's array jobs");
        cmd.add_option(
               "--view", a.view,
               "What OUT.png shows: shaded (default), depth, normal, id, uv, triangles (density), overdraw (fragments per pixel; "
               "rasterizers), cost (BVH nodes + triangles tested per primary ray; ray caster) or shadow-map (the map of the light --select "
               "names, else the first, against the ray caster's shadow rays: red acne, blue peter-panning; rasterizers); the diagnostic views are "
               "made from the backend's own visibility and counters, and the legend is printed")
            ->capture_default_str();
    }
    cmd.add_option("--size", a.size,
                   command == Command::Compare  ? "Image size WIDTHxHEIGHT (default 960x540)"
                   : command == Command::Render ? "Image size WIDTHxHEIGHT (default 1280x720, or the size --camera-json / --cameras name)"
                                                : "Image size WIDTHxHEIGHT (default 1280x720)");
    cmd.add_option("--intrinsics", a.intrinsics, "Perspective camera from K for the image size: fx,fy,cx,cy in pixels (top-left origin)");
    cmd.add_option("--camera-json", a.cameraJson, "Render from exactly this camera: a sidecar P.json (or its camera object)");
    cmd.add_flag("--overwrite", a.overwrite, "Replace existing output files");
    cmd.add_option("--camera", a.camera, "Use the scene's N-th camera (0-based; default: the active one)");
    addTableOptions<sg::RenderSettings>(cmd, a.settings);
    addTableOptions<sg::Projection>(cmd, a.projection);
    cmd.add_option("--time", a.time, "Pose the scene at this time (seconds) of its animation (skins, morph weights, transforms)");
    cmd.add_option("--animation", a.animation, "Which animation clip --time poses (0-based; default 0)");
    if (command == Command::Inspect) return;
    cmd.add_option("--overlay", a.overlay,
                   std::string("Draw overlays on the image, the same pixels in every backend: a comma-separated list of ") + rnd::overlayNameList());
    cmd.add_option("--select", a.select, "The node (by name) that --overlay selection outlines, and the light whose map --view shadow-map shows");
}

// --aov's list; checkAovs() has held it to the known kinds before anything renders.
std::vector<rnd::Aov> aovKinds(const RenderArgs& a) {
    std::vector<rnd::Aov> kinds;
    (void)ui::parseAovList(a.aov, kinds);
    return kinds;
}

// --aov: the extra files next to `out` (P.png -> P.depth.pfm, P.normal.png, P.id.png, P.json).
// Checked before rendering: known kinds only, and no existing file replaced without --overwrite.
std::string checkAovs(const RenderArgs& a, const fs::path& out) {
    std::vector<rnd::Aov> kinds;
    if (std::string e = ui::parseAovList(a.aov, kinds); !e.empty()) return "--aov: " + e;
    std::error_code ec;
    for (const fs::path& f : ui::aovFiles(out, kinds))
        if (!a.overwrite && fs::exists(fs::symlink_status(f, ec))) return f.string() + ": file exists (use --overwrite to replace it)";
    return {};
}

// One image of `viewer render`: render, write the PNG (or its diagnostic view) and the AOVs.
std::string renderJob(const RenderArgs& a, const CameraJob& job, const sg::Scene& scene, rnd::DiagnosticView view,
                      const rnd::OverlayOptions& overlays) {
    const int w = job.width, h = job.height;
    sg::FrameInput frame = sg::flatten(scene, float(w) / float(h));
    std::string err = applyCameraJob(a, job, frame);
    if (!err.empty()) return (job.index >= 0 ? job.out.string() + ": " : std::string()) + err;
    rnd::RenderRequest request;
    request.aovs = ui::aovSetOf(aovKinds(a));   // the normal and id images: the visibility
    rnd::requestFor(view, request);
    Shot shot = renderWith(a.backend, frame, w, h, request);
    if (!shot.stats.ok) return shot.stats.error;   // starts with the backend's name
    rnd::DiagnosticImage shown;
    if (view == rnd::DiagnosticView::ShadowMap) {   // the backend's maps against the ray caster's shadow rays
        const int light = rnd::shadowMapViewLight(frame, a.select.empty() ? sg::kNoNode : scene.findByName(a.select));
        const std::unique_ptr<rnd::Renderer> exact = rnd::makeExactShadowBackend();
        shown = rnd::shadowMapView(frame, shot.image, light, *shot.renderer, exact.get());
    } else {
        shown = rnd::diagnosticImage(view, frame, shot.image);
    }
    shown.image.depth = shot.image.depth;   // overlays are hidden behind the rendered surfaces
    rnd::drawOverlays(frame, overlays, shown.image);
    err = assets::writePng(job.out, shown.image.width, shown.image.height, shown.image.color.data(), a.overwrite);
    if (!err.empty()) return err;
    const std::vector<rnd::Aov> kinds = aovKinds(a);
    const bool ids = std::find(kinds.begin(), kinds.end(), rnd::Aov::Id) != kinds.end();   // the id -> node table only when it is written
    if (!(err = ui::writeAovs(job.out, kinds, a.backend, ids ? ui::aovInstances(scene, frame) : std::vector<assets::AovInstance>{}, frame, shot.image,
                              a.overwrite))
             .empty())
        return err;
    std::printf("%s: %dx%d, %s backend, %s, %.1f ms\n", job.out.string().c_str(), w, h, a.backend.c_str(), shot.stats.config.describe().c_str(),
                shot.stats.milliseconds);
    if (!shown.legend.empty() && job.index <= 0) std::printf("%s view: %s\n", a.view.c_str(), shown.legend.c_str());
    return {};
}

int runRender(const RenderArgs& args) {
    RenderArgs a = args;
    std::string note;          // said once the arguments are known good: an error stays one line
    if (a.backend.empty()) {   // the registry decides from what GL runs on here, never from a name
        rnd::BackendChoice choice = rnd::defaultRenderBackend();
        a.backend = choice.name;
        note = std::move(choice.note);
    }
    std::string err;
    std::vector<CameraJob> jobs;
    if (!(err = planCameraJobs(a, jobs)).empty()) return fail(err);
    for (const CameraJob& job : jobs) {
        std::error_code ec;
        if (!a.overwrite && fs::exists(fs::symlink_status(job.out, ec)))
            return fail(job.out.string() + ": file exists (use --overwrite to replace it)");
        if (!(err = checkAovs(a, job.out)).empty()) return fail(err);
    }
    rnd::DiagnosticView view = rnd::DiagnosticView::Shaded;
    if (!rnd::parseDiagnosticView(a.view, view)) {
        std::string names;
        for (std::string_view n : rnd::diagnosticViewNames()) names += (names.empty() ? "" : ", ") + std::string(n);
        return fail("--view '" + a.view + "': expected one of " + names);
    }
    if (auto r = rnd::makeRenderer(a.backend); r && !rnd::diagnosticViewSupported(view, r->capabilities())) {
        // Decided from capabilities, before any rendering; names the backends that can.
        std::string can;
        for (const std::string& b : rnd::rendererNames())
            if (auto other = rnd::makeRenderer(b); other && rnd::diagnosticViewSupported(view, other->capabilities()))
                can += (can.empty() ? "" : ", ") + b;
        return fail("--view " + a.view + ": the " + a.backend + " backend cannot make this view" +
                    (can.empty() ? std::string() : " (backends that can: " + can + ")"));
    }
    std::vector<assets::AnimationClip> clips;
    auto scene = loadSceneArg(a.scene, err, &clips);
    if (!scene) return fail(err);
    err = applyPose(a, clips, *scene);
    if (err.empty()) err = applyOverrides(a, *scene);
    rnd::OverlayOptions overlays;
    if (err.empty()) err = overlayOptions(a, *scene, jobs.empty() ? 1.0f : float(jobs.front().width) / float(jobs.front().height), overlays);
    if (!err.empty()) return fail(err);
    if (!jobs.empty() && jobs.front().index >= 0) {
        std::error_code ec;
        if (jobs.front().out.has_parent_path()) fs::create_directories(jobs.front().out.parent_path(), ec);
    }
    if (!note.empty()) std::fprintf(stderr, "viewer: note: %s\n", note.c_str());
    for (const CameraJob& job : jobs)
        if (!(err = renderJob(a, job, *scene, view, overlays)).empty()) return fail(err);
    return 0;
}

int runCompare(const RenderArgs& a) {
    int w = 0, h = 0;
    std::string err;
    if (!parseSize(a.size.empty() ? "960x540" : a.size, w, h, err)) return fail(err);
    std::vector<assets::AnimationClip> clips;
    auto scene = loadSceneArg(a.scene, err, &clips);
    if (!scene) return fail(err);
    err = applyPose(a, clips, *scene);
    if (err.empty()) err = applyOverrides(a, *scene);
    rnd::OverlayOptions overlays;
    if (err.empty()) err = overlayOptions(a, *scene, float(w) / float(h), overlays);
    if (!err.empty()) return fail(err);
    fs::path dir = a.out;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir, ec)) return fail(dir.string() + ": cannot create output folder");
    sg::FrameInput frame = sg::flatten(*scene, float(w) / float(h));

    std::vector<Shot> shots;
    nlohmann::json table;
    table["scene"] = a.scene;
    table["size"] = {w, h};
    std::ostringstream md;
    md << "| backend | ms | image |\n|---|---|---|\n";
    int failures = 0;
    for (const std::string& b : rnd::rendererNames()) {
        Shot s = renderWith(b, frame, w, h);
        if (!s.stats.ok) {
            std::fprintf(stderr, "viewer: %s: %s\n", b.c_str(), s.stats.error.c_str());
            table["backends"][b] = {{"error", s.stats.error}};
            ++failures;
            continue;
        }
        rnd::drawOverlays(frame, overlays, s.image);
        fs::path p = dir / (b + ".png");
        err = assets::writePng(p, w, h, s.image.color.data(), a.overwrite);
        if (!err.empty()) return fail(err);
        table["backends"][b] = {{"ms", s.stats.milliseconds},
                                {"image", p.filename().string()},
                                {"aa_asked", s.stats.config.aaAsked},
                                {"aa_used", s.stats.config.aaUsed},
                                {"samples_per_pixel", s.stats.config.samplesPerPixel},
                                {"notes", s.stats.config.notes},
                                {"not_drawn", s.stats.config.unsupported}};
        md << "| " << b << " | " << s.stats.milliseconds << " | " << p.filename().string() << " |\n";
        std::printf("%s\n", p.string().c_str());
        shots.push_back(std::move(s));
    }
    md << "\n| pair | mean abs (/255) | max | within 3/255 | PSNR dB | diff image |\n|---|---|---|---|---|---|\n";
    for (size_t i = 0; i < shots.size(); ++i)
        for (size_t j = i + 1; j < shots.size(); ++j) {
            rnd::ImageDiff d = rnd::compareImages(shots[i].image, shots[j].image, 3);
            std::string name = "diff-" + shots[i].backend + "-" + shots[j].backend + ".png";
            rnd::Framebuffer img = rnd::diffImage(shots[i].image, shots[j].image, 3);
            err = assets::writePng(dir / name, w, h, img.color.data(), a.overwrite);
            if (!err.empty()) return fail(err);
            table["pairs"].push_back({{"a", shots[i].backend},
                                      {"b", shots[j].backend},
                                      {"meanAbs", d.meanAbs},
                                      {"maxAbs", d.maxAbs},
                                      {"within3", d.fractionWithin},
                                      {"psnr", std::isinf(d.psnr) ? 999.0 : d.psnr},
                                      {"image", name}});
            md << "| " << shots[i].backend << " vs " << shots[j].backend << " | " << d.meanAbs << " | " << d.maxAbs << " | " << d.fractionWithin * 100
               << "% | " << d.psnr << " | " << name << " |\n";
            std::printf("%s\n", (dir / name).string().c_str());
        }
    err = assets::writeFileAtomic(dir / "compare.json", table.dump(2) + "\n", a.overwrite);
    if (!err.empty()) return fail(err);
    err = assets::writeFileAtomic(dir / "compare.md", md.str(), a.overwrite);
    if (!err.empty()) return fail(err);
    std::printf("%s\n%s\n", (dir / "compare.json").string().c_str(), (dir / "compare.md").string().c_str());
    return failures == 0 ? 0 : 1;
}

int runDemoShots(const std::string& outDir, const std::string& size) {
    int w = 0, h = 0;
    std::string err;
    if (!parseSize(size, w, h, err)) return fail(err);
    fs::path dir = outDir;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir, ec)) return fail(dir.string() + ": cannot create output folder");
    sg::Scene scene = assets::makeDemoScene();
    sg::FrameInput frame = sg::flatten(scene, float(w) / float(h));
    int ok = 0;
    for (const std::string& b : rnd::rendererNames()) {
        Shot s = renderWith(b, frame, w, h);
        if (!s.stats.ok) {
            std::fprintf(stderr, "viewer: %s backend: %s\n", b.c_str(), s.stats.error.c_str());
            continue;
        }
        fs::path p = dir / ("demo-" + b + ".png");
        err = assets::writePng(p, w, h, s.image.color.data(), /*overwrite=*/true);
        if (!err.empty()) {
            std::fprintf(stderr, "viewer: %s\n", err.c_str());
            continue;
        }
        std::printf("demo rendered with %-8s -> %s (%.1f ms)\n", b.c_str(), p.string().c_str(), s.stats.milliseconds);
        ++ok;
    }
    return ok > 0 ? 0 : 1;
}

int runConvert(const std::string& sceneArg, const std::string& out, bool overwrite) {
    std::string err;
    std::vector<assets::AnimationClip> clips;
    auto scene = loadSceneArg(sceneArg, err, &clips);
    if (!scene) return fail(err);
    if (!clips.empty())
        std::fprintf(stderr, "viewer: note: %s: %zu animation clip(s) are not saved (the JSON format keeps the pose as loaded)\n", sceneArg.c_str(),
                     clips.size());
    err = assets::saveSceneJson(*scene, out, overwrite);
    if (!err.empty()) return fail(err);
    std::printf("%s\n", out.c_str());
    return 0;
}

int runInspect(const RenderArgs& a) {
    int w = 0, h = 0, x = -1, y = -1;
    std::string err;
    if (!parseSize(a.size.empty() ? "1280x720" : a.size, w, h, err)) return fail(err);
    char tail = 0;
    if (std::sscanf(a.at.c_str(), "%d,%d%c", &x, &y, &tail) != 2) return fail("--at '" + a.at + "': expected X,Y");
    if (x < 0 || y < 0 || x >= w || y >= h)
        return fail("--at " + a.at + ": outside the " + std::to_string(w) + "x" + std::to_string(h) + " image (0.." + std::to_string(w - 1) +
                    ", 0.." + std::to_string(h - 1) + ")");
    std::vector<std::string> backends = rnd::rendererNames();
    if (a.backend != "all") {
        if (std::find(backends.begin(), backends.end(), a.backend) == backends.end())
            return fail("--backend '" + a.backend + "': expected all or one of " + [&] {
                std::string l;
                for (const std::string& b : backends) l += (l.empty() ? "" : ", ") + b;
                return l;
            }());
        backends = {a.backend};
    }
    std::vector<assets::AnimationClip> clips;
    auto scene = loadSceneArg(a.scene, err, &clips);
    if (!scene) return fail(err);
    err = applyPose(a, clips, *scene);
    if (err.empty()) err = applyOverrides(a, *scene);
    if (!err.empty()) return fail(err);
    const sg::FrameInput frame = sg::flatten(*scene, float(w) / float(h));
    const sg::InstanceTable ids = sg::instanceTable(frame);
    nlohmann::json out = {{"x", x}, {"y", y}, {"width", w}, {"height", h}};
    std::vector<std::pair<std::string, std::array<int, 3>>> rgb;
    int failures = 0;
    for (const std::string& b : backends) {
        rnd::RenderRequest visibility;
        visibility.aovs.add(rnd::Aov::Visibility);
        Shot s = renderWith(b, frame, w, h, visibility);
        if (!s.stats.ok) {
            out["backends"][b] = {{"error", s.stats.error}};
            ++failures;
            continue;
        }
        const rnd::SurfaceAt surface = rnd::surfaceAt(frame, ids, s.image, x, y);
        const std::vector<float> shadows =
            surface.hit ? s.renderer->lightVisibility(frame, surface.position, surface.geometricNormal) : std::vector<float>{};
        out["backends"][b] = provenanceJson(*scene, frame, ids, s.image, x, y, shadows);
        const uint8_t* p = s.image.pixel(x, y);
        rgb.push_back({b, {p[0], p[1], p[2]}});
    }
    for (size_t i = 0; i < rgb.size(); ++i)   // pairwise colour differences (b - a, sRGB bytes)
        for (size_t j = i + 1; j < rgb.size(); ++j)
            out["differences"][rgb[i].first + "-" + rgb[j].first] = {rgb[j].second[0] - rgb[i].second[0], rgb[j].second[1] - rgb[i].second[1],
                                                                     rgb[j].second[2] - rgb[i].second[2]};
    std::printf("%s\n", out.dump(2).c_str());
    return failures == 0 ? 0 : 1;
}

}   // namespace cli
