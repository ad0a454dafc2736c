// layout.cpp - drawUi(): one frame of the whole window. Main menu, the Scene panel on the
// left, the Properties panel (animation bar, tabs) on the right, the viewport between them, the
// status bar (load progress, render notes), the dialogs; Escape closing menus, and the keyboard
// shortcuts (handleShortcuts).
#include "panels/panel_common.h"

#include <imgui_internal.h>   // the open-popup stack: Escape closes the innermost menu or combo

#include <cstdio>

namespace ui {

using namespace panels_detail;

void handleShortcuts(ViewerState& st) {
    ImGuiIO& io = ImGui::GetIO();
    if (io.WantTextInput || st.view.flyMode) return;
    if (ImGui::IsPopupOpen(nullptr, ImGuiPopupFlags_AnyPopupId)) return;
    bool ctrl = io.KeyCtrl;
    if (ctrl) {
        if (ImGui::IsKeyPressed(keys::O, false)) st.ui.requests.openDialog = true;
        if (ImGui::IsKeyPressed(keys::S, false)) {
            if (io.KeyShift)
                st.ui.requests.saveAsDialog = true;
            else
                st.save();
        }
        if (ImGui::IsKeyPressed(keys::N, false)) st.requestNew();
        if (ImGui::IsKeyPressed(keys::Q, false)) st.requestQuit();
        if (ImGui::IsKeyPressed(keys::D, false)) st.duplicateNode(st.doc.selected);
        if (ImGui::IsKeyPressed(keys::Z, false)) {
            if (io.KeyShift)
                st.redo();
            else
                st.undo();
        }
        if (ImGui::IsKeyPressed(keys::Y, false)) st.redo();
        if (ImGui::IsKeyPressed(keys::Kp1, false)) st.viewAlong(AxisView::Back);
        if (ImGui::IsKeyPressed(keys::Kp3, false)) st.viewAlong(AxisView::Left);
        if (ImGui::IsKeyPressed(keys::Kp7, false)) st.viewAlong(AxisView::Bottom);
        if (ImGui::IsKeyPressed(keys::Space, false)) st.view.panelsHidden = !st.view.panelsHidden;
        return;
    }
    if (ImGui::IsKeyPressed(keys::Kp1, false)) st.viewAlong(AxisView::Front);
    if (ImGui::IsKeyPressed(keys::Kp3, false)) st.viewAlong(AxisView::Right);
    if (ImGui::IsKeyPressed(keys::Kp7, false)) st.viewAlong(AxisView::Top);
    if (ImGui::IsKeyPressed(keys::Kp5, false)) st.togglePerspective();
    if (ImGui::IsKeyPressed(keys::KpDecimal, false)) st.fitView(!st.selection().empty());
    if (ImGui::IsKeyPressed(keys::Escape, false) && st.ui.panels.showHelp) st.ui.panels.showHelp = false;   // Help > Controls
    for (int i = 0; i < 3; ++i)
        if (ImGui::IsKeyPressed(keys::Num1 + i, false)) {
            st.setBackendIndex(i);
            st.showView(ViewMode::Single);
        }
    if (ImGui::IsKeyPressed(keys::F, false)) st.fitView(!st.selection().empty());
    if (ImGui::IsKeyPressed(keys::Home, false)) st.resetView();
    if (ImGui::IsKeyPressed(keys::F12, false)) st.ui.requests.screenshot = true;
    if (ImGui::IsKeyPressed(keys::Delete, false)) st.removeSelection();
    if (ImGui::IsKeyPressed(keys::F2, false) && st.doc.scene.valid(st.doc.selected) && st.doc.selected != st.doc.scene.root()) {
        st.ui.panels.renaming = st.doc.selected;
        st.ui.panels.renameBuffer = st.doc.scene.node(st.doc.selected).name;
    }
}

namespace {

constexpr ImGuiWindowFlags kPanelFlags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoBringToFrontOnFocus;

// The two panels' widths for this window: each its fraction of the width, within pixel limits
// that scale with the UI; when the window is too narrow for both at their minimum beside a
// viewport of half the width, both shrink in proportion (the viewport keeps at least half).
struct PanelWidths {
    float left, right;
};
PanelWidths panelWidths(const View& v, float windowW) {
    float left = std::clamp(v.leftFraction * windowW, px(150), px(360));
    float right = std::clamp(v.rightFraction * windowW, px(240), px(520));
    const float room = 0.5f * windowW;   // what the panels may take together
    if (left + right > room) {
        const float k = room / (left + right);
        left *= k;
        right *= k;
    }
    return {left, right};
}

// A panel's width this frame (call inside its Begin); while the user drags its edge, the width
// they drag to sets its fraction of the window.
float placePanel(float& fraction, bool& resizing, float windowW) {
    const float w = ImGui::GetWindowWidth();
    resizing = ImGui::GetCurrentWindow()->ResizeBorderHeld != -1;
    if (resizing) fraction = std::clamp(w / std::max(windowW, 1.0f), 0.05f, 0.45f);
    return w;
}

// Left: the scene tree. Returns its width.
float drawScenePanel(ViewerState& st, float top, float bodyH) {
    ImGuiIO& io = ImGui::GetIO();
    const float width = panelWidths(st.view, io.DisplaySize.x).left;
    ImGui::SetNextWindowPos(ImVec2(0, top), ImGuiCond_Always);
    if (!st.ui.panels.resizingLeft) ImGui::SetNextWindowSize(ImVec2(width, bodyH), ImGuiCond_Always);
    ImGui::SetNextWindowSizeConstraints(ImVec2(px(80), bodyH), ImVec2(io.DisplaySize.x * 0.45f, bodyH));
    float w = width;
    if (ImGui::Begin("Scene", nullptr, kPanelFlags | ImGuiWindowFlags_NoSavedSettings)) {
        w = placePanel(st.view.leftFraction, st.ui.panels.resizingLeft, io.DisplaySize.x);
        drawSceneTree(st);
    }
    ImGui::End();
    return w;
}

// One tab of the right panel; selected when the automation asks for it. Its rectangle is
// recorded for the tab itself (before its contents).
void drawTab(ViewerState& st, const char* name, void (*draw)(ViewerState&)) {
    bool open = ImGui::BeginTabItem(name, nullptr, st.hooks.requestedTab == name ? ImGuiTabItemFlags_SetSelected : 0);
    record(st, std::string("tab/") + name);
    if (open) {
        draw(st);
        ImGui::EndTabItem();
    }
}

// Right: the animation bar (scenes with clips) above the tabs. Returns its width.
float drawPropertiesPanel(ViewerState& st, float top, float bodyH) {
    ImGuiIO& io = ImGui::GetIO();
    const float width = panelWidths(st.view, io.DisplaySize.x).right;
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x, top), ImGuiCond_Always, ImVec2(1.0f, 0.0f));
    if (!st.ui.panels.resizingRight) ImGui::SetNextWindowSize(ImVec2(width, bodyH), ImGuiCond_Always);
    ImGui::SetNextWindowSizeConstraints(ImVec2(px(120), bodyH), ImVec2(io.DisplaySize.x * 0.45f, bodyH));
    float w = width;
    if (ImGui::Begin("Properties", nullptr, kPanelFlags | ImGuiWindowFlags_NoSavedSettings)) {
        w = placePanel(st.view.rightFraction, st.ui.panels.resizingRight, io.DisplaySize.x);
        ImGui::PushItemWidth(-px(150));   // room for the labels on the right
        drawAnimationPanel(st);           // only when the scene has clips
        if (ImGui::BeginTabBar("tabs")) {
            drawTab(st, "Inspector", drawInspector);
            drawTab(st, "Camera", drawCameraPanel);
            drawTab(st, "Rendering", drawRenderingPanel);
            drawTab(st, "Compare", drawComparePanel);
            drawTab(st, "Pixel", drawPixelPanel);
            ImGui::EndTabBar();
        }
        st.hooks.requestedTab.clear();
        ImGui::PopItemWidth();
    }
    ImGui::End();
    return w;
}

