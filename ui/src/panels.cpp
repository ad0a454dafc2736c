// panels.cpp - Dear ImGui panels of the viewer (see panels.h).
//
// Sections:
//   1. helpers (item-rect recording, small widgets)
//   2. style
//   3. main menu
//   4. scene tree (select, visibility, context menu, drag-and-drop re-parenting)
//   5. inspector (transform TRS / matrix, world matrix, payloads, material), animation bar
//   6. camera panel (projection, scene cameras, live matrices)
//   7. rendering panel (RenderSettings)
//   8. compare panel (split / wipe / difference)
//   9. viewport (images, dividers, overlay, camera input)
//  10. dialogs (unsaved changes, errors, file browser, screenshot)
//  11. shortcuts and layout
#include "ui/panels.h"

#include "assets/aov_io.h"
#include "ui/colour.h"

#include "assets/scene_io.h"
#include "renderers/framebuffer.h"
#include "renderers/renderer.h"
#include "scenegraph/camera_model.h"
#include "scenegraph/deform.h"
#include "scenegraph/params.h"
#include "scenegraph/scene_defaults.h"
#include "scenegraph/setting_names.h"
#include "scenegraph/transforms.h"

#include <imgui.h>
#include <imgui_internal.h>   // the open-popup stack: Escape closes the innermost menu or combo
#include <imgui_stdlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>

namespace fs = std::filesystem;

namespace ui {

// --- 1. helpers --------------------------------------------------------------------------------

namespace {

// Content scale (HiDPI), set by setupStyle. It stays file-scope on purpose: it describes the
// ImGui context's style and font atlas (ImGui's own globals), which setupStyle scales
// together; per-viewer state lives in ViewerState (PanelState for the panels).
float g_scale = 1.0f;
float px(float v) { return v * g_scale; }

// Records the last item's rectangle under `key` (test hook: click widgets by position).
void record(ViewerState& st, const std::string& key) {
    ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
    st.hooks.itemRects[key] = ItemRect{a.x, a.y, b.x, b.y};
}

// A colour editor for a colour the scene stores linear: it shows and takes sRGB-encoded 0..255
// values (what the viewport and a colour picker show); only an edit writes back, so an
// untouched value never drifts. Values above 1 (HDR light colours) switch to floats.
bool srgbColorEdit(const char* label, sg::vec3& linear, ImGuiColorEditFlags flags = 0) {
    sg::vec3 shown = srgbFromLinear(linear);
    if (std::max({shown.x, shown.y, shown.z}) > 1.0f) flags |= ImGuiColorEditFlags_Float | ImGuiColorEditFlags_HDR;
    if (!ImGui::ColorEdit3(label, &shown.x, flags)) return false;
    linear = linearFromSrgb(shown);
    return true;
}

bool escapePressed() { return ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape), false); }

// Escape in a modal dialog: Cancel (or OK), unless the same press closed a menu or combo in it.
bool escapeCancels(const ViewerState& st) { return escapePressed() && !st.ui.panels.escapeClosedPopup; }

// The last item's tooltip (a table entry's help; nothing when empty).
void tooltip(std::string_view text) {
    if (!text.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%.*s", int(text.size()), text.data());
}

// A combo over a name table's entries (labels shown, help as tooltips); items recorded as label/entry label.
template <class E>
bool enumCombo(ViewerState& st, const char* label, E& value, std::span<const sg::NamedValue<E>> items) {
    std::string preview = "?";
    for (const auto& e : items)
        if (e.value == value) preview = e.label;
    bool changed = false;
    if (ImGui::BeginCombo(label, preview.c_str())) {
        for (const auto& e : items) {
            std::string name(e.label);
            if (ImGui::Selectable(name.c_str(), e.value == value)) {
                changed = e.value != value;
                value = e.value;
            }
            tooltip(e.help);
            record(st, std::string(label) + "/" + name);
        }
        ImGui::EndCombo();
    }
    record(st, label);
    return changed;
}
// A settings enum: its table from setting_names.h.
template <class E>
bool enumCombo(ViewerState& st, const char* label, E& value) {
    return enumCombo(st, label, value, sg::nameTable<E>().entries);
}

// A row of radio buttons over a name table; each recorded as key/entry label.
template <class E>
bool enumRadios(ViewerState& st, const std::string& key, E& value) {
    bool changed = false;
    ImGui::PushID(key.c_str());
    for (const auto& e : sg::nameTable<E>().entries) {
        if (&e != sg::nameTable<E>().entries.data()) ImGui::SameLine();
        std::string name(e.label);
        if (ImGui::RadioButton(name.c_str(), e.value == value)) {
            changed = true;
            value = e.value;
        }
        tooltip(e.help);
        record(st, key + "/" + name);
    }
    ImGui::PopID();
    return changed;
}

// The names of the shown backends that do not draw `feature` ("" when all do).
std::string backendsWithout(const ViewerState& st, sg::Feature feature);

// One parameter's widget from its table row (scenegraph/params.h): checkbox, slider or drag
// over the row's range, colour editor, combo or radio buttons; the help as tooltip; a note when
// a shown backend does not draw it. Recorded as `prefix`/KEY (a choice's entries as
// prefix/KEY/LABEL). Returns true when the value changed (written into `object`).
template <class T>
bool paramWidget(ViewerState& st, const std::string& prefix, const sg::Param<T>& p, T& object) {
    if (p.label.empty() || (p.shown && !p.shown(object))) return false;
    const std::string label(p.label), key = prefix + "/" + std::string(p.key);
    sg::ParamValue v = p.get(object);
    bool changed = false;
    ImGuiSliderFlags flags = ImGuiSliderFlags_AlwaysClamp | (p.logScale ? ImGuiSliderFlags_Logarithmic : 0);
    switch (p.kind) {
    case sg::ParamKind::Bool: {
        bool b = std::get<bool>(v);
        changed = ImGui::Checkbox(label.c_str(), &b);
        v = b;
        break;
    }
    case sg::ParamKind::Int: {
        int i = std::get<int>(v);
        changed = ImGui::SliderInt(label.c_str(), &i, int(p.min), int(p.max), "%d", flags);
        v = i;
        break;
    }
    case sg::ParamKind::Float: {
        float f = std::get<float>(v);
        if (p.drag)
            changed = ImGui::DragFloat(label.c_str(), &f, std::max(std::abs(f), 1e-3f) * 0.01f, float(p.min), float(p.max),
                                       p.format ? p.format : "%.3f", flags);
        else
            changed = ImGui::SliderFloat(label.c_str(), &f, float(p.min), float(p.max), p.format ? p.format : "%.3f", flags);
        v = f;
        break;
    }
    case sg::ParamKind::Color: {
        sg::vec3 c = std::get<sg::vec3>(v);
        changed = srgbColorEdit(label.c_str(), c, p.max > 1.0 ? ImGuiColorEditFlags_HDR : 0);
        if (changed) c = glm::clamp(c, sg::vec3(float(p.min)), sg::vec3(float(p.max)));
        v = c;
        break;
    }
    case sg::ParamKind::Choice: {
        const std::string cur = std::get<std::string>(v);
        const sg::ParamChoice* shown = nullptr;
        for (const sg::ParamChoice& c : p.choices)
            if (c.name == cur) shown = &c;
        ImGui::PushID(key.c_str());
        if (p.radios) {
            for (const sg::ParamChoice& c : p.choices) {
                if (&c != p.choices.data()) ImGui::SameLine();
                if (ImGui::RadioButton(std::string(c.label).c_str(), &c == shown) && &c != shown) {
                    v = std::string(c.name);
                    changed = true;
                }
                tooltip(c.help);
                record(st, key + "/" + std::string(c.label));
            }
            ImGui::SameLine();
            ImGui::TextUnformatted(label.c_str());
            tooltip(p.help);
        } else if (ImGui::BeginCombo(label.c_str(), shown ? std::string(shown->label).c_str() : cur.c_str())) {
            for (const sg::ParamChoice& c : p.choices) {
                if (ImGui::Selectable(std::string(c.label).c_str(), &c == shown) && &c != shown) {
                    v = std::string(c.name);
                    changed = true;
                }
                tooltip(c.help);
                record(st, key + "/" + std::string(c.label));
            }
            ImGui::EndCombo();
        }
        ImGui::PopID();
        break;
    }
    }
    if (p.kind != sg::ParamKind::Choice || !p.radios) {
        tooltip(p.help);
        record(st, key);
    }
    if (p.needs != sg::Feature::None)
        if (std::string without = backendsWithout(st, p.needs); !without.empty()) {
            ImGui::SameLine();
            ImGui::TextDisabled("(not drawn by %s)", without.c_str());
        }
    return changed && p.set(object, v);
}

// Every row of T's table in `section` (all rows when empty), in table order.
template <class T>
bool paramSection(ViewerState& st, const std::string& prefix, std::string_view section, T& object) {
    bool changed = false;
    for (const sg::Param<T>& p : sg::params<T>())
        if (section.empty() || p.section == section) changed |= paramWidget(st, prefix, p, object);
    return changed;
}

// A read-only 4x4 matrix as four rows.
void matrixTable(const char* id, const sg::mat4& m) {
    if (ImGui::BeginTable(id, 4, ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_SizingStretchSame)) {
        for (int r = 0; r < 4; ++r) {
            ImGui::TableNextRow();
            for (int c = 0; c < 4; ++c) {
                ImGui::TableSetColumnIndex(c);
                ImGui::Text("%8.3f", m[c][r]);
            }
        }
        ImGui::EndTable();
    }
}

// A titled separator (ImGui 1.86 has no SeparatorText).
void section(const char* title) {
    ImGui::Spacing();
    ImGui::TextColored(ImVec4(0.55f, 0.75f, 1.0f, 1.0f), "%s", title);
    ImGui::Separator();
}

void helpMarker(const char* text) {
    ImGui::SameLine();
    ImGui::TextDisabled("(?)");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text);
}

const char* payloadIcon(const sg::Payload& p) {
    switch (p.index()) {
    case 0: return "[G]";
    case 1: return "[M]";
    case 2: return "[C]";
    case 3: return "[L]";
    case 4: return "[S]";
    case 5: return "[B]";
    case 6: return "[P]";
    case 7: return "[V]";
    default: return "[?]";
    }
}

// The "Add" menu items (shared by the toolbar popup and the context menu).
void addMenuItems(ViewerState& st, sg::NodeId parent) {
    if (ImGui::MenuItem("Group")) st.addGroup(parent);
    ImGui::Separator();
    for (const auto& e : sg::nameTable<sg::ImplicitType>().entries) {
        const sg::ImplicitType t = e.value;
        const std::string label(e.label);
        const char* name = label.c_str();
        if (ImGui::MenuItem(name)) st.addShape(t, parent);
        record(st, std::string("add/") + name);
    }
    ImGui::Separator();
    for (const auto& e : sg::nameTable<sg::CsgOp>().entries)
        if (ImGui::MenuItem(("CSG " + std::string(e.name)).c_str())) st.addCsg(e.value, parent);
    ImGui::Separator();
    for (const auto& e : sg::nameTable<sg::LightType>().entries)
        if (ImGui::MenuItem((std::string(e.label) + " light").c_str())) st.addLight(e.value, parent);
    if (ImGui::MenuItem("Camera (at current view)")) st.addCamera();
}

}   // namespace

const rnd::Capabilities& backendCapabilities(const std::string& backend) {
    static std::mutex mutex;
    static std::map<std::string, rnd::Capabilities> known;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = known.find(backend);
    if (it == known.end()) {
        rnd::Capabilities c;
        if (auto r = rnd::makeRenderer(backend)) c = r->capabilities();   // a GL backend makes no context until it renders
        it = known.emplace(backend, std::move(c)).first;
    }
    return it->second;
}

