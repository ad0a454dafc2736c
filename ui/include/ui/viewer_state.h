// viewer_state.h - everything the viewer knows, as plain data plus actions (no GL, no ImGui).
//
// Sections: CompareConfig (split / wipe / difference views), Requests (things the window
// must do: screenshots, quit, file dialogs), LoadControl (cancel flag + progress shared with
// the loader thread), the parts of a ViewerState, ViewerState itself (actions: edits, camera,
// unsaved-changes guard, load/save with progress and cancel, animation playback), config
// helpers (per-user config folder, recent files, screenshot names).
//
// ViewerState's parts, by lifetime:
//   doc    Document    the scene being edited, its file, dirty flag, selection (setScene replaces it)
//   view   View        orbit camera, viewport, shown backends, compare config, AA overrides
//   load   AsyncLoad   the load running off the UI thread (becomes the document in pollLoad)
//   anim   Playback    animation clips of the loaded file and their playback (never an edit)
//   ui     UiState     status line, error popup, unsaved-changes question, requests, panel state
//   config UserConfig  per-user config folder and recent files
//   hooks  TestHooks   recorded widget rectangles and the automation's tab request
// The ImGui panels (panels.h) edit a ViewerState; the GLFW window (viewer.cpp) owns one, runs
// the renderers for it and shows their images. Tests drive the state directly, or through
// the panels in headless ImGui frames.
#pragma once

#include "assets/scene_io.h"
#include "renderers/diagnostic.h"
#include "renderers/overlay.h"
#include "scenegraph/camera_model.h"
#include "scenegraph/frame.h"
#include "scenegraph/scene.h"
#include "ui/orbit_camera.h"
#include "ui/panel_state.h"
#include "ui/undo.h"

#include <array>
#include <atomic>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ui {

// How the viewport shows backends.
enum class ViewMode { Single, Split, Difference };

std::string defaultBackend();   // the first registered backend

// The split and difference views. Each keeps its own backends: chosen when the view is first
// shown (ViewerState::showView: the single view's backend, then the other registered backends
// in registry order, so the defaults always compare different backends) and kept after that,
// whatever the other view or the single view shows.
struct CompareConfig {
    ViewMode mode = ViewMode::Single;
    int count = 2;                                // backends in the split view (2 or 3)
    std::array<std::string, 3> split;             // split view, left to right ("" until first shown)
    std::array<std::string, 2> diff;              // difference view: A, B ("" until first shown)
    std::array<float, 2> dividers{0.5f, 0.75f};   // wipe positions, fractions of the width
    int threshold = 8;                            // diffImage highlight threshold (0..255)
};

// The backends a comparison starting from `first` shows: `first`, then the other registered
// backends in registry order (rnd::rendererNames; `first` once only), `n` of them; fewer
// registered backends than n repeat the last.
std::vector<std::string> comparisonBackends(const std::string& first, size_t n);

// Work for the window: set by panels and shortcuts, consumed by viewer.cpp.
struct Requests {
    bool screenshot = false;                         // F12: screenshot(s) of the current view
    int screenshotWidth = 0, screenshotHeight = 0;   // 0 = viewport size
    bool quit = false;                               // confirmed quit
    bool openDialog = false;                         // show the file browser (open)
    bool saveAsDialog = false;                       // show the file browser (save as)
    bool screenshotDialog = false;
    bool exportDialog = false;   // the screenshot dialog with the depth/normal/id export ticked
};

// What the unsaved-changes confirmation is about.
enum class PendingAction { None, Open, New, Quit };
enum class ConfirmChoice { Save, Discard, Cancel };
// What a save did: wrote the file, is waiting for an answer (a file name, or whether to replace
// an existing file), or failed (the error is in UiState::errorPopup).
enum class SaveOutcome { Saved, Asked, Failed };

// Item rectangles recorded by the panels (name -> min/max in screen pixels), so tests can
// click real ImGui widgets by position.
struct ItemRect {
    float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    float cx() const { return 0.5f * (x0 + x1); }
    float cy() const { return 0.5f * (y0 + y1); }
};

