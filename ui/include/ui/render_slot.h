// render_slot.h - one backend rendering for the viewport without blocking the UI thread.
//
// A RenderSlot owns a renderer made by name. request() hands it a frame; the slot renders it
// coarse-to-fine (1/4 resolution first, then full resolution once the user stops interacting)
// and keeps the last finished image for display. CPU backends run on a worker thread
// (std::thread) with RenderControl cancel/progress: a new request cancels the render in
// flight and restarts. While the user interacts (a camera drag, a playing animation) the
// slot measures instead: when its last full-resolution frame took less than liveBudgetMs it
// renders full resolution without the preview, and a frame in flight is let finish, the
// newest one asked for after it (needs() says no meanwhile). Backends that need the window's
// GL context ("gl") render synchronously in poll(), on the UI thread, where the context is
// current.
// No GL or ImGui here; the window uploads image() to a texture.
#pragma once

#include "renderers/renderer.h"

#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace ui {

struct SlotStatus {
    std::string backend;
    bool rendering = false;   // a render is in flight
    float progress = 0.0f;    // of the render in flight, 0..1 (of the shapes' rebuild while `shapes`)
    bool shapes = false;      // the render in flight is tessellating shapes anew before its image
    int level = 1;            // resolution divisor of the image shown (1 = full)
    bool refining = false;    // a finer image follows: the one shown is a preview or a one-sample image
    rnd::RenderStats stats;   // of the image shown (or the last failure)
    std::string error;        // last render's error ("" when it worked)
};

class RenderSlot {
public:
    // Where the renderer runs: Auto = a worker thread, except for backends whose capabilities
    // say they render with the caller's GL context (ContextAffinity::CurrentGLContext), which
    // render synchronously in poll(); Worker = always a worker thread (such a backend then
    // makes its own headless context there); UiThread = always synchronously in poll().
    enum class Threading { Auto, Worker, UiThread };
    explicit RenderSlot(std::string backend, Threading threading = Threading::Auto);
    ~RenderSlot();
    RenderSlot(const RenderSlot&) = delete;
    RenderSlot& operator=(const RenderSlot&) = delete;

    const std::string& backend() const { return m_backend; }
    const rnd::Capabilities& capabilities() const { return m_caps; }   // empty when the backend failed to make
    bool threaded() const { return m_threaded; }                       // renders on a worker thread (else in poll())
    // Renders `frame` at width x height. `key` identifies the content (scene+view+size): an
    // unchanged key is ignored. interacting: render one quick image, the preview level
    // (1/previewDivisor), or full resolution at one sample per pixel when the last such frame
    // fitted liveBudgetMs (planSteps); ignored while an interacting frame is still pending or
    // rendering (needs()).
    // On a worker thread an anti-aliased frame refines in steps: the preview and a full-
    // resolution image at one sample per pixel come first, then the anti-aliased image.
    // counters: the AOVs the full-resolution image should carry besides the visibility
    // (RenderRequest::aovs: the counters Overdraw / TraversalCost of the diagnostic view shown;
    // asked only where the backend has them, and included in what `key` identifies).
    void request(std::shared_ptr<const sg::FrameInput> frame, int width, int height, uint64_t key, bool interacting,
                 const rnd::RenderRequest& counters = {});
    // True when request() with this key would start work (so callers can skip building frames):
    // a new key, or the same one when the interaction stopped; while interacting, not before the
    // interacting frame pending or in flight is done (it finishes instead of being cancelled by
    // every new camera position or animation time, which showed nothing but previews).
    bool needs(uint64_t key, bool interacting) const;
    // Runs synchronous work and collects finished images; returns true when image() changed.
    bool poll();
    // Last finished image (UI thread only; valid until the next poll()). Full-resolution
    // images carry the visibility (picking, the pixel inspector) when the backend has it,
    // except anti-aliased ones rendered while interacting (that would be a second pass);
    // imageFrame() is the frame they show.
    const rnd::Framebuffer& image() const { return m_shown; }
    const std::shared_ptr<const sg::FrameInput>& imageFrame() const { return m_shownFrame; }
    // The backend's shadows at a point of imageFrame() (rnd::Renderer::lightVisibility); empty
    // when it has none, or while a render is in flight (asked again on a later frame).
    std::vector<float> lightVisibility(const sg::vec3& p, const sg::vec3& ng);
    // The same for one light at many points (rnd::Renderer::lightVisibilityMany: the shadow-map
    // view); nullopt while a render is in flight or waiting (ask again later).
    std::optional<std::vector<float>> lightVisibilityMany(int light, const std::vector<sg::vec3>& p, const std::vector<sg::vec3>& ng);
    uint64_t imageSerial() const { return m_serial; }   // bumped whenever image() changes
    SlotStatus status() const;
    // Blocks until nothing is pending (tests, screenshots at exit).
    void waitIdle();
    // Drops the shown image, its stats and every render pending or in flight (a different scene
    // was loaded: the old one's picture and figures must not stay on screen). A render that
    // finishes afterwards is thrown away; the next request() starts afresh.
    void forget();
    bool hasImage() const { return m_shown.width > 0; }