std::vector<std::string> visibleBackends(const ViewerState& st) {
    const CompareConfig& c = st.view.compare;
    // A view whose backends were never chosen (mode set without showView) shows its defaults.
    auto chosen = [&](auto& slots, size_t n) {
        std::vector<std::string> v = comparisonBackends(st.view.backend, slots.size());
        for (size_t i = 0; i < slots.size(); ++i)
            if (!slots[i].empty()) v[i] = slots[i];
        v.resize(n);
        return v;
    };
    switch (c.mode) {
    case ViewMode::Single: return {st.view.backend};
    case ViewMode::Split: return chosen(c.split, size_t(std::clamp(c.count, 2, 3)));
    case ViewMode::Difference: return chosen(c.diff, 2);
    }
    return {st.view.backend};
}

namespace {
std::string backendsWithout(const ViewerState& st, sg::Feature feature) {
    std::string names;
    for (const std::string& b : visibleBackends(st))
        if (!rnd::hasFeature(backendCapabilities(b), feature) && names.find(b) == std::string::npos) names += (names.empty() ? "" : ", ") + b;
    return names;
}
}   // namespace

// --- 2. style ----------------------------------------------------------------------------------

void setupStyle(float scale, const char* fontPath) {
    g_scale = std::clamp(scale, 0.5f, 4.0f);
    ImGuiIO& io = ImGui::GetIO();
    ImGui::GetStyle() = ImGuiStyle();   // sizes are scaled below: start from the defaults
    ImGui::StyleColorsDark();
    ImGuiStyle& s = ImGui::GetStyle();
    io.Fonts->Clear();
    s.WindowRounding = 0.0f;
    s.FrameRounding = 3.0f;
    s.GrabRounding = 3.0f;
    s.TabRounding = 3.0f;
    s.ScrollbarRounding = 3.0f;
    s.WindowBorderSize = 1.0f;
    s.FramePadding = ImVec2(6, 4);
    s.ItemSpacing = ImVec2(8, 5);
    s.IndentSpacing = 14.0f;
    ImVec4* c = s.Colors;
    c[ImGuiCol_WindowBg] = ImVec4(0.13f, 0.14f, 0.16f, 1.0f);
    c[ImGuiCol_ChildBg] = ImVec4(0.11f, 0.12f, 0.14f, 1.0f);
    c[ImGuiCol_MenuBarBg] = ImVec4(0.10f, 0.11f, 0.13f, 1.0f);
    c[ImGuiCol_Header] = ImVec4(0.22f, 0.36f, 0.56f, 0.70f);
    c[ImGuiCol_HeaderHovered] = ImVec4(0.26f, 0.42f, 0.66f, 0.80f);
    c[ImGuiCol_HeaderActive] = ImVec4(0.28f, 0.46f, 0.72f, 1.00f);
    c[ImGuiCol_FrameBg] = ImVec4(0.19f, 0.20f, 0.23f, 1.0f);
    c[ImGuiCol_TitleBgActive] = ImVec4(0.16f, 0.29f, 0.48f, 1.0f);
    s.ScaleAllSizes(g_scale);
    if (fontPath && fs::exists(fontPath)) {
        ImFontConfig cfg;
        cfg.OversampleH = 2;
        io.Fonts->AddFontFromFileTTF(fontPath, std::round(15.0f * g_scale), &cfg);
    } else {
        ImFontConfig cfg;
        cfg.SizePixels = std::round(13.0f * g_scale);
        io.Fonts->AddFontDefault(&cfg);
    }
}

// --- 3. main menu ------------------------------------------------------------------------------

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

// --- 4. scene tree -----------------------------------------------------------------------------

namespace {

void nodeContextMenu(ViewerState& st, sg::NodeId id) {
    if (!ImGui::BeginPopupContextItem()) return;
    st.selectNode(id);
    // No Node references are held here: adding nodes may reallocate the scene's node array.
    if (ImGui::BeginMenu("Add child")) {
        addMenuItems(st, id);
        ImGui::EndMenu();
    }
    if (st.doc.scene.valid(id) && id != st.doc.scene.root()) {
        if (ImGui::MenuItem("Rename", "F2")) {
            st.ui.panels.renaming = id;
            st.ui.panels.renameBuffer = st.doc.scene.node(id).name;
        }
        if (ImGui::MenuItem("Duplicate", "Ctrl+D")) st.duplicateNode(id);
        bool visible = st.doc.scene.valid(id) && st.doc.scene.node(id).visible;
        if (ImGui::MenuItem(visible ? "Hide" : "Show")) st.setVisible(id, !visible);
        if (ImGui::MenuItem("Delete", "Del")) st.removeNode(id);
    }
    if (st.doc.scene.valid(id)) {
        if (ImGui::MenuItem("Frame in view", "F")) st.fitView(true);
        if (std::holds_alternative<sg::Camera>(st.doc.scene.node(id).payload) && ImGui::MenuItem("Look through")) st.useSceneCamera(id);
    }
    ImGui::EndPopup();
}

// Iterative-safe enough: depth is capped, deeper levels are listed flat under a marker.
void drawNode(ViewerState& st, sg::NodeId id, int depth) {
    const sg::Node& n = st.doc.scene.node(id);
    ImGui::PushID(int(id));
    // Visibility toggle.
    bool vis = n.visible;
    ImGui::PushStyleVar(ImGuiStyleVar_FramePadding, ImVec2(1, 1));
    if (id != st.doc.scene.root()) {
        if (ImGui::Checkbox("##vis", &vis)) st.setVisible(id, vis);
        record(st, "tree/vis/" + n.name);
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("Show / hide");
        ImGui::SameLine();
    }
    ImGui::PopStyleVar();

    ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_OpenOnArrow | ImGuiTreeNodeFlags_OpenOnDoubleClick | ImGuiTreeNodeFlags_SpanAvailWidth;
    if (n.children.empty()) flags |= ImGuiTreeNodeFlags_Leaf;
    if (depth < 2) flags |= ImGuiTreeNodeFlags_DefaultOpen;
    if (st.isSelected(id)) flags |= ImGuiTreeNodeFlags_Selected;
    bool dim = !st.doc.scene.effectiveVisible(id);
    if (dim) ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
    std::string label = std::string(payloadIcon(n.payload)) + " " + n.name + (id == st.doc.scene.activeCamera ? "  (active)" : "");
    bool open;
    if (st.ui.panels.renaming == id) {
        open = ImGui::TreeNodeEx("##renaming", flags | ImGuiTreeNodeFlags_AllowItemOverlap, "%s", payloadIcon(n.payload));
        ImGui::SameLine();
        ImGui::SetKeyboardFocusHere();
        ImGui::SetNextItemWidth(-1);
        if (ImGui::InputText("##rename", &st.ui.panels.renameBuffer, ImGuiInputTextFlags_EnterReturnsTrue | ImGuiInputTextFlags_AutoSelectAll)) {
            st.renameNode(id, st.ui.panels.renameBuffer);
            st.ui.panels.renaming = sg::kNoNode;
        } else if (ImGui::IsItemDeactivated() || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) {
            st.ui.panels.renaming = sg::kNoNode;
        }
    } else {
        open = ImGui::TreeNodeEx("##node", flags, "%s", label.c_str());
        record(st, "tree/" + n.name);
        if (ImGui::IsItemClicked() && !ImGui::IsItemToggledOpen()) {
            if (ImGui::GetIO().KeyCtrl)
                st.toggleSelected(id);   // Ctrl+click adds or takes out
            else
                st.selectNode(id);
        }
        if (ImGui::IsItemHovered() && ImGui::IsMouseDoubleClicked(0) && n.children.empty() && id != st.doc.scene.root()) {
            st.ui.panels.renaming = id;
            st.ui.panels.renameBuffer = n.name;
        }
    }
    if (dim) ImGui::PopStyleColor();

    // Drag source / drop target: re-parent keeping the world transform.
    if (id != st.doc.scene.root() && ImGui::BeginDragDropSource()) {
        sg::NodeId payload = id;
        ImGui::SetDragDropPayload("SG_NODE", &payload, sizeof(payload));
        ImGui::Text("Move %s", st.doc.scene.node(id).name.c_str());
        ImGui::EndDragDropSource();
    }
    if (ImGui::BeginDragDropTarget()) {
        if (const ImGuiPayload* p = ImGui::AcceptDragDropPayload("SG_NODE")) {
            sg::NodeId moved = *static_cast<const sg::NodeId*>(p->Data);
            std::string err;
            if (st.doc.scene.valid(moved) && !st.reparent(moved, id, &err) && !err.empty())
                st.ui.errorPopup = "Cannot move '" + st.doc.scene.node(moved).name + "' under '" + st.doc.scene.node(id).name + "':\n" + err;
        }
        ImGui::EndDragDropTarget();
    }
    nodeContextMenu(st, id);

    if (open) {
        // Copy: edits in the loop (context menu) may change the children vector.
        std::vector<sg::NodeId> kids = st.doc.scene.valid(id) ? st.doc.scene.node(id).children : std::vector<sg::NodeId>{};
        for (sg::NodeId c : kids) {
            if (!st.doc.scene.valid(c)) continue;
            if (depth > 200) {
                ImGui::TextDisabled("... (deeper levels not shown)");
                break;
            }
            drawNode(st, c, depth + 1);
        }
        ImGui::TreePop();
    }
    ImGui::PopID();
}

}   // namespace

void drawSceneTree(ViewerState& st) {
    // Toolbar.
    if (ImGui::Button("Add")) ImGui::OpenPopup("add_popup");
    record(st, "tree/addButton");
    if (ImGui::BeginPopup("add_popup")) {
        addMenuItems(st, sg::kNoNode);
        ImGui::EndPopup();
    }
    ImGui::SameLine();
    bool canEdit = st.doc.scene.valid(st.doc.selected) && st.doc.selected != st.doc.scene.root();
    ImGui::BeginDisabled(!canEdit);
    if (ImGui::Button("Duplicate")) st.duplicateNode(st.doc.selected);
    ImGui::SameLine();
    if (ImGui::Button("Delete")) st.removeSelection();
    ImGui::EndDisabled();
    ImGui::Separator();

    ImGui::BeginChild("tree", ImVec2(0, 0), false);
    drawNode(st, st.doc.scene.root(), 0);
    // Empty space below the tree: drop here to move under the root; click to deselect.
    ImVec2 avail = ImGui::GetContentRegionAvail();
    ImGui::InvisibleButton("##treeEmpty", ImVec2(std::max(avail.x, 1.0f), std::max(avail.y, px(20))));
    if (ImGui::IsItemClicked()) st.selectNode(sg::kNoNode);
    if (ImGui::BeginDragDropTarget()) {
        if (const ImGuiPayload* p = ImGui::AcceptDragDropPayload("SG_NODE"))
            st.reparent(*static_cast<const sg::NodeId*>(p->Data), st.doc.scene.root());
        ImGui::EndDragDropTarget();
    }
    ImGui::EndChild();
}

// --- 5. inspector ------------------------------------------------------------------------------

