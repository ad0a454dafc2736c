// viewer.cpp - the viewer window: GLFW + glad + Dear ImGui (GL3 backend) around a ViewerState.
//
// Sections:
//   1. GL helpers (textures, window read-back)
//   2. Viewer: slots per backend, per-frame render requests, difference image, screenshots
//   3. automation (hidden command-line scripting for tests and docs)
//   4. GLFW callbacks (file drop, close with unsaved changes)
//   5. start-up and shutdown (automation script, window + GL context, ImGui, initial scene)
//   6. main loop (one frame: events, UI, renders, present)
//
// Threads: the UI thread owns GLFW, GL, ImGui and the ViewerState. CPU backends render on
// their RenderSlot worker threads; the GL backend renders on the UI thread with the window's
// context current (into its own FBO). Scene loading runs in std::async (ViewerState), with
// progress and cancel in the status bar. Animations advance once per frame on the UI thread.
#include "ui/viewer.h"

#include "automation.h"
#include "shadow_map_window.h"

#include "assets/demo.h"
#include "assets/image_io.h"
#include "ui/aov_export.h"
#include "ui/panels.h"
#include "ui/render_slot.h"
#include "ui/viewer_state.h"

// glad must come before GLFW (it refuses a gl.h included before it).
#include <glad/gl.h>

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <memory>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;

static_assert(ui::keys::F == GLFW_KEY_F && ui::keys::Num1 == GLFW_KEY_1 && ui::keys::Home == GLFW_KEY_HOME && ui::keys::F12 == GLFW_KEY_F12 &&
                  ui::keys::Delete == GLFW_KEY_DELETE && ui::keys::W == GLFW_KEY_W && ui::keys::F2 == GLFW_KEY_F2 && ui::keys::Q == GLFW_KEY_Q &&
                  ui::keys::Space == GLFW_KEY_SPACE && ui::keys::Y == GLFW_KEY_Y && ui::keys::Z == GLFW_KEY_Z && ui::keys::Kp1 == GLFW_KEY_KP_1 &&
                  ui::keys::Kp3 == GLFW_KEY_KP_3 && ui::keys::Kp5 == GLFW_KEY_KP_5 && ui::keys::Kp7 == GLFW_KEY_KP_7 &&
                  ui::keys::KpDecimal == GLFW_KEY_KP_DECIMAL && ui::keys::Escape == GLFW_KEY_ESCAPE,
              "panel key codes must match GLFW's");

namespace ui {

// --- 1. GL helpers -----------------------------------------------------------------------------

namespace {

// A GL texture showing one Framebuffer (already sRGB-encoded bytes: shown as is).
struct Texture {
    GLuint id = 0;
    int width = 0, height = 0;
    void upload(const rnd::Framebuffer& fb) {
        if (fb.width < 1 || fb.height < 1) return;
        if (!id) glGenTextures(1, &id);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);   // a backend may have left a PBO bound
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, id);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
        if (fb.width != width || fb.height != height) {
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
            glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, fb.width, fb.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, fb.color.data());
            width = fb.width;
            height = fb.height;
        } else {
            glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, fb.width, fb.height, GL_RGBA, GL_UNSIGNED_BYTE, fb.color.data());
        }
    }
    void release() {
        if (id) glDeleteTextures(1, &id);
        id = 0;
        width = height = 0;
    }
    void* imguiId() const { return id ? reinterpret_cast<void*>(uintptr_t(id)) : nullptr; }
};

// Clears the window context's latched GL errors, reporting each on stderr with `where` (what
// ran since the last check). GL keeps an error until someone calls glGetError: without this, a
// later GL render in the same context (a GL screenshot on the UI thread) reports it as its own
// failure. Returns how many there were.
int drainGlErrors(const char* where) {
    int n = 0;
    for (GLenum e; (e = glGetError()) != GL_NO_ERROR && n < 16; ++n) std::fprintf(stderr, "viewer: OpenGL error 0x%x in %s\n", e, where);
    return n;
}

WindowRect workAreaFor(GLFWwindow* win, const std::optional<WindowRect>& r);   // section 5

// Reads the default framebuffer (the whole window) into a PNG.
std::string saveWindowPng(GLFWwindow* win, const fs::path& path) {
    int w = 0, h = 0;
    glfwGetFramebufferSize(win, &w, &h);
    if (w < 1 || h < 1) return "window has no size";
    std::vector<uint8_t> px(size_t(w) * h * 4), flipped(px.size());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
    for (int y = 0; y < h; ++y) std::memcpy(&flipped[size_t(y) * w * 4], &px[size_t(h - 1 - y) * w * 4], size_t(w) * 4);
    for (size_t i = 3; i < flipped.size(); i += 4) flipped[i] = 255;
    std::error_code ec;
    if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
    return assets::writePng(path, w, h, flipped.data(), /*overwrite=*/true);
}

}   // namespace

// --- 2. Viewer ---------------------------------------------------------------------------------

