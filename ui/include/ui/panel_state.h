// panel_state.h - what the ImGui panels remember from one frame to the next that is not the
// document or the view: the file browser, the screenshot dialog, the overlay and help toggles,
// the scene tree's in-place rename and the split view's divider drag. Plain data (no ImGui):
// the viewer's ViewerState holds one, so every viewer (and every test) has its own instead of
// sharing file-scope globals.
#pragma once

#include "scenegraph/scene.h"
#include "ui/pixel_probe.h"

#include <filesystem>
#include <string>

namespace ui {

// File > Open / Save As: a modal listing one folder.
struct FileBrowserState {
    bool open = false;
    bool saving = false;       // Save As (else Open)
    bool justOpened = false;   // open the popup on the next frame
    std::filesystem::path dir;
    std::string fileName;
    std::string error;
};

// File > Screenshot at resolution... and File > Export depth, normal, id...: what F12 writes too.
struct ScreenshotDialogState {
    bool open = false;
    bool windowSize = true;   // render at the viewport size (else width x height)
    int width = 1920, height = 1080;
    bool asShown = true;   // the image as the viewport shows it: View > Diagnostic view and View > Overlays (else shaded, bare)
    bool exportDepth = false, exportNormal = false, exportId = false;   // the synthetic-data export next to each PNG
    std::filesystem::path dir;                                          // where screenshots go, F12's too ("" = the folder the viewer started in)
    std::string dirText;                                                // the folder field being edited (filled when the dialog opens)
    std::string error;                                                  // why Take was refused (a folder that cannot be made)
};

struct PanelState {
    FileBrowserState browser;
    ScreenshotDialogState shotDialog;
    bool showOverlay = true;                            // View > Stats overlay
    bool showHelp = false;                              // Help > Controls
    bool resizingLeft = false, resizingRight = false;   // the user is dragging a panel's edge
    // Scene tree: the node being renamed in place (F2, double click, context menu) and its text.
    sg::NodeId renaming = sg::kNoNode;
    std::string renameBuffer;
    int dragDivider = -1;             // split view: the wipe divider being dragged (-1: none)
    bool escapeClosedPopup = false;   // this frame's Escape closed a menu / combo: a dialog under it stays
    PixelProbeState probe;            // the pixel inspector: hovered or pinned point, per-backend answers
};

}   // namespace ui
