// render_slot.cpp - coarse-to-fine, cancellable rendering for one viewport backend.
#include "ui/render_slot.h"

#include <chrono>

namespace ui {

RenderSlot::RenderSlot(std::string backend, Threading threading) : m_backend(std::move(backend)), m_threaded(threading != Threading::UiThread) {
    m_renderer = rnd::makeRenderer(m_backend, &m_makeError);
    if (m_renderer) m_caps = m_renderer->capabilities();
    // A backend that renders with the caller's GL context runs here (in poll(), on the UI
    // thread that owns the window's context) unless a worker is asked for explicitly.
    if (threading == Threading::Auto && m_renderer && m_caps.affinity == rnd::ContextAffinity::CurrentGLContext) m_threaded = false;
    m_status.backend = m_backend;
    if (!m_renderer) m_status.error = m_makeError.empty() ? "unknown backend " + m_backend : m_makeError;
    if (m_threaded && m_renderer) m_thread = std::thread([this] { workerLoop(); });
}

RenderSlot::~RenderSlot() {
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_quit = true;
        if (m_control) m_control->cancel = true;
    }
    m_cv.notify_all();
    if (m_thread.joinable()) m_thread.join();
}

bool RenderSlot::needs(uint64_t key, bool interacting) const {
    if (!m_renderer) return false;
    return !(key == m_lastKey && (interacting || !m_lastPreviewOnly));
}

void RenderSlot::request(std::shared_ptr<const sg::FrameInput> frame, int width, int height, uint64_t key, bool interacting,
                         const rnd::RenderRequest& counters) {
    if (!m_renderer || width < 1 || height < 1) return;
    if (!needs(key, interacting)) return;   // nothing new to draw
    m_lastKey = key;
    m_lastPreviewOnly = interacting;
    std::lock_guard<std::mutex> lock(m_mutex);
    m_pending = Job{std::move(frame), width, height, key, interacting, interacting, counters.overdraw, counters.traversalCost, m_generation};
    if (m_control) m_control->cancel = true;   // restart with the new frame
    m_cv.notify_all();
}

void RenderSlot::publish(rnd::Framebuffer&& fb, const rnd::RenderStats& st, int level, bool refining, const Job& job) {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (job.generation != m_generation) return;   // rendered for a scene forget() dropped
    m_status.stats = st;
    m_status.error = st.ok ? std::string() : (st.error.empty() ? "render failed" : st.error);
    if (st.ok) {
        m_finished = std::move(fb);
        m_finishedFrame = job.frame;
        m_publishedKey = job.key;
        m_publishedLevel = level;
        m_status.level = level;
        m_status.refining = refining;
        m_haveNew = true;
        if (onPublish) onPublish(m_finished, m_status);
    }
}

// The steps of a job: the preview (1/previewDivisor, one sample per pixel), then full
// resolution. An anti-aliased frame on a worker thread gets a one-sample full-resolution step
// before the anti-aliased one, so a sharp image shows in a fraction of the anti-aliased time
// (SSAA 4x4 takes 16 times as long) and the viewport refines instead of waiting; the last step
// keeps that step's visibility and counters instead of rendering a second pass for them.
void RenderSlot::runJob(const Job& job) {
    struct Step {
        int divisor;
        bool singleSample;
    };
    std::vector<Step> steps;
    // A preview larger than ~1/16 of the pixels is pointless for tiny viewports.
    bool preview = previewDivisor > 1 && job.width / previewDivisor >= 8;
    if (preview && !job.previewOnly) {   // the camera stopped: its preview may be on screen already
        std::lock_guard<std::mutex> lock(m_mutex);
        if (m_publishedKey == job.key && m_publishedLevel == previewDivisor) preview = false;
    }
    if (preview) steps.push_back({previewDivisor, true});
    if (!preview || !job.previewOnly) {
        if (m_threaded && job.frame->settings.aa != sg::AAMode::None) steps.push_back({1, true});
        steps.push_back({1, false});
    }
    rnd::Framebuffer oneSample;   // the full-resolution one-sample step's image, for its visibility and counters
    for (size_t i = 0; i < steps.size(); ++i) {
        const int d = steps[i].divisor;
        const bool last = i + 1 == steps.size();
        int w = std::max(1, job.width / d), h = std::max(1, job.height / d);
        rnd::RenderControl control;
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            if (m_pending || m_quit) return;   // superseded
            m_control = &control;
            m_status.rendering = true;
            m_status.progress = 0.0f;
            m_status.shapes = false;
        }
        rnd::Framebuffer fb;
        rnd::RenderStats st;
        rnd::RenderRequest request;
        request.singleSample = steps[i].singleSample;
        // Visibility at full resolution; while the camera moves only when it is free (one pass,
        // no anti-aliasing), so a click right after an edit still picks.
        const bool onePass = steps[i].singleSample || job.frame->settings.aa == sg::AAMode::None;
        const bool fullPass = d == 1 && (!job.interacting || onePass);
        const bool reuse = d == 1 && !steps[i].singleSample && oneSample.width == w && oneSample.height == h;
        request.visibility = m_caps.visibility && fullPass && !reuse;
        // The diagnostic view's counters under the same rule (a second pass when anti-aliased).
        request.overdraw = m_caps.overdraw && job.overdraw && fullPass && !reuse;
        request.traversalCost = m_caps.traversalCost && job.traversalCost && fullPass && !reuse;
        try {
            std::lock_guard<std::mutex> rendering(m_renderMutex);
            m_renderedFrame = job.frame.get();
            st = m_renderer->render(*job.frame, w, h, fb, &control, request);
        } catch (const std::exception& e) {
            st.ok = false;
            st.error = std::string("exception: ") + e.what();
        }
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            m_control = nullptr;
            m_status.rendering = !last && st.ok && !control.cancel;
            m_status.shapes = false;
        }
        if (control.cancel || st.cancelled) return;
        if (st.ok && (fb.width != w || fb.height != h || fb.color.size() != size_t(w) * h * 4)) {
            st.ok = false;
            st.error = "backend returned a " + std::to_string(fb.width) + "x" + std::to_string(fb.height) + " image";
        }
        if (st.ok && reuse) fb.takeVisibilityAndCounters(std::move(oneSample));   // the same pixel centres
        if (d == 1 && !last) {   // the one-sample step's visibility and counters, for the last step (fb itself moves on)
            oneSample.width = fb.width;
            oneSample.height = fb.height;
            oneSample.drawable = fb.drawable;   // copies: fb (colour and all) is published below
            oneSample.primitive = fb.primitive;
            oneSample.overdraw = fb.overdraw;
            oneSample.costNodes = fb.costNodes;
            oneSample.costPrims = fb.costPrims;
        }
        publish(std::move(fb), st, d, !last, job);
        if (!st.ok) return;
    }
}

