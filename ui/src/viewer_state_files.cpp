// viewer_state_files.cpp - ViewerState's files and time (see viewer_state.h): the unsaved-changes
// guard, loading off the UI thread with progress and cancel, saving without ever replacing a
// file unasked, animation playback; and the per-user config helpers (config folder, recent
// files, window placement, UI scale).
#include "ui/viewer_state.h"

#include "ui/aov_export.h"

#include "assets/files.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <utility>

namespace fs = std::filesystem;

namespace ui {

// --- files -----------------------------------------------------------------------------------

namespace {
// Where Save As writes for a chosen path: a native .json scene, so another extension gains one
// ("engine.gltf" -> "engine.gltf.json"): an import is never written over.
fs::path nativeTarget(const fs::path& path) {
    fs::path target = path;
    if (target.extension() != ".json") target += ".json";
    return target;
}

bool isNativeScene(const fs::path& path) { return !path.empty() && path.extension() == ".json"; }
}   // namespace

bool ViewerState::requestOpen(const fs::path& path) {
    // A file that cannot be opened is refused before any question about unsaved changes.
    if (std::string err = assets::checkSceneFile(path); !err.empty()) {
        ui.errorPopup = "Could not open " + path.string() + ":\n" + err;
        ui.status = "Open failed; the current scene is unchanged";
        return false;
    }
    if (doc.dirty) {
        ui.pending = PendingAction::Open;
        ui.pendingPath = path;
        ui.confirmOpen = true;
        return false;
    }
    startLoad(path);
    return true;
}

bool ViewerState::requestNew() {
    if (doc.dirty) {
        ui.pending = PendingAction::New;
        ui.confirmOpen = true;
        return false;
    }
    newScene();
    return true;
}

void ViewerState::newScene() {
    sg::Scene s;
    s.name = "untitled";
    sg::Light sun;
    sun.type = sg::LightType::Directional;
    sun.intensity = 1.0f;
    sun.inverseSquare = false;
    sg::NodeId light = s.addNode("light", s.root(), sun);
    sg::LocalTransform t;
    t.setEulerDegrees(sg::vec3(-50, 30, 0));   // from above, over the camera's shoulder
    s.setLocal(light, t);
    s.addDefaultCamera();   // frames the unit box around the origin, where new shapes go
    setScene(std::move(s), {});
    ui.status = "New scene";
}

bool ViewerState::requestQuit() {
    if (doc.dirty) {
        ui.pending = PendingAction::Quit;
        ui.confirmOpen = true;
        return false;
    }
    ui.requests.quit = true;
    return true;
}

void ViewerState::confirm(ConfirmChoice choice) {
    PendingAction action = ui.pending;
    ui.pending = PendingAction::None;
    ui.confirmOpen = false;
    if (choice == ConfirmChoice::Cancel || action == PendingAction::None) {
        ui.status = "Cancelled";
        return;
    }
    if (choice == ConfirmChoice::Save) {
        if (!isNativeScene(doc.path)) {
            // Needs a file name first: Save As asks for one, and the action follows the save.
            ui.afterSave = action;
            ui.afterSavePath = ui.pendingPath;
            ui.requests.saveAsDialog = true;
            ui.status = "Choose where to save; then " + std::string(action == PendingAction::Quit  ? "the viewer quits"
                                                                    : action == PendingAction::New ? "the new scene opens"
                                                                                                   : "the file opens");
            return;
        }
        if (save() != SaveOutcome::Saved) return;   // failed: keep everything, the error is shown
    }
    // The dirty flag stays as it is: only a scene that actually replaces this one (setScene
    // after a successful load, a new scene) clears it. A failed or cancelled load after
    // "Discard" leaves the document exactly as it was, unsaved edits and '*' included.
    switch (action) {
    case PendingAction::Open: startLoad(ui.pendingPath); break;
    case PendingAction::New: newScene(); break;
    case PendingAction::Quit: ui.requests.quit = true; break;
    case PendingAction::None: break;
    }
}

void ViewerState::startLoad(const fs::path& path) {
    if (load.task.valid()) {
        ui.status = "Still loading " + load.path.filename().string();
        return;
    }
    load.path = path;
    ui.status = "Loading " + path.string() + " ...";
    load.control = std::make_shared<LoadControl>();
    load.task = std::async(std::launch::async, [path, control = load.control] {
        try {
            assets::LoadOptions options;
            options.cancel = &control->cancel;
            options.progress = &control->progress;
            return assets::loadScene(path, options);
        } catch (const std::exception& e) {
            assets::LoadResult r;
            r.error = path.string() + ": " + e.what();
            return r;
        }
    });
}

bool ViewerState::pollLoad(bool wait) {
    if (!load.task.valid()) return false;
    if (!wait && load.task.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
    assets::LoadResult r = load.task.get();
    if (loadCancelRequested()) {   // whatever the importer returned: the user said no
        ui.status = "Loading " + load.path.filename().string() + " cancelled; the current scene is unchanged";
        return true;
    }
    doc.loadWarnings = r.warnings;
    if (!r.scene) {
        ui.errorPopup = "Could not open " + load.path.string() + ":\n" + (r.error.empty() ? "unknown error" : r.error);
        ui.status = "Open failed; the current scene is unchanged";
        return true;
    }
    sg::Scene& loaded = *r.scene;   // its size-dependent defaults are set (assets::loadScene)
    setScene(std::move(loaded), load.path);
    anim.clips = std::move(r.animations);
    if (!anim.clips.empty()) anim.time = anim.clips.front().start;
    addRecent(fs::absolute(load.path).lexically_normal().string());
    ui.status = "Opened " + load.path.string() + (r.warnings.empty() ? "" : " (" + std::to_string(r.warnings.size()) + " warnings)") +
                (anim.clips.empty() ? "" : ", " + std::to_string(anim.clips.size()) + " animation(s): Space plays");
    return true;
}

void ViewerState::cancelLoad() {
    if (!load.task.valid() || !load.control || load.control->cancel.load()) return;
    load.control->cancel = true;
    ui.status = "Cancelling loading " + load.path.filename().string() + " ...";
}

SaveOutcome ViewerState::save() {
    if (!isNativeScene(doc.path)) {
        // New, or imported from another format: the first save chooses a native file.
        ui.requests.saveAsDialog = true;
        ui.status = doc.path.empty() ? "Choose where to save the scene"
                                     : "Choose where to save: " + doc.path.filename().string() + " is kept as it is, the scene is saved as .json";
        return SaveOutcome::Asked;
    }
    return writeScene(doc.path, /*replace=*/true);
}

fs::path ViewerState::documentFolder() const {
    std::error_code ec;
    return doc.path.empty() ? fs::current_path(ec) : fs::absolute(doc.path, ec).parent_path();
}

SaveOutcome ViewerState::saveAs(const fs::path& path) {
    if (path.empty()) {
        ui.requests.saveAsDialog = true;
        return SaveOutcome::Asked;
    }
    fs::path target = nativeTarget(path);
    std::error_code ec;
    if (fs::exists(fs::symlink_status(target, ec))) {
        ui.replacePath = target;
        ui.replaceOpen = true;
        ui.status = target.filename().string() + " exists: replace it?";
        return SaveOutcome::Asked;
    }
    return writeScene(target, /*replace=*/false);
}

void ViewerState::confirmReplace(bool replace) {
    fs::path target = ui.replacePath;
    ui.replacePath.clear();
    ui.replaceOpen = false;
    if (target.empty()) return;
    if (!replace) {
        ui.afterSave = PendingAction::None;
        ui.status = "Not saved; " + target.string() + " is unchanged";
        return;
    }
    writeScene(target, /*replace=*/true);
}

void ViewerState::saveAsCancelled() {
    if (ui.afterSave != PendingAction::None) ui.status = "Not saved; cancelled";
    ui.afterSave = PendingAction::None;
}

SaveOutcome ViewerState::writeScene(const fs::path& target, bool replace) {
    storeViewInCamera();
    std::string err;
    try {
        err = assets::saveSceneJson(doc.scene, target, replace);
    } catch (const std::exception& e) { err = target.string() + ": " + e.what(); }
    if (!err.empty()) {
        ui.afterSave = PendingAction::None;
        ui.errorPopup = "Could not save:\n" + err;
        ui.status = "Save failed";
        return SaveOutcome::Failed;
    }
    doc.path = target;
    doc.history.markSaved();
    doc.dirty = false;
    addRecent(fs::absolute(target).lexically_normal().string());
    ui.status = "Saved " + target.string();
    // The unsaved-changes question's Save was waiting on this file name: go on with its action.
    PendingAction after = std::exchange(ui.afterSave, PendingAction::None);
    switch (after) {
    case PendingAction::Open: startLoad(ui.afterSavePath); break;
    case PendingAction::New: newScene(); break;
    case PendingAction::Quit: ui.requests.quit = true; break;
    case PendingAction::None: break;
    }
    return SaveOutcome::Saved;
}

void ViewerState::addRecent(const std::string& path) {
    std::erase(config.recentFiles, path);
    config.recentFiles.insert(config.recentFiles.begin(), path);
    if (config.recentFiles.size() > 10) config.recentFiles.resize(10);
    if (!config.dir.empty()) saveRecentFiles(config.dir, config.recentFiles);
}

// --- animation playback ----------------------------------------------------------------------

namespace {
// Writes the clip's pose at t into the scene: a re-render, not an edit (dirty untouched).
void applyPose(ViewerState& st, const assets::AnimationClip& clip, double t) {
    assets::applyAnimation(st.doc.scene, clip, float(t));
    ++st.doc.version;
}
}   // namespace

const assets::AnimationClip* ViewerState::currentAnimation() const {
    if (anim.clip < 0 || size_t(anim.clip) >= anim.clips.size()) return nullptr;
    return &anim.clips[size_t(anim.clip)];
}

double ViewerState::animationEnd() const {
    const assets::AnimationClip* c = currentAnimation();
    return c ? std::max(double(c->duration), double(c->start)) : 0.0;
}

void ViewerState::selectAnimation(int index) {
    if (index < 0 || size_t(index) >= anim.clips.size()) return;
    anim.clip = index;
    anim.playing = false;
    anim.time = anim.clips[size_t(index)].start;
    applyPose(*this, anim.clips[size_t(index)], anim.time);
    ui.status = "Animation: " + (anim.clips[size_t(index)].name.empty() ? "clip " + std::to_string(index) : anim.clips[size_t(index)].name);
}

void ViewerState::setAnimationPlaying(bool play) {
    const assets::AnimationClip* c = currentAnimation();
    if (!c) {
        anim.playing = false;
        return;
    }
    if (play && !anim.loop && anim.time >= animationEnd()) anim.time = c->start;   // replay
    anim.playing = play;
    applyPose(*this, *c, anim.time);
}

void ViewerState::setAnimationTime(double t) {
    const assets::AnimationClip* c = currentAnimation();
    if (!c || !std::isfinite(t)) return;
    anim.time = std::clamp(t, double(c->start), animationEnd());
    applyPose(*this, *c, anim.time);
}

void ViewerState::advanceAnimation(double dt) {
    const assets::AnimationClip* c = currentAnimation();
    if (!c || !anim.playing) return;
    double start = c->start, end = animationEnd(), length = end - start;
    double t = anim.time + (std::isfinite(dt) ? std::max(dt, 0.0) : 0.0);
    if (t > end) {
        if (anim.loop && length > 0.0) {
            t = start + std::fmod(t - start, length);
        } else {   // not looping (or a single-key clip): stop at the end
            t = end;
            anim.playing = false;
        }
    }
    anim.time = std::clamp(t, start, end);
    applyPose(*this, *c, anim.time);
}

// --- config helpers --------------------------------------------------------------------------

float loadUiScale(const fs::path& dir) {
    std::string text;
    if (dir.empty() || !assets::readFileLimited(dir / "ui-scale.txt", 64, text).empty()) return 1.0f;
    char* end = nullptr;
    const float v = std::strtof(text.c_str(), &end);
    return std::isfinite(v) && v >= 0.5f && v <= 3.0f ? v : 1.0f;
}

std::string saveUiScale(const fs::path& dir, float scale) {
    if (dir.empty()) return {};
    std::error_code ec;
    fs::create_directories(dir, ec);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g\n", double(scale));
    return assets::writeFileAtomic(dir / "ui-scale.txt", buf, /*overwrite=*/true);
}

fs::path defaultConfigDir() {
    if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return fs::path(x) / "sceneviewer";
    if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".config" / "sceneviewer";
    return fs::temp_directory_path() / "sceneviewer";
}

std::vector<std::string> loadRecentFiles(const fs::path& dir) {
    std::vector<std::string> out;
    std::string text;
    if (!assets::readFileLimited(dir / "recent.txt", 1 << 20, text).empty()) return out;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line) && out.size() < 10)
        if (!line.empty()) out.push_back(line);
    return out;
}

