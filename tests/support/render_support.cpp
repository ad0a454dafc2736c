// render_support.cpp - renderBackend() and BackendImages (see render_support.h).
#include "render_support.h"

#include "test_support.h"

namespace testing_support {

::testing::AssertionResult renderBackend(const std::string& backend, const sg::FrameInput& frame, int width, int height, rnd::Framebuffer& out,
                                         const RenderCase& c) {
    const std::string label = c.what.empty() ? backend : backend + " " + c.what;
    std::string err;
    std::unique_ptr<rnd::Renderer> r = rnd::makeRenderer(backend, &err);
    if (!r) return ::testing::AssertionFailure() << "makeRenderer(\"" << backend << "\"): " << err;
    const rnd::RenderStats st = r->render(frame, width, height, out, nullptr, c.request);
    if (c.stats) *c.stats = st;
    if (!st.ok) return ::testing::AssertionFailure() << label << ": could not render: " << st.error;
    if (out.width != width || out.height != height)
        return ::testing::AssertionFailure() << label << ": rendered " << out.width << "x" << out.height << ", asked for " << width << "x" << height;
    return ::testing::AssertionSuccess();
}

rnd::Framebuffer BackendImages::operator()(const std::string& backend, const sg::FrameInput& frame, const RenderCase& c) const {
    rnd::Framebuffer fb;
    EXPECT_TRUE(renderBackend(backend, frame, width, height, fb, c));
    if (!suite.empty() && fb.width > 0 && fb.height > 0) writeImage(fb, suite, image + "-" + backend + (c.what.empty() ? "" : "-" + c.what));
    return fb;
}

}   // namespace testing_support
