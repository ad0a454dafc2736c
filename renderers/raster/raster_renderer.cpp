// Placeholder until the raster backend lands: reports a clear error instead of an image.
#include "raster/raster_renderer.h"

namespace rnd {
namespace {
class RasterRenderer final : public Renderer {
public:
    std::string_view name() const override { return "raster"; }
    Capabilities capabilities() const override { return {}; }
    RenderStats render(const sg::FrameInput&, int w, int h, Framebuffer& target, RenderControl*) override {
        target.resize(w, h);
        RenderStats s;
        s.error = "the raster backend is not built yet";
        return s;
    }
};
}  // namespace
std::unique_ptr<Renderer> makeRasterRenderer() { return std::make_unique<RasterRenderer>(); }
}  // namespace rnd