// Shared between the UI thread and one asynchronous load (the task holds a shared_ptr, so
// the flags live as long as either side needs them): the UI sets `cancel`, the importer polls
// it and reports `progress` (0..1).
struct LoadControl {
    std::atomic<bool> cancel{false};
    std::atomic<float> progress{0.0f};
};

// The document: the scene being edited, where it lives on disk, whether it has unsaved
// edits and its undo history. setScene (a load, a new scene, the demo) replaces scene and
// path, clears the dirty flag, the selection and the history.
struct Document {
    sg::Scene scene;
    std::filesystem::path path;              // empty for the demo / a new scene
    bool dirty = false;                      // unsaved edits (= !history.atSavedState() after every edit, undo, redo, save)
    UndoStack history;                       // every scene edit, for Edit > Undo / Redo
    uint64_t version = 1;                    // bumped on every scene change, edits and animation poses (re-render)
    uint64_t sceneSerial = 1;                // bumped by setScene only: a different scene (drop the old one's images)
    sg::NodeId selected = sg::kNoNode;       // the active node: what the inspector edits, F2 renames, Ctrl+D duplicates
    std::vector<sg::NodeId> alsoSelected;    // more nodes added with Ctrl+click (outlined, fitted, deleted with it)
    std::vector<std::string> loadWarnings;   // of the load that brought this scene
};

// Figures of the difference view (filled by the window from the two shown images). The
// Compare tab, the viewport overlay and the automation's `print diff` all write them with the
// functions below, so they never disagree.
struct DiffFigures {
    bool valid = false;   // both full-resolution images are there
    double mean = 0, psnr = 0;
    int max = 0;
    double within = 1;   // fraction of pixels within the threshold

    std::string meanText() const;     // "0.42"
    std::string psnrText() const;     // "41.3 dB", "identical" (infinite)
    std::string withinText() const;   // "99.97%": cut, not rounded, so 100% means every pixel
    // "|A - B|  mean 0.42  max 37  PSNR 41.3 dB  within 8: 99.97%"
    std::string summary(const std::string& a, const std::string& b, int threshold) const;
};

// How the scene is looked at: the orbit camera, the viewport, which backends show it and how
// they render. Not saved with the scene (except the camera, stored into the active scene
// camera on save); camera moves bump `version` (re-render, not an edit).
struct View {
    OrbitCamera camera;
    sg::Projection fallbackProjection;   // used when the scene has no camera
    float fallbackFocus = 5.0f;
    uint64_t version = 1;                        // bumped on camera moves (re-render)
    int viewportWidth = 1, viewportHeight = 1;   // pixels, set by the viewport panel
    double lastInteraction = -1e9;               // time (s) of the last camera drag/zoom/fly
    bool flyMode = false;
    float flySpeed = 1.0f;   // world units per second while flying: sceneSizeSpeed() when fly mode starts

    std::string backend = defaultBackend();   // the single view's backend
    // What each shown image is drawn as: the shaded image, or a diagnostic view made from its
    // visibility (renderers/diagnostic.h), the same for every backend.
    rnd::DiagnosticView diagnostic = rnd::DiagnosticView::Shaded;
    // The diagnostic view's legend per shown backend (backend -> line; the window fills it as
    // it draws the images, the automation's `print legend` reads it).
    std::map<std::string, std::string> legends;
    // View > Overlays: drawn on every shown image alike (renderers/overlay.h); the selection
    // and the scene's cameras are filled in when drawn.
    rnd::OverlayOptions overlays;
    CompareConfig compare;
    DiffFigures diff;
    // Per-backend anti-aliasing overrides for this session (backend -> "msaa4", ...); the
    // scene's own setting (saved) applies to backends without one.
    std::map<std::string, std::string> aaOverride;
    // Run the GL backend on a worker thread with its own headless context (never blocks the
    // UI with software GL); off = on the UI thread with the window's context.
    bool glOnWorker = false;
    bool panelsHidden = false;   // View > Viewport only (Ctrl+Space): the panels hidden
    // View > UI scale: a factor on the monitor's content scale (GLFW), which the window follows
    // on its own; kept per user (ui-scale.txt in the config folder).
    float uiScale = 1.0f;
    bool uiScaleChanged = false;   // set by the menu, applied by the window between frames
    // Widths of the Scene and Properties panels as fractions of the window's width (they follow
    // the window; dragging a panel's edge sets its fraction). Clamped to sensible pixel limits.
    float leftFraction = 0.19f, rightFraction = 0.27f;
};

