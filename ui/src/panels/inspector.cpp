// inspector.cpp - drawInspector(): the Inspector tab. Nothing selected: the scene's summary and
// ambient light. A node: name and visibility, transform (TRS or matrix, world matrix) and one
// section per payload kind (mesh, implicit shape, CSG, light, camera, parametric surface, density
// grid) with its material.
#include "panels/panel_common.h"

#include "scenegraph/deform.h"
#include "scenegraph/transforms.h"

#include <imgui_stdlib.h>

namespace ui {

using namespace panels_detail;

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
    if (st.doc.scene.settings.reflection == sg::ReflectionModel::Pbr) {
        // glTF's parameters: base colour, metallic, roughness, ... (ka, kd, ks and n are Phong's).
        for (std::string_view key : {"baseColor"}) ch |= paramWidget(st, "material", *sg::findParam<sg::Material>(key), m);
        ch |= paramSection(st, "material", "Physically based", m);
        for (std::string_view key : {"emissive", "reflectivity", "unlit", "doubleSided"})
            ch |= paramWidget(st, "material", *sg::findParam<sg::Material>(key), m);
    } else {
        ch |= paramSection(st, "material", "Phong", m);
    }
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

}   // namespace ui
