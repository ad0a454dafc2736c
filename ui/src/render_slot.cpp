// render_slot.cpp - coarse-to-fine, cancellable rendering for one viewport backend.
#include "ui/render_slot.h"

#include <algorithm>
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
    if (key == m_lastKey && (interacting || !m_lastPreviewOnly)) return false;
    if (interacting && m_threaded) {   // let the interacting frame pending or in flight finish
        std::lock_guard<std::mutex> lock(m_mutex);
        if ((m_pending && m_pending->interacting) || (m_busy && m_runningInteracting)) return false;
    }
    return true;
}

double RenderSlot::fullFrameMs() const {
    std::lock_guard<std::mutex> lock(m_mutex);
    return m_fullMs;
}

double RenderSlot::liveFrameEstimate(double fullMs, bool fullLive, double previewMs, int divisor, int previewsSince) {
    if (fullMs >= 0 && fullLive && previewsSince < kProbeAfter) return fullMs;
    const double bound = previewMs >= 0 ? previewMs * divisor * divisor : -1;
    if (fullMs < 0) return bound;
    return bound >= 0 ? std::min(fullMs, bound) : fullMs;
}

std::vector<RenderSlot::Step> RenderSlot::planSteps(const PlanInput& in) {
    // A preview larger than ~1/16 of the pixels is pointless for tiny viewports.
    bool preview = in.previewDivisor > 1 && in.width / in.previewDivisor >= 8;
    if (in.interacting) {
        if (in.fullMs >= 0 && in.fullMs < in.budgetMs) return {{1, true}};   // a full frame fits: no preview
        if (preview) return {{in.previewDivisor, true}};
    } else if (in.shownLevel == 1) {   // this very view at full resolution is on screen already
        if (in.shownFinal) return {};
        return {{1, false}};   // its one-sample image: only the anti-aliased one is left
    } else if (in.shownLevel == in.previewDivisor) {
        preview = false;   // the camera stopped: its preview is on screen already
    }
    std::vector<Step> steps;
    if (preview) steps.push_back({in.previewDivisor, true});
    if (in.threaded && in.antialiased) steps.push_back({1, true});
    steps.push_back({1, false});
    return steps;
}

void RenderSlot::request(std::shared_ptr<const sg::FrameInput> frame, int width, int height, uint64_t key, bool interacting,
                         const rnd::RenderRequest& counters) {
    if (!m_renderer || width < 1 || height < 1) return;
    if (!needs(key, interacting)) return;   // nothing new to draw
    m_lastKey = key;
    m_lastPreviewOnly = interacting;
    std::lock_guard<std::mutex> lock(m_mutex);
    m_pending = Job{std::move(frame), width, height, key, interacting, interacting, counters.aovs, m_generation, liveBudgetMs};
    if (m_control) m_control->cancel = true;   // restart with the new frame
    m_cv.notify_all();
}

void RenderSlot::publish(rnd::Framebuffer&& fb, const rnd::RenderStats& st, int level, bool refining, const Job& job) {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (job.generation != m_generation) return;   // rendered for a scene forget() dropped
    m_status.stats = st;
    m_status.error = st.ok ? std::string() : (st.error.empty() ? "render failed" : st.error);
    if (st.ok) {
        std::swap(m_finished, fb);   // fb: the image this one replaces, kept to render into again
        if (fb.width > 0) {
            if (m_spares.size() >= 4) m_spares.erase(m_spares.begin());
            m_spares.push_back(std::move(fb));
        }
        m_finishedFrame = job.frame;
        m_publishedKey = job.key;
        m_publishedLevel = level;
        m_publishedFinal = !refining;
        m_status.level = level;
        m_status.refining = refining;
        m_haveNew = true;
        if (onPublish) onPublish(m_finished, m_status);
    }
}

