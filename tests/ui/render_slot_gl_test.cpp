// render_slot_gl_test.cpp - the GL backend on a worker thread (software GL: the window renders it
// there, with its own context) answers the pixel inspector's shadow question with its own maps,
// as the CPU rasterizer does, however often it is asked: the question runs on the worker, so the
// renderer's objects stay in the one context that made them (asked from another thread they were
// once all dropped, a leak of every mesh and map per click).
#include "assets/demo.h"
#include "gl/gl_context.h"
#include "ui/pixel_probe.h"
#include "ui/render_slot.h"
#include "ui/viewer_state.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace ui;

namespace {

struct Shown {
    std::unique_ptr<RenderSlot> slot;
    std::shared_ptr<const sg::FrameInput> frame;
};

Shown renderStill(const std::string& backend, RenderSlot::Threading threading, const std::shared_ptr<const sg::FrameInput>& frame, int w, int h) {
    Shown s;
    s.frame = frame;
    s.slot = std::make_unique<RenderSlot>(backend, threading);
    s.slot->request(frame, w, h, 1, /*interacting=*/false);
    s.slot->waitIdle();
    s.slot->poll();
    return s;
}

}   // namespace

TEST(RenderSlotGLTest, WorkerGlAnswersShadowsWithItsOwnMapsEveryTime) {
    ViewerState st;
    st.view.viewportWidth = 160;
    st.view.viewportHeight = 120;
    st.setScene(assets::makeDemoScene(), {});
    st.doc.scene.settings.shadows = true;
    auto frame = std::make_shared<sg::FrameInput>(st.buildFrame(160.0f / 120.0f));
    frame->settings = st.settingsFor("gl");
    frame->settings.aa = sg::AAMode::None;
    Shown gl = renderStill("gl", RenderSlot::Threading::Worker, frame, 160, 120);
    Shown raster = renderStill("raster", RenderSlot::Threading::Auto, frame, 160, 120);
    ASSERT_EQ(gl.slot->status().error, "");
    ASSERT_EQ(raster.slot->status().error, "");
    ASSERT_TRUE(gl.slot->image().has(rnd::Aov::Visibility));
    ASSERT_TRUE(raster.slot->image().has(rnd::Aov::Visibility));
    ASSERT_FALSE(frame->lights.empty());

    // This thread has a context of its own current, as the window's UI thread has the window's.
    std::string err;
    std::unique_ptr<rnd::gl::GlContext> window = rnd::gl::createHeadlessContext("", &err);
    ASSERT_TRUE(window) << err;
    ASSERT_TRUE(window->makeCurrent(&err)) << err;
    int probed = 0, shadowed = 0, agree = 0;
    for (int round = 0; round < 3; ++round) {   // asked again and again: the same answers
        for (int j = 1; j < 12; ++j)
            for (int i = 1; i < 16; ++i) {
                const float u = float(i) / 16.0f, v = float(j) / 12.0f;
                const ProbeResult a = probeAt(st, {"gl", &gl.slot->image(), gl.frame, gl.slot.get()}, u, v);
                const ProbeResult b = probeAt(st, {"raster", &raster.slot->image(), raster.frame, raster.slot.get()}, u, v);
                if (!a.surface.hit || !b.surface.hit || a.surface.node != b.surface.node) continue;
                ASSERT_TRUE(a.shadowsKnown) << "GL gave no shadows at (" << u << ", " << v << "), round " << round;
                ASSERT_TRUE(b.shadowsKnown);
                ASSERT_EQ(a.terms.lights.size(), b.terms.lights.size());
                for (size_t l = 0; l < a.terms.lights.size(); ++l) {
                    ++probed;
                    shadowed += a.terms.lights[l].visibility < 0.5f;
                    agree += std::fabs(a.terms.lights[l].visibility - b.terms.lights[l].visibility) < 0.25f;
                }
            }
        // A render between the questions: the maps (and everything else) are still in the context
        // that made them, so the frame renders as before.
        gl.slot->request(frame, 160, 120, 2 + round, false);
        gl.slot->waitIdle();
        gl.slot->poll();
        ASSERT_EQ(gl.slot->status().error, "");
    }
    window->release();
    EXPECT_GT(probed, 300);
    EXPECT_GT(shadowed, 0) << "the demo has shadowed points under some light";
    // The two rasterizers' maps are the same plan; texel-edge points may differ.
    EXPECT_GE(agree, probed * 95 / 100) << agree << " of " << probed;
}
