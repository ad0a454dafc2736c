// provenance_json.h - a pixel's provenance (renderers/inspect.h) as the JSON object that
// `viewer inspect` prints for each backend.
#pragma once

#include "renderers/framebuffer.h"
#include "scenegraph/instances.h"

#include <nlohmann/json.hpp>

namespace cli {

// {"rgb":[r,g,b] (sRGB bytes), "linear":[..], "depth": optical depth or 0, "node": name|null,
//  "path": "/a/b"|null, "instance": k, "drawable": k, "triangle": index|null,
//  "barycentric": [..]|null, "uv": [..]|null, "position": [..], "normal": [..],
//  "terms": {"albedo", "ambient", "emissive", "lights": [{"light", "radiance", "shadow", "n_dot_l",
//  "diffuse", "specular"}], "fog_visibility", "before_fog", "predicted", "predicted_rgb", "notes"}}
// lightVisibility: the backend's shadows at the surface (rnd::Renderer::lightVisibility).
nlohmann::json provenanceJson(const sg::Scene& scene, const sg::FrameInput& frame, const sg::InstanceTable& ids, const rnd::Framebuffer& fb, int x,
                              int y, const std::vector<float>& lightVisibility);

}   // namespace cli