    int previewDivisor = 4;
    // While interacting, full resolution when the last full-resolution one-sample frame of the
    // same size took less than this, else the preview (taken by request(); the window sets
    // 1/20 s while the camera moves, 1/10 s while an animation plays on its own).
    double liveBudgetMs = 50.0;
    // How long that frame took (ms; < 0: none at the current size yet).
    double fullFrameMs() const;
    // What a full-resolution one-sample frame will cost while interacting (ms; < 0: unknown):
    // the last one rendered while interacting, until kProbeAfter previews followed it; else the
    // last still one, or divisor^2 previews when that is less (a full frame costs at most that
    // many previews: what the first frame of a scene pays once, textures, environment, shows
    // in a still frame's time, not again). So one slow frame, a busy machine's, does not keep
    // the preview for the rest of a playback: a full frame is tried again now and then.
    static constexpr int kProbeAfter = 30;
    static double liveFrameEstimate(double fullMs, bool fullLive, double previewMs, int divisor, int previewsSince = 0);

    // One step of a job: the resolution divisor and whether it takes one sample per pixel.
    struct Step {
        int divisor = 1;
        bool singleSample = false;
        bool operator==(const Step&) const = default;
    };
    // What the steps of a job depend on.
    struct PlanInput {
        int width = 0;              // full resolution
        bool interacting = false;   // the camera moves or an animation plays: one quick image
        bool antialiased = false;   // the frame asks for anti-aliasing
        bool threaded = true;       // on a worker: an anti-aliased frame refines through a one-sample image
        int previewDivisor = 4;
        double fullMs = -1;        // the last full-resolution one-sample frame of this size (< 0: none)
        double budgetMs = 50;      // liveBudgetMs
        int shownLevel = 0;        // the level of the image published for this very key (0: none)
        bool shownFinal = false;   // and it was the job's last step (nothing refines it)
    };
    // The steps of a job, coarse to fine (pure; public for tests): interacting, full resolution
    // at one sample when fullMs < budgetMs, else the preview; otherwise the preview (unless that
    // of this key is shown), a one-sample full-resolution image for anti-aliased frames on a
    // worker, then the final image; none of what this key has shown already.
    static std::vector<Step> planSteps(const PlanInput& in);
    // Called on the rendering thread with every step published (tests watch the refinement).
    std::function<void(const rnd::Framebuffer&, const SlotStatus&)> onPublish;

private:
    struct Job {
        std::shared_ptr<const sg::FrameInput> frame;
        int width = 0, height = 0;
        uint64_t key = 0;
        bool previewOnly = false;
        bool interacting = false;   // no visibility while the camera moves (anti-aliased)
        rnd::AovSet aovs;           // AOVs asked for (with the visibility)
        uint64_t generation = 0;    // m_generation when requested: forget() outdates it
        double budgetMs = 50;       // liveBudgetMs when requested
    };
    // A question for the renderer between renders, answered on the worker (a GL renderer's maps
    // live in the worker's context: asked from the UI thread, whose context is the window's, the
    // answer would need the objects of another context).
    struct Question {
        std::shared_ptr<const sg::FrameInput> frame;
        sg::vec3 p{0.0f}, ng{0.0f};
        int light = -1;                              // >= 0: the visibility of that light at many points
        const std::vector<sg::vec3>* ps = nullptr;   // (lightVisibilityMany's, outliving the question)
        const std::vector<sg::vec3>* ngs = nullptr;
        std::vector<float> answer;
        bool done = false;   // guarded by m_mutex
    };
    void workerLoop();
    std::vector<float> answer(const Question& q);
    std::optional<std::vector<float>> ask(Question& q);   // answered here or handed to the worker (nullopt: busy)
    // Renders one job step by step (runJob in render_slot.cpp); publishes each finished step.
    void runJob(const Job& job);
    void publish(rnd::Framebuffer&& fb, const rnd::RenderStats& st, int level, bool refining, const Job& job);