std::string saveRecentFiles(const fs::path& dir, const std::vector<std::string>& files) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::string text;
    for (const auto& f : files) text += f + "\n";
    return assets::writeFileAtomic(dir / "recent.txt", text, /*overwrite=*/true);
}

namespace {
WindowRect centred(int width, int height, const WindowRect& area) {
    return {area.x + (area.width - width) / 2, area.y + (area.height - height) / 2, width, height};
}
}   // namespace

WindowRect placeWindow(const WindowRect& workArea, const std::optional<WindowRect>& remembered, int requestedWidth, int requestedHeight) {
    WindowRect r;
    if (requestedWidth > 0 && requestedHeight > 0)
        r = centred(requestedWidth, requestedHeight, workArea);
    else if (remembered && remembered->width > 0 && remembered->height > 0)
        r = *remembered;
    else
        r = centred(workArea.width * 85 / 100, workArea.height * 85 / 100, workArea);
    r.width = std::clamp(r.width, std::min(320, workArea.width), std::max(workArea.width, 1));
    r.height = std::clamp(r.height, std::min(240, workArea.height), std::max(workArea.height, 1));
    r.x = std::clamp(r.x, workArea.x, workArea.x + std::max(workArea.width - r.width, 0));
    r.y = std::clamp(r.y, workArea.y, workArea.y + std::max(workArea.height - r.height, 0));
    return r;
}

