// aov_export.h - the synthetic-data export next to a rendered PNG, shared by `viewer render
// --aov` and the window's screenshots (File > Export depth, normal, id...; F12 with the
// screenshot dialog's export boxes ticked). For P.png it writes
//   P.depth.pfm   depth along the optical axis (scene units, 0 = nothing), grey float32 PFM
//   P.normal.png  world normal as 0.5 n + 0.5, 8-bit RGB, black where nothing was drawn
//   P.id.png      16-bit grey instance id (sg::instanceTable), 0 = nothing
//   P.json        the sidecar: size, backend, camera (K, world_to_camera, projection, near, far),
//                 the files written and, with the id image, the id -> node table
// (formulas: docs/math.md, "Synthetic-data export").
#pragma once

#include "assets/aov_io.h"
#include "renderers/framebuffer.h"
#include "scenegraph/frame.h"
#include "scenegraph/scene.h"

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace ui {

// ".depth.pfm", ".normal.png", ".id.png" for "depth", "normal", "id"; nullptr for anything else.
const char* aovSuffix(std::string_view kind);
// "depth,normal" -> {"depth", "normal"} (order kept, duplicates and empty items dropped).
std::vector<std::string> parseAovList(const std::string& list);
// The normal and id images need the render's visibility (RenderRequest::visibility); depth does not.
bool aovsNeedVisibility(const std::vector<std::string>& kinds);
// The files the export of `kinds` writes next to `png` (the sidecar last); none for no kinds.
// Unknown kinds are left out (check them with aovSuffix first).
std::vector<std::filesystem::path> aovFiles(const std::filesystem::path& png, const std::vector<std::string>& kinds);

// The id -> node table of the id export for `frame` (flattened from `scene`): id k is
// sg::instanceTable(frame)'s instance k. Made where the scene may be read (the UI thread).
std::vector<assets::AovInstance> aovInstances(const sg::Scene& scene, const sg::FrameInput& frame);

// Writes the export of `kinds` for the image `img` (rendered from `frame` by `backend`, with
// visibility when aovsNeedVisibility) next to `png`; `instances` from aovInstances. An existing
// file is replaced only with `overwrite`. "" or a one-line error naming the file.
std::string writeAovs(const std::filesystem::path& png, const std::vector<std::string>& kinds, const std::string& backend,
                      const std::vector<assets::AovInstance>& instances, const sg::FrameInput& frame, const rnd::Framebuffer& img, bool overwrite);

}   // namespace ui