// The axis views of View > Front ... Isometric and the keypad (Blender's 1/3/7, Ctrl for the
// opposite side): the orbit camera turned to look along an axis at the same pivot and distance.
enum class AxisView { Front, Back, Right, Left, Top, Bottom, Isometric };

// A scene load running off the UI thread: startLoad starts it, pollLoad finishes it (the
// document changes only then, and only when it succeeded).
struct AsyncLoad {
    std::future<assets::LoadResult> task;
    std::filesystem::path path;
    std::shared_ptr<LoadControl> control;   // of the current / last load
};

// Animation playback (glTF node TRS clips of the loaded file). Playing changes node locals
// and re-renders (doc.version) but is not an edit: the dirty flag is untouched. Clips come
// with a load and are dropped by setScene (new scene, demo).
struct Playback {
    std::vector<assets::AnimationClip> clips;
    int clip = 0;        // index into clips
    double time = 0.0;   // seconds, within [clip.start, clip end]
    bool playing = false;
    bool loop = true;   // wrap at the end (else stop there)
};

// Transient UI state: messages, the unsaved-changes question, work requested of the window
// and the panels' own state (dialogs, toggles). None of it is saved.
struct UiState {
    std::string status;       // one line shown in the status bar
    std::string errorPopup;   // shown in a modal until dismissed (e.g. load failure)
    // Unsaved-changes guard: the action waiting for the answer.
    PendingAction pending = PendingAction::None;
    std::filesystem::path pendingPath;
    bool confirmOpen = false;   // the modal should be shown
    // Save As never replaces a file without a question: the existing file it would replace,
    // while the question is shown.
    std::filesystem::path replacePath;
    bool replaceOpen = false;
    // The action the unsaved-changes question's Save is waiting on while Save As asks for a
    // file name: it runs once the scene is saved and is dropped when Save As is cancelled.
    PendingAction afterSave = PendingAction::None;
    std::filesystem::path afterSavePath;
    Requests requests;
    PanelState panels;
};

// Per-user files: the config folder and the recent-files list kept there.
struct UserConfig {
    std::filesystem::path dir;              // where recent.txt lives ("" = don't persist)
    std::vector<std::string> recentFiles;   // most recent first
};

// Test and automation hooks: the widget rectangles the panels record (tests click real
// widgets by position) and the tab an automation script wants shown.
struct TestHooks {
    std::map<std::string, ItemRect> itemRects;
    ItemRect viewportRect;      // the 3D viewport's window, in window pixels (automation's `print viewport`)
    std::string requestedTab;   // select this right-panel tab next frame
};

struct ViewerState {
    Document doc;
    View view;
    AsyncLoad load;
    Playback anim;
    UiState ui;
    UserConfig config;
    TestHooks hooks;

    // --- actions -----------------------------------------------------------------------
    // Replaces the scene (after a load): resets selection, dirty flag, history and camera.
    void setScene(sg::Scene s, std::filesystem::path path);
    void markViewChanged();   // camera moved: re-render only

    // Every scene edit below is recorded as one undo step (ui/undo.h). An empty mergeKey makes
    // its own step; the panels pass one per edited target ("local 5", "material 2", ...) so the
    // frames of one drag merge into one step (they close it when no widget is active).
    UndoStep newStep(std::string label) const;   // with the selection before the edit
    // Records an edit already made to doc.scene: pushes it, updates the dirty flag, re-renders.
    void commit(UndoStep step, std::string_view mergeKey = {});
    bool undo();   // Edit > Undo (Ctrl+Z): false when there is nothing to undo
    bool redo();   // Edit > Redo (Ctrl+Shift+Z, Ctrl+Y)
    // An edit made to doc.scene outside the history (tests): dirty, and undo can no longer
    // bring back the saved state.
    void markEdited();

