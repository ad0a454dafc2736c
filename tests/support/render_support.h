// render_support.h - one render by backend name, for the tests that run every backend (the
// conformance tests and the agreement tests): the backend made, the frame rendered with a
// request, and every way it can go wrong reported naming the backend and the case. Linked by
// the library render_support (test_support plus the backends' registry).
#pragma once

#include "renderers/framebuffer.h"
#include "renderers/renderer.h"
#include "scenegraph/frame.h"

#include <gtest/gtest.h>

#include <string>

namespace testing_support {

// What a render asks for besides the backend, the frame and the size.
struct RenderCase {
    std::string what;                    // the case, named in failure messages (and the image written)
    rnd::RenderRequest request = {};     // AOVs, one sample per pixel
    rnd::RenderStats* stats = nullptr;   // receives the render's statistics when given
};

// Makes `backend` and renders `frame` at width x height into `out`; says why not when the
// backend cannot be made, the render fails or the image has another size (for ASSERT_TRUE).
::testing::AssertionResult renderBackend(const std::string& backend, const sg::FrameInput& frame, int width, int height, rnd::Framebuffer& out,
                                         const RenderCase& c = {});

// The same as an image: a failure fails the current test without ending it (the test goes on
// with what it got: an empty image when the backend could not be made). With `suite` given
// the image is written to test-output/<suite>/<image>-<backend>-<what>.png.
struct BackendImages {
    int width = 0, height = 0;
    std::string suite;   // "" writes nothing
    std::string image;   // the images' prefix in the suite's folder
    rnd::Framebuffer operator()(const std::string& backend, const sg::FrameInput& frame, const RenderCase& c = {}) const;
    rnd::Framebuffer operator()(const std::string& backend, const sg::FrameInput& frame, const std::string& what) const {
        return (*this)(backend, frame, RenderCase{what});
    }
};

}   // namespace testing_support