namespace {

// Material editor for the material index of node `id`'s payload. Returns true when the index
// changed. Edits of one material while a widget is held merge into one undo step.
bool materialEditor(ViewerState& st, sg::NodeId id, int& index) {
    bool indexChanged = false;
    std::string preview = index < 0 || size_t(index) >= st.doc.scene.materials.size()
                              ? std::string("(default)")
                              : std::to_string(index) + ": " + st.doc.scene.materials[index].name;
    if (ImGui::BeginCombo("Material", preview.c_str())) {
        if (ImGui::Selectable("(default)", index < 0)) {
            index = -1;
            indexChanged = true;
        }
        for (size_t i = 0; i < st.doc.scene.materials.size(); ++i) {
            std::string n = std::to_string(i) + ": " + st.doc.scene.materials[i].name;
            if (ImGui::Selectable(n.c_str(), int(i) == index)) {
                index = int(i);
                indexChanged = true;
            }
        }
        ImGui::EndCombo();
    }
    ImGui::SameLine();
    if (ImGui::SmallButton("New")) {   // one undo step: the material and the node's index
        sg::Material m = st.doc.scene.material(index);
        m.name = "material " + std::to_string(st.doc.scene.materials.size());
        int added = st.addMaterialFor(id, m);
        if (added >= 0) index = added;   // the node already has it: no second step
    }
    record(st, "material/new");
    if (index < 0 || size_t(index) >= st.doc.scene.materials.size()) {
        ImGui::TextDisabled("Default material (press New to edit a copy)");
        return indexChanged;
    }
    sg::Material m = st.doc.scene.materials[index];
    bool ch = false;
    ch |= ImGui::InputText("Name##mat", &m.name, ImGuiInputTextFlags_EnterReturnsTrue);
    ch |= paramSection(st, "material", "Phong", m);
    int tex = m.diffuseTexture;
    if (ImGui::InputInt("Texture index", &tex)) {
        m.diffuseTexture = std::clamp(tex, -1, int(st.doc.scene.textures.size()) - 1);
        ch = true;
    }
    helpMarker("-1 = none; index into the scene's textures");
    ch |= paramSection(st, "material", "Alpha", m);
    if (ch) st.setMaterial(index, m, "material " + std::to_string(index));
    return indexChanged;
}

bool implicitEditor(ViewerState& st, sg::ImplicitShape& s) {
    bool ch = enumCombo(st, "Shape", s.type);
    switch (s.type) {
    case sg::ImplicitType::Sphere: ch |= ImGui::DragFloat("Radius", &s.radius, 0.01f, 0.001f, 1e4f); break;
    case sg::ImplicitType::Box: ch |= ImGui::DragFloat3("Half extents", &s.halfExtents.x, 0.01f, 0.001f, 1e4f); break;
    case sg::ImplicitType::Cylinder:
    case sg::ImplicitType::Cone:
        ch |= ImGui::DragFloat("Radius", &s.radius, 0.01f, 0.001f, 1e4f);
        ch |= ImGui::DragFloat("Half height", &s.halfHeight, 0.01f, 0.001f, 1e4f);
        break;
    case sg::ImplicitType::Torus:
        ch |= ImGui::DragFloat("Major radius", &s.majorRadius, 0.01f, 0.001f, 1e4f);
        ch |= ImGui::DragFloat("Minor radius", &s.minorRadius, 0.01f, 0.001f, 1e4f);
        break;
    case sg::ImplicitType::Plane: ch |= ImGui::DragFloat("Drawn half size", &s.planeHalfSize, 0.1f, 0.01f, 1e5f); break;
    case sg::ImplicitType::Quadric:
        ImGui::TextUnformatted("Q (x^T Q x = 0), rows:");
        for (int r = 0; r < 4; ++r) {
            float row[4] = {s.quadric[0][r], s.quadric[1][r], s.quadric[2][r], s.quadric[3][r]};
            ImGui::PushID(r);
            if (ImGui::DragFloat4("##q", row, 0.01f)) {
                for (int c = 0; c < 4; ++c) s.quadric[c][r] = s.quadric[r][c] = row[c];   // keep Q symmetric
                ch = true;
            }
            ImGui::PopID();
        }
        ch |= ImGui::DragFloat3("Clip min", &s.quadricBounds.min.x, 0.01f);
        ch |= ImGui::DragFloat3("Clip max", &s.quadricBounds.max.x, 0.01f);
        break;
    }
    return ch;
}

void transformEditor(ViewerState& st, sg::NodeId id) {
    const sg::Node& n = st.doc.scene.node(id);
    sg::LocalTransform t = n.local;
    bool trs = t.mode == sg::LocalTransform::Mode::TRS;
    ImGui::Text("Mode: %s", trs ? "TRS (translate, rotate, scale)" : "Matrix (general affine)");
    if (trs) {
        sg::vec3 e = t.eulerDegrees();
        bool ch = false;
        ch |= ImGui::DragFloat3("Translation", &t.translation.x, 0.01f);
        record(st, "inspector/translation");
        if (ImGui::DragFloat3("Rotation (deg)", &e.x, 0.5f)) {
            t.setEulerDegrees(e);
            ch = true;
        }
        helpMarker("Euler angles applied X, then Y, then Z (R = Rz Ry Rx)");
        ch |= ImGui::DragFloat3("Scale", &t.scale.x, 0.01f);
        if (ch) st.setLocal(id, t, "local " + std::to_string(id));
    } else {
        if (ImGui::Button("Convert back to TRS")) {
            sg::LocalTransform c = t;
            if (c.tryMakeTRS())
                st.setLocal(id, c);
            else
                st.ui.errorPopup = "This matrix has shear (or is not affine): it cannot be written as translate * rotate * scale.";
        }
        record(st, "inspector/toTRS");
    }
    ImGui::TextUnformatted("Local matrix (rows; editing switches to Matrix mode):");
    sg::mat4 m = t.toMatrix();
    bool mch = false;
    for (int r = 0; r < 3; ++r) {
        float row[4] = {m[0][r], m[1][r], m[2][r], m[3][r]};
        ImGui::PushID(r);
        ImGui::SetNextItemWidth(-1);
        if (ImGui::DragFloat4("##row", row, 0.01f, 0, 0, "%.3f")) {
            for (int c = 0; c < 4; ++c) m[c][r] = row[c];
            mch = true;
        }
        record(st, "inspector/matrixRow" + std::to_string(r));
        ImGui::PopID();
    }
    ImGui::TextDisabled("   0.000      0.000      0.000      1.000");
    if (ImGui::SmallButton("Mirror X")) {
        m = m * glm::scale(sg::mat4(1.0f), sg::vec3(-1, 1, 1));
        mch = true;
    }
    record(st, "inspector/mirrorX");
    ImGui::SameLine();
    if (ImGui::SmallButton("Shear XY")) {
        sg::mat4 s(1.0f);
        s[1][0] = 0.25f;
        m = m * s;
        mch = true;
    }
    record(st, "inspector/shear");
    ImGui::SameLine();
    if (ImGui::SmallButton("Identity")) { st.setLocal(id, sg::LocalTransform{}); }
    if (mch) {
        if (sg::isFinite(m) && sg::isInvertible(m))
            st.setLocal(id, sg::LocalTransform::fromMatrix(m), "local " + std::to_string(id));
        else
            st.ui.status = "Matrix edit refused: singular or not finite";
    }
    if (ImGui::TreeNode("World matrix (read-only)")) {
        matrixTable("world", st.doc.scene.world(id));
        ImGui::TreePop();
    }
}

// Inspector with nothing selected: what the scene holds, and its ambient light.
void sceneSummary(ViewerState& st) {
    sg::Scene& scene = st.doc.scene;
    ImGui::TextDisabled("Select a node in the scene tree.");
    ImGui::Spacing();
    ImGui::Text("Scene: %s", scene.name.c_str());
    ImGui::Text("Nodes: %zu   meshes: %zu   materials: %zu   textures: %zu", scene.nodeCount(), scene.meshes.size(), scene.materials.size(),
                scene.textures.size());
    sg::RenderSettings s = scene.settings;
    if (paramWidget(st, "render", *sg::findParam<sg::RenderSettings>("ambientLight"), s)) st.setSettings(s, "settings");
}

// Name, kind and id, visibility.
void nodeHeader(ViewerState& st, sg::NodeId id) {
    const sg::Node& n = st.doc.scene.node(id);
    std::string name = n.name;
    ImGui::SetNextItemWidth(-px(70));
    if (ImGui::InputText("Name", &name, ImGuiInputTextFlags_EnterReturnsTrue)) st.renameNode(id, name);
    record(st, "inspector/name");
    ImGui::TextDisabled("%s  (id %u)", std::string(sg::payloadKind(n.payload)).c_str(), id);
    if (id != st.doc.scene.root()) {
        ImGui::SameLine();
        bool vis = n.visible;
        if (ImGui::Checkbox("Visible", &vis)) st.setVisible(id, vis);
        record(st, "inspector/visible");
    }
}

// The payload sections below edit a copy of the payload and return true when it changed;
// drawInspector writes it back.

bool materialSection(ViewerState& st, sg::NodeId id, int& index) {
    return ImGui::CollapsingHeader("Material", ImGuiTreeNodeFlags_DefaultOpen) && materialEditor(st, id, index);
}

// Mesh facts, the skin, and the instance's morph weights (editable; an animation playing sets them too).
bool meshSection(const ViewerState& st, sg::MeshInstance& mi) {
    if (!ImGui::CollapsingHeader("Mesh", ImGuiTreeNodeFlags_DefaultOpen)) return false;
    const sg::Scene& scene = st.doc.scene;
    if (mi.mesh < 0 || size_t(mi.mesh) >= scene.meshes.size() || !scene.meshes[mi.mesh]) {
        ImGui::TextColored(ImVec4(1, 0.5f, 0.4f, 1), "Mesh index %d is missing", mi.mesh);
        return false;
    }
    const sg::Mesh& mesh = *scene.meshes[mi.mesh];
    ImGui::Text("Mesh %d: %zu vertices, %zu triangles", mi.mesh, mesh.positions.size(), mesh.indices.size() / 3);
    if (sg::isSkinned(scene, mi)) {
        const sg::Skin& skin = scene.skins[size_t(mi.skin)];
        ImGui::Text("Skin '%s': %zu joints (drawn where the joints put it)", skin.name.c_str(), skin.joints.size());
    }
    if (mesh.morphTargets.empty()) return false;
    std::vector<float> w = sg::instanceMorphWeights(mesh, mi);
    bool ch = false;
    for (size_t k = 0; k < w.size() && k < 16; ++k) ch |= ImGui::SliderFloat(("Morph weight " + std::to_string(k)).c_str(), &w[k], 0.0f, 1.0f);
    if (w.size() > 16) ImGui::TextDisabled("(%zu more morph targets)", w.size() - 16);
    if (ch) mi.weights = std::move(w);
    return ch;
}

// Operation, and a menu adding implicit operands under the node `id`.
bool csgSection(ViewerState& st, sg::NodeId id, sg::CsgPayload& cp) {
    if (!ImGui::CollapsingHeader("CSG", ImGuiTreeNodeFlags_DefaultOpen)) return false;
    bool ch = enumCombo(st, "Operation", cp.csg.op);
    ImGui::TextDisabled("Children combine left to right (first child minus the others for difference).");
    if (ImGui::Button("Add operand")) ImGui::OpenPopup("csg_add");
    if (ImGui::BeginPopup("csg_add")) {
        for (const auto& e : sg::nameTable<sg::ImplicitType>().entries)
            if (ImGui::MenuItem(std::string(e.label).c_str())) st.addShape(e.value, id);
        ImGui::EndPopup();
    }
    return ch;
}

bool lightSection(ViewerState& st, sg::Light& l) {
    if (!ImGui::CollapsingHeader("Light", ImGuiTreeNodeFlags_DefaultOpen)) return false;
    bool ch = paramSection(st, "light", "", l);
    l.spotInnerDeg = std::min(l.spotInnerDeg, l.spotOuterDeg);
    ImGui::TextDisabled("Lights point down their local -z axis.");
    return ch;
}

bool cameraSection(ViewerState& st, sg::NodeId id, sg::Camera& cam) {
    if (!ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) return false;
    if (ImGui::Button("Look through this camera")) st.useSceneCamera(id);
    ImGui::SameLine();
    ImGui::TextDisabled("(projection: Camera tab)");
    return ImGui::DragFloat("Focus distance", &cam.focusDistance, 0.05f, 0.001f, 1e5f);
}

bool parametricSection(ViewerState& st, sg::ParametricPayload& pp) {
    if (!ImGui::CollapsingHeader("Parametric surface", ImGuiTreeNodeFlags_DefaultOpen)) return false;
    bool ch = enumCombo(st, "Surface", pp.surface.type);
    if (pp.surface.type == sg::ParametricType::Torus) {
        ch |= ImGui::DragFloat("Major radius", &pp.surface.majorRadius, 0.01f, 0.001f, 1e4f);
        ch |= ImGui::DragFloat("Minor radius", &pp.surface.minorRadius, 0.01f, 0.001f, 1e4f);
    } else if (ImGui::TreeNode("Control points")) {
        for (int i = 0; i < 16; ++i) {
            ImGui::PushID(i);
            ch |= ImGui::DragFloat3("##cp", &pp.surface.control[i].x, 0.01f);
            ImGui::PopID();
        }
        ImGui::TreePop();
    }
    return ch;
}

bool gridSection(sg::GridPayload& gp) {
    if (!ImGui::CollapsingHeader("Density grid", ImGuiTreeNodeFlags_DefaultOpen) || !gp.grid) return false;
    ImGui::Text("%d x %d x %d samples", gp.grid->dims.x, gp.grid->dims.y, gp.grid->dims.z);
    float iso = gp.grid->isoValue;
    if (!ImGui::SliderFloat("Iso value", &iso, 0.0f, 2.0f)) return false;
    auto copy = std::make_shared<sg::DensityGrid>(*gp.grid);   // payloads share grids: copy on write
    copy->isoValue = iso;
    gp.grid = copy;
    return true;
}

// The sections of the node's payload kind (its material last, for kinds that have one).
bool payloadEditor(ViewerState& st, sg::NodeId id, sg::Payload& p) {
    bool ch = false;
    if (auto* mi = std::get_if<sg::MeshInstance>(&p)) {
        ch |= meshSection(st, *mi);
        ch |= materialSection(st, id, mi->material);
    } else if (auto* ip = std::get_if<sg::ImplicitPayload>(&p)) {
        if (ImGui::CollapsingHeader("Implicit shape", ImGuiTreeNodeFlags_DefaultOpen)) ch |= implicitEditor(st, ip->shape);
        ch |= materialSection(st, id, ip->material);
    } else if (auto* cp = std::get_if<sg::CsgPayload>(&p)) {
        ch |= csgSection(st, id, *cp);
        ch |= materialSection(st, id, cp->material);
    } else if (auto* lp = std::get_if<sg::Light>(&p)) {
        ch |= lightSection(st, *lp);
    } else if (auto* cam = std::get_if<sg::Camera>(&p)) {
        ch |= cameraSection(st, id, *cam);
    } else if (auto* pp = std::get_if<sg::ParametricPayload>(&p)) {
        ch |= parametricSection(st, *pp);
        ch |= materialSection(st, id, pp->material);
    } else if (auto* gp = std::get_if<sg::GridPayload>(&p)) {
        ch |= gridSection(*gp);
        ch |= materialSection(st, id, gp->material);
    }
    return ch;
}

}   // namespace