rnd::Framebuffer RenderSlot::takeSpare(int width, int height) {
    std::lock_guard<std::mutex> lock(m_mutex);
    // After a poll m_finished holds the image shown before it (poll swaps): nobody reads it again.
    if (!m_haveNew && m_finished.width == width && m_finished.height == height) {
        rnd::Framebuffer fb = std::move(m_finished);
        m_finished = {};
        return fb;
    }
    for (size_t i = m_spares.size(); i-- > 0;)
        if (m_spares[i].width == width && m_spares[i].height == height) {
            rnd::Framebuffer fb = std::move(m_spares[i]);
            m_spares.erase(m_spares.begin() + std::ptrdiff_t(i));
            return fb;   // its old pixels stay until the renderer writes every one (Renderer::render)
        }
    return {};
}

// The steps of a job (planSteps): the preview (1/previewDivisor, one sample per pixel), then
// full resolution. An anti-aliased frame on a worker thread gets a one-sample full-resolution
// step before the anti-aliased one, so a sharp image shows in a fraction of the anti-aliased
// time (SSAA 4x4 takes 16 times as long) and the viewport refines instead of waiting; the last
// step keeps that step's visibility and counters instead of rendering a second pass for them.
// Every full-resolution one-sample step is timed: interacting jobs skip the preview while
// such a frame fits liveBudgetMs.
void RenderSlot::runJob(const Job& job) {
    const bool antialiased = job.frame->settings.aa != sg::AAMode::None;
    PlanInput plan;
    plan.width = job.width;
    plan.interacting = job.previewOnly;   // a synchronous render (poll) plans as if still
    plan.antialiased = antialiased;
    plan.threaded = m_threaded;
    plan.previewDivisor = previewDivisor;
    plan.budgetMs = job.budgetMs;
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        const bool fullHere = m_fullWidth == job.width && m_fullHeight == job.height;
        const bool previewHere = m_previewWidth == job.width && m_previewHeight == job.height && m_previewLevel == previewDivisor;
        plan.fullMs = liveFrameEstimate(fullHere ? m_fullMs : -1, m_fullLive, previewHere ? m_previewMs : -1, previewDivisor, m_previewsSinceFull);
        if (m_publishedKey == job.key) {
            plan.shownLevel = m_publishedLevel;
            plan.shownFinal = m_publishedFinal;
        }
    }
    const std::vector<Step> steps = planSteps(plan);
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
        rnd::Framebuffer fb = takeSpare(w, h);
        rnd::RenderStats st;
        rnd::RenderRequest request;
        request.singleSample = steps[i].singleSample;
        // Visibility at full resolution; while the camera moves only when it is free (one pass,
        // no anti-aliasing), so a click right after an edit still picks.
        const bool onePass = steps[i].singleSample || job.frame->settings.aa == sg::AAMode::None;
        const bool fullPass = d == 1 && (!job.interacting || onePass);
        const bool reuse = d == 1 && !steps[i].singleSample && oneSample.width == w && oneSample.height == h;
        // The diagnostic view's counters under the same rule (a second pass when anti-aliased).
        if (fullPass && !reuse)
            for (rnd::Aov a : rnd::AovSet(job.aovs).add(rnd::Aov::Visibility).list()) request.aovs.set(a, m_caps.aovs.has(a));
        const auto start = std::chrono::steady_clock::now();
        try {
            std::lock_guard<std::mutex> rendering(m_renderMutex);
            m_renderedFrame = job.frame.get();
            st = m_renderer->render(*job.frame, w, h, fb, &control, request);
        } catch (const std::exception& e) {
            st.ok = false;
            st.error = std::string("exception: ") + e.what();
        }
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            m_control = nullptr;
            m_status.rendering = !last && st.ok && !control.cancel;
            m_status.shapes = false;
            if (st.ok && !control.cancel && !st.cancelled) {   // what a frame costs while interacting
                if (d == 1 && onePass) {
                    m_fullMs = ms;
                    m_fullWidth = w;
                    m_fullHeight = h;
                    m_fullLive = job.interacting;
                    m_previewsSinceFull = 0;
                } else if (d > 1) {
                    m_previewsSinceFull += job.interacting;
                    m_previewMs = ms;
                    m_previewWidth = job.width;
                    m_previewHeight = job.height;
                    m_previewLevel = d;
                }
            }
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
        // A one-sample image of an anti-aliased frame (rendered while interacting too) is refined later.
        publish(std::move(fb), st, d, !last || (d == 1 && steps[i].singleSample && antialiased), job);
        if (!st.ok) return;
    }
}

