// provenance_json.cpp - provenanceJson() (see provenance_json.h).
#include "provenance_json.h"

#include "renderers/inspect.h"
#include "renderers/shading.h"

namespace cli {

namespace {

nlohmann::json vec(const sg::vec3& v) { return {v.x, v.y, v.z}; }

nlohmann::json termsJson(const sg::FrameInput& frame, const rnd::PixelTerms& t) {
    using nlohmann::json;
    json lights = json::array();
    for (size_t i = 0; i < t.lights.size(); ++i) {
        const rnd::LightPart& l = t.lights[i];
        lights.push_back({{"light", i},
                          {"radiance", vec(l.radiance)},
                          {"shadow", l.visibility},
                          {"n_dot_l", l.nDotL},
                          {"diffuse", vec(l.diffuse)},
                          {"specular", vec(l.specular)}});
    }
    json notes = json::array();
    if (frame.settings.shading == sg::ShadingModel::Gouraud) notes.push_back("evaluated per pixel; Gouraud interpolates vertex terms");
    return {{"lit", t.lit},
            {"albedo", vec(t.albedo)},
            {"ambient", vec(t.ambient)},
            {"emissive", vec(t.emissive)},
            {"lights", lights},
            {"fog_visibility", t.fogVisibility},
            {"before_fog", vec(t.beforeFog)},
            {"predicted", vec(t.predicted)},
            {"predicted_rgb", {rnd::toByteSRGB(t.predicted.x), rnd::toByteSRGB(t.predicted.y), rnd::toByteSRGB(t.predicted.z)}},
            {"notes", notes}};
}

}   // namespace

nlohmann::json provenanceJson(const sg::Scene& scene, const sg::FrameInput& frame, const sg::InstanceTable& ids, const rnd::Framebuffer& fb, int x,
                              int y, const std::vector<float>& lightVisibility) {
    using nlohmann::json;
    const uint8_t* px = fb.pixel(x, y);
    json j = {{"rgb", {px[0], px[1], px[2]}}, {"linear", vec(rnd::srgbBytesToLinear(px))}};
    const rnd::SurfaceAt s = rnd::surfaceAt(frame, ids, fb, x, y);
    j["depth"] = s.opticalDepth;
    if (!s.hit) {
        j["node"] = nullptr;
        j["path"] = nullptr;
        j["instance"] = 0;
        return j;
    }
    j["node"] = scene.valid(s.node) ? json(scene.node(s.node).name) : json(nullptr);
    j["path"] = scene.valid(s.node) ? json(sg::nodePath(scene, s.node)) : json(nullptr);
    j["instance"] = s.instance;
    j["drawable"] = s.drawable;
    j["kind"] = s.analytic ? "analytic" : s.triangle ? "triangle" : "point/line";
    j["triangle"] = s.triangle ? json(s.primitive) : json(nullptr);
    if (!s.triangle && !s.analytic) j["primitive"] = s.primitive;
    j["barycentric"] = s.triangle ? vec(s.barycentric) : json(nullptr);
    j["uv"] = s.hasUv ? json({s.uv.x, s.uv.y}) : json(nullptr);
    j["position"] = vec(s.position);
    j["normal"] = vec(s.normal);
    j["terms"] = termsJson(frame, rnd::pixelTerms(frame, s, lightVisibility));
    return j;
}

}   // namespace cli
