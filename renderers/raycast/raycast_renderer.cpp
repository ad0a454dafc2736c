// Placeholder until the raycast backend lands: reports a clear error instead of an image.
#include "raycast/raycast_renderer.h"

namespace rnd {
namespace {
class RaycastRenderer final : public Renderer {
public:
    std::string_view name() const override { return "raycast"; }
    Capabilities capabilities() const override { return {}; }
    RenderStats render(const sg::FrameInput&, int w, int h, Framebuffer& target, RenderControl*) override {
        target.resize(w, h);
        RenderStats s;
        s.error = "the raycast backend is not built yet";
        return s;
    }
};
}  // namespace
std::unique_ptr<Renderer> makeRaycastRenderer() { return std::make_unique<RaycastRenderer>(); }
}  // namespace rnd