std::optional<WindowRect> loadWindowRect(const fs::path& dir, std::string* error) {
    std::string text;
    std::error_code ec;
    if (dir.empty() || !fs::exists(dir / "window.txt", ec)) return std::nullopt;
    std::string readError = assets::readFileLimited(dir / "window.txt", 4096, text);
    std::istringstream in(text);
    WindowRect r;
    if (readError.empty() && (in >> r.x >> r.y >> r.width >> r.height) && r.width >= 1 && r.height >= 1 && r.width <= 100000 && r.height <= 100000)
        return r;
    if (error) *error = (dir / "window.txt").string() + ": " + (readError.empty() ? "expected 'x y width height'" : readError) + "; ignored";
    return std::nullopt;
}

std::string saveWindowRect(const fs::path& dir, const WindowRect& r) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::string text = std::to_string(r.x) + " " + std::to_string(r.y) + " " + std::to_string(r.width) + " " + std::to_string(r.height) + "\n";
    return assets::writeFileAtomic(dir / "window.txt", text, /*overwrite=*/true);
}

fs::path screenshotPath(const fs::path& dir, const std::string& backend, const std::string& stem, const std::vector<rnd::Aov>& exports) {
    std::error_code ec;
    auto taken = [&](const fs::path& png) {
        if (fs::exists(fs::symlink_status(png, ec))) return true;
        for (const fs::path& f : aovFiles(png, exports))
            if (fs::exists(fs::symlink_status(f, ec))) return true;
        return false;
    };
    const std::string name = stem + "-" + backend;
    fs::path p = dir / (name + ".png");
    for (int i = 1; taken(p) && i < 1000000; ++i) p = dir / (name + "-" + std::to_string(i) + ".png");
    return p;
}