namespace {

struct BackendView {
    std::unique_ptr<RenderSlot> slot;
    Texture texture;
    std::vector<sg::NodeId> outlined;                               // the selection outlined in the texture
    uint64_t outlinedVersion = 0;                                   // doc.version when it was outlined
    rnd::DiagnosticView diagnostic = rnd::DiagnosticView::Shaded;   // what the texture shows
    std::string legend;                                             // of that diagnostic view
    uint64_t overlays = 0;                                          // overlayKey() when uploaded
    bool retryDiagnostic = false;                                   // the view waits for the backend's answers
};

// A screenshot in progress (CPU backends render it on a thread; GL right away).
struct PendingShot {
    std::string backend;
    fs::path path;
    std::vector<rnd::Aov> exports;
    std::future<std::string> result;   // "" or error
};

class Viewer final : public AutomationHost {
public:
    ViewerState st;
    GLFWwindow* window = nullptr;
    std::map<std::string, BackendView> views;
    ShadowMapWindowView shadowMapView;   // the shadow-map view's reference (exact shadows)
    Texture diffTexture;
    uint64_t diffKey = ~uint64_t(0);
    std::vector<PendingShot> shots;
    std::vector<std::string> droppedFiles;
    float newContentScale = 0.0f;   // set by the content-scale callback, applied between frames
    float contentScale = 1.0f;      // the monitor's, as last applied (times View > UI scale)
    std::string iniPath;            // imgui.ini; ImGui keeps the char pointer, so it lives here
    double now = 0;

    BackendView& viewFor(const std::string& name) {
        BackendView& v = views[name];
        if (!v.slot) v.slot = std::make_unique<RenderSlot>(name, slotThreading());
        return v;
    }

    // Backends bound to the caller's GL context render on the UI thread with the window's
    // context, or on a worker with their own when view.glOnWorker (software GL); others always on a
    // worker (Auto).
    RenderSlot::Threading slotThreading() const { return st.view.glOnWorker ? RenderSlot::Threading::Worker : RenderSlot::Threading::Auto; }
    static bool contextBound(const RenderSlot& slot) { return slot.capabilities().affinity == rnd::ContextAffinity::CurrentGLContext; }

    // After setScene (a load, File > New): every slot drops the previous scene's image, stats and
    // renders in flight, so the viewport says "rendering..." until the new scene's first
    // (coarse) image instead of showing the old one. The textures stay (this
    // frame's UI may draw them) but are not shown while their slot has no image.
    void forgetOldScene() {
        if (st.doc.sceneSerial == m_shownScene) return;
        m_shownScene = st.doc.sceneSerial;
        for (auto& [name, v] : views) v.slot->forget();
        diffKey = ~uint64_t(0);
    }

    // Requests renders for the visible backends and uploads finished images.
    void updateRenders() {
        forgetOldScene();
        if (st.view.glOnWorker != m_glOnWorker) {   // where context-bound backends run changed: new slots
            m_glOnWorker = st.view.glOnWorker;
            for (auto& [name, v] : views) {
                if (!v.slot || !contextBound(*v.slot)) continue;
                v.slot.reset();   // joins its worker first
                v.slot = std::make_unique<RenderSlot>(name, slotThreading());
            }
        }
        int w = st.view.viewportWidth, h = st.view.viewportHeight;
        float aspect = float(w) / float(std::max(h, 1));
        // A playing animation changes the scene every frame: one quick image per frame, like a
        // camera drag: the preview, or full resolution where a full frame fits the slot's budget
        // (1/20 s while the camera moves, where the image must follow the hand; 1/10 s for
        // playback alone, where a sharp image at 10 frames per second beats a blurred one); a
        // frame in flight finishes and the newest time follows (RenderSlot::needs). The
        // anti-aliased image follows when it pauses.
        const bool cameraMoves =
            (now - st.view.lastInteraction) < 0.25 || ImGui::GetIO().MouseDown[0] || ImGui::GetIO().MouseDown[1] || ImGui::GetIO().MouseDown[2];
        const bool interacting = cameraMoves || st.anim.playing;
        const double liveBudgetMs = cameraMoves ? 50.0 : 100.0;
        std::vector<std::string> names = visibleBackends(st);
        std::shared_ptr<sg::FrameInput> base;
        uint64_t key = (st.doc.version * 1000003u) ^ (st.view.version * 7919u) ^ (uint64_t(w) << 40) ^ (uint64_t(h) << 20);
        for (const std::string& n : names) {
            BackendView& v = viewFor(n);
            sg::RenderSettings settings = st.settingsFor(n);
            // The counters of the diagnostic view shown, where this backend has them.
            rnd::RenderRequest counters;
            if (rnd::diagnosticViewSupported(st.view.diagnostic, v.slot->capabilities())) rnd::requestFor(st.view.diagnostic, counters);
            uint64_t k = key ^ std::hash<std::string>{}(settings.aaName()) ^ (counters.aovs.has(rnd::Aov::Overdraw) ? 0x5bd1e995ull << 8 : 0) ^
                         (counters.aovs.has(rnd::Aov::TraversalCost) ? 0x27d4eb2full << 16 : 0);
            bool preview = interacting && v.slot->threaded();   // a synchronous render has no preview level
            v.slot->liveBudgetMs = liveBudgetMs;
            if (!v.slot->needs(k, preview)) continue;
            if (!base) base = std::make_shared<sg::FrameInput>(st.buildFrame(aspect));   // flatten once per change
            auto frame = std::make_shared<sg::FrameInput>(*base);
            frame->settings = settings;
            v.slot->request(std::move(frame), w, h, k, preview, counters);
        }
        for (auto& [name, v] : views) refreshTexture(v);
    }