void RenderSlot::workerLoop() {
    for (;;) {
        Job job;
        {
            std::unique_lock<std::mutex> lock(m_mutex);
            m_cv.wait(lock, [&] { return m_quit || m_pending.has_value() || m_question; });
            if (m_quit) return;
            if (Question* q = m_question) {   // between renders: the renderer's state is that of the last frame
                m_question = nullptr;
                lock.unlock();
                std::vector<float> a = answer(*q);
                lock.lock();
                q->answer = std::move(a);
                q->done = true;
                lock.unlock();
                m_cv.notify_all();
                continue;
            }
            job = std::move(*m_pending);
            m_pending.reset();
            m_busy = true;
            m_runningInteracting = job.interacting;
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

// The renderer answers for the frame it rendered last: only while that is the one shown.
std::vector<float> RenderSlot::answer(const Question& q) {
    std::lock_guard<std::mutex> rendering(m_renderMutex);
    if (m_renderedFrame != q.frame.get()) return {};
    if (q.light >= 0) return m_renderer->lightVisibilityMany(*q.frame, q.light, *q.ps, *q.ngs);
    return m_renderer->lightVisibility(*q.frame, q.p, q.ng);
}

std::vector<float> RenderSlot::lightVisibility(const sg::vec3& p, const sg::vec3& ng) {
    if (!m_renderer || !m_shownFrame) return {};
    Question q;
    q.frame = m_shownFrame;
    q.p = p;
    q.ng = ng;
    return ask(q).value_or(std::vector<float>{});
}

std::optional<std::vector<float>> RenderSlot::lightVisibilityMany(int light, const std::vector<sg::vec3>& p, const std::vector<sg::vec3>& ng) {
    if (!m_renderer || !m_shownFrame) return {};
    Question q;
    q.frame = m_shownFrame;
    q.light = light;
    q.ps = &p;
    q.ngs = &ng;
    return ask(q);
}

std::optional<std::vector<float>> RenderSlot::ask(Question& q) {
    if (!m_threaded) return answer(q);   // renders run here too (poll): none is in flight
    // On the worker, where the renderer renders (and its GL context, if it has one, is made
    // current); not while a render is in flight or waiting (asked again on a later frame).
    std::unique_lock<std::mutex> lock(m_mutex);
    if (m_quit) return std::vector<float>{};
    if (m_busy || m_pending || m_question) return std::nullopt;
    m_question = &q;
    m_cv.notify_all();
    if (!m_cv.wait_for(lock, std::chrono::milliseconds(500), [&] { return q.done || m_question != &q; })) {
        m_question = nullptr;   // not taken (the worker is stuck elsewhere): no answer this time
        return std::nullopt;
    }
    m_cv.wait(lock, [&] { return q.done; });   // taken: the worker writes into q, which must outlive that
    return std::move(q.answer);
}

void RenderSlot::forget() {
    std::lock_guard<std::mutex> lock(m_mutex);
    ++m_generation;
    m_pending.reset();
    if (m_control) m_control->cancel = true;
    m_haveNew = false;
    m_finished = {};
    m_spares.clear();
    m_shown = {};
    m_finishedFrame.reset();
    m_shownFrame.reset();
    ++m_serial;
    m_status.stats = {};
    m_status.error.clear();
    m_status.level = 1;
    m_lastKey = ~uint64_t(0);
    m_publishedKey = ~uint64_t(0);
    m_publishedFinal = false;
    m_fullMs = m_previewMs = -1;   // what frames of the old scene cost says nothing about the new one
    m_fullLive = false;
    m_previewsSinceFull = 0;
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
