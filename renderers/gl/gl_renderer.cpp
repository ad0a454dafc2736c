// Placeholder until the gl backend lands: reports a clear error instead of an image.
#include "gl/gl_renderer.h"

namespace rnd {
namespace {
class GlRenderer final : public Renderer {
public:
    std::string_view name() const override { return "gl"; }
    Capabilities capabilities() const override { return {}; }
    RenderStats render(const sg::FrameInput&, int w, int h, Framebuffer& target, RenderControl*) override {
        target.resize(w, h);
        RenderStats s;
        s.error = "the gl backend is not built yet";
        return s;
    }
};
}  // namespace
std::unique_ptr<Renderer> makeGlRenderer() { return std::make_unique<GlRenderer>(); }
}  // namespace rnd