    // Uploads a new image, and again when the selection or the diagnostic view changes: the
    // image is drawn as the chosen diagnostic view and the selection is outlined in it, in
    // every backend's image alike, from its visibility (ui/pixel_probe.h, renderers/diagnostic.h).
    void refreshTexture(BackendView& v) {
        const bool fresh = v.slot->poll();
        const std::vector<sg::NodeId> sel = st.selection();
        const uint64_t overlays = overlayKey();
        if (!fresh && !v.retryDiagnostic && sel == v.outlined && st.view.diagnostic == v.diagnostic && overlays == v.overlays &&
            (sel.empty() || v.outlinedVersion == st.doc.version))
            return;
        v.overlays = overlays;
        v.outlined = sel;
        v.outlinedVersion = st.doc.version;
        v.diagnostic = st.view.diagnostic;
        const rnd::Framebuffer& img = v.slot->image();
        // What the view is made from: the counters for overdraw and cost, else the visibility
        // (the shaded image's selection outline too).
        const rnd::AovSet made = v.diagnostic == rnd::DiagnosticView::Shaded ? rnd::AovSet{rnd::Aov::Visibility} : rnd::aovsFor(v.diagnostic);
        bool visible = v.slot->imageFrame() != nullptr;
        for (rnd::Aov a : made.list()) visible = visible && img.has(a);
        const bool supported = rnd::diagnosticViewSupported(v.diagnostic, v.slot->capabilities());
        if ((sel.empty() && v.diagnostic == rnd::DiagnosticView::Shaded) || !visible || !supported) {
            if (overlays && v.slot->imageFrame()) {
                rnd::Framebuffer shown = img;
                drawViewOverlays(shown, *v.slot->imageFrame());
                v.texture.upload(shown);
            } else {
                v.texture.upload(img);
            }
            const std::string view(rnd::nameOf(v.diagnostic));
            v.legend = v.diagnostic == rnd::DiagnosticView::Shaded ? ""
                       : supported                                 ? view + ": waiting for the full image"
                                   : view + ": the " + v.slot->backend() + " backend cannot make this view (showing the shaded image)";
            return;
        }
        rnd::DiagnosticImage shown = v.diagnostic == rnd::DiagnosticView::ShadowMap
                                         ? shadowMapView.make(*v.slot, shadowMapSelection(sel), v.retryDiagnostic)
                                         : rnd::diagnosticImage(v.diagnostic, *v.slot->imageFrame(), img);
        v.legend = shown.legend;
        shown.image.drawable = img.drawable;   // outlineNodes reads the visibility
        shown.image.primitive = img.primitive;
        outlineNodes(shown.image, *v.slot->imageFrame(), st.doc.scene, sel);
        shown.image.depth = img.depth;
        drawViewOverlays(shown.image, *v.slot->imageFrame());
        v.texture.upload(shown.image);
    }

    // View > Overlays: which are on (0 = none) and what they depend on, to redraw on a change.
    uint64_t overlayKey() const {
        const rnd::OverlayOptions& o = st.view.overlays;
        if (!o.any()) return 0;
        const uint64_t flags = uint64_t(o.grid) | uint64_t(o.axes) << 1 | uint64_t(o.lights) << 2 | uint64_t(o.cameras) << 3 |
                               uint64_t(o.bounds) << 4 | uint64_t(o.selection) << 5 | uint64_t(o.gridOnTop) << 6;
        uint64_t sel = 0;
        for (sg::NodeId n : st.selection()) sel = sel * 1000003u + uint64_t(n) + 1;
        return flags ^ (st.doc.version << 8) ^ (sel << 40);
    }
    void drawViewOverlays(rnd::Framebuffer& img, const sg::FrameInput& frame) const {
        if (!st.view.overlays.any()) return;
        rnd::drawOverlays(frame, overlayOptions(float(img.width) / float(std::max(img.height, 1))), img);
    }
    // View > Overlays with what they need from the document: the selected nodes (each with its
    // descendants) and the scene's cameras.
    rnd::OverlayOptions overlayOptions(float aspect) const {
        rnd::OverlayOptions o = st.view.overlays;
        rnd::setSceneOverlayInputs(st.doc.scene, st.selection(), aspect, o);
        return o;
    }

    void updateDiff() {
        st.view.diff.valid = false;
        if (st.view.compare.mode != ViewMode::Difference) return;
        std::vector<std::string> names = visibleBackends(st);
        const RenderSlot& a = *viewFor(names[0]).slot;
        const RenderSlot& b = *viewFor(names[1]).slot;
        const rnd::Framebuffer& fa = a.image();
        const rnd::Framebuffer& fb = b.image();
        if (fa.width == 0 || fa.width != fb.width || fa.height != fb.height || a.status().level != 1 || b.status().level != 1) {
            // Not shown (viewportInput checks diff.valid) but not deleted either: this frame's
            // ImGui draw data, recorded before this call, may still name the texture, and
            // drawing a deleted texture is GL_INVALID_OPERATION.
            diffKey = ~uint64_t(0);
            return;
        }
        // Recompute when either image, the pair or the threshold changed.
        uint64_t k = (a.imageSerial() * 1000003u) ^ (b.imageSerial() * 7919u) ^ (uint64_t(st.view.compare.threshold) << 56) ^
                     std::hash<std::string>{}(names[0] + "|" + names[1]);
        if (k != diffKey) {
            diffKey = k;
            diffTexture.upload(rnd::diffImage(fa, fb, st.view.compare.threshold));
            rnd::ImageDiff d = rnd::compareImages(fa, fb, st.view.compare.threshold);
            m_lastDiff = d;
        }
        st.view.diff.valid = true;
        st.view.diff.mean = m_lastDiff.meanAbs;
        st.view.diff.max = m_lastDiff.maxAbs;
        st.view.diff.psnr = m_lastDiff.psnr;
        st.view.diff.within = m_lastDiff.fractionWithin;
    }