void drawInspector(ViewerState& st) {
    sg::NodeId id = st.doc.selected;
    if (!st.doc.scene.valid(id)) {
        sceneSummary(st);
        return;
    }
    nodeHeader(st, id);
    if (id != st.doc.scene.root() && ImGui::CollapsingHeader("Transform", ImGuiTreeNodeFlags_DefaultOpen)) transformEditor(st, id);

    sg::Payload p = st.doc.scene.node(id).payload;
    if (payloadEditor(st, id, p) && st.doc.scene.valid(id)) st.setPayload(id, p, "payload " + std::to_string(id));
}

void drawAnimationPanel(ViewerState& st) {
    if (st.anim.clips.empty()) return;
    section("Animation");
    const assets::AnimationClip* cur = st.currentAnimation();
    auto clipName = [&](int i) {
        const std::string& n = st.anim.clips[size_t(i)].name;
        return n.empty() ? "clip " + std::to_string(i) : n;
    };
    if (ImGui::BeginCombo("Clip", cur ? clipName(st.anim.clip).c_str() : "-")) {
        for (int i = 0; i < int(st.anim.clips.size()); ++i) {
            ImGui::PushID(i);
            if (ImGui::Selectable(clipName(i).c_str(), i == st.anim.clip) && i != st.anim.clip) st.selectAnimation(i);
            ImGui::PopID();
        }
        ImGui::EndCombo();
    }
    record(st, "anim/clip");
    if (!cur) return;
    if (ImGui::Button(st.anim.playing ? "Pause###animPlay" : "Play###animPlay", ImVec2(px(64), 0))) st.toggleAnimation();
    record(st, "anim/play");
    ImGui::SameLine();
    ImGui::Checkbox("Loop", &st.anim.loop);
    record(st, "anim/loop");
    ImGui::SameLine();
    ImGui::TextDisabled("(Space in the viewport)");
    float t = float(st.anim.time);
    float t0 = cur->start, t1 = float(st.animationEnd());
    if (ImGui::SliderFloat("Time", &t, t0, std::max(t1, t0 + 1e-3f), "%.2f s")) st.setAnimationTime(t);
    record(st, "anim/time");
}

// --- 6. camera panel ---------------------------------------------------------------------------

namespace {

// The viewer's frame camera for the current viewport.
sg::FrameCamera viewportCamera(const ViewerState& st) {
    float aspect = float(std::max(st.view.viewportWidth, 1)) / float(std::max(st.view.viewportHeight, 1));
    return sg::makeFrameCamera(st.view.camera.world(), st.viewProjection(), aspect, st.view.camera.distance);
}

// K for the viewport's size, editable: a new K becomes the off-centre frustum with that K
// (sg::projectionFromIntrinsics). Orthographic and oblique cameras have no K.
void drawIntrinsics(ViewerState& st) {
    section("Intrinsics K (computer vision)");
    const int w = st.view.viewportWidth, h = st.view.viewportHeight;
    const sg::CameraModel m = sg::cameraModelOf(viewportCamera(st), w, h);
    if (!m.pinhole) {
        ImGui::TextDisabled("No K: %s projections are not pinhole cameras.", std::string(sg::nameOf(st.projection().type)).c_str());
        return;
    }
    float k[4] = {float(m.K[0][0]), float(m.K[1][1]), float(m.K[0][2]), float(m.K[1][2])};
    ImGui::Text("for %d x %d pixels, origin top-left:", w, h);
    if (ImGui::InputFloat4("fx fy cx cy", k, "%.2f", ImGuiInputTextFlags_EnterReturnsTrue)) {
        sg::Projection p;
        std::string err;
        const sg::Projection cur = st.projection();
        if (sg::projectionFromIntrinsics(k[0], k[1], k[2], k[3], w, h, cur.zNear, cur.zFar, p, &err))
            st.setProjection(p, "");
        else
            st.ui.status = "K not applied: " + err;
    }
    helpMarker(
        "Enter applies: the perspective becomes the general frustum with this K for the current viewport size "
        "(viewer render --intrinsics fx,fy,cx,cy does the same for an image).");
    ImGui::TextDisabled("K = [[%.2f, %.2f, %.2f], [0, %.2f, %.2f], [0, 0, 1]]", m.K[0][0], m.K[0][1], m.K[0][2], m.K[1][1], m.K[1][2]);
}

// Eye, centre and up of the view (lookAt); the orbit camera keeps world +y up (no roll).
void drawLookAt(ViewerState& st) {
    section("Look-at");
    float eye[3], centre[3];
    const sg::vec3 e = st.view.camera.eye(), c = st.view.camera.pivot;
    std::copy(&e.x, &e.x + 3, eye);
    std::copy(&c.x, &c.x + 3, centre);
    bool ch = ImGui::InputFloat3("Eye", eye, "%.3f", ImGuiInputTextFlags_EnterReturnsTrue);
    ch |= ImGui::InputFloat3("Centre", centre, "%.3f", ImGuiInputTextFlags_EnterReturnsTrue);
    const sg::vec3 up = st.view.camera.up();
    ImGui::TextDisabled("Up (%.3f, %.3f, %.3f): the orbit camera keeps world +y up (no roll)", up.x, up.y, up.z);
    if (ch) {
        const sg::vec3 ne(eye[0], eye[1], eye[2]), nc(centre[0], centre[1], centre[2]);
        const float d = glm::length(nc - ne);
        if (!(d > 1e-6f) || !std::isfinite(d)) {
            st.ui.status = "Look-at not applied: eye and centre must differ";
        } else {
            st.view.camera.setFromWorld(glm::inverse(sg::lookAt(ne, nc, sg::vec3(0, 1, 0))), d);
            st.markViewChanged();
        }
    }
}

// Copy / Paste the view as the sidecar's camera JSON (viewer render --camera-json takes it).
void drawCameraJson(ViewerState& st) {
    const int w = st.view.viewportWidth, h = st.view.viewportHeight;
    if (ImGui::Button("Copy camera as JSON")) {
        const sg::FrameCamera fc = viewportCamera(st);
        ImGui::SetClipboardText(assets::aovCameraJson(sg::cameraModelOf(fc, w, h), std::string(sg::nameOf(fc.projection.type)), w, h).c_str());
        st.ui.status = "Camera copied as JSON (" + std::to_string(w) + "x" + std::to_string(h) + "): viewer render --camera-json takes it";
    }
    ImGui::SameLine();
    if (ImGui::Button("Paste camera")) {
        const char* text = ImGui::GetClipboardText();
        assets::AovCamera c;
        std::string err = assets::parseAovCamera(text ? text : "", "clipboard", c);
        if (err.empty()) err = st.setViewFromCameraModel(c.model, c.projection, c.width, c.height);
        st.ui.status = err.empty() ? "Camera pasted" : "Camera not pasted: " + err;
    }
}

}   // namespace

void drawCameraPanel(ViewerState& st) {
    std::vector<sg::NodeId> cams = st.doc.scene.cameras();
    std::string preview = st.doc.scene.valid(st.doc.scene.activeCamera) ? st.doc.scene.node(st.doc.scene.activeCamera).name : "(viewer camera)";
    if (ImGui::BeginCombo("Scene camera", preview.c_str())) {
        for (sg::NodeId c : cams)
            if (ImGui::Selectable(st.doc.scene.node(c).name.c_str(), c == st.doc.scene.activeCamera)) st.useSceneCamera(c);
        ImGui::EndCombo();
    }
    if (ImGui::Button("Fit (F)")) st.fitView(!st.selection().empty());
    ImGui::SameLine();
    if (ImGui::Button("Reset (Home)")) st.resetView();
    ImGui::SameLine();
    if (ImGui::Button("New camera here")) st.addCamera();
    if (st.doc.scene.valid(st.doc.scene.activeCamera)) {
        if (ImGui::Button("Store view in active camera")) st.storeViewInCamera();
        helpMarker("Also done on save, so the scene reopens with this view.");
    }
    ImGui::TextDisabled(cams.empty() ? "No scene camera: edits apply to the viewer's own camera." : "Edits apply to the active scene camera.");

    section("Projection");
    sg::Projection p = st.projection();
    bool ch = false;
    for (const sg::Param<sg::Projection>& row : sg::params<sg::Projection>()) {
        // The type's combo also offers the oblique presets (cavalier, cabinet). The frustum's
        // four sides (one JSON array, not table rows) come before the clip planes.
        if (row.key == "near") {
            if (p.type == sg::ProjectionType::Perspective && p.useFrustum) {
                ch |= ImGui::DragFloat2("Left / right", &p.left, 0.001f);
                ch |= ImGui::DragFloat2("Bottom / top", &p.bottom, 0.001f);
            }
        }
        ch |= paramWidget(st, "camera", row, p);
    }
    if (ch) {
        p.zFar = std::max(p.zFar, p.zNear * 1.001f);
        st.setProjection(p, "projection");
    }
    ImGui::TextDisabled("Zoom factor %.3f  (orthographic / oblique)", st.view.camera.orthoScale);
    drawIntrinsics(st);
    drawLookAt(st);
    drawCameraJson(st);

    section("Live matrices");
    float aspect = float(std::max(st.view.viewportWidth, 1)) / float(std::max(st.view.viewportHeight, 1));
    sg::FrameCamera fc = viewportCamera(st);
    const sg::mat4 model = st.doc.scene.valid(st.doc.selected) ? st.doc.scene.world(st.doc.selected) : sg::mat4(1.0f);
    if (st.doc.scene.valid(st.doc.selected)) {
        ImGui::Text("Model (world of '%s')", st.doc.scene.node(st.doc.selected).name.c_str());
        matrixTable("model", model);
    } else {
        ImGui::TextDisabled("Model: select a node (identity below)");
    }
    ImGui::TextUnformatted("View");
    matrixTable("view", fc.view);
    ImGui::TextUnformatted("Model-view");
    matrixTable("modelview", fc.view * model);
    ImGui::Text("Projection (aspect %.3f)", aspect);
    matrixTable("proj", fc.proj);
    ImGui::TextUnformatted("MVP = projection x view x model");
    matrixTable("mvp", fc.proj * fc.view * model);
    // Viewport: NDC -> window pixels (origin bottom-left, depth 0..1), as glViewport + glDepthRange.
    const float vw = float(st.view.viewportWidth), vh = float(st.view.viewportHeight);
    sg::mat4 vp(1.0f);
    vp[0][0] = 0.5f * vw;
    vp[1][1] = 0.5f * vh;
    vp[2][2] = 0.5f;
    vp[3] = sg::vec4(0.5f * vw, 0.5f * vh, 0.5f, 1.0f);
    ImGui::Text("Viewport (%d x %d, depth 0..1)", st.view.viewportWidth, st.view.viewportHeight);
    matrixTable("viewport", vp);
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
    ImGui::TextWrapped("Eye (%.2f, %.2f, %.2f)  pivot (%.2f, %.2f, %.2f)  distance %.3f", fc.eye.x, fc.eye.y, fc.eye.z, st.view.camera.pivot.x,
                       st.view.camera.pivot.y, st.view.camera.pivot.z, st.view.camera.distance);
    ImGui::PopStyleColor();
}