    void selectNode(sg::NodeId id);   // the selection becomes `id` alone (kNoNode: nothing)
    // Ctrl+click: adds `id` (it becomes the active node) or, when selected, takes it out (the
    // last one added becomes active). kNoNode changes nothing.
    void toggleSelected(sg::NodeId id);
    std::vector<sg::NodeId> selection() const;   // the active node first, then the others; valid ones only
    bool isSelected(sg::NodeId id) const;
    bool removeSelection();   // Delete: every selected node (a subtree once) as one undo step
    bool renameNode(sg::NodeId id, const std::string& name);
    void setVisible(sg::NodeId id, bool visible);
    // New nodes go under `parent` (the selection's parent-or-self when kNoNode). Return the id.
    sg::NodeId addGroup(sg::NodeId parent = sg::kNoNode);
    sg::NodeId addShape(sg::ImplicitType type, sg::NodeId parent = sg::kNoNode);
    sg::NodeId addCsg(sg::CsgOp op, sg::NodeId parent = sg::kNoNode);
    sg::NodeId addLight(sg::LightType type, sg::NodeId parent = sg::kNoNode);
    sg::NodeId addCamera();   // at the current view
    bool removeNode(sg::NodeId id);
    sg::NodeId duplicateNode(sg::NodeId id);
    // Re-parents keeping the world transform; on refusal returns false and sets status/error.
    bool reparent(sg::NodeId id, sg::NodeId newParent, std::string* error = nullptr);
    void setLocal(sg::NodeId id, const sg::LocalTransform& t, std::string_view mergeKey = {});
    void setPayload(sg::NodeId id, const sg::Payload& p, std::string_view mergeKey = {});
    void setMaterial(int index, const sg::Material& m, std::string_view mergeKey = {});
    // A new material (a copy of m) assigned to the node's payload, as one step. Its index, or
    // -1 when the node's payload has no material.
    int addMaterialFor(sg::NodeId id, const sg::Material& m);
    // Refused (the reason returned, also in the status line) when s.validate() fails.
    std::string setSettings(const sg::RenderSettings& s, std::string_view mergeKey = {});

    // One parameter by its key in the tables of scenegraph/params.h: a render setting (fog.mode,
    // shading, aa, ambientLight), `material.KEY` of the selection's material (material.kd,
    // material.baseColor [1,0,0]), `light.KEY` of the selected light or `camera.KEY` of the
    // projection (camera.fovy 30). The value as typed (sg::parseParamText), checked against the
    // table's range and RenderSettings::validate, applied as one undoable edit. "" or the
    // reason it was refused.
    std::string setByName(const std::string& key, const std::string& value);

    // The view modes, one way for the View menu, the Compare tab, --view and the automation:
    // Single, Split (splitCount 2 or 3; 0 keeps the current count) or Difference.
    void showView(ViewMode mode, int splitCount = 0);
    // By name: single, split, split3, difference. False for other names.
    bool showView(std::string_view name);
    std::string viewName() const;   // the current one, as showView(name) takes it

    void setBackend(const std::string& name);
    // 0-based backend index (keys 1/2/3); ignores indices beyond the built backends.
    void setBackendIndex(int index);