    ViewportInput viewportInput() {
        ViewportInput in;
        for (const std::string& n : visibleBackends(st)) {
            BackendView& v = viewFor(n);
            SlotView s;
            s.texture = v.slot->hasImage() ? v.texture.imguiId() : nullptr;
            s.width = v.texture.width;
            s.height = v.texture.height;
            s.status = v.slot->status();
            s.probe = ProbeImage{n, &v.slot->image(), v.slot->imageFrame(), v.slot.get()};
            s.legend = v.legend;
            st.view.legends[n] = v.legend;
            in.slots.push_back(s);
        }
        if (st.view.compare.mode == ViewMode::Difference && st.view.diff.valid) {
            in.diff.texture = diffTexture.imguiId();
            in.diff.width = diffTexture.width;
            in.diff.height = diffTexture.height;
        }
        return in;
    }

    // Starts offscreen screenshots of every visible backend at w x h (0 = viewport size) into
    // the dialog's folder (made absolute, created when missing; a folder that cannot be made is a
    // one-line error in the status bar). With the dialog's "as shown" the image is what the
    // viewport shows (diagnostic view, View > Overlays); its export boxes add the depth / normal /
    // id files and the camera sidecar next to each PNG (ui/aov_export.h).
    void startScreenshots(int w, int h, const ScreenshotDialogState& dialog) {
        if (w < 1 || h < 1) {
            w = st.view.viewportWidth;
            h = st.view.viewportHeight;
        }
        std::string folderError;
        fs::path dir = prepareScreenshotFolder(dialog.dir, &folderError);
        if (dir.empty()) {
            st.ui.status = "Screenshot failed: " + folderError;
            return;
        }
        float aspect = float(w) / float(h);
        auto base = std::make_shared<sg::FrameInput>(st.buildFrame(aspect));
        const std::vector<rnd::Aov> exports = screenshotExports(dialog);
        const bool ids = std::find(exports.begin(), exports.end(), rnd::Aov::Id) != exports.end();
        // Everything read from the document is taken here, on the UI thread; the jobs see copies.
        auto instances =
            std::make_shared<const std::vector<assets::AovInstance>>(ids ? aovInstances(st.doc.scene, *base) : std::vector<assets::AovInstance>{});
        const rnd::DiagnosticView view = dialog.asShown ? st.view.diagnostic : rnd::DiagnosticView::Shaded;
        rnd::OverlayOptions overlays;
        if (dialog.asShown && st.view.overlays.any()) overlays = overlayOptions(aspect);
        const bool visibility = aovsNeedVisibility(exports);
        std::vector<std::string> names = visibleBackends(st);
        std::sort(names.begin(), names.end());
        names.erase(std::unique(names.begin(), names.end()), names.end());
        for (const std::string& n : names) {
            auto frame = std::make_shared<sg::FrameInput>(*base);
            frame->settings = st.settingsFor(n);
            fs::path path = screenshotPath(dir, n, "screenshot", exports);
            std::string err;
            std::shared_ptr<rnd::Renderer> r = rnd::makeRenderer(n, &err);
            PendingShot p{n, path, exports, {}};
            if (!r) {
                std::promise<std::string> pr;
                pr.set_value(err);
                p.result = pr.get_future();
                shots.push_back(std::move(p));
                continue;
            }
            // A view this backend cannot make: its shaded image, as the viewport shows it.
            const rnd::DiagnosticView shotView = rnd::diagnosticViewSupported(view, r->capabilities()) ? view : rnd::DiagnosticView::Shaded;
            const int shadowLight =
                shotView == rnd::DiagnosticView::ShadowMap ? rnd::shadowMapViewLight(*frame, shadowMapSelection(st.selection())) : -1;
            auto job = [n, r, frame, w, h, path, exports, instances, shotView, overlays, visibility, shadowLight]() -> std::string {
                rnd::Framebuffer fb;
                rnd::RenderRequest request;
                request.aovs.set(rnd::Aov::Visibility, visibility && r->capabilities().aovs.has(rnd::Aov::Visibility));
                rnd::requestFor(shotView, request);
                rnd::RenderStats s = r->render(*frame, w, h, fb, nullptr, request);
                if (!s.ok) return s.error.empty() ? n + ": render failed" : s.error;
                rnd::DiagnosticImage shown = shotView == rnd::DiagnosticView::ShadowMap   // the maps against the ray caster's shadow rays
                                                 ? rnd::shadowMapView(*frame, fb, shadowLight, *r, rnd::makeExactShadowBackend().get())
                                                 : rnd::diagnosticImage(shotView, *frame, fb);
                shown.image.depth = fb.depth;   // overlays are hidden behind the rendered surfaces
                rnd::drawOverlays(*frame, overlays, shown.image);
                std::string e = assets::writePng(path, shown.image.width, shown.image.height, shown.image.color.data(), /*overwrite=*/false);
                if (e.empty()) e = writeAovs(path, exports, n, *instances, *frame, fb, /*overwrite=*/false);
                return e;
            };
            if (r->capabilities().affinity == rnd::ContextAffinity::CurrentGLContext) {   // the window's context: here, now
                drainGlErrors("the window's context before a GL screenshot");             // not this render's errors
                std::promise<std::string> pr;
                pr.set_value(job());
                p.result = pr.get_future();
            } else {
                p.result = std::async(std::launch::async, job);
            }
            shots.push_back(std::move(p));
        }
        st.ui.status = "Screenshot: rendering " + std::to_string(names.size()) + " image(s) at " + std::to_string(w) + "x" + std::to_string(h) +
                       " into " + dir.string() + "...";
    }