// --- 7. rendering panel ------------------------------------------------------------------------

namespace {

// One combo per backend: its anti-aliasing override for this session, or "(scene)" for the
// scene's own setting. Overrides are kept by name and re-render without an edit.
void aaOverrideCombos(ViewerState& st) {
    const sg::NameTable<sg::AAChoice>& aaNames = sg::nameTable<sg::AAChoice>();
    for (const std::string& b : rnd::rendererNames()) {
        auto it = st.view.aaOverride.find(b);
        std::string ov = it == st.view.aaOverride.end() ? "" : it->second;
        const sg::NamedValue<sg::AAChoice>* cur = aaNames.find(ov);
        std::string label = "AA " + b;
        if (ImGui::BeginCombo(label.c_str(), cur ? std::string(cur->label).c_str() : "(scene)")) {
            if (ImGui::Selectable("(scene)", ov.empty())) {
                st.view.aaOverride.erase(b);
                st.markViewChanged();
            }
            for (const auto& e : aaNames.entries) {
                if (ImGui::Selectable(std::string(e.label).c_str(), &e == cur)) {
                    st.view.aaOverride[b] = std::string(e.name);
                    st.markViewChanged();
                }
                tooltip(e.help);
            }
            ImGui::EndCombo();
        }
    }
}

}   // namespace

void drawRenderingPanel(ViewerState& st) {
    sg::RenderSettings s = st.doc.scene.settings;
    bool ch = false;
    // The rows of the render-settings table, section by section; what is not a scene setting
    // (per-backend AA overrides, where GL renders) sits in its section after them.
    std::vector<std::string_view> sections;
    for (const auto& p : sg::params<sg::RenderSettings>())
        if (!p.label.empty() && std::find(sections.begin(), sections.end(), p.section) == sections.end()) sections.push_back(p.section);
    for (std::string_view name : sections) {
        section(std::string(name).c_str());
        ch |= paramSection(st, "render", name, s);
        if (name == "Anti-aliasing") {
            aaOverrideCombos(st);
            if (ImGui::Checkbox("GL on a worker thread", &st.view.glOnWorker)) st.markViewChanged();
            helpMarker(
                "The gl backend renders on its own thread with a headless context: the UI never waits, even with software GL.\nOff: it renders "
                "on the UI thread with the window's context.");
        }
    }
    if (ch) st.setSettings(s, "settings");   // refused values: the reason goes to the status line
}

// --- 8. compare panel --------------------------------------------------------------------------

void drawComparePanel(ViewerState& st) {
    CompareConfig& c = st.view.compare;
    int mode = int(c.mode);
    ImGui::RadioButton("Single", &mode, 0);
    record(st, "compare/single");
    ImGui::SameLine();
    ImGui::RadioButton("Split / wipe", &mode, 1);
    record(st, "compare/split");
    ImGui::SameLine();
    ImGui::RadioButton("Difference", &mode, 2);
    record(st, "compare/difference");
    if (ViewMode(mode) != c.mode) st.showView(ViewMode(mode));
    std::vector<std::string> names = rnd::rendererNames();
    auto backendCombo = [&](const char* label, std::string& value) {
        if (ImGui::BeginCombo(label, value.c_str())) {
            for (const auto& n : names)
                if (ImGui::Selectable(n.c_str(), n == value)) value = n;
            ImGui::EndCombo();
        }
    };
    section("Backends (one shared camera)");
    if (c.mode == ViewMode::Single) {
        std::string b = st.view.backend;
        backendCombo("Backend", b);
        if (b != st.view.backend) st.setBackend(b);
        ImGui::TextDisabled("Keys 1 / 2 / 3 switch backends.");
    } else if (c.mode == ViewMode::Split) {
        int count = c.count;
        if (ImGui::SliderInt("Count", &count, 2, 3)) st.showView(ViewMode::Split, count);
        const char* labels[] = {"Left", c.count == 3 ? "Middle" : "Right", "Right"};
        for (int i = 0; i < c.count; ++i) backendCombo(labels[i], c.split[size_t(i)]);
        ImGui::SliderFloat("Divider 1", &c.dividers[0], 0.0f, 1.0f);
        if (c.count == 3) ImGui::SliderFloat("Divider 2", &c.dividers[1], 0.0f, 1.0f);
        c.dividers[1] = std::max(c.dividers[1], c.dividers[0]);
        ImGui::TextDisabled("Drag the dividers in the viewport.");
    } else {
        backendCombo("A", c.diff[0]);
        backendCombo("B", c.diff[1]);
        if (c.diff[0] == c.diff[1]) ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.4f, 1.0f), "A and B are the same backend: nothing to compare.");
    }
    if (c.mode == ViewMode::Difference) {
        section("Difference");
        ImGui::Text("|%s - %s| per pixel", c.diff[0].c_str(), c.diff[1].c_str());
        ImGui::SliderInt("Threshold", &c.threshold, 0, 255);
        record(st, "compare/threshold");
        const DiffFigures& d = st.view.diff;   // the overlay writes the same texts
        if (d.valid) {
            ImGui::Text("Mean |a-b|  %s", d.meanText().c_str());
            ImGui::Text("Max  |a-b|  %d", d.max);
            ImGui::Text("PSNR        %s", d.psnrText().c_str());
            ImGui::Text("Within %d   %s of the pixels", c.threshold, d.withinText().c_str());
        } else {
            ImGui::TextDisabled("Waiting for both full-resolution images...");
        }
    }
}

// --- 9. viewport -------------------------------------------------------------------------------