// Centre: the viewport between the two panels.
void drawViewportWindow(ViewerState& st, const ViewportInput& view, double time, float dt, ImVec2 pos, ImVec2 size) {
    ImGui::SetNextWindowPos(pos, ImGuiCond_Always);
    ImGui::SetNextWindowSize(size, ImGuiCond_Always);
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowBorderSize, 0.0f);
    if (ImGui::Begin("Viewport", nullptr,
                     ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                         ImGuiWindowFlags_NoBringToFrontOnFocus | ImGuiWindowFlags_NoScrollWithMouse))
        drawViewport(st, view, time, dt);
    ImGui::End();
    ImGui::PopStyleVar(2);
}

// One line for the status bar: what the shown backends do not honour as asked (from their
// last RenderStats: AA substitutions, features they do not draw), "" when all is honoured.
std::string renderNotes(const ViewportInput& view) {
    std::string line;
    for (const SlotView& v : view.slots) {
        const rnd::RenderConfig& c = v.status.stats.config;
        std::string part;
        for (const std::string& n : c.notes) part += (part.empty() ? "" : "; ") + n;
        std::string list;   // shadows/reflections are on by default and not drawn by every backend
                            // (reflections: the ray caster only): the stats overlay lists them, the
                            // status line would always show them
        for (const std::string& u : c.unsupported)
            if (u != "shadows" && u != "reflections") list += (list.empty() ? "" : ", ") + u;
        if (!list.empty()) part += (part.empty() ? "" : "; ") + std::string("does not draw ") + list;
        if (!part.empty()) line += (line.empty() ? "" : "   ") + v.status.backend + ": " + part;
    }
    return line;
}