    void pollScreenshots(bool wait) {
        for (size_t i = 0; i < shots.size();) {
            if (!wait && shots[i].result.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
                ++i;
                continue;
            }
            std::string err = shots[i].result.get();
            if (!err.empty()) std::fprintf(stderr, "viewer: screenshot: %s: %s\n", shots[i].backend.c_str(), err.c_str());
            shotResults.push_back({shots[i].backend, shots[i].path, err, shots[i].exports});
            shots.erase(shots.begin() + i);
        }
        if (shots.empty() && !shotResults.empty()) {   // the whole batch is done: one line naming every file
            st.ui.status = screenshotSummary(shotResults);
            shotResults.clear();
        }
    }

    bool allIdle() {
        if (st.loadInProgress() || !shots.empty()) return false;
        for (const std::string& n : visibleBackends(st)) {
            BackendView& v = viewFor(n);
            SlotStatus s = v.slot->status();
            if (s.rendering) return false;
            if (s.error.empty() && (v.slot->image().width == 0 || s.level != 1)) return false;
        }
        return true;
    }

    void releaseGL() {
        for (auto& [n, v] : views) {
            v.slot.reset();   // joins workers; the GL renderer frees its objects with the context current
            v.texture.release();
        }
        diffTexture.release();
    }

    std::vector<ScreenshotResult> shotResults;   // of the batch in flight, finished so far

    // --- AutomationHost ---
    ViewerState& state() override { return st; }
    bool idle() override { return allIdle(); }
    void pollScreenshots() override { pollScreenshots(false); }
    void startScreenshots(const fs::path& dir) override {   // F12 into `dir`, with the dialog's other choices
        ScreenshotDialogState d = st.ui.panels.shotDialog;
        d.dir = dir;
        startScreenshots(0, 0, d);
    }
    void printStats() override {
        for (const std::string& n : visibleBackends(st)) {
            const RenderSlot& slot = *viewFor(n).slot;
            SlotStatus s = slot.status();
            if (!slot.hasImage() && s.error.empty()) {
                std::printf("viewer: stats %s %dx%d: no image yet\n", n.c_str(), st.view.viewportWidth, st.view.viewportHeight);
                continue;
            }
            std::printf("viewer: stats %s %dx%d level %d: %.1f ms, %llu triangles, %llu rays%s%s%s%s\n", n.c_str(), st.view.viewportWidth,
                        st.view.viewportHeight, s.level, s.stats.milliseconds, (unsigned long long)s.stats.triangles,
                        (unsigned long long)s.stats.rays, s.refining ? ", refining" : "", s.rendering ? ", rendering" : "",
                        s.error.empty() ? "" : ", error: ", s.error.c_str());
        }
        std::fflush(stdout);
    }
    // As GLFW would deliver it: the ImGui GLFW backend's callback sets KeysDown and the
    // modifier flags the panels read.
    void keyEvent(int key, bool press, int mods) override {
        ImGui_ImplGlfw_KeyCallback(window, key, glfwGetKeyScancode(key), press ? GLFW_PRESS : GLFW_RELEASE, mods);
    }
    WindowRect windowRect() override {
        WindowRect r;
        glfwGetWindowPos(window, &r.x, &r.y);
        glfwGetWindowSize(window, &r.width, &r.height);
        return r;
    }
    WindowRect workArea() override { return workAreaFor(window, windowRect()); }
    void resizeWindow(int width, int height) override { glfwSetWindowSize(window, width, height); }

private:
    rnd::ImageDiff m_lastDiff;
    bool m_glOnWorker = false;
    uint64_t m_shownScene = 0;   // doc.sceneSerial the slots' images belong to
};

}   // namespace

// --- 3. automation -----------------------------------------------------------------------------
//
// The script commands are in automation.cpp; Viewer is their AutomationHost (section 2).

// --- 4. GLFW callbacks -------------------------------------------------------------------------

namespace {

// DejaVu Sans (Debian fonts-dejavu-core) when present; ImGui's built-in font otherwise.
constexpr const char* kFontPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

void onDrop(GLFWwindow* w, int count, const char** paths) {
    auto* v = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
    for (int i = 0; i < count; ++i) v->droppedFiles.emplace_back(paths[i]);
}

void onClose(GLFWwindow* w) {
    auto* v = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
    if (!v->st.requestQuit()) glfwSetWindowShouldClose(w, GLFW_FALSE);   // the modal asks first
}

// Moved to a monitor of another DPI: the main loop rebuilds fonts and style between frames.
void onContentScale(GLFWwindow* w, float xs, float ys) { static_cast<Viewer*>(glfwGetWindowUserPointer(w))->newContentScale = std::max(xs, ys); }

void onGlfwError(int code, const char* msg) { std::fprintf(stderr, "viewer: GLFW error %d: %s\n", code, msg); }

}   // namespace