namespace {

void centeredText(ImDrawList* dl, ImVec2 a, ImVec2 b, const std::string& text, ImU32 col) {
    float wrap = std::max(b.x - a.x - px(24), px(50));
    ImVec2 sz = ImGui::CalcTextSize(text.c_str(), nullptr, false, wrap);
    ImVec2 p((a.x + b.x - sz.x) * 0.5f, (a.y + b.y - sz.y) * 0.5f);
    dl->AddRectFilled(ImVec2(p.x - px(10), p.y - px(8)), ImVec2(p.x + sz.x + px(10), p.y + sz.y + px(8)), IM_COL32(20, 20, 24, 220), px(4));
    dl->AddText(nullptr, 0.0f, p, col, text.c_str(), nullptr, wrap);
}

// Draws one backend's image over [a, b] showing the u-range [u0, u1] of the image.
void drawSlotImage(ImDrawList* dl, const SlotView& v, ImVec2 a, ImVec2 b, float u0, float u1) {
    if (v.texture && v.width > 0) {
        dl->AddImage(v.texture, a, b, ImVec2(u0, 0), ImVec2(u1, 1));
    } else {
        dl->AddRectFilled(a, b, IM_COL32(24, 25, 29, 255));
    }
    std::string msg;
    if (!v.status.error.empty())
        msg = v.status.backend + ": " + v.status.error;
    else if (!v.texture)
        msg = v.status.backend + ": rendering...";
    if (!msg.empty()) centeredText(dl, a, b, msg, v.status.error.empty() ? IM_COL32(200, 200, 210, 255) : IM_COL32(255, 150, 120, 255));
}

std::string slotStats(const SlotView& v) {
    if (!v.texture && v.status.error.empty()) return v.status.backend + "  rendering...";   // no figures of a picture not shown
    char buf[256];
    const rnd::RenderStats& s = v.status.stats;
    std::string extra;
    if (s.rays > 0 && s.milliseconds > 0) {
        char r[64];
        std::snprintf(r, sizeof r, "  %.2f Mrays/s", double(s.rays) / (s.milliseconds * 1000.0));
        extra += r;
    }
    if (v.status.level > 1) extra += "  (1/" + std::to_string(v.status.level) + " res)";
    if (v.status.refining && s.config.samplesPerPixel == 1 && s.config.aaAsked != "none")   // a one-sample step of an anti-aliased image
        extra += "  1 sample/pixel, " + s.config.aaAsked + " follows";
    else if (s.ok || !s.config.aaUsed.empty())
        extra += "  " + s.config.describe();
    if (!s.config.unsupported.empty()) {
        extra += "  no";
        for (const std::string& u : s.config.unsupported) extra += " " + u;
    }
    if (v.status.rendering) extra += "  " + std::to_string(int(v.status.progress * 100)) + "%";
    std::snprintf(buf, sizeof buf, "%-8s %7.1f ms  %6.1fk tris%s", v.status.backend.c_str(), s.milliseconds, double(s.triangles) / 1000.0,
                  extra.c_str());
    return buf;
}

// One line for the status bar: what the shown backends do not honour as asked (from their
// last RenderStats: AA substitutions, features they do not draw), "" when all is honoured.
std::string renderNotes(const ViewportInput& view) {
    std::string line;
    for (const SlotView& v : view.slots) {
        const rnd::RenderConfig& c = v.status.stats.config;
        std::string part;
        for (const std::string& n : c.notes) part += (part.empty() ? "" : "; ") + n;
        std::string list;   // shadows/reflections are on by default and drawn only by the ray caster:
                            // the stats overlay lists them, the status line would always show them
        for (const std::string& u : c.unsupported)
            if (u != "shadows" && u != "reflections") list += (list.empty() ? "" : ", ") + u;
        if (!list.empty()) part += (part.empty() ? "" : "; ") + std::string("does not draw ") + list;
        if (!part.empty()) line += (line.empty() ? "" : "   ") + v.status.backend + ": " + part;
    }
    return line;
}

void cameraInput(ViewerState& st, ImVec2 a, ImVec2 b, double time, float dt) {
    ImGuiIO& io = ImGui::GetIO();
    bool hovered = ImGui::IsItemHovered();
    bool active = ImGui::IsItemActive();
    const sg::Projection& proj = st.projection();
    bool ortho = proj.type != sg::ProjectionType::Perspective;
    bool moved = false;
    // Divider drag (split view) takes precedence over the camera when grabbed near a divider.
    int& dragDivider = st.ui.panels.dragDivider;
    if (st.view.compare.mode == ViewMode::Split && ImGui::IsItemClicked(ImGuiMouseButton_Left)) {
        dragDivider = -1;
        for (int i = 0; i < st.view.compare.count - 1; ++i) {
            float x = a.x + st.view.compare.dividers[i] * (b.x - a.x);
            if (std::abs(io.MousePos.x - x) < px(6)) dragDivider = i;
        }
    }
    if (!io.MouseDown[0]) dragDivider = -1;
    if (dragDivider >= 0 && active) {
        float f = std::clamp((io.MousePos.x - a.x) / std::max(b.x - a.x, 1.0f), 0.0f, 1.0f);
        st.view.compare.dividers[dragDivider] = f;
        if (dragDivider == 0)
            st.view.compare.dividers[1] = std::max(st.view.compare.dividers[1], f);
        else
            st.view.compare.dividers[0] = std::min(st.view.compare.dividers[0], f);
        return;
    }
    if (active && (io.MouseDelta.x != 0 || io.MouseDelta.y != 0)) {
        bool panning = io.MouseDown[2] || (io.MouseDown[0] && io.KeyShift);
        if (io.MouseDown[1]) {
            st.view.camera.look(io.MouseDelta.x, io.MouseDelta.y);
            moved = true;
        } else if (panning) {
            st.view.camera.pan(io.MouseDelta.x, io.MouseDelta.y, st.view.camera.panScale(proj.fovyDeg, b.y - a.y, ortho, proj.orthoHalfHeight));
            moved = true;
        } else if (io.MouseDown[0]) {
            st.view.camera.orbit(io.MouseDelta.x, io.MouseDelta.y);
            moved = true;
        }
    }
    if (hovered && io.MouseWheel != 0.0f) {
        st.view.camera.zoom(io.MouseWheel);
        moved = true;
    }
    // Fly mode: right mouse held + WASD (QE down/up), Shift = faster.
    bool wasFlying = st.view.flyMode;
    st.view.flyMode = active && io.MouseDown[1];
    if (st.view.flyMode && !wasFlying) st.view.flySpeed = sg::flySpeedFor(st.doc.scene);   // the scene's size, once per flight
    if (st.view.flyMode) {
        float speed = st.view.flySpeed * dt * (io.KeyShift ? 4.0f : 1.0f);
        sg::vec3 o(0.0f);
        if (ImGui::IsKeyDown(keys::W)) o.z += speed;
        if (ImGui::IsKeyDown(keys::S)) o.z -= speed;
        if (ImGui::IsKeyDown(keys::D)) o.x += speed;
        if (ImGui::IsKeyDown(keys::A)) o.x -= speed;
        if (ImGui::IsKeyDown(keys::E)) o.y += speed;
        if (ImGui::IsKeyDown(keys::Q)) o.y -= speed;
        if (o != sg::vec3(0.0f)) {
            st.view.camera.fly(o);
            moved = true;
        }
    }
    if (moved) {
        st.view.lastInteraction = time;
        st.markViewChanged();
    }
}

// The viewport's parts, each drawn over [a, a + avail].

// Split view: each backend's image over its part of the width, its name on top, the dividers.
void drawSplitView(ImDrawList* dl, const ViewerState& st, const ViewportInput& view, ImVec2 a, ImVec2 avail) {
    ImVec2 b(a.x + avail.x, a.y + avail.y);
    int n = std::min<int>(int(view.slots.size()), std::clamp(st.view.compare.count, 2, 3));
    float edges[4] = {0.0f, st.view.compare.dividers[0], n == 3 ? st.view.compare.dividers[1] : 1.0f, 1.0f};
    if (n == 2) edges[2] = 1.0f;
    for (int i = 0; i < n; ++i) {
        float u0 = edges[i], u1 = edges[i + 1];
        if (u1 <= u0) continue;
        ImVec2 p0(a.x + u0 * avail.x, a.y), p1(a.x + u1 * avail.x, b.y);
        drawSlotImage(dl, view.slots[i], p0, p1, u0, u1);
        // Backend label at the top of its region.
        const std::string& name = view.slots[i].status.backend;
        ImVec2 ts = ImGui::CalcTextSize(name.c_str());
        ImVec2 lp(p0.x + (p1.x - p0.x - ts.x) * 0.5f, a.y + px(8));
        dl->AddRectFilled(ImVec2(lp.x - px(6), lp.y - px(3)), ImVec2(lp.x + ts.x + px(6), lp.y + ts.y + px(3)), IM_COL32(0, 0, 0, 160), px(3));
        dl->AddText(lp, IM_COL32(255, 255, 255, 255), name.c_str());
    }
    for (int i = 0; i + 1 < n; ++i) {
        float x = a.x + st.view.compare.dividers[i] * avail.x;
        dl->AddLine(ImVec2(x, a.y), ImVec2(x, b.y), IM_COL32(255, 255, 255, 200), px(2));
        dl->AddCircleFilled(ImVec2(x, (a.y + b.y) * 0.5f), px(7), IM_COL32(255, 255, 255, 230));
        dl->AddCircle(ImVec2(x, (a.y + b.y) * 0.5f), px(7), IM_COL32(40, 40, 40, 255), 0, px(1.5f));
    }
}

// The heat map's colours for a largest-channel difference of 0..64 (64 and above look the
// same), and of a pixel within the threshold (a dimmed grey copy of image A, here of mid grey):
// taken from rnd::diffImage itself on a ramp, so the legend cannot drift from the image.
struct HeatColours {
    std::array<ImU32, 65> ramp;
    ImU32 within;
};
HeatColours heatColours() {
    rnd::Framebuffer x, y;
    x.resize(66, 1);
    y.resize(66, 1);
    std::fill(x.color.begin(), x.color.end(), uint8_t(0));
    std::fill(y.color.begin(), y.color.end(), uint8_t(0));
    for (int i = 0; i < 66; ++i) x.color[size_t(i) * 4 + 3] = y.color[size_t(i) * 4 + 3] = 255;
    for (int v = 0; v <= 64; ++v) y.color[size_t(v) * 4] = uint8_t(v);   // pixel v differs by v
    for (int c = 0; c < 3; ++c) x.color[65 * 4 + size_t(c)] = y.color[65 * 4 + size_t(c)] = 128;
    rnd::Framebuffer d = rnd::diffImage(x, y, 0);
    auto colour = [&](int i) { return IM_COL32(d.color[size_t(i) * 4], d.color[size_t(i) * 4 + 1], d.color[size_t(i) * 4 + 2], 255); };
    HeatColours h{};
    for (int v = 0; v <= 64; ++v) h.ramp[size_t(v)] = colour(v);
    h.within = colour(65);
    return h;
}

// Legend (top right of the heat map): what grey and the red-to-white ramp mean.
void drawDiffLegend(ImDrawList* dl, ViewerState& st, ImVec2 a, ImVec2 avail) {
    const HeatColours heat = heatColours();
    int t = std::clamp(st.view.compare.threshold, 0, 255);
    const std::string title = "|A - B|, largest channel (0-255)", within = "0-" + std::to_string(t) + ": within threshold (A, dimmed)";
    float lh = ImGui::GetTextLineHeight(), barH = px(12), pad = px(8);
    float w = std::max(ImGui::CalcTextSize(title.c_str()).x, px(26) + ImGui::CalcTextSize(within.c_str()).x) + 2 * pad;
    ImVec2 o(a.x + std::max(avail.x - w - px(10), 0.0f), a.y + px(10));
    ImVec2 end(o.x + w, o.y + pad * 2 + lh * 3 + barH + px(8));
    dl->AddRectFilled(o, end, IM_COL32(0, 0, 0, 190), px(4));
    ImU32 text = IM_COL32(230, 230, 235, 255);
    float x0 = o.x + pad, x1 = end.x - pad, y = o.y + pad;
    dl->AddText(ImVec2(x0, y), text, title.c_str());
    y += lh + px(2);
    dl->AddRectFilled(ImVec2(x0, y + px(2)), ImVec2(x0 + px(18), y + lh - px(2)), heat.within);
    dl->AddRect(ImVec2(x0, y + px(2)), ImVec2(x0 + px(18), y + lh - px(2)), IM_COL32(120, 120, 120, 255));
    dl->AddText(ImVec2(x0 + px(26), y), text, within.c_str());
    y += lh + px(4);
    int from = std::min(t + 1, 64);   // the ramp from the first highlighted difference
    int steps = std::max(64 - from, 1);
    for (int i = 0; i < steps; ++i) {
        float u0 = x0 + (x1 - x0) * float(i) / float(steps), u1 = x0 + (x1 - x0) * float(i + 1) / float(steps);
        ImU32 c0 = heat.ramp[size_t(std::min(from + i, 64))], c1 = heat.ramp[size_t(std::min(from + i + 1, 64))];
        dl->AddRectFilledMultiColor(ImVec2(u0, y), ImVec2(u1, y + barH), c0, c1, c1, c0);
    }
    y += barH + px(2);
    std::string left = std::to_string(t + 1), right = t + 1 >= 64 ? "" : "64+";
    dl->AddText(ImVec2(x0, y), text, left.c_str());
    dl->AddText(ImVec2(x1 - ImGui::CalcTextSize(right.c_str()).x, y), text, right.c_str());
    st.hooks.itemRects["diff/legend"] = ItemRect{o.x, o.y, end.x, end.y};
}

// Difference view: the heat map (or why there is none yet), its legend and the figures at the
// bottom (DiffFigures::summary, as the Compare tab writes them).
void drawDifferenceView(ImDrawList* dl, ViewerState& st, const ViewportInput& view, ImVec2 a, ImVec2 avail) {
    ImVec2 b(a.x + avail.x, a.y + avail.y);
    SlotView d = view.diff;
    if (!d.texture) {
        // No diff yet: say why (an error of either side, or still rendering).
        std::string msg = "Waiting for both images...";
        for (const SlotView& s : view.slots)
            if (!s.status.error.empty()) msg = s.status.backend + ": " + s.status.error;
        dl->AddRectFilled(a, b, IM_COL32(24, 25, 29, 255));
        centeredText(dl, a, b, msg, IM_COL32(255, 170, 140, 255));
    } else {
        dl->AddImage(d.texture, a, b);
        drawDiffLegend(dl, st, a, avail);
    }
    if (view.slots.size() >= 2) {
        std::string line = st.view.diff.summary(view.slots[0].status.backend, view.slots[1].status.backend, st.view.compare.threshold);
        ImVec2 ts = ImGui::CalcTextSize(line.c_str());
        ImVec2 lp(a.x + (avail.x - ts.x) * 0.5f, b.y - ts.y - px(12));
        dl->AddRectFilled(ImVec2(lp.x - px(8), lp.y - px(4)), ImVec2(lp.x + ts.x + px(8), lp.y + ts.y + px(4)), IM_COL32(0, 0, 0, 180), px(3));
        dl->AddText(lp, IM_COL32(255, 230, 160, 255), line.c_str());
    }
}

// Stats overlay (top-left): one line per shown backend and the viewport size; progress bars
// at the bottom for renders in flight.
void drawStatsOverlay(ImDrawList* dl, const ViewerState& st, const ViewportInput& view, ImVec2 a, ImVec2 avail) {
    ImVec2 b(a.x + avail.x, a.y + avail.y);
    std::vector<std::string> lines;
    for (const SlotView& v : view.slots) lines.push_back(slotStats(v));
    char buf[128];
    std::snprintf(buf, sizeof buf, "%d x %d   %s", st.view.viewportWidth, st.view.viewportHeight, st.view.flyMode ? "FLY (WASD QE)" : "");
    lines.emplace_back(buf);
    if (!view.slots.empty() && !view.slots[0].legend.empty()) lines.push_back(view.slots[0].legend);   // the diagnostic view's
    float h = ImGui::GetTextLineHeightWithSpacing();
    float w = 0;
    for (auto& l : lines) w = std::max(w, ImGui::CalcTextSize(l.c_str()).x);
    ImVec2 o(a.x + px(10), a.y + (st.view.compare.mode == ViewMode::Split ? px(36) : px(10)));
    dl->AddRectFilled(o, ImVec2(o.x + w + px(16), o.y + h * lines.size() + px(10)), IM_COL32(0, 0, 0, 150), px(4));
    for (size_t i = 0; i < lines.size(); ++i) {
        bool rendering = i < view.slots.size() && view.slots[i].status.rendering;
        dl->AddText(ImVec2(o.x + px(8), o.y + px(5) + h * i), rendering ? IM_COL32(255, 220, 120, 255) : IM_COL32(220, 230, 240, 255),
                    lines[i].c_str());
    }
    // Progress bars for renders in flight.
    for (size_t i = 0; i < view.slots.size(); ++i) {
        if (!view.slots[i].status.rendering) continue;
        float y = b.y - px(4) - px(5) * i;
        dl->AddRectFilled(ImVec2(a.x, y - px(3)), ImVec2(a.x + avail.x * view.slots[i].status.progress, y), IM_COL32(90, 170, 255, 220));
    }
}

}   // namespace