// Bottom: load progress and Cancel, the status line, what the backends do not honour, and
// on the right the view mode and frame rate.
void drawStatusBar(ViewerState& st, const ViewportInput& view, float height) {
    ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(0, io.DisplaySize.y - height), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(io.DisplaySize.x, height), ImGuiCond_Always);
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(px(8), px(2)));
    if (ImGui::Begin(
            "##status", nullptr,
            ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus)) {
        const std::string& status = st.ui.status;
        bool bad = status.rfind("Move refused", 0) == 0 || status.find("fail") != std::string::npos || status.find("refused") != std::string::npos;
        if (st.loadInProgress()) {   // progress of the load (off the UI thread) and its Cancel
            float f = st.loadProgress();
            char label[32];
            std::snprintf(label, sizeof label, "%.0f%%", 100.0f * f);
            ImGui::ProgressBar(f, ImVec2(px(180), 0), label);
            record(st, "status/loadProgress");
            ImGui::SameLine();
            ImGui::BeginDisabled(st.loadCancelRequested());
            if (ImGui::Button("Cancel##load")) st.cancelLoad();
            ImGui::EndDisabled();
            record(st, "status/cancelLoad");
            ImGui::SameLine();
        }
        if (bad)
            ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.45f, 1.0f), "%s", status.c_str());
        else
            ImGui::TextUnformatted(status.empty() ? "Ready" : status.c_str());
        if (std::string notes = renderNotes(view); !notes.empty()) {   // never a silent substitution
            ImGui::SameLine(0, px(24));
            ImGui::TextColored(ImVec4(0.95f, 0.8f, 0.4f, 1.0f), "%s", notes.c_str());
            record(st, "status/renderNotes");
        }
        const CompareConfig& c = st.view.compare;
        char right[160];
        std::string mode = c.mode == ViewMode::Single ? st.view.backend : c.mode == ViewMode::Split ? "split view" : "difference view";
        std::snprintf(right, sizeof right, "%s   %s   %.0f fps", mode.c_str(), st.loadInProgress() ? "loading..." : "", io.Framerate);
        float w = ImGui::CalcTextSize(right).x;
        ImGui::SameLine(io.DisplaySize.x - w - px(12));
        ImGui::TextDisabled("%s", right);
    }
    ImGui::End();
    ImGui::PopStyleVar();
}

}   // namespace

namespace {

// Escape closes the innermost open menu, submenu, combo or context menu, one per press. A modal
// dialog on top is left to its own Cancel (escapeCancels), so its answer is never skipped.
void closePopupOnEscape(ViewerState& st) {
    st.ui.panels.escapeClosedPopup = false;
    ImGuiContext& g = *ImGui::GetCurrentContext();
    if (!escapePressed() || g.OpenPopupStack.empty()) return;
    const ImGuiWindow* top = g.OpenPopupStack.back().Window;
    if (top && (top->Flags & ImGuiWindowFlags_Modal)) return;
    ImGui::ClosePopupToLevel(g.OpenPopupStack.Size - 1, /*restore_focus_to_window_under_popup=*/true);
    st.ui.panels.escapeClosedPopup = true;
}

}   // namespace

void drawUi(ViewerState& st, const ViewportInput& view, double time, float dt) {
    ImGuiIO& io = ImGui::GetIO();
    closePopupOnEscape(st);
    drawMainMenu(st);
    float menuH = ImGui::GetFrameHeight();
    float statusH = ImGui::GetFrameHeight() + px(4);
    float bodyH = std::max(io.DisplaySize.y - menuH - statusH, 50.0f);
    // View > Viewport only (Ctrl+Space) hides both panels.
    float leftW = st.view.panelsHidden ? 0.0f : drawScenePanel(st, menuH, bodyH);
    float rightW = st.view.panelsHidden ? 0.0f : drawPropertiesPanel(st, menuH, bodyH);
    const ImVec2 vpPos(leftW, menuH), vpSize(std::max(io.DisplaySize.x - leftW - rightW, 1.0f), bodyH);
    st.hooks.viewportRect = ItemRect{vpPos.x, vpPos.y, vpPos.x + vpSize.x, vpPos.y + vpSize.y};
    drawViewportWindow(st, view, time, dt, vpPos, vpSize);
    drawStatusBar(st, view, statusH);
    drawDialogs(st);
    handleShortcuts(st);
    // The mouse was released (or never pressed): the next edit starts a new undo step instead
    // of merging into the last drag's.
    if (!ImGui::IsAnyItemActive()) st.doc.history.closeMerge();
}

}   // namespace ui
