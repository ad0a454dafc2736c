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
#include "renderers/aov.h"
#include "renderers/framebuffer.h"
#include "scenegraph/frame.h"
#include "scenegraph/scene.h"

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace ui {

// The AOVs (renderers/aov.h) the export writes, by their names in rnd::nameOf(Aov): depth,
// normal and id. ".depth.pfm", ".normal.png", ".id.png" for those; nullptr for the others.
const char* aovSuffix(rnd::Aov aov);
// "depth,normal" -> {Depth, Normal} (order kept, duplicates and empty items dropped) into
// `out`. "" or, for a name that is not an exported AOV, "unknown kind 'x' (known: depth,
// normal, id)".
std::string parseAovList(const std::string& list, std::vector<rnd::Aov>& out);
// The AOVs of the list as a set (RenderRequest::aovs: the normal and id images ask for the
// render's visibility, depth for nothing more).
rnd::AovSet aovSetOf(const std::vector<rnd::Aov>& kinds);
// The normal and id images need the render's visibility (RenderRequest::aovs); depth does not.
bool aovsNeedVisibility(const std::vector<rnd::Aov>& kinds);
// The files the export of `kinds` writes next to `png` (the sidecar last); none for no kinds.
// AOVs without a file are left out.
std::vector<std::filesystem::path> aovFiles(const std::filesystem::path& png, const std::vector<rnd::Aov>& kinds);

// The id -> node table of the id export for `frame` (flattened from `scene`): id k is
// sg::instanceTable(frame)'s instance k. Made where the scene may be read (the UI thread).
std::vector<assets::AovInstance> aovInstances(const sg::Scene& scene, const sg::FrameInput& frame);

// Writes the export of `kinds` for the image `img` (rendered from `frame` by `backend`, with
// visibility when aovsNeedVisibility) next to `png`; `instances` from aovInstances. An existing
// file is replaced only with `overwrite`. "" or a one-line error naming the file.
std::string writeAovs(const std::filesystem::path& png, const std::vector<rnd::Aov>& kinds, const std::string& backend,
                      const std::vector<assets::AovInstance>& instances, const sg::FrameInput& frame, const rnd::Framebuffer& img, bool overwrite);

}   // namespace ui