std::vector<rnd::Aov> screenshotExports(const ScreenshotDialogState& dialog) {
    std::vector<rnd::Aov> kinds;
    if (dialog.exportDepth) kinds.push_back(rnd::Aov::Depth);
    if (dialog.exportNormal) kinds.push_back(rnd::Aov::Normal);
    if (dialog.exportId) kinds.push_back(rnd::Aov::Id);
    return kinds;
}

std::string screenshotSummary(const std::vector<ScreenshotResult>& results) {
    std::string saved, failed;
    int count = 0;
    fs::path dir;
    for (const ScreenshotResult& r : results) {
        if (!r.error.empty()) {
            std::string_view why = r.error;
            if (why.rfind(r.backend + ": ", 0) == 0) why.remove_prefix(r.backend.size() + 2);   // "gl: ..." from the renderer
            failed += "; " + r.backend + " failed: " + std::string(why);
            continue;
        }
        saved += (count++ ? ", " : "") + r.path.filename().string();
        dir = r.path.parent_path();
    }
    std::string line = count == 0   ? "Screenshot failed"
                       : count == 1 ? "Saved " + saved + " in " + dir.string()
                                    : "Saved " + std::to_string(count) + " screenshots in " + dir.string() + ": " + saved;
    std::string exports;
    for (const ScreenshotResult& r : results)
        if (r.error.empty() && !r.exports.empty()) {
            for (rnd::Aov k : r.exports) exports += (exports.empty() ? "" : ", ") + std::string(rnd::nameOf(k));
            break;   // one batch, one set of choices
        }
    if (!exports.empty()) line += "; with " + exports + " and the camera .json";
    return count == 0 && !failed.empty() ? line + ": " + failed.substr(2) : line + failed;
}