    // Camera.
    const sg::Projection& projection() const;   // the active scene camera's, or the fallback
    // The active scene camera's projection (an edit), or the viewer's fallback (a view change).
    void setProjection(const sg::Projection& p, std::string_view mergeKey = {});
    float focusDistance() const;
    void fitView(bool selectionOnly);   // F
    // The orbit pivot's distance ahead of a camera at cameraWorld, so orbiting keeps the model in
    // view: `stored` (the camera's focus distance) when that point is within the scene's bounds
    // (grown by 10%), else the bounds' centre projected onto the view ray (when ahead).
    float pivotDistance(const sg::mat4& cameraWorld, float stored) const;
    void resetView();                             // Home: back to the active scene camera
    void viewAlong(AxisView v);                   // keypad 1/3/7 (Ctrl: opposite), View > Front ...
    void togglePerspective();                     // keypad 5: perspective <-> orthographic, same framing at the pivot
    void useSceneCamera(sg::NodeId cameraNode);   // make active and look through it
    void storeViewInCamera();                     // writes the orbit view into the active camera
    // Camera > Paste camera: the view (pose and projection) from a computer-vision camera model
    // (a sidecar's, assets/aov_io.h) made for a width x height image (0: the viewport's). K is
    // scaled to the viewport. "" or the reason it cannot be used.
    std::string setViewFromCameraModel(const sg::CameraModel& m, const std::string& projection, int width, int height);
    sg::mat4 cameraWorld() const { return view.camera.world(); }
    // The effective projection of the view (ortho zoom applied).
    sg::Projection viewProjection() const;
    // Flattened frame for the current view: sg::flatten, then the orbit camera.
    sg::FrameInput buildFrame(float aspect) const;
    // The settings a backend renders with (the scene's, plus its AA override).
    sg::RenderSettings settingsFor(const std::string& backend) const;

    // Files. requestX checks the dirty flag: when there are unsaved edits it opens the
    // confirmation instead and returns false; confirm() then continues or cancels.
    bool requestOpen(const std::filesystem::path& path);
    bool requestNew();
    bool requestQuit();
    // Answers the confirmation. Discard does not clear the dirty flag by itself: a pending
    // Open keeps it until the loaded scene replaces this one, so a failed or cancelled load
    // leaves the document (edits and dirty flag) exactly as it was.
    void confirm(ConfirmChoice choice);
    // Replaces the scene by a new one without asking: a directional light and a camera, so the
    // first shape added is lit and in view.
    void newScene();
    // std::async with a fresh LoadControl (progress + cancel).
    void startLoad(const std::filesystem::path& path);
    bool loadInProgress() const { return load.task.valid(); }
    // Asks the running load to stop; pollLoad then keeps the current scene and reports
    // "Loading X cancelled" (also when the importer finished before it saw the request).
    void cancelLoad();
    bool loadCancelRequested() const { return load.control && load.control->cancel.load(); }
    float loadProgress() const { return load.control ? load.control->progress.load() : 0.0f; }
    // Finishes a completed load (non-blocking); returns true when a load finished.
    bool pollLoad(bool wait = false);
    // Saving. Nothing on disk is replaced without a question, except the document's own native
    // file by Save. Each writes the view into the active camera first.
    //
    // Save (Ctrl+S): writes the document's own .json scene; a document without one (new, or
    // imported from glTF/OBJ/...) opens Save As instead, in the document's folder.
    SaveOutcome save();
    // Save As with `path` chosen (".json" appended when it has another extension): writes it,
    // or, when the file exists, asks first (ui.replaceOpen) and returns Asked.
    SaveOutcome saveAs(const std::filesystem::path& path);
    // Where Save As starts and a typed relative path lands: the document's own folder (the
    // working directory for a document never saved or loaded).
    std::filesystem::path documentFolder() const;
    // Answers the replace question: Replace writes over the file, Cancel leaves it as it is.
    void confirmReplace(bool replace);
    // Save As closed without a file: an action waiting on the save is dropped.
    void saveAsCancelled();
    // Writes the scene to `target` (over an existing file only with `replace`), then runs the
    // action a save was waiting on.
    SaveOutcome writeScene(const std::filesystem::path& target, bool replace);

    void addRecent(const std::string& path);

    // Animation playback. The clip's time range is [start, end] with end = its latest key.
    const assets::AnimationClip* currentAnimation() const;
    double animationEnd() const;           // latest key time of the current clip
    void selectAnimation(int index);       // stops, rewinds to the clip start, applies
    void setAnimationPlaying(bool play);   // play at the end of a non-looping clip rewinds
    void toggleAnimation() { setAnimationPlaying(!anim.playing); }
    void setAnimationTime(double t);   // scrub: clamps to the clip range and applies
    // Called every frame: when playing, advances by dt (wrapping when looping, else stopping at
    // the end) and applies the clip.
    void advanceAnimation(double dt);
};