// --- 5. start-up and shutdown -----------------------------------------------------------------

namespace {

// The automation script: the --automate file, or the shorthand --frames N [--screenshot P] =
// "frames N / wait / window-shot P / frames 1 / quit". False (message printed) when the file
// cannot be read.
bool loadAutomation(const ViewerOptions& opt, Automation& automation) {
    if (!opt.script.empty()) {
        std::ifstream in(opt.script);
        if (!in) {
            std::fprintf(stderr, "viewer: error: cannot read automation script '%s'\n", opt.script.c_str());
            return false;
        }
        for (std::string line; std::getline(in, line);) automation.lines.push_back(line);
    } else if (opt.frames > 0 || !opt.screenshot.empty()) {
        automation.lines = {"frames " + std::to_string(std::max(opt.frames, 1)), "wait"};
        if (!opt.screenshot.empty()) automation.lines.push_back("window-shot " + opt.screenshot);
        automation.lines.push_back("frames 1");
        automation.lines.push_back("quit");
    }
    return true;
}

// GLFW, a window with a current GL 3.3 core context, the GL functions. Null (message printed,
// GLFW terminated) on failure. Scripted runs do not wait for vsync.
GLFWwindow* createWindow(const ViewerOptions& opt, bool automated) {
    glfwSetErrorCallback(onGlfwError);
    if (!glfwInit()) {
        std::fprintf(stderr, "viewer: error: cannot open a window (no X display? try xvfb-run, or use 'viewer render' headless)\n");
        return nullptr;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);   // shown by placeWindowOnScreen, at its place and size
    GLFWwindow* win = glfwCreateWindow(std::max(opt.width, 320), std::max(opt.height, 240), "Scene viewer", nullptr, nullptr);
    if (!win) {
        std::fprintf(stderr, "viewer: error: cannot create a GL 3.3 core window\n");
        glfwTerminate();
        return nullptr;
    }
    glfwMakeContextCurrent(win);
    glfwSwapInterval(automated ? 0 : 1);
    if (!gladLoadGL(reinterpret_cast<GLADloadfunc>(glfwGetProcAddress))) {
        std::fprintf(stderr, "viewer: error: cannot load OpenGL functions\n");
        glfwDestroyWindow(win);
        glfwTerminate();
        return nullptr;
    }
    return win;
}

// The work area of the monitor holding the centre of `r` (the primary monitor when none does,
// or without `r`), less the window's frame (title bar, borders) where the window manager says.
WindowRect workAreaFor(GLFWwindow* win, const std::optional<WindowRect>& r) {
    int count = 0;
    GLFWmonitor** monitors = glfwGetMonitors(&count);
    GLFWmonitor* chosen = glfwGetPrimaryMonitor();
    WindowRect area;
    for (int i = 0; r && i < count; ++i) {
        WindowRect a;
        glfwGetMonitorWorkarea(monitors[i], &a.x, &a.y, &a.width, &a.height);
        int cx = r->x + r->width / 2, cy = r->y + r->height / 2;
        if (cx >= a.x && cx < a.x + a.width && cy >= a.y && cy < a.y + a.height) chosen = monitors[i];
    }
    if (chosen) glfwGetMonitorWorkarea(chosen, &area.x, &area.y, &area.width, &area.height);
    if (area.width < 1 || area.height < 1) area = {0, 0, 1600, 900};   // no monitor information: the old fixed size
    int left = 0, top = 0, right = 0, bottom = 0;
    glfwGetWindowFrameSize(win, &left, &top, &right, &bottom);
    return {area.x + left, area.y + top, std::max(area.width - left - right, 1), std::max(area.height - top - bottom, 1)};
}

// Sizes and places the (hidden) window from the monitor's work area, the rectangle remembered
// from the last run or --window-size, always inside the work area, then shows it. Screen coordinates throughout, so the content scale
// (HiDPI) stays the fonts' business.
void placeWindowOnScreen(GLFWwindow* win, const ViewerOptions& opt, const fs::path& configDir) {
    std::string error;
    std::optional<WindowRect> remembered = loadWindowRect(configDir, &error);
    if (!error.empty()) std::fprintf(stderr, "viewer: warning: %s\n", error.c_str());
    WindowRect r = placeWindow(workAreaFor(win, remembered), remembered, opt.width, opt.height);
    glfwSetWindowSize(win, r.width, r.height);
    glfwSetWindowPos(win, r.x, r.y);
    glfwShowWindow(win);
}

// Remembers the window's rectangle for the next run. Not when maximized or minimized (the next
// run would open that way without being so), nor after a run sized by --window-size (tests,
// documentation shots: a one-off that must not change the user's next window).
void rememberWindow(GLFWwindow* win, const fs::path& configDir, const ViewerOptions& opt) {
    if (configDir.empty() || (opt.width > 0 && opt.height > 0)) return;
    if (glfwGetWindowAttrib(win, GLFW_MAXIMIZED) || glfwGetWindowAttrib(win, GLFW_ICONIFIED)) return;
    WindowRect r;
    glfwGetWindowPos(win, &r.x, &r.y);
    glfwGetWindowSize(win, &r.width, &r.height);
    if (std::string err = saveWindowRect(configDir, r); !err.empty())
        std::fprintf(stderr, "viewer: warning: cannot remember the window size: %s\n", err.c_str());
}

// Connects the window to the viewer (callbacks), picks where the GL backend renders, reads the
// per-user config and sets up ImGui (context, layout file, style at the window's scale).
void setUpViewer(Viewer& v, GLFWwindow* win) {
    ViewerState& st = v.st;
    v.window = win;
    glfwSetWindowUserPointer(win, &v);
    glfwSetDropCallback(win, onDrop);
    glfwSetWindowCloseCallback(win, onClose);
    glfwSetWindowContentScaleCallback(win, onContentScale);   // moved to a monitor of another DPI

    // On a software GL (Mesa llvmpipe/softpipe) a GL frame of a big scene takes hundreds of
    // milliseconds: render it on a worker thread with its own context so the UI never freezes.
    // On a hardware GL the window's context on the UI thread is the fast path.
    if (const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER))) st.view.glOnWorker = rnd::isSoftwareGLRenderer(renderer);

    // Config: imgui.ini (layout) and recent files in the per-user config folder.
    st.config.dir = defaultConfigDir();
    std::error_code ec;
    fs::create_directories(st.config.dir, ec);
    st.config.recentFiles = loadRecentFiles(st.config.dir);
    v.iniPath = (st.config.dir / "imgui.ini").string();

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = ec ? nullptr : v.iniPath.c_str();
    float xs = 1.0f, ys = 1.0f;
    glfwGetWindowContentScale(win, &xs, &ys);
    v.contentScale = std::max(xs, ys);
    st.view.uiScale = loadUiScale(st.config.dir);
    setupStyle(v.contentScale * st.view.uiScale, kFontPath);
    ImGui_ImplGlfw_InitForOpenGL(win, true);
    ImGui_ImplOpenGL3_Init("#version 330");
}