void RenderSlot::workerLoop() {
    for (;;) {
        Job job;
        {
            std::unique_lock<std::mutex> lock(m_mutex);
            m_cv.wait(lock, [&] { return m_quit || m_pending.has_value(); });
            if (m_quit) return;
            job = std::move(*m_pending);
            m_pending.reset();
            m_busy = true;
        }
        runJob(job);
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            m_busy = false;
        }
        m_cv.notify_all();
    }
}

bool RenderSlot::poll() {
    if (!m_threaded && m_renderer) {
        std::optional<Job> job;
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            job.swap(m_pending);
        }
        if (job) {
            // Synchronous (GL): full resolution right away, it is fast enough to be "instant".
            job->previewOnly = false;
            int keep = previewDivisor;
            previewDivisor = 1;
            runJob(*job);
            previewDivisor = keep;
        }
    }
    std::lock_guard<std::mutex> lock(m_mutex);
    if (m_control) {
        m_status.shapes = m_control->stage.load() == rnd::RenderStage::Shapes;
        m_status.progress = m_control->progress.load();
    }
    if (!m_haveNew) return false;
    m_haveNew = false;
    std::swap(m_shown, m_finished);
    std::swap(m_shownFrame, m_finishedFrame);
    ++m_serial;
    return true;
}

std::vector<float> RenderSlot::lightVisibility(const sg::vec3& p, const sg::vec3& ng) {
    if (!m_renderer || !m_shownFrame) return {};
    std::unique_lock<std::mutex> rendering(m_renderMutex, std::try_to_lock);
    if (!rendering.owns_lock()) return {};
    // The renderer answers for the frame it rendered last: only while that is the one shown.
    if (m_renderedFrame != m_shownFrame.get()) return {};
    return m_renderer->lightVisibility(*m_shownFrame, p, ng);
}

void RenderSlot::forget() {
    std::lock_guard<std::mutex> lock(m_mutex);
    ++m_generation;
    m_pending.reset();
    if (m_control) m_control->cancel = true;
    m_haveNew = false;
    m_finished = {};
    m_shown = {};
    m_finishedFrame.reset();
    m_shownFrame.reset();
    ++m_serial;
    m_status.stats = {};
    m_status.error.clear();
    m_status.level = 1;
    m_lastKey = ~uint64_t(0);
    m_publishedKey = ~uint64_t(0);
    if (!m_renderer) m_status.error = m_makeError.empty() ? "unknown backend " + m_backend : m_makeError;
}

SlotStatus RenderSlot::status() const {
    std::lock_guard<std::mutex> lock(m_mutex);
    return m_status;
}

void RenderSlot::waitIdle() {
    if (!m_threaded) {
        poll();
        return;
    }
    std::unique_lock<std::mutex> lock(m_mutex);
    m_cv.wait(lock, [&] { return m_quit || (!m_pending && !m_busy); });
}

}   // namespace ui