// Per-user config folder: $XDG_CONFIG_HOME/sceneviewer, else $HOME/.config/sceneviewer.
std::filesystem::path defaultConfigDir();
std::vector<std::string> loadRecentFiles(const std::filesystem::path& configDir);
std::string saveRecentFiles(const std::filesystem::path& configDir, const std::vector<std::string>& files);
// A window's place on the desktop in screen coordinates (GLFW's: pixels on X11 and Windows,
// points on macOS; monitor work areas use the same units, so HiDPI needs no factor here).
struct WindowRect {
    int x = 0, y = 0, width = 0, height = 0;
    bool operator==(const WindowRect&) const = default;
};
// Where the viewer window opens on a monitor whose work area (the desktop less panels and
// docks) is `workArea`: the requested size when given (--window-size), else the remembered
// rectangle, else 85% of the work area; centred unless remembered; always clamped so the whole
// window lies inside the work area (a 1600x900 default never spills off a 1366x768 screen).
WindowRect placeWindow(const WindowRect& workArea, const std::optional<WindowRect>& remembered, int requestedWidth = 0, int requestedHeight = 0);
// The last window rectangle, kept in configDir/window.txt ("x y width height"); nullopt when
// there is none or it does not parse (then the default applies, nothing fails; *error says
// why a file that is there was not used).
std::optional<WindowRect> loadWindowRect(const std::filesystem::path& configDir, std::string* error = nullptr);
std::string saveWindowRect(const std::filesystem::path& configDir, const WindowRect& r);
// View > UI scale, kept in ui-scale.txt (one number, 0.5..3); 1 when absent or unreadable.
float loadUiScale(const std::filesystem::path& configDir);
std::string saveUiScale(const std::filesystem::path& configDir, float scale);

// dir/"<stem>-<backend>.png" or, when taken, the first free "-N" variant: free for the PNG and
// for every export file of `exports` next to it (ui/aov_export.h), so nothing is overwritten.
std::filesystem::path screenshotPath(const std::filesystem::path& dir, const std::string& backend, const std::string& stem = "screenshot",
                                     const std::vector<rnd::Aov>& exports = {});
// The AOVs exported (Depth, Normal, Id: ui/aov_export.h) the screenshot dialog's boxes ask for.
std::vector<rnd::Aov> screenshotExports(const ScreenshotDialogState& dialog);

// One backend's screenshot, finished: the file written, or why not.
struct ScreenshotResult {
    std::string backend;
    std::filesystem::path path;           // absolute
    std::string error;                    // "" when written
    std::vector<rnd::Aov> exports = {};   // the AOVs exported next to it (Depth, Normal, Id)
};
// The status line for a finished batch: every file written, the folder once (absolute), the
// exports next to them ("; with depth, normal, id and the camera .json"), then each failure ("Saved 2 screenshots in /home/me/shots: screenshot-gl.png, screenshot-raster.png",
// "Saved screenshot-raster.png in /home/me/shots; gl failed: OpenGL error 0x502 ...").
std::string screenshotSummary(const std::vector<ScreenshotResult>& results);
// `folder` absolute and normalised, without a trailing separator ("" = the current folder).
std::filesystem::path absoluteFolder(const std::filesystem::path& folder);
// `folder` made absolute (empty = the current folder) and created when missing; empty with
// *error set when it cannot be.
std::filesystem::path prepareScreenshotFolder(const std::filesystem::path& folder, std::string* error);
// The size a screenshot from the dialog is written at: the viewport's while "Viewport size" is
// ticked, else the dialog's width x height; and the checkbox's label, which names it.
std::pair<int, int> screenshotSize(const ScreenshotDialogState& dialog, const View& view);
std::string screenshotSizeLabel(const ScreenshotDialogState& dialog, const View& view);

}   // namespace ui