// The demo, or the file (loaded off the UI thread); then the initial backend and view.
void openInitialScene(ViewerState& st, const ViewerOptions& opt) {
    // A path that cannot be opened (a folder, a missing file, an unsupported type) opens the demo
    // instead and says why, on the status line and on standard error.
    const std::string refused = opt.scene.empty() || opt.scene == "demo" ? std::string() : assets::checkSceneFile(opt.scene);
    if (opt.scene.empty() || opt.scene == "demo" || !refused.empty()) {
        st.setScene(assets::makeDemoScene(), {});
        st.ui.status = "Demo scene. Drop a file on the window or use File > Open.";
        if (!refused.empty()) {
            std::fprintf(stderr, "viewer: error: %s\n", refused.c_str());
            st.ui.status = "Could not open " + refused + "; showing the demo scene";
        }
    } else {
        st.doc.scene = sg::Scene{};
        st.startLoad(opt.scene);
    }
    if (!opt.backend.empty()) st.setBackend(opt.backend);
    if (!opt.view.empty() && !st.showView(opt.view))
        std::fprintf(stderr, "viewer: warning: --view '%s': expected single, split, split3 or difference\n", opt.view.c_str());
}

// Finishes the screenshots in flight, stops a running load, frees the GL objects while the
// context is current, then ImGui, the window and GLFW.
void shutDown(Viewer& v, GLFWwindow* win, const ViewerOptions& opt) {
    v.pollScreenshots(true);
    v.st.cancelLoad();   // a load still running stops soon instead of finishing for nobody

    rememberWindow(win, v.st.config.dir, opt);
    v.releaseGL();
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(win);
    glfwTerminate();
}

}   // namespace

// --- 6. main loop ------------------------------------------------------------------------------

namespace {

// One frame: wait for events, advance the clock, take in what arrived (files, a finished load,
// animation time, screenshots), run the script, draw the UI, start renders for what it
// decided, present.
class MainLoop {
public:
    MainLoop(Viewer& v, GLFWwindow* win, Automation& automation, const ViewerOptions& opt)
        : m_v(v), m_st(v.st), m_win(win), m_automation(automation), m_opt(opt), m_automated(!automation.lines.empty()) {}

    // Runs frames until the viewer quits (window, Ctrl+Q, end of the script); the exit code.
    int run() {
        m_start = std::chrono::steady_clock::now();
        bool running = true;
        while (running) {
            waitForEvents();
            float dt = tick();
            if (m_automated && m_v.now > m_opt.timeoutSeconds) {
                std::fprintf(stderr, "viewer: automation: timed out after %.0f s\n", m_opt.timeoutSeconds);
                m_exitCode = 3;
                break;
            }
            handleEvents(dt);
            if (m_automated && !m_automation.step(m_v)) {
                running = false;
                if (m_automation.failed) m_exitCode = 2;
            }
            drawUiFrame(dt);
            updateRenders();   // after the UI decided viewport size, camera and settings for this frame
            present();
            if (m_st.ui.requests.quit) running = false;
            updateTitle();
        }
        return m_exitCode;
    }

private:
    // Polls while work is in flight or the user just moved the camera; otherwise sleeps until
    // an event arrives (at most 0.1 s).
    void waitForEvents() {
        bool busy = !m_v.shots.empty() || m_st.loadInProgress() || m_st.anim.playing || m_automated;
        for (auto& [n, bv] : m_v.views) busy |= bv.slot->status().rendering;
        if (busy || (m_v.now - m_st.view.lastInteraction) < 0.5)
            glfwPollEvents();
        else
            glfwWaitEventsTimeout(0.1);
    }

