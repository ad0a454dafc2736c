// render_slot.h - one backend rendering for the viewport without blocking the UI thread.
//
// A RenderSlot owns a renderer made by name. request() hands it a frame; the slot renders it
// coarse-to-fine (1/4 resolution first, then full resolution once the user stops interacting)
// and keeps the last finished image for display. CPU backends run on a worker thread
// (std::thread) with RenderControl cancel/progress: a new request cancels the render in
// flight and restarts. Backends that need the window's GL context ("gl") render synchronously
// in poll(), on the UI thread, where the context is current.
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
    // unchanged key is ignored. interacting: render only the preview level (1/previewDivisor).
    // On a worker thread an anti-aliased frame refines in steps: the preview and a full-
    // resolution image at one sample per pixel come first, then the anti-aliased image.
    // counters: the per-pixel counters the full-resolution image should carry (RenderRequest's
    // overdraw / traversalCost, for the diagnostic view shown; asked only where the backend has
    // them, and included in what `key` identifies).
    void request(std::shared_ptr<const sg::FrameInput> frame, int width, int height, uint64_t key, bool interacting,
                 const rnd::RenderRequest& counters = {});
    // True when request() with this key would start work (so callers can skip building frames).
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
    // Called on the rendering thread with every step published (tests watch the refinement).
    std::function<void(const rnd::Framebuffer&, const SlotStatus&)> onPublish;

private:
    struct Job {
        std::shared_ptr<const sg::FrameInput> frame;
        int width = 0, height = 0;
        uint64_t key = 0;
        bool previewOnly = false;
        bool interacting = false;                       // no visibility while the camera moves
        bool overdraw = false, traversalCost = false;   // counters asked for (with the visibility)
        uint64_t generation = 0;                        // m_generation when requested: forget() outdates it
    };
    void workerLoop();
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
    rnd::RenderControl* m_control = nullptr;   // of the render in flight (guarded by m_mutex)
    bool m_haveNew = false;
    uint64_t m_generation = 0;   // bumped by forget() (guarded by m_mutex)
    // The key and level of the last image published (guarded by m_mutex): when the camera stops,
    // the preview of that very view is already on screen and is not rendered again.
    uint64_t m_publishedKey = ~uint64_t(0);
    int m_publishedLevel = 0;
    rnd::Framebuffer m_finished;   // published by the worker
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