namespace {

// The shown image under viewport fraction u (single: the one image; split: the part under the
// cursor; difference: A).
const SlotView* slotUnder(const ViewerState& st, const ViewportInput& view, float u) {
    if (view.slots.empty()) return nullptr;
    if (st.view.compare.mode != ViewMode::Split) return &view.slots[0];
    const int n = std::min<int>(int(view.slots.size()), std::clamp(st.view.compare.count, 2, 3));
    if (u < st.view.compare.dividers[0]) return &view.slots[0];
    if (n == 3 && u >= st.view.compare.dividers[1]) return &view.slots[2];
    return &view.slots[1];
}

// A left click (no drag, no modifier that pans) in the viewport: pick the node under it
// (nothing there clears the selection; as soon as the image under it has its visibility) and
// pin the pixel inspector there.
void pickAndProbe(ViewerState& st, const ViewportInput& view, ImVec2 a, ImVec2 avail) {
    ImGuiIO& io = ImGui::GetIO();
    const float u = (io.MousePos.x - a.x) / avail.x, v = (io.MousePos.y - a.y) / avail.y;
    const bool inside = u >= 0 && v >= 0 && u < 1 && v < 1;
    PixelProbeState& probe = st.ui.panels.probe;
    if (inside && ImGui::IsItemDeactivated() && ImGui::IsMouseReleased(ImGuiMouseButton_Left) && io.MouseDragMaxDistanceSqr[0] < px(3) * px(3) &&
        !io.KeyShift) {
        probe.pinned = true;
        probe.u = u;
        probe.v = v;
        probe.pickPending = true;
        probe.pickAdds = io.KeyCtrl;
        probe.pickViewVersion = st.view.version;
        probe.pickDocVersion = st.doc.version;
    } else if (!probe.pinned) {
        probe.u = inside && ImGui::IsItemHovered() ? u : -1.0f;
        probe.v = inside && ImGui::IsItemHovered() ? v : -1.0f;
    }
    if (probe.pickPending && (probe.pickViewVersion != st.view.version || probe.pickDocVersion != st.doc.version)) probe.pickPending = false;
    if (probe.pickPending)
        if (const SlotView* s = slotUnder(st, view, probe.u); s && s->probe.image && s->probe.image->hasVisibility()) {
            const sg::NodeId picked = pickAt(s->probe, probe.u, probe.v);
            if (probe.pickAdds)
                st.toggleSelected(picked);   // Ctrl+click: adds or takes out; on empty space nothing changes
            else
                st.selectNode(picked);
            probe.pickPending = false;
        }
    probe.results.clear();
    if (probe.u < 0) return;
    for (const SlotView& s : view.slots) probe.results.push_back(probeAt(st, s.probe, probe.u, probe.v));
}

}   // namespace

void drawViewport(ViewerState& st, const ViewportInput& view, double time, float dt) {
    ImVec2 a = ImGui::GetCursorScreenPos();
    ImVec2 avail = ImGui::GetContentRegionAvail();
    avail.x = std::max(avail.x, 1.0f);
    avail.y = std::max(avail.y, 1.0f);
    ImVec2 b(a.x + avail.x, a.y + avail.y);
    // Render at framebuffer pixels (HiDPI: DisplayFramebufferScale).
    ImVec2 fbs = ImGui::GetIO().DisplayFramebufferScale;
    st.view.viewportWidth = std::max(1, int(avail.x * fbs.x));
    st.view.viewportHeight = std::max(1, int(avail.y * fbs.y));

    ImGui::InvisibleButton("##viewport", avail,
                           ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight | ImGuiButtonFlags_MouseButtonMiddle);
    record(st, "viewport");
    cameraInput(st, a, b, time, dt);
    pickAndProbe(st, view, a, avail);
    // Space: play / pause the animation while the viewport has focus (not while typing).
    if (!st.anim.clips.empty() && ImGui::IsWindowFocused() && !ImGui::GetIO().WantTextInput && ImGui::IsKeyPressed(keys::Space, false))
        st.toggleAnimation();

    ImDrawList* dl = ImGui::GetWindowDrawList();
    dl->PushClipRect(a, b, true);
    switch (st.view.compare.mode) {
    case ViewMode::Single:
        if (!view.slots.empty()) drawSlotImage(dl, view.slots[0], a, b, 0, 1);
        break;
    case ViewMode::Split: drawSplitView(dl, st, view, a, avail); break;
    case ViewMode::Difference: drawDifferenceView(dl, st, view, a, avail); break;
    }
    if (st.ui.panels.showOverlay) drawStatsOverlay(dl, st, view, a, avail);
    dl->PopClipRect();
}

// --- 10. dialogs -------------------------------------------------------------------------------