    // Sets v.now (seconds since the start); returns the frame time, clamped to [0.1 ms, 0.25 s].
    float tick() {
        m_v.now = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
        float dt = float(std::clamp(m_v.now - m_last, 1e-4, 0.25));
        m_last = m_v.now;
        return dt;
    }

    static bool isRadianceHdr(const std::string& path) {
        std::string ext = std::filesystem::path(path).extension().string();
        for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
        return ext == ".hdr";
    }

    // A dropped .hdr lights the scene: the environment of the pbr model (switched to it), one undo
    // step; a file that cannot be read leaves everything as it was and says why (setSettings).
    void useEnvironment(const std::string& path) {
        sg::RenderSettings s = m_st.doc.scene.settings;
        s.environment = path;
        s.reflection = sg::ReflectionModel::Pbr;
        if (m_st.setSettings(s, "environment").empty()) m_st.ui.status = "Environment: " + path + " (pbr reflection model)";
    }

    // Events that arrived through callbacks, a finished load, animation time, screenshots.
    void handleEvents(float dt) {
        if (!m_v.droppedFiles.empty()) {
            const std::string path = m_v.droppedFiles.front();
            m_v.droppedFiles.clear();
            if (isRadianceHdr(path))
                useEnvironment(path);
            else
                m_st.requestOpen(path);
        }
        if (m_st.pollLoad()) m_v.forgetOldScene();   // before the script or the UI look at the images
        m_st.advanceAnimation(dt);
        m_v.pollScreenshots(false);
    }

    void drawUiFrame(float dt) {
        if (m_v.newContentScale > 0.0f || m_st.view.uiScaleChanged) {   // HiDPI or UI scale change: fonts and style anew
            if (m_v.newContentScale > 0.0f) m_v.contentScale = m_v.newContentScale;
            m_st.view.uiScaleChanged = false;
            setupStyle(m_v.contentScale * m_st.view.uiScale, kFontPath);
            ImGui_ImplOpenGL3_DestroyFontsTexture();
            ImGui_ImplOpenGL3_CreateFontsTexture();
            m_v.newContentScale = 0.0f;
        }
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        if (m_automated) m_automation.overrideMouse();   // a scripted click, as the mouse of this frame
        ImGui::NewFrame();
        drawUi(m_st, m_v.viewportInput(), m_v.now, dt);
        ImGui::Render();
    }

    // Renders for the shown backends, the difference image, a requested screenshot.
    void updateRenders() {
        m_v.updateRenders();
        m_v.updateDiff();
        Requests& r = m_st.ui.requests;
        if (r.screenshot) {
            r.screenshot = false;
            m_v.startScreenshots(r.screenshotWidth, r.screenshotHeight, m_st.ui.panels.shotDialog);
            r.screenshotWidth = r.screenshotHeight = 0;
        }
    }

    // Draws the UI into the window, takes the script's window shot, swaps.
    void present() {
        int fbw = 0, fbh = 0;
        glfwGetFramebufferSize(m_win, &fbw, &fbh);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, fbw, fbh);
        glDisable(GL_FRAMEBUFFER_SRGB);   // the UI colours and the images are already sRGB
        glDisable(GL_DEPTH_TEST);
        glClearColor(0.08f, 0.09f, 0.10f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        drainGlErrors("the UI drawing");
        if (!m_automation.windowShot.empty()) {
            std::string err = saveWindowPng(m_win, m_automation.windowShot);
            if (!err.empty()) {
                std::fprintf(stderr, "viewer: window-shot: %s\n", err.c_str());
                m_exitCode = 2;
            } else {
                std::printf("viewer: wrote %s\n", m_automation.windowShot.c_str());
            }
            m_automation.windowShot.clear();
        }
        glfwSwapBuffers(m_win);
    }

    // Window title: file name and the unsaved-changes marker.
    void updateTitle() {
        const Document& doc = m_st.doc;
        std::string title = (doc.path.empty() ? doc.scene.name : doc.path.filename().string()) + (doc.dirty ? " *" : "") + " - Scene viewer";
        if (title != m_windowTitle) {
            m_windowTitle = title;
            glfwSetWindowTitle(m_win, title.c_str());
        }
    }

    Viewer& m_v;
    ViewerState& m_st;
    GLFWwindow* m_win;
    Automation& m_automation;
    const ViewerOptions& m_opt;
    const bool m_automated;
    std::chrono::steady_clock::time_point m_start;
    double m_last = 0;
    int m_exitCode = 0;
    std::string m_windowTitle;
};

}   // namespace

int runViewer(const ViewerOptions& opt) {
    Automation automation;
    if (!loadAutomation(opt, automation)) return 1;
    GLFWwindow* win = createWindow(opt, /*automated=*/!automation.lines.empty());
    if (!win) return 1;
    auto viewer = std::make_unique<Viewer>();   // outlives the ImGui context (it holds the ini path)
    setUpViewer(*viewer, win);
    placeWindowOnScreen(win, opt, viewer->st.config.dir);
    openInitialScene(viewer->st, opt);
    int exitCode = MainLoop(*viewer, win, automation, opt).run();
    shutDown(*viewer, win, opt);
    return exitCode;
}

}   // namespace ui
