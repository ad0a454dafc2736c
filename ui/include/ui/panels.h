// panels.h - the viewer's Dear ImGui panels and layout. They read and edit a ViewerState and
// call ImGui; they never touch GLFW or GL (textures arrive as opaque ids), so tests run them
// in headless ImGui frames (CreateContext, DisplaySize, fonts built, NewFrame ... Render).
//
// Layout (drawUi): main menu bar; left "Scene" panel (tree); right panel with the animation
// bar (scenes with clips only) above tabs Inspector / Camera / Rendering / Compare; the viewport in between (images, split wipe, difference,
// stats overlay, camera mouse/keyboard input); a status bar (with load progress + Cancel);
// modal dialogs.
#pragma once

#include "ui/pixel_probe.h"
#include "ui/render_slot.h"
#include "ui/viewer_state.h"

#include <string>
#include <vector>

namespace ui {

// Key codes the panels read from io.KeysDown (ImGui 1.86 uses the platform's codes; these
// equal GLFW's, which viewer.cpp static_asserts).
namespace keys {
constexpr int Space = 32, Num1 = 49, Num2 = 50, Num3 = 51;
constexpr int A = 65, D = 68, E = 69, F = 70, N = 78, O = 79, Q = 81, S = 83, W = 87, Y = 89, Z = 90;
constexpr int Delete = 261, Home = 268, F2 = 291, F12 = 301, Escape = 256;
// The numeric keypad (Blender's view keys): 1 front, 3 right, 7 top (Ctrl: the opposite side),
// 5 perspective / orthographic, . (decimal) frame the selection.
constexpr int Kp1 = 321, Kp3 = 323, Kp5 = 325, Kp7 = 327, KpDecimal = 330;
}   // namespace keys

// One backend's picture for the viewport.
struct SlotView {
    void* texture = nullptr;     // ImTextureID (GL texture name), null when no image yet
    int width = 0, height = 0;   // of the texture
    SlotStatus status;
    ProbeImage probe;     // the image itself, its frame and slot: picking and the pixel inspector
    std::string legend;   // the diagnostic view's legend ("" for the shaded image)
};
struct ViewportInput {
    std::vector<SlotView> slots;   // single view: slot 0; split: count slots; difference: A, B
    SlotView diff;                 // the difference heat-map (difference view)
};

// UI scale (HiDPI): call once after creating the context, before building fonts.
void setupStyle(float contentScale, const char* fontPath = nullptr);

// The whole window, one frame. `time` in seconds, `dt` the frame time.
void drawUi(ViewerState& st, const ViewportInput& view, double time, float dt);

// The parts (drawUi calls them; tests may call them inside their own Begin/End).
void drawMainMenu(ViewerState& st);
void drawSceneTree(ViewerState& st);
void drawInspector(ViewerState& st);
// Clip combo, Play/Pause, loop, time slider; draws nothing when the scene has no clips.
void drawAnimationPanel(ViewerState& st);
void drawCameraPanel(ViewerState& st);
void drawRenderingPanel(ViewerState& st);
void drawComparePanel(ViewerState& st);
// The pixel inspector (right panel tab "Pixel"): what the probed pixel shows in each backend.
void drawPixelPanel(ViewerState& st);
void drawViewport(ViewerState& st, const ViewportInput& view, double time, float dt);
void drawDialogs(ViewerState& st);
void handleShortcuts(ViewerState& st);

// Backends shown by the current view mode (the slots the window must render).
std::vector<std::string> visibleBackends(const ViewerState& st);
// What a backend can do (asked once per name and kept: Capabilities are constant for the life
// of a backend, GL's driver limits included, which it reads once per process whether or not it
// has rendered; empty for an unknown name). The menus decide from these, never from names.
const rnd::Capabilities& backendCapabilities(const std::string& backend);

}   // namespace ui
