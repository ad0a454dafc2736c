// scene_tree.cpp - drawSceneTree(): the left panel's node tree (select, Ctrl+click, visibility
// boxes, in-place rename, context menu, drag-and-drop re-parenting) and its Add / Duplicate /
// Delete toolbar.
#include "panels/panel_common.h"

#include <imgui_stdlib.h>

namespace ui {

using namespace panels_detail;

namespace {

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

}   // namespace ui