namespace {

void openBrowser(bool saving, ViewerState& st) {
    FileBrowserState& browser = st.ui.panels.browser;
    browser.open = true;
    browser.justOpened = true;
    browser.saving = saving;
    browser.error.clear();
    std::error_code ec;
    fs::path start = st.doc.path.empty() ? fs::current_path(ec) : fs::absolute(st.doc.path, ec).parent_path();
    // Save As starts in the document's own folder; Open where the browser was last.
    if ((saving && !st.doc.path.empty()) || browser.dir.empty() || !fs::is_directory(browser.dir, ec)) browser.dir = start;
    browser.fileName = saving ? (st.doc.path.empty() ? st.doc.scene.name + ".json" : st.doc.path.stem().string() + ".json") : "";
}

void drawFileBrowser(ViewerState& st) {
    FileBrowserState& browser = st.ui.panels.browser;
    if (!browser.open) return;
    const char* title = browser.saving ? "Save scene as###browser" : "Open scene###browser";
    if (browser.justOpened) {
        ImGui::OpenPopup(title);
        browser.justOpened = false;
    }
    ImVec2 ds = ImGui::GetIO().DisplaySize;
    ImGui::SetNextWindowSize(ImVec2(std::min(px(640), ds.x * 0.9f), std::min(px(480), ds.y * 0.9f)), ImGuiCond_Appearing);
    ImGui::SetNextWindowPos(ImVec2(ds.x * 0.5f, ds.y * 0.5f), ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    bool keep = true;
    if (!ImGui::BeginPopupModal(title, &keep)) {
        if (!keep) {
            browser.open = false;
            if (browser.saving) st.saveAsCancelled();
        }
        return;
    }
    std::error_code ec;
    std::string dirText = browser.dir.string();
    if (ImGui::Button("Up")) browser.dir = browser.dir.parent_path();
    ImGui::SameLine();
    ImGui::SetNextItemWidth(-1);
    if (ImGui::InputText("##dir", &dirText, ImGuiInputTextFlags_EnterReturnsTrue) && fs::is_directory(dirText, ec)) browser.dir = dirText;

    std::vector<std::string> exts = assets::supportedSceneExtensions();
    std::vector<fs::directory_entry> dirs, files;
    for (fs::directory_iterator it(browser.dir, fs::directory_options::skip_permission_denied, ec), end; !ec && it != end; it.increment(ec)) {
        const fs::directory_entry& e = *it;
        std::string name = e.path().filename().string();
        if (name.empty() || name[0] == '.') continue;
        if (e.is_directory(ec))
            dirs.push_back(e);
        else {
            std::string ext = e.path().extension().string();
            std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
            if (std::find(exts.begin(), exts.end(), ext) != exts.end()) files.push_back(e);
        }
        if (dirs.size() + files.size() > 5000) break;
    }
    auto byName = [](const fs::directory_entry& x, const fs::directory_entry& y) { return x.path().filename() < y.path().filename(); };
    std::sort(dirs.begin(), dirs.end(), byName);
    std::sort(files.begin(), files.end(), byName);

    float footer = ImGui::GetFrameHeightWithSpacing() * 2.5f;
    fs::path chosen;
    ImGui::BeginChild("entries", ImVec2(0, -footer), true);
    for (const auto& d : dirs) {
        std::string label = "[dir] " + d.path().filename().string();
        if (ImGui::Selectable(label.c_str(), false, ImGuiSelectableFlags_AllowDoubleClick) && ImGui::IsMouseDoubleClicked(0)) browser.dir = d.path();
    }
    for (const auto& f : files) {
        std::string name = f.path().filename().string();
        if (ImGui::Selectable(name.c_str(), browser.fileName == name, ImGuiSelectableFlags_AllowDoubleClick)) {
            browser.fileName = name;
            if (ImGui::IsMouseDoubleClicked(0)) chosen = f.path();
        }
    }
    ImGui::EndChild();
    ImGui::SetNextItemWidth(-px(170));
    bool enter = ImGui::InputText("##file", &browser.fileName, ImGuiInputTextFlags_EnterReturnsTrue);
    ImGui::SameLine();
    if (ImGui::Button(browser.saving ? "Save" : "Open", ImVec2(px(75), 0)) || enter) {
        // A folder typed into the name field (relative to the listed one, or absolute; "~"
        // is home) is opened in the list instead of being taken as the file.
        std::error_code dirEc;
        fs::path typed = browser.fileName;
        if (browser.fileName == "~" || browser.fileName.rfind("~/", 0) == 0)
            if (const char* home = std::getenv("HOME"))
                typed = fs::path(home) / browser.fileName.substr(std::min<size_t>(2, browser.fileName.size()));
        const fs::path target = typed.is_absolute() ? typed : browser.dir / typed;
        if (!browser.fileName.empty() && fs::is_directory(target, dirEc)) {
            browser.dir = fs::weakly_canonical(target, dirEc);
            browser.fileName.clear();
        } else if (!browser.fileName.empty()) {
            chosen = target;
        }
    }
    record(st, "browser/accept");
    ImGui::SameLine();
    if (ImGui::Button("Cancel", ImVec2(px(75), 0)) || escapeCancels(st)) {
        browser.open = false;
        if (browser.saving) st.saveAsCancelled();
        ImGui::CloseCurrentPopup();
    }
    ImGui::TextDisabled(browser.saving ? "Native JSON scene (.json)" : "Formats: .json .gltf .glb .obj .off .ply .stl");
    if (!chosen.empty()) {
        browser.open = false;
        ImGui::CloseCurrentPopup();
        if (browser.saving)
            st.saveAs(chosen);
        else
            st.requestOpen(chosen);
    }
    ImGui::EndPopup();
}

// Width and height fields: the viewport's size, read-only, while "Viewport size" is ticked
// (so they show what will be written), else the custom size with presets.
void screenshotSizeFields(ScreenshotDialogState& dialog, const View& view) {
    bool viewport = dialog.windowSize;
    int w = viewport ? view.viewportWidth : dialog.width, h = viewport ? view.viewportHeight : dialog.height;
    ImGui::BeginDisabled(viewport);
    ImGui::InputInt("Width", &w);
    ImGui::InputInt("Height", &h);
    for (auto [pw, ph] : {std::pair{1280, 720}, std::pair{1920, 1080}, std::pair{3840, 2160}}) {
        if (pw != 1280) ImGui::SameLine();
        if (ImGui::SmallButton((std::to_string(pw) + "x" + std::to_string(ph)).c_str())) w = pw, h = ph;
    }
    ImGui::EndDisabled();
    if (viewport) return;
    dialog.width = std::clamp(w, 1, 16384);
    dialog.height = std::clamp(h, 1, 16384);
}

// The subfolders of `dir` by name (hidden ones left out; at most `limit`); none when it is not a
// readable folder.
std::vector<std::string> subfolders(const fs::path& dir, size_t limit) {
    std::vector<std::string> names;
    std::error_code ec;
    for (fs::directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end; !ec && it != end && names.size() < limit;
         it.increment(ec)) {
        std::string name = it->path().filename().string();
        if (!name.empty() && name[0] != '.' && it->is_directory(ec)) names.push_back(name);
    }
    std::sort(names.begin(), names.end());
    return names;
}

// The folder: typed, or chosen with Up and a click on one of its subfolders.
void screenshotFolderPicker(ViewerState& st, ScreenshotDialogState& dialog) {
    if (ImGui::Button("Up##shotFolder")) dialog.dirText = absoluteFolder(dialog.dirText).parent_path().string();
    record(st, "shot/up");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(px(360));
    ImGui::InputText("Folder", &dialog.dirText);
    record(st, "shot/folder");
    ImGui::BeginChild("shotFolders", ImVec2(px(420), px(110)), true);
    std::vector<std::string> names = subfolders(dialog.dirText, 500);
    std::error_code ec;
    if (names.empty()) ImGui::TextDisabled(fs::is_directory(dialog.dirText, ec) ? "(no subfolders)" : "(not a folder yet: Take makes it)");
    for (const std::string& name : names) {
        if (ImGui::Selectable(("[dir] " + name).c_str())) dialog.dirText = (absoluteFolder(dialog.dirText) / name).string();
        record(st, "shot/dir/" + name);
    }
    ImGui::EndChild();
}

// Take: the folder typed is checked (made when missing) before anything renders; a folder
// that cannot be used keeps the dialog open with the reason.
bool takeScreenshot(ViewerState& st, ScreenshotDialogState& dialog, std::string& error) {
    fs::path dir = prepareScreenshotFolder(dialog.dirText, &error);
    if (dir.empty()) return false;
    dialog.dir = dir;
    auto [w, h] = screenshotSize(dialog, st.view);
    st.ui.requests.screenshot = true;
    st.ui.requests.screenshotWidth = w;
    st.ui.requests.screenshotHeight = h;
    return true;
}

// The export boxes: depth / normal / id files and the camera sidecar next to each PNG.
void screenshotExportBoxes(ViewerState& st, ScreenshotDialogState& dialog) {
    ImGui::TextUnformatted("Export next to each PNG (with the camera sidecar .json):");
    ImGui::Checkbox("Depth (.depth.pfm)", &dialog.exportDepth);
    record(st, "shot/depth");
    ImGui::SameLine();
    ImGui::Checkbox("Normal (.normal.png)", &dialog.exportNormal);
    record(st, "shot/normal");
    ImGui::SameLine();
    ImGui::Checkbox("Id (.id.png)", &dialog.exportId);
    record(st, "shot/id");
}

void drawScreenshotDialog(ViewerState& st) {
    ScreenshotDialogState& dialog = st.ui.panels.shotDialog;
    if (st.ui.requests.screenshotDialog || st.ui.requests.exportDialog) {
        if (st.ui.requests.exportDialog && screenshotExports(dialog).empty()) dialog.exportDepth = dialog.exportNormal = dialog.exportId = true;
        st.ui.requests.screenshotDialog = st.ui.requests.exportDialog = false;
        dialog.open = true;
        dialog.error.clear();
        dialog.dirText = absoluteFolder(dialog.dir).string();
        ImGui::OpenPopup("Screenshot");
    }
    if (!ImGui::BeginPopupModal("Screenshot", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
    ImGui::Checkbox(screenshotSizeLabel(dialog, st.view).c_str(), &dialog.windowSize);
    record(st, "shot/viewportSize");
    screenshotSizeFields(dialog, st.view);
    ImGui::Checkbox("As the viewport shows it (diagnostic view, overlays)", &dialog.asShown);
    record(st, "shot/asShown");
    screenshotExportBoxes(st, dialog);
    screenshotFolderPicker(st, dialog);
    if (!dialog.error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.45f, 1.0f), "%s", dialog.error.c_str());
    ImGui::TextDisabled(
        "One PNG per backend shown, rendered offscreen;\nnamed screenshot-<backend>[-N].png, never overwriting.\nF12 saves into the same folder "
        "with the same choices.");
    if (ImGui::Button("Take", ImVec2(px(90), 0)) && takeScreenshot(st, dialog, dialog.error)) ImGui::CloseCurrentPopup();
    record(st, "shot/take");
    ImGui::SameLine();
    if (ImGui::Button("Cancel", ImVec2(px(90), 0)) || escapeCancels(st)) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
}

// Help > Controls: input and action in two table columns (the font is proportional, so
// space-padded text never lined up).
void drawControlsHelp(ViewerState& st) {
    static constexpr std::pair<const char*, const char*> kControls[] = {
        {"Click", "select (empty space clears), pin the pixel inspector"},
        {"Ctrl+click", "add to / take out of the selection"},
        {"Left drag", "orbit around the pivot"},
        {"Middle / Shift+left drag", "pan"},
        {"Wheel", "zoom"},
        {"Right drag + WASD", "fly (Q/E down/up, Shift faster)"},
        {"F", "fit scene / selection"},
        {"Home", "reset to the scene camera"},
        {"1 / 2 / 3", "backend gl / raster / raycast"},
        {"F12", "screenshot (as set in File > Screenshot at resolution...)"},
        {"Space", "play / pause the animation (viewport)"},
        {"F2", "rename selection"},
        {"Del, Ctrl+D", "delete / duplicate selection"},
        {"Ctrl+Z", "undo (Edit menu names the step)"},
        {"Ctrl+Shift+Z, Ctrl+Y", "redo"},
        {"Ctrl+N/O/S/Q", "new / open / save / quit"},
        {"Escape", "close a menu, list or dialog"},
    };
    // Sized to its table, so no row is ever cut off (a fixed width clipped the longer actions).
    if (ImGui::Begin("Controls", &st.ui.panels.showHelp, ImGuiWindowFlags_AlwaysAutoResize)) {
        if (ImGui::BeginTable("controls", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
            for (const auto& [input, action] : kControls) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(input);
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(action);
            }
            ImGui::EndTable();
        }
        ImGui::TextUnformatted("Drag tree nodes onto others to re-parent.\nDrop files onto the window to open them.");
    }
    ImGui::End();
}

}   // namespace

void drawDialogs(ViewerState& st) {
    if (st.ui.requests.openDialog) {
        st.ui.requests.openDialog = false;
        openBrowser(false, st);
    }
    if (st.ui.requests.saveAsDialog) {
        st.ui.requests.saveAsDialog = false;
        openBrowser(true, st);
    }
    drawFileBrowser(st);
    drawScreenshotDialog(st);

    if (st.ui.confirmOpen && !ImGui::IsPopupOpen("Unsaved changes")) ImGui::OpenPopup("Unsaved changes");
    if (ImGui::BeginPopupModal("Unsaved changes", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        if (!st.ui.confirmOpen) ImGui::CloseCurrentPopup();   // answered elsewhere (automation's `answer`)
        const char* what = st.ui.pending == PendingAction::Quit  ? "quitting"
                           : st.ui.pending == PendingAction::New ? "starting a new scene"
                                                                 : "opening another file";
        ImGui::Text("The scene has unsaved changes.\nSave them before %s?", what);
        ImGui::Spacing();
        if (ImGui::Button("Save", ImVec2(px(90), 0))) {
            st.confirm(ConfirmChoice::Save);
            ImGui::CloseCurrentPopup();
        }
        record(st, "confirm/save");
        ImGui::SameLine();
        if (ImGui::Button("Discard", ImVec2(px(90), 0))) {
            st.confirm(ConfirmChoice::Discard);
            ImGui::CloseCurrentPopup();
        }
        record(st, "confirm/discard");
        ImGui::SameLine();
        if (ImGui::Button("Cancel", ImVec2(px(90), 0)) || escapeCancels(st)) {
            st.confirm(ConfirmChoice::Cancel);
            ImGui::CloseCurrentPopup();
        }
        record(st, "confirm/cancel");
        ImGui::EndPopup();
    }

    // Save As onto an existing file: nothing is replaced without this question.
    if (st.ui.replaceOpen && !ImGui::IsPopupOpen("Replace file?")) ImGui::OpenPopup("Replace file?");
    if (ImGui::BeginPopupModal("Replace file?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        if (!st.ui.replaceOpen) ImGui::CloseCurrentPopup();   // answered elsewhere (automation's `answer`)
        ImGui::Text("%s already exists.\nReplace it with this scene?", st.ui.replacePath.filename().string().c_str());
        ImGui::TextDisabled("%s", st.ui.replacePath.parent_path().string().c_str());
        ImGui::Spacing();
        if (ImGui::Button("Replace", ImVec2(px(90), 0))) {
            st.confirmReplace(true);
            ImGui::CloseCurrentPopup();
        }
        record(st, "replace/replace");
        ImGui::SameLine();
        if (ImGui::Button("Cancel", ImVec2(px(90), 0)) || escapeCancels(st)) {
            st.confirmReplace(false);
            ImGui::CloseCurrentPopup();
        }
        record(st, "replace/cancel");
        ImGui::EndPopup();
    }

    if (!st.ui.errorPopup.empty() && !ImGui::IsPopupOpen("Error")) ImGui::OpenPopup("Error");
    if (ImGui::BeginPopupModal("Error", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::PushTextWrapPos(px(520));
        ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.5f, 1.0f), "%s", st.ui.errorPopup.c_str());
        ImGui::PopTextWrapPos();
        if (ImGui::Button("OK", ImVec2(px(90), 0)) || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Enter)) || escapeCancels(st)) {
            st.ui.errorPopup.clear();
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }

    if (st.ui.panels.showHelp) drawControlsHelp(st);
}

// --- 11. shortcuts and layout ------------------------------------------------------------------

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
        return;
    }
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

// Left: the scene tree (width resizable and persisted in imgui.ini). Returns its width.
float drawScenePanel(ViewerState& st, float top, float bodyH) {
    ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(0, top), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(px(260), bodyH), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSizeConstraints(ImVec2(px(160), bodyH), ImVec2(std::max(px(160), io.DisplaySize.x * 0.45f), bodyH));
    if (ImGui::Begin("Scene", nullptr, kPanelFlags)) drawSceneTree(st);
    float w = ImGui::GetWindowWidth();
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
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x, top), ImGuiCond_Always, ImVec2(1.0f, 0.0f));
    ImGui::SetNextWindowSize(ImVec2(px(380), bodyH), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSizeConstraints(ImVec2(px(220), bodyH), ImVec2(std::max(px(220), io.DisplaySize.x * 0.45f), bodyH));
    if (ImGui::Begin("Properties", nullptr, kPanelFlags)) {
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
    float w = ImGui::GetWindowWidth();
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
    float leftW = drawScenePanel(st, menuH, bodyH);
    float rightW = drawPropertiesPanel(st, menuH, bodyH);
    drawViewportWindow(st, view, time, dt, ImVec2(leftW, menuH), ImVec2(std::max(io.DisplaySize.x - leftW - rightW, 1.0f), bodyH));
    drawStatusBar(st, view, statusH);
    drawDialogs(st);
    handleShortcuts(st);
    // The mouse was released (or never pressed): the next edit starts a new undo step instead
    // of merging into the last drag's.
    if (!ImGui::IsAnyItemActive()) st.doc.history.closeMerge();
}

}   // namespace ui
