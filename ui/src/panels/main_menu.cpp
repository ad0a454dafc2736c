// main_menu.cpp - drawMainMenu(): the main menu bar (File, Edit with named undo / redo, View with
// the view modes, diagnostic views, overlays and scene cameras, Backend, Help) and, on its right,
// the file name with the unsaved-changes marker.
#include "panels/panel_common.h"

#include "renderers/renderer.h"

namespace ui {

using namespace panels_detail;

namespace {

// Edit: Undo / Redo naming the step they apply (greyed when there is none), then the
// selection's rename / duplicate / delete.
void drawEditMenu(ViewerState& st) {
    bool open = ImGui::BeginMenu("Edit");
    record(st, "menu/edit");
    if (!open) return;
    const UndoStack& h = st.doc.history;
    std::string undo = h.canUndo() ? "Undo " + h.undoLabel() : std::string("Undo");
    std::string redo = h.canRedo() ? "Redo " + h.redoLabel() : std::string("Redo");
    if (ImGui::MenuItem((undo + "###undo").c_str(), "Ctrl+Z", false, h.canUndo())) st.undo();
    record(st, "edit/undo");
    if (ImGui::MenuItem((redo + "###redo").c_str(), "Ctrl+Shift+Z", false, h.canRedo())) st.redo();
    record(st, "edit/redo");
    ImGui::Separator();
    sg::NodeId sel = st.doc.selected;
    bool canEdit = st.doc.scene.valid(sel) && sel != st.doc.scene.root();
    if (ImGui::MenuItem("Rename", "F2", false, canEdit)) {
        st.ui.panels.renaming = sel;
        st.ui.panels.renameBuffer = st.doc.scene.node(sel).name;
    }
    if (ImGui::MenuItem("Duplicate", "Ctrl+D", false, canEdit)) st.duplicateNode(sel);
    if (ImGui::MenuItem("Delete", "Del", false, canEdit)) st.removeNode(sel);
    ImGui::EndMenu();
}

}   // namespace

void drawMainMenu(ViewerState& st) {
    if (!ImGui::BeginMainMenuBar()) return;
    bool fileOpen = ImGui::BeginMenu("File");
    record(st, "menu/file");
    if (fileOpen) {
        if (ImGui::MenuItem("New", "Ctrl+N")) st.requestNew();
        if (ImGui::MenuItem("Open...", "Ctrl+O")) st.ui.requests.openDialog = true;
        if (ImGui::BeginMenu("Open Recent", !st.config.recentFiles.empty())) {
            for (const std::string& f : st.config.recentFiles)
                if (ImGui::MenuItem(f.c_str())) st.requestOpen(f);
            ImGui::EndMenu();
        }
        ImGui::Separator();
        if (ImGui::MenuItem("Save", "Ctrl+S")) st.save();
        if (ImGui::MenuItem("Save As...", "Ctrl+Shift+S")) st.ui.requests.saveAsDialog = true;
        ImGui::Separator();
        if (ImGui::MenuItem("Screenshot", "F12")) st.ui.requests.screenshot = true;
        if (ImGui::MenuItem("Screenshot at resolution...")) st.ui.requests.screenshotDialog = true;
        record(st, "file/screenshotDialog");
        if (ImGui::MenuItem("Export depth, normal, id...")) st.ui.requests.exportDialog = true;
        record(st, "file/exportDialog");
        ImGui::Separator();
        if (ImGui::MenuItem("Quit", "Ctrl+Q")) st.requestQuit();
        ImGui::EndMenu();
    }
    drawEditMenu(st);
    bool viewOpen = ImGui::BeginMenu("View");
    record(st, "menu/view");
    if (viewOpen) {
        if (ImGui::MenuItem("Fit to scene / selection", "F")) st.fitView(!st.selection().empty());
        if (ImGui::MenuItem("Reset to scene camera", "Home")) st.resetView();
        if (ImGui::BeginMenu("Axis view")) {
            // Blender's keypad: 1 front, 3 right, 7 top; Ctrl for the opposite side.
            static constexpr std::pair<AxisView, std::pair<const char*, const char*>> kViews[] = {
                {AxisView::Front, {"Front", "Keypad 1"}},     {AxisView::Back, {"Back", "Ctrl+Keypad 1"}},
                {AxisView::Right, {"Right", "Keypad 3"}},     {AxisView::Left, {"Left", "Ctrl+Keypad 3"}},
                {AxisView::Top, {"Top", "Keypad 7"}},         {AxisView::Bottom, {"Bottom", "Ctrl+Keypad 7"}},
                {AxisView::Isometric, {"Isometric", nullptr}}};
            for (const auto& [v, text] : kViews) {
                if (ImGui::MenuItem(text.first, text.second)) st.viewAlong(v);
                record(st, std::string("view/axis/") + text.first);
            }
            ImGui::EndMenu();
        }
        record(st, "view/axis");
        if (ImGui::MenuItem("Perspective / orthographic", "Keypad 5", st.projection().type == sg::ProjectionType::Perspective))
            st.togglePerspective();
        if (ImGui::MenuItem("Viewport only", "Ctrl+Space", st.view.panelsHidden)) st.view.panelsHidden = !st.view.panelsHidden;
        record(st, "view/panels");
        if (ImGui::BeginMenu("UI scale")) {   // on top of the monitor's content scale
            for (float f : {0.75f, 1.0f, 1.25f, 1.5f, 2.0f}) {
                char label[16];
                std::snprintf(label, sizeof label, "%.0f%%", 100.0f * f);
                if (ImGui::MenuItem(label, nullptr, std::abs(st.view.uiScale - f) < 1e-3f) && std::abs(st.view.uiScale - f) >= 1e-3f) {
                    st.view.uiScale = f;
                    st.view.uiScaleChanged = true;
                    saveUiScale(st.config.dir, f);
                }
            }
            ImGui::EndMenu();
        }
        ImGui::Separator();
        // The same modes as the Compare tab, --view and the automation's `view` (showView).
        std::string mode = st.viewName();
        if (ImGui::MenuItem("Single backend", nullptr, mode == "single")) st.showView(ViewMode::Single);
        record(st, "view/single");
        if (ImGui::MenuItem("Split view, 2 backends (wipe)", nullptr, mode == "split")) st.showView(ViewMode::Split, 2);
        record(st, "view/split");
        if (ImGui::MenuItem("Split view, 3 backends", nullptr, mode == "split3")) st.showView(ViewMode::Split, 3);
        record(st, "view/split3");
        if (ImGui::MenuItem("Difference view", nullptr, mode == "difference")) st.showView(ViewMode::Difference);
        record(st, "view/difference");
        ImGui::Separator();
        bool diagOpen = ImGui::BeginMenu("Diagnostic view");
        record(st, "view/diagnostic");
        if (diagOpen) {
            // A view no shown backend can make (overdraw: rasterizers, cost: the ray caster) is
            // greyed out, with the backends that can in its tooltip.
            const std::vector<std::string> shown = visibleBackends(st);
            for (std::string_view name : rnd::diagnosticViewNames()) {
                rnd::DiagnosticView v{};
                rnd::parseDiagnosticView(name, v);
                bool any = false;
                for (const std::string& b : shown) any = any || rnd::diagnosticViewSupported(v, backendCapabilities(b));
                if (ImGui::MenuItem(std::string(name).c_str(), nullptr, st.view.diagnostic == v, any)) st.view.diagnostic = v;
                record(st, "diagnostic/" + std::string(name));
                if (!any && ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
                    std::string can;
                    for (const std::string& b : rnd::rendererNames())
                        if (rnd::diagnosticViewSupported(v, backendCapabilities(b))) can += (can.empty() ? "" : ", ") + b;
                    ImGui::SetTooltip("%s: not available in the shown backends%s", std::string(name).c_str(),
                                      can.empty() ? "" : (" (backends that can: " + can + ")").c_str());
                }
            }
            ImGui::EndMenu();
        }
        if (ImGui::BeginMenu("Overlays")) {   // renderers/overlay.h; the selection is outlined already
            rnd::OverlayOptions& o = st.view.overlays;
            for (auto [label, flag] : {std::pair{"Grid", &o.grid},
                                       {"Axes", &o.axes},
                                       {"Lights", &o.lights},
                                       {"Cameras", &o.cameras},
                                       {"Bounding boxes", &o.bounds},
                                       {"Selection bounds", &o.selection}})
                ImGui::MenuItem(label, nullptr, flag);
            ImGui::Separator();
            // The grid is hidden behind surfaces (lines on a floor still show); this draws it over them.
            ImGui::MenuItem("Grid on top", nullptr, &o.gridOnTop, o.grid);
            if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
                ImGui::SetTooltip("Draw the grid over every surface instead of behind them");
            ImGui::EndMenu();
        }
        ImGui::MenuItem("Stats overlay", nullptr, &st.ui.panels.showOverlay);
        if (ImGui::BeginMenu("Scene cameras", !st.doc.scene.cameras().empty())) {
            for (sg::NodeId c : st.doc.scene.cameras())
                if (ImGui::MenuItem(st.doc.scene.node(c).name.c_str(), nullptr, c == st.doc.scene.activeCamera)) st.useSceneCamera(c);
            ImGui::EndMenu();
        }
        ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Backend")) {
        std::vector<std::string> names = rnd::rendererNames();
        for (size_t i = 0; i < names.size(); ++i) {
            std::string key = std::to_string(i + 1);
            if (ImGui::MenuItem(names[i].c_str(), key.c_str(), st.view.backend == names[i])) {
                st.setBackend(names[i]);
                st.showView(ViewMode::Single);
            }
        }
        ImGui::EndMenu();
    }
    bool helpOpen = ImGui::BeginMenu("Help");
    record(st, "menu/help");
    if (helpOpen) {
        ImGui::MenuItem("Controls", nullptr, &st.ui.panels.showHelp);
        record(st, "help/controls");
        ImGui::EndMenu();
    }
    // Right side: file name and dirty marker.
    std::string title = (st.doc.path.empty() ? st.doc.scene.name : st.doc.path.filename().string()) + (st.doc.dirty ? " *" : "");
    float w = ImGui::CalcTextSize(title.c_str()).x;
    ImGui::SameLine(ImGui::GetWindowWidth() - w - px(12));
    ImGui::TextDisabled("%s", title.c_str());
    ImGui::EndMainMenuBar();
}

}   // namespace ui