std::pair<int, int> screenshotSize(const ScreenshotDialogState& dialog, const View& view) {
    if (dialog.windowSize) return {std::max(view.viewportWidth, 1), std::max(view.viewportHeight, 1)};
    return {std::clamp(dialog.width, 1, 16384), std::clamp(dialog.height, 1, 16384)};
}

std::string screenshotSizeLabel(const ScreenshotDialogState& dialog, const View& view) {
    ScreenshotDialogState viewport = dialog;
    viewport.windowSize = true;
    auto [w, h] = screenshotSize(viewport, view);
    return "Viewport size (" + std::to_string(w) + "x" + std::to_string(h) + ")###viewportSize";
}

fs::path absoluteFolder(const fs::path& folder) {
    std::error_code ec;
    fs::path dir = fs::absolute(folder.empty() ? fs::path(".") : folder, ec).lexically_normal();
    if (ec) return folder;
    if (!dir.has_filename() && dir != dir.root_path()) dir = dir.parent_path();   // "/a/b/" -> "/a/b"
    return dir;
}

fs::path prepareScreenshotFolder(const fs::path& folder, std::string* error) {
    std::error_code ec;
    fs::path dir = absoluteFolder(folder);
    fs::create_directories(dir, ec);
    if (!ec && !fs::is_directory(dir, ec)) ec = std::make_error_code(std::errc::not_a_directory);
    if (ec) {
        if (error) *error = "cannot use folder '" + folder.string() + "': " + ec.message();
        return {};
    }
    return dir;
}

}   // namespace ui