    std::string m_backend;
    bool m_threaded;
    std::unique_ptr<rnd::Renderer> m_renderer;
    rnd::Capabilities m_caps;
    std::string m_makeError;

    uint64_t m_lastKey = ~uint64_t(0);
    bool m_lastPreviewOnly = false;

    mutable std::mutex m_mutex;
    std::condition_variable m_cv;
    std::optional<Job> m_pending;
    bool m_busy = false;
    bool m_quit = false;
    Question* m_question = nullptr;            // asked by lightVisibility, taken by the worker (guarded by m_mutex)
    rnd::RenderControl* m_control = nullptr;   // of the render in flight (guarded by m_mutex)
    bool m_haveNew = false;
    uint64_t m_generation = 0;   // bumped by forget() (guarded by m_mutex)
    // The key and level of the last image published (guarded by m_mutex): when the camera stops,
    // the preview of that very view is already on screen and is not rendered again.
    uint64_t m_publishedKey = ~uint64_t(0);
    int m_publishedLevel = 0;
    bool m_publishedFinal = false;       // the last step of its job (nothing refines it)
    bool m_runningInteracting = false;   // the job in flight is an interacting one (guarded by m_mutex)
    // The last full-resolution one-sample frame: its time, size and whether it was rendered
    // while interacting; the last preview's time and size (guarded by m_mutex).
    double m_fullMs = -1;
    int m_fullWidth = 0, m_fullHeight = 0;
    bool m_fullLive = false;
    int m_previewsSinceFull = 0;   // interacting previews since that frame
    double m_previewMs = -1;
    int m_previewWidth = 0, m_previewHeight = 0, m_previewLevel = 0;
    rnd::Framebuffer m_finished;   // published by the worker
    // Images publish() took back (the one the UI showed before its last poll, or an unshown one
    // a newer image replaced), each rendered into again by a later step of its size: a new
    // image's vectors are zero-filled page by page as they grow, 20-45 ms at 1280x720 with the
    // visibility, every full-resolution frame (guarded by m_mutex; takeSpare).
    std::vector<rnd::Framebuffer> m_spares;
    rnd::Framebuffer takeSpare(int width, int height);
    std::shared_ptr<const sg::FrameInput> m_finishedFrame;
    std::mutex m_renderMutex;                          // held while m_renderer renders (lightVisibility asks between renders)
    const sg::FrameInput* m_renderedFrame = nullptr;   // the frame m_renderer rendered last (guarded by m_renderMutex)
    SlotStatus m_status;
    std::thread m_thread;

    rnd::Framebuffer m_shown;   // UI thread
    std::shared_ptr<const sg::FrameInput> m_shownFrame;
    uint64_t m_serial = 0;
};

}   // namespace ui
