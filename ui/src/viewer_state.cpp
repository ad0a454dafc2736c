// viewer_state.cpp - the viewer's pure state and actions (see viewer_state.h).
//
// Sections: scene + edits, backend, camera, files (guard, async load with progress/cancel,
// save), animation playback, config helpers.
#include "ui/viewer_state.h"

#include "ui/aov_export.h"

#include "assets/files.h"
#include "renderers/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace ui {

// --- scene + edits --------------------------------------------------------------------------

void ViewerState::setScene(sg::Scene s, fs::path path) {
    doc.scene = std::move(s);
    doc.path = std::move(path);
    doc.dirty = false;
    doc.selected = sg::kNoNode;
    doc.alsoSelected.clear();
    doc.history.clear();
    ui.panels.renaming = sg::kNoNode;
    anim.clips.clear();   // a load puts its clips back after this
    anim.clip = 0;
    anim.time = 0.0;
    anim.playing = false;
    ++doc.version;
    ++doc.sceneSerial;
    resetView();
}

void ViewerState::markEdited() {
    doc.history.forgetSaved();
    doc.dirty = true;
    ++doc.version;
}

void ViewerState::markViewChanged() { ++view.version; }

UndoStep ViewerState::newStep(std::string label) const {
    UndoStep step;
    step.label = std::move(label);
    step.selectedBefore = doc.selected;
    return step;
}

void ViewerState::commit(UndoStep step, std::string_view mergeKey) {
    if (step.changes.empty()) return;
    step.selectedAfter = doc.selected;
    std::erase_if(doc.alsoSelected, [&](sg::NodeId id) { return !doc.scene.valid(id); });   // never a stale id a later add reuses
    doc.history.push(std::move(step), mergeKey);
    doc.dirty = !doc.history.atSavedState();
    ++doc.version;
}

namespace {
// After undo / redo: the step's selection when its node is there, else none; an in-place
// rename of a node that is gone ends.
void afterHistoryMove(ViewerState& st, sg::NodeId selection, const std::string& what) {
    st.selectNode(selection);
    if (!st.doc.scene.valid(st.ui.panels.renaming)) st.ui.panels.renaming = sg::kNoNode;
    st.doc.dirty = !st.doc.history.atSavedState();
    ++st.doc.version;
    st.ui.status = what;
}
}   // namespace

bool ViewerState::undo() {
    std::string err;
    const UndoStep* step = doc.history.undo(doc.scene, &err);
    if (!step) {
        if (!err.empty()) afterHistoryMove(*this, doc.selected, err);
        return false;
    }
    afterHistoryMove(*this, step->selectedBefore, "Undone: " + step->label);
    return true;
}

bool ViewerState::redo() {
    std::string err;
    const UndoStep* step = doc.history.redo(doc.scene, &err);
    if (!step) {
        if (!err.empty()) afterHistoryMove(*this, doc.selected, err);
        return false;
    }
    afterHistoryMove(*this, step->selectedAfter, "Redone: " + step->label);
    return true;
}

void ViewerState::selectNode(sg::NodeId id) {
    doc.selected = doc.scene.valid(id) ? id : sg::kNoNode;
    doc.alsoSelected.clear();
}

void ViewerState::toggleSelected(sg::NodeId id) {
    if (!doc.scene.valid(id)) return;
    std::vector<sg::NodeId> others = selection();
    const bool had = std::find(others.begin(), others.end(), id) != others.end();
    std::erase(others, id);
    if (!had) {   // added: the new active node
        doc.selected = id;
        doc.alsoSelected = std::move(others);
        return;
    }
    doc.selected = others.empty() ? sg::kNoNode : others.front();   // taken out: the last added (selection() is newest first) takes over
    if (!others.empty()) others.erase(others.begin());
    doc.alsoSelected = std::move(others);
}

std::vector<sg::NodeId> ViewerState::selection() const {
    std::vector<sg::NodeId> s;
    if (doc.scene.valid(doc.selected)) s.push_back(doc.selected);
    for (sg::NodeId id : doc.alsoSelected)
        if (doc.scene.valid(id) && std::find(s.begin(), s.end(), id) == s.end()) s.push_back(id);
    return s;
}

bool ViewerState::isSelected(sg::NodeId id) const {
    return doc.scene.valid(id) && (id == doc.selected || std::find(doc.alsoSelected.begin(), doc.alsoSelected.end(), id) != doc.alsoSelected.end());
}

bool ViewerState::renameNode(sg::NodeId id, const std::string& name) {
    if (!doc.scene.valid(id) || name.empty() || doc.scene.node(id).name == name) return false;
    UndoStep step = newStep("Rename " + doc.scene.node(id).name);
    step.changes.push_back(NodeNameChange{id, doc.scene.node(id).name, name});
    doc.scene.setName(id, name);
    commit(std::move(step));
    return true;
}

void ViewerState::setVisible(sg::NodeId id, bool v) {
    if (!doc.scene.valid(id) || doc.scene.node(id).visible == v) return;
    UndoStep step = newStep((v ? "Show " : "Hide ") + doc.scene.node(id).name);
    step.changes.push_back(NodeVisibleChange{id, !v, v});
    doc.scene.setVisible(id, v);
    commit(std::move(step));
}

namespace {
// Default parent for new nodes: the selection when it can hold children, else the root.
sg::NodeId parentFor(const ViewerState& st, sg::NodeId parent) {
    if (st.doc.scene.valid(parent)) return parent;
    sg::NodeId s = st.doc.selected;
    if (!st.doc.scene.valid(s)) return st.doc.scene.root();
    const sg::Payload& p = st.doc.scene.node(s).payload;
    if (std::holds_alternative<std::monostate>(p) || std::holds_alternative<sg::CsgPayload>(p)) return s;
    return st.doc.scene.valid(st.doc.scene.node(s).parent) ? st.doc.scene.node(s).parent : st.doc.scene.root();
}
std::string uniqueName(const sg::Scene& s, const std::string& base) {
    if (s.findByName(base) == sg::kNoNode) return base;
    for (int i = 2;; ++i) {
        std::string n = base + " " + std::to_string(i);
        if (s.findByName(n) == sg::kNoNode) return n;
    }
}
// The step of a node just added (with its subtree): selects it and records it.
sg::NodeId commitAdded(ViewerState& st, UndoStep step, sg::NodeId id) {
    step.label += " " + st.doc.scene.node(id).name;
    step.changes.insert(step.changes.begin(), SubtreeChange{id, /*added=*/true, {}});
    st.selectNode(id);
    st.commit(std::move(step));
    return id;
}
}   // namespace

sg::NodeId ViewerState::addGroup(sg::NodeId parent) {
    UndoStep step = newStep("Add");
    sg::NodeId id = doc.scene.addNode(uniqueName(doc.scene, "group"), parentFor(*this, parent));
    return commitAdded(*this, std::move(step), id);
}

sg::NodeId ViewerState::addShape(sg::ImplicitType type, sg::NodeId parent) {
    UndoStep step = newStep("Add");
    sg::ImplicitPayload p;
    p.shape.type = type;
    if (type == sg::ImplicitType::Quadric) {
        // A one-sheet hyperboloid x^2 + z^2 - y^2 = 0.25, clipped to the unit box.
        p.shape.quadric = sg::mat4(1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -0.25f);
    }
    sg::NodeId id = doc.scene.addNode(uniqueName(doc.scene, std::string(sg::toString(type))), parentFor(*this, parent), p);
    return commitAdded(*this, std::move(step), id);
}

sg::NodeId ViewerState::addCsg(sg::CsgOp op, sg::NodeId parent) {
    UndoStep step = newStep("Add");
    sg::NodeId id = doc.scene.addNode(uniqueName(doc.scene, "csg " + std::string(sg::toString(op))), parentFor(*this, parent),
                                      sg::CsgPayload{sg::CsgNode{op}, -1});
    // Two operands so the node shows something right away.
    sg::ImplicitShape a;
    a.type = sg::ImplicitType::Box;
    a.halfExtents = sg::vec3(0.6f);
    sg::ImplicitShape b;
    b.type = sg::ImplicitType::Sphere;
    b.radius = 0.75f;
    doc.scene.addNode("box", id, sg::ImplicitPayload{a, -1});
    doc.scene.addNode("sphere", id, sg::ImplicitPayload{b, -1});
    return commitAdded(*this, std::move(step), id);
}

sg::NodeId ViewerState::addLight(sg::LightType type, sg::NodeId parent) {
    UndoStep step = newStep("Add");
    sg::Light l;
    l.type = type;
    l.intensity = type == sg::LightType::Directional ? 1.0f : 10.0f;
    l.inverseSquare = type != sg::LightType::Directional;
    sg::NodeId id = doc.scene.addNode(uniqueName(doc.scene, std::string(sg::toString(type)) + " light"), parentFor(*this, parent), l);
    sg::LocalTransform t = sg::LocalTransform::fromTRS(view.camera.pivot + sg::vec3(0, 3, 0));
    t.setEulerDegrees(sg::vec3(-90, 0, 0));   // point down
    doc.scene.setLocal(id, t);
    return commitAdded(*this, std::move(step), id);
}

sg::NodeId ViewerState::addCamera() {
    UndoStep step = newStep("Add");
    sg::Camera c;
    c.projection = projection();
    c.focusDistance = view.camera.distance;
    sg::NodeId id = doc.scene.addNode(uniqueName(doc.scene, "camera"), doc.scene.root(), c);
    doc.scene.setLocalMatrix(id, view.camera.world());
    sg::LocalTransform t = doc.scene.node(id).local;
    if (t.tryMakeTRS()) doc.scene.setLocal(id, t);
    if (!doc.scene.valid(doc.scene.activeCamera)) {
        step.changes.push_back(ActiveCameraChange{doc.scene.activeCamera, id});
        doc.scene.activeCamera = id;
    }
    return commitAdded(*this, std::move(step), id);
}

bool ViewerState::removeNode(sg::NodeId id) {
    if (!doc.scene.valid(id) || id == doc.scene.root()) return false;
    UndoStep step = newStep("Delete " + doc.scene.node(id).name);
    sg::DetachedSubtree d = doc.scene.detach(id);   // also clears the active camera when it was inside
    if (d.id != id) return false;
    step.changes.push_back(SubtreeChange{id, /*added=*/false, std::move(d)});
    if (!doc.scene.valid(doc.selected)) doc.selected = sg::kNoNode;
    commit(std::move(step));
    return true;
}

bool ViewerState::removeSelection() {
    std::vector<sg::NodeId> del;   // the selected nodes no other selected node contains (a subtree goes once)
    for (sg::NodeId id : selection()) {
        if (id == doc.scene.root()) continue;
        bool inside = false;
        for (sg::NodeId other : selection()) inside = inside || (other != id && other != doc.scene.root() && doc.scene.isAncestor(other, id));
        if (!inside) del.push_back(id);
    }
    if (del.empty()) return false;
    if (del.size() == 1) return removeNode(del[0]);
    UndoStep step = newStep("Delete " + std::to_string(del.size()) + " nodes");
    for (sg::NodeId id : del) {
        sg::DetachedSubtree d = doc.scene.detach(id);
        if (d.id == id) step.changes.push_back(SubtreeChange{id, /*added=*/false, std::move(d)});
    }
    selectNode(sg::kNoNode);
    commit(std::move(step));
    return true;
}

sg::NodeId ViewerState::duplicateNode(sg::NodeId id) {
    if (!doc.scene.valid(id) || id == doc.scene.root()) return sg::kNoNode;
    UndoStep step = newStep("Duplicate " + doc.scene.node(id).name);
    sg::NodeId c = doc.scene.duplicate(id);
    if (!doc.scene.valid(c)) return c;
    doc.scene.setName(c, uniqueName(doc.scene, doc.scene.node(id).name + " copy"));
    step.changes.push_back(SubtreeChange{c, /*added=*/true, {}});
    selectNode(c);
    commit(std::move(step));
    return c;
}

bool ViewerState::reparent(sg::NodeId id, sg::NodeId newParent, std::string* error) {
    std::string err;
    if (doc.scene.valid(id) && doc.scene.valid(newParent) && doc.scene.node(id).parent == newParent) return false;   // no-op
    NodePlace before;
    if (doc.scene.valid(id)) before = NodePlace{doc.scene.node(id).parent, doc.scene.childIndex(id), doc.scene.node(id).local};
    if (!doc.scene.reparent(id, newParent, /*keepWorld=*/true, &err)) {
        if (err.empty()) err = "cannot move this node there";
        ui.status = "Move refused: " + err;
        if (error) *error = err;
        return false;
    }
    UndoStep step = newStep("Move " + doc.scene.node(id).name + " under " + doc.scene.node(newParent).name);
    step.changes.push_back(MoveChange{id, before, NodePlace{newParent, doc.scene.childIndex(id), doc.scene.node(id).local}});
    commit(std::move(step));
    return true;
}

void ViewerState::setLocal(sg::NodeId id, const sg::LocalTransform& t, std::string_view mergeKey) {
    if (!doc.scene.valid(id) || doc.scene.node(id).local == t) return;
    UndoStep step = newStep("Transform " + doc.scene.node(id).name);
    step.changes.push_back(NodeLocalChange{id, doc.scene.node(id).local, t});
    doc.scene.setLocal(id, t);
    commit(std::move(step), mergeKey);
}

void ViewerState::setPayload(sg::NodeId id, const sg::Payload& p, std::string_view mergeKey) {
    if (!doc.scene.valid(id) || doc.scene.node(id).payload == p) return;
    UndoStep step = newStep("Edit " + doc.scene.node(id).name);
    step.changes.push_back(NodePayloadChange{id, doc.scene.node(id).payload, p});
    doc.scene.setPayload(id, p);
    commit(std::move(step), mergeKey);
}

void ViewerState::setMaterial(int index, const sg::Material& m, std::string_view mergeKey) {
    if (index < 0 || size_t(index) >= doc.scene.materials.size() || doc.scene.materials[size_t(index)] == m) return;
    UndoStep step = newStep("Edit material " + doc.scene.materials[size_t(index)].name);
    step.changes.push_back(MaterialChange{index, doc.scene.materials[size_t(index)], m});
    doc.scene.materials[size_t(index)] = m;
    commit(std::move(step), mergeKey);
}

namespace {
// A "Setting refused: ..." status line goes once a valid value is set.
void clearRefusal(ViewerState& st) {
    if (st.ui.status.rfind("Setting refused", 0) == 0) st.ui.status.clear();
}
// The material index of a payload kind that has one (null for groups, cameras, lights).
int* materialIndexOf(sg::Payload& p) {
    return std::visit(
        [](auto& x) -> int* {
            if constexpr (requires { x.material; })
                return &x.material;
            else
                return nullptr;
        },
        p);
}
}   // namespace

int ViewerState::addMaterialFor(sg::NodeId id, const sg::Material& m) {
    if (!doc.scene.valid(id)) return -1;
    sg::Payload p = doc.scene.node(id).payload;
    int* slot = materialIndexOf(p);
    if (!slot) return -1;
    UndoStep step = newStep("New material for " + doc.scene.node(id).name);
    int index = int(doc.scene.materials.size());
    step.changes.push_back(MaterialChange{index, std::nullopt, m});
    doc.scene.materials.push_back(m);
    *slot = index;
    step.changes.push_back(NodePayloadChange{id, doc.scene.node(id).payload, p});
    doc.scene.setPayload(id, p);
    commit(std::move(step));
    return index;
}

std::string ViewerState::setSettings(const sg::RenderSettings& s, std::string_view mergeKey) {
    std::string err = s.validate();
    if (!err.empty()) {
        ui.status = "Setting refused: " + err;
        return err;
    }
    clearRefusal(*this);   // valid again (also when dragged back to the value it had)
    if (s == doc.scene.settings) return {};
    std::string names = sg::changedParams(doc.scene.settings, s);
    UndoStep step = newStep("Change " + (names.empty() ? std::string("rendering settings") : names));
    step.changes.push_back(SettingsChange{doc.scene.settings, s});
    doc.scene.settings = s;
    commit(std::move(step), mergeKey);
    return {};
}

// --- backend ---------------------------------------------------------------------------------

void ViewerState::setBackend(const std::string& name) {
    if (view.backend == name) return;
    view.backend = name;   // the split and difference views keep their own backends
    ui.status = "Backend: " + name;
}

std::string defaultBackend() {
    std::vector<std::string> names = rnd::rendererNames();
    return names.empty() ? std::string() : names.front();
}

std::vector<std::string> comparisonBackends(const std::string& first, size_t n) {
    std::vector<std::string> out{first};
    for (const std::string& b : rnd::rendererNames())
        if (out.size() < n && b != first) out.push_back(b);
    while (out.size() < n) out.push_back(out.back());
    out.resize(n);
    return out;
}

void ViewerState::setBackendIndex(int index) {
    std::vector<std::string> names = rnd::rendererNames();
    if (index >= 0 && size_t(index) < names.size()) setBackend(names[index]);
}

// --- view modes ------------------------------------------------------------------------------

void ViewerState::showView(ViewMode mode, int splitCount) {
    CompareConfig& c = view.compare;
    c.mode = mode;
    // First shown: start from the single view's backend and compare it with the others.
    if (mode == ViewMode::Split && std::any_of(c.split.begin(), c.split.end(), [](const std::string& b) { return b.empty(); })) {
        std::vector<std::string> d = comparisonBackends(view.backend, 3);
        std::copy(d.begin(), d.end(), c.split.begin());
    }
    if (mode == ViewMode::Difference && (c.diff[0].empty() || c.diff[1].empty())) {
        std::vector<std::string> d = comparisonBackends(view.backend, 2);
        std::copy(d.begin(), d.end(), c.diff.begin());
    }
    if (mode == ViewMode::Split && (splitCount == 2 || splitCount == 3) && splitCount != c.count) {
        c.count = splitCount;
        c.dividers = splitCount == 2 ? std::array<float, 2>{0.5f, 0.75f} : std::array<float, 2>{1.0f / 3.0f, 2.0f / 3.0f};
    }
}

bool ViewerState::showView(std::string_view name) {
    if (name == "single")
        showView(ViewMode::Single);
    else if (name == "split")
        showView(ViewMode::Split, 2);
    else if (name == "split3")
        showView(ViewMode::Split, 3);
    else if (name == "difference")
        showView(ViewMode::Difference);
    else
        return false;
    return true;
}

std::string ViewerState::viewName() const {
    switch (view.compare.mode) {
    case ViewMode::Single: return "single";
    case ViewMode::Split: return view.compare.count == 3 ? "split3" : "split";
    case ViewMode::Difference: return "difference";
    }
    return "single";
}

// --- difference figures ----------------------------------------------------------------------

std::string DiffFigures::meanText() const {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", mean);
    return buf;
}

std::string DiffFigures::psnrText() const {
    if (!std::isfinite(psnr)) return "identical";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f dB", psnr);
    return buf;
}

std::string DiffFigures::withinText() const {
    if (within >= 1.0) return "100%";
    char buf[32];   // cut to 0.01%: 99.997% is "99.99%", never a rounded-up 100%
    std::snprintf(buf, sizeof buf, "%.2f%%", std::floor(std::max(within, 0.0) * 10000.0 + 1e-6) / 100.0);
    return buf;
}

std::string DiffFigures::summary(const std::string& a, const std::string& b, int threshold) const {
    std::string s = "|" + a + " - " + b + "|";
    if (valid)
        s += "   mean " + meanText() + "   max " + std::to_string(max) + "   PSNR " + psnrText() + "   within " + std::to_string(threshold) + ": " +
             withinText();
    return s;
}

// --- camera ----------------------------------------------------------------------------------

namespace {
const sg::Camera* activeCam(const sg::Scene& s) {
    if (!s.valid(s.activeCamera)) return nullptr;
    return std::get_if<sg::Camera>(&s.node(s.activeCamera).payload);
}
}   // namespace

const sg::Projection& ViewerState::projection() const {
    const sg::Camera* c = activeCam(doc.scene);
    return c ? c->projection : view.fallbackProjection;
}

void ViewerState::setProjection(const sg::Projection& p, std::string_view mergeKey) {
    sg::NodeId cam = doc.scene.activeCamera;
    if (doc.scene.valid(cam) && std::holds_alternative<sg::Camera>(doc.scene.node(cam).payload)) {
        sg::Payload payload = doc.scene.node(cam).payload;
        std::get<sg::Camera>(payload).projection = p;
        setPayload(cam, payload, mergeKey);
        return;
    }
    view.fallbackProjection = p;
    ++view.version;
}

float ViewerState::focusDistance() const {
    const sg::Camera* c = activeCam(doc.scene);
    return c ? c->focusDistance : view.fallbackFocus;
}

sg::Projection ViewerState::viewProjection() const {
    sg::Projection p = projection();
    p.orthoHalfHeight *= view.camera.orthoScale;
    // Keep the clip range around the pivot when the user zooms far out or in.
    if (p.type == sg::ProjectionType::Perspective && !p.useFrustum) {
        float ratio = view.camera.distance / std::max(focusDistance(), 1e-6f);
        if (ratio > 1.0f) p.zFar *= ratio;
        if (ratio < 1.0f) p.zNear = std::max(p.zNear * ratio, 1e-4f);
    }
    return p;
}

void ViewerState::fitView(bool selectionOnly) {
    sg::Aabb b;
    if (selectionOnly) {
        // Bounds of the selected subtrees (a node without geometry: a unit box about its origin).
        for (sg::NodeId sel : selection()) {
            sg::Aabb one;
            for (sg::NodeId id : doc.scene.depthFirstOrder())
                if (doc.scene.isAncestor(sel, id)) one.extend(doc.scene.nodeWorldBounds(id));   // skinned meshes as posed
            if (one.empty()) one = sg::Aabb{sg::vec3(doc.scene.world(sel)[3]) - 0.5f, sg::vec3(doc.scene.world(sel)[3]) + 0.5f};
            b.extend(one);
        }
    }
    if (b.empty()) b = doc.scene.worldBounds();
    float aspect = float(std::max(view.viewportWidth, 1)) / float(std::max(view.viewportHeight, 1));
    view.camera.fit(b, projection().effectiveFovyDeg(aspect), aspect, projection().orthoHalfHeight);
    markViewChanged();
}

std::string ViewerState::setViewFromCameraModel(const sg::CameraModel& m, const std::string& projection, int width, int height) {
    const int vw = std::max(view.viewportWidth, 1), vh = std::max(view.viewportHeight, 1);
    if (width < 1 || height < 1) {
        width = vw;
        height = vh;
    }
    sg::Projection p = this->projection();
    p.zNear = m.zNear;
    p.zFar = m.zFar;
    std::string err;
    if (projection == "perspective") {
        if (!m.pinhole) return "a perspective camera needs K";
        const double sx = double(vw) / width, sy = double(vh) / height;
        if (!sg::projectionFromIntrinsics(m.K[0][0] * sx, m.K[1][1] * sy, m.K[0][2] * sx, m.K[1][2] * sy, vw, vh, m.zNear, m.zFar, p, &err))
            return err;
    } else {
        if (!(std::fabs(m.projection[1][1]) > 0)) return "the projection matrix has no vertical scale";
        p.type = projection == "oblique" ? sg::ProjectionType::Oblique : sg::ProjectionType::Orthographic;
        p.orthoHalfHeight = 1.0f / std::fabs(m.projection[1][1]);
    }
    const sg::mat4 flip = glm::scale(sg::mat4(1.0f), sg::vec3(1.0f, -1.0f, -1.0f));
    const sg::mat4 cameraWorld = m.cameraToWorld * flip;   // computer-vision axes -> the camera's own (looks down -z)
    if (!sg::isFinite(cameraWorld)) return "the pose is not finite";
    view.camera.setFromWorld(cameraWorld, pivotDistance(cameraWorld, view.camera.distance));
    view.camera.orthoScale = 1.0f;
    setProjection(p, "");
    markViewChanged();
    return {};
}

void ViewerState::viewAlong(AxisView v) {
    // yaw 0 puts the eye on +z of the pivot (looking toward -z: the front), pitch + above it.
    constexpr float kPi = 3.14159265358979f, kUp = 89.0f * kPi / 180.0f;
    float yaw = 0.0f, pitch = 0.0f;
    switch (v) {
    case AxisView::Front: break;
    case AxisView::Back: yaw = kPi; break;
    case AxisView::Right: yaw = 0.5f * kPi; break;
    case AxisView::Left: yaw = -0.5f * kPi; break;
    case AxisView::Top: pitch = kUp; break;
    case AxisView::Bottom: pitch = -kUp; break;
    case AxisView::Isometric:
        yaw = 0.25f * kPi;
        pitch = std::atan(1.0f / std::sqrt(2.0f));   // 35.26 degrees: the three axes equally foreshortened
        break;
    }
    view.camera.yaw = yaw;
    view.camera.pitch = pitch;
    markViewChanged();
}

void ViewerState::togglePerspective() {
    sg::Projection p = projection();
    const float aspect = float(std::max(view.viewportWidth, 1)) / float(std::max(view.viewportHeight, 1));
    const float d = view.camera.distance;
    if (p.type == sg::ProjectionType::Perspective) {
        // The orthographic view shows what the perspective showed at the pivot's depth.
        p.type = sg::ProjectionType::Orthographic;
        p.orthoHalfHeight = std::max(d * std::tan(sg::radians(p.effectiveFovyDeg(aspect)) * 0.5f), 1e-6f);
        view.camera.orthoScale = 1.0f;
    } else {
        p.type = sg::ProjectionType::Perspective;
        const float h = p.orthoHalfHeight * view.camera.orthoScale;
        view.camera.distance = std::max(h / std::tan(sg::radians(p.effectiveFovyDeg(aspect)) * 0.5f), OrbitCamera::kMinDistance);
        view.camera.orthoScale = 1.0f;
    }
    setProjection(p, "");
    ui.status = std::string("Projection: ") + std::string(sg::nameOf(p.type));
    markViewChanged();
}

float ViewerState::pivotDistance(const sg::mat4& cameraWorld, float stored) const {
    const sg::Aabb b = doc.scene.worldBounds();
    if (b.empty()) return stored;
    const sg::vec3 eye(cameraWorld[3]), fwd = glm::normalize(-sg::vec3(cameraWorld[2]));
    const sg::vec3 grow = 0.1f * b.extent() + sg::vec3(1e-6f);
    const sg::vec3 at = eye + fwd * stored;
    const bool inside = glm::all(glm::greaterThanEqual(at, b.min - grow)) && glm::all(glm::lessThanEqual(at, b.max + grow));
    if (std::isfinite(stored) && stored > 0.0f && inside) return stored;
    // The bounds' centre on the view ray: the model stays in view while orbiting.
    const float t = glm::dot(b.center() - eye, fwd);
    return t > OrbitCamera::kMinDistance && std::isfinite(t) ? t : stored;
}

void ViewerState::resetView() {
    const sg::Camera* c = activeCam(doc.scene);
    if (c) {
        const sg::mat4 world = doc.scene.world(doc.scene.activeCamera);
        view.camera.setFromWorld(world, pivotDistance(world, c->focusDistance));
    } else {
        if (doc.scene.cameras().empty()) {
            view.camera = OrbitCamera{};
            view.camera.yaw = std::atan2(0.5f, 1.0f);
            view.camera.pitch = 0.35f;
            float aspect = float(std::max(view.viewportWidth, 1)) / float(std::max(view.viewportHeight, 1));
            view.camera.fit(doc.scene.worldBounds(), view.fallbackProjection.fovyDeg, aspect, view.fallbackProjection.orthoHalfHeight);
            sg::Aabb b = doc.scene.worldBounds();
            float r = b.empty() ? 2.0f : 0.5f * glm::length(b.extent());
            view.fallbackProjection.zNear = std::max(view.camera.distance - 3.0f * r, view.camera.distance * 0.01f);
            view.fallbackProjection.zFar = view.camera.distance + 3.0f * r;
            view.fallbackFocus = view.camera.distance;
        } else {
            useSceneCamera(doc.scene.cameras().front());
            return;
        }
    }
    markViewChanged();
}

void ViewerState::useSceneCamera(sg::NodeId id) {
    if (!doc.scene.valid(id) || !std::holds_alternative<sg::Camera>(doc.scene.node(id).payload)) return;
    if (doc.scene.activeCamera != id) {
        UndoStep step = newStep("Look through " + doc.scene.node(id).name);
        step.changes.push_back(ActiveCameraChange{doc.scene.activeCamera, id});
        doc.scene.activeCamera = id;
        commit(std::move(step));
    }
    const sg::mat4 world = doc.scene.world(id);
    view.camera.setFromWorld(world, pivotDistance(world, std::get<sg::Camera>(doc.scene.node(id).payload).focusDistance));
    markViewChanged();
}

void ViewerState::storeViewInCamera() {
    sg::NodeId id = doc.scene.activeCamera;
    if (!doc.scene.valid(id) || !std::holds_alternative<sg::Camera>(doc.scene.node(id).payload)) return;
    sg::NodeId parent = doc.scene.node(id).parent;
    sg::mat4 parentWorld = doc.scene.valid(parent) ? doc.scene.world(parent) : sg::mat4(1.0f);
    sg::LocalTransform t = sg::LocalTransform::fromMatrix(glm::inverse(parentWorld) * view.camera.world());
    t.tryMakeTRS();
    sg::Camera c = std::get<sg::Camera>(doc.scene.node(id).payload);
    float focus = view.camera.distance;
    float ortho = c.projection.orthoHalfHeight * view.camera.orthoScale;
    bool changed = !(doc.scene.node(id).local == t) || c.focusDistance != focus || c.projection.orthoHalfHeight != ortho;
    if (!changed) return;
    UndoStep step = newStep("Store view in " + doc.scene.node(id).name);
    step.changes.push_back(NodeLocalChange{id, doc.scene.node(id).local, t});
    doc.scene.setLocal(id, t);
    sg::Payload before = doc.scene.node(id).payload;
    c.focusDistance = focus;
    c.projection.orthoHalfHeight = ortho;
    step.changes.push_back(NodePayloadChange{id, std::move(before), c});
    doc.scene.setPayload(id, c);
    view.camera.orthoScale = 1.0f;
    commit(std::move(step));
}

sg::FrameInput ViewerState::buildFrame(float aspect) const {
    sg::FrameInput f = sg::flatten(doc.scene, aspect, doc.scene.activeCamera);
    f.camera = sg::makeFrameCamera(view.camera.world(), viewProjection(), aspect, view.camera.distance);
    return f;
}

sg::RenderSettings ViewerState::settingsFor(const std::string& b) const {
    sg::RenderSettings s = doc.scene.settings;
    auto it = view.aaOverride.find(b);
    if (it != view.aaOverride.end()) s.setAA(it->second);
    return s;
}

// --- files -----------------------------------------------------------------------------------

namespace {
// Where Save As writes for a chosen path: a native .json scene, so another extension gains one
// ("engine.gltf" -> "engine.gltf.json"): an import is never written over.
fs::path nativeTarget(const fs::path& path) {
    fs::path target = path;
    if (target.extension() != ".json") target += ".json";
    return target;
}

bool isNativeScene(const fs::path& path) { return !path.empty() && path.extension() == ".json"; }
}   // namespace

bool ViewerState::requestOpen(const fs::path& path) {
    // A file that cannot be opened is refused before any question about unsaved changes.
    if (std::string err = assets::checkSceneFile(path); !err.empty()) {
        ui.errorPopup = "Could not open " + path.string() + ":\n" + err;
        ui.status = "Open failed; the current scene is unchanged";
        return false;
    }
    if (doc.dirty) {
        ui.pending = PendingAction::Open;
        ui.pendingPath = path;
        ui.confirmOpen = true;
        return false;
    }
    startLoad(path);
    return true;
}

bool ViewerState::requestNew() {
    if (doc.dirty) {
        ui.pending = PendingAction::New;
        ui.confirmOpen = true;
        return false;
    }
    newScene();
    return true;
}

void ViewerState::newScene() {
    sg::Scene s;
    s.name = "untitled";
    sg::Light sun;
    sun.type = sg::LightType::Directional;
    sun.intensity = 1.0f;
    sun.inverseSquare = false;
    sg::NodeId light = s.addNode("light", s.root(), sun);
    sg::LocalTransform t;
    t.setEulerDegrees(sg::vec3(-50, 30, 0));   // from above, over the camera's shoulder
    s.setLocal(light, t);
    s.addDefaultCamera();   // frames the unit box around the origin, where new shapes go
    setScene(std::move(s), {});
    ui.status = "New scene";
}

bool ViewerState::requestQuit() {
    if (doc.dirty) {
        ui.pending = PendingAction::Quit;
        ui.confirmOpen = true;
        return false;
    }
    ui.requests.quit = true;
    return true;
}

void ViewerState::confirm(ConfirmChoice choice) {
    PendingAction action = ui.pending;
    ui.pending = PendingAction::None;
    ui.confirmOpen = false;
    if (choice == ConfirmChoice::Cancel || action == PendingAction::None) {
        ui.status = "Cancelled";
        return;
    }
    if (choice == ConfirmChoice::Save) {
        if (!isNativeScene(doc.path)) {
            // Needs a file name first: Save As asks for one, and the action follows the save.
            ui.afterSave = action;
            ui.afterSavePath = ui.pendingPath;
            ui.requests.saveAsDialog = true;
            ui.status = "Choose where to save; then " + std::string(action == PendingAction::Quit  ? "the viewer quits"
                                                                    : action == PendingAction::New ? "the new scene opens"
                                                                                                   : "the file opens");
            return;
        }
        if (save() != SaveOutcome::Saved) return;   // failed: keep everything, the error is shown
    }
    // The dirty flag stays as it is: only a scene that actually replaces this one (setScene
    // after a successful load, a new scene) clears it. A failed or cancelled load after
    // "Discard" leaves the document exactly as it was, unsaved edits and '*' included.
    switch (action) {
    case PendingAction::Open: startLoad(ui.pendingPath); break;
    case PendingAction::New: newScene(); break;
    case PendingAction::Quit: ui.requests.quit = true; break;
    case PendingAction::None: break;
    }
}

void ViewerState::startLoad(const fs::path& path) {
    if (load.task.valid()) {
        ui.status = "Still loading " + load.path.filename().string();
        return;
    }
    load.path = path;
    ui.status = "Loading " + path.string() + " ...";
    load.control = std::make_shared<LoadControl>();
    load.task = std::async(std::launch::async, [path, control = load.control] {
        try {
            assets::LoadOptions options;
            options.cancel = &control->cancel;
            options.progress = &control->progress;
            return assets::loadScene(path, options);
        } catch (const std::exception& e) {
            assets::LoadResult r;
            r.error = path.string() + ": " + e.what();
            return r;
        }
    });
}

bool ViewerState::pollLoad(bool wait) {
    if (!load.task.valid()) return false;
    if (!wait && load.task.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
    assets::LoadResult r = load.task.get();
    if (loadCancelRequested()) {   // whatever the importer returned: the user said no
        ui.status = "Loading " + load.path.filename().string() + " cancelled; the current scene is unchanged";
        return true;
    }
    doc.loadWarnings = r.warnings;
    if (!r.scene) {
        ui.errorPopup = "Could not open " + load.path.string() + ":\n" + (r.error.empty() ? "unknown error" : r.error);
        ui.status = "Open failed; the current scene is unchanged";
        return true;
    }
    sg::Scene& loaded = *r.scene;   // its size-dependent defaults are set (assets::loadScene)
    setScene(std::move(loaded), load.path);
    anim.clips = std::move(r.animations);
    if (!anim.clips.empty()) anim.time = anim.clips.front().start;
    addRecent(fs::absolute(load.path).lexically_normal().string());
    ui.status = "Opened " + load.path.string() + (r.warnings.empty() ? "" : " (" + std::to_string(r.warnings.size()) + " warnings)") +
                (anim.clips.empty() ? "" : ", " + std::to_string(anim.clips.size()) + " animation(s): Space plays");
    return true;
}

void ViewerState::cancelLoad() {
    if (!load.task.valid() || !load.control || load.control->cancel.load()) return;
    load.control->cancel = true;
    ui.status = "Cancelling loading " + load.path.filename().string() + " ...";
}

SaveOutcome ViewerState::save() {
    if (!isNativeScene(doc.path)) {
        // New, or imported from another format: the first save chooses a native file.
        ui.requests.saveAsDialog = true;
        ui.status = doc.path.empty() ? "Choose where to save the scene"
                                     : "Choose where to save: " + doc.path.filename().string() + " is kept as it is, the scene is saved as .json";
        return SaveOutcome::Asked;
    }
    return writeScene(doc.path, /*replace=*/true);
}

SaveOutcome ViewerState::saveAs(const fs::path& path) {
    if (path.empty()) {
        ui.requests.saveAsDialog = true;
        return SaveOutcome::Asked;
    }
    fs::path target = nativeTarget(path);
    std::error_code ec;
    if (fs::exists(fs::symlink_status(target, ec))) {
        ui.replacePath = target;
        ui.replaceOpen = true;
        ui.status = target.filename().string() + " exists: replace it?";
        return SaveOutcome::Asked;
    }
    return writeScene(target, /*replace=*/false);
}

void ViewerState::confirmReplace(bool replace) {
    fs::path target = ui.replacePath;
    ui.replacePath.clear();
    ui.replaceOpen = false;
    if (target.empty()) return;
    if (!replace) {
        ui.afterSave = PendingAction::None;
        ui.status = "Not saved; " + target.string() + " is unchanged";
        return;
    }
    writeScene(target, /*replace=*/true);
}

void ViewerState::saveAsCancelled() {
    if (ui.afterSave != PendingAction::None) ui.status = "Not saved; cancelled";
    ui.afterSave = PendingAction::None;
}

SaveOutcome ViewerState::writeScene(const fs::path& target, bool replace) {
    storeViewInCamera();
    std::string err;
    try {
        err = assets::saveSceneJson(doc.scene, target, replace);
    } catch (const std::exception& e) { err = target.string() + ": " + e.what(); }
    if (!err.empty()) {
        ui.afterSave = PendingAction::None;
        ui.errorPopup = "Could not save:\n" + err;
        ui.status = "Save failed";
        return SaveOutcome::Failed;
    }
    doc.path = target;
    doc.history.markSaved();
    doc.dirty = false;
    addRecent(fs::absolute(target).lexically_normal().string());
    ui.status = "Saved " + target.string();
    // The unsaved-changes question's Save was waiting on this file name: go on with its action.
    PendingAction after = std::exchange(ui.afterSave, PendingAction::None);
    switch (after) {
    case PendingAction::Open: startLoad(ui.afterSavePath); break;
    case PendingAction::New: newScene(); break;
    case PendingAction::Quit: ui.requests.quit = true; break;
    case PendingAction::None: break;
    }
    return SaveOutcome::Saved;
}

void ViewerState::addRecent(const std::string& path) {
    std::erase(config.recentFiles, path);
    config.recentFiles.insert(config.recentFiles.begin(), path);
    if (config.recentFiles.size() > 10) config.recentFiles.resize(10);
    if (!config.dir.empty()) saveRecentFiles(config.dir, config.recentFiles);
}

// --- animation playback ----------------------------------------------------------------------

namespace {
// Writes the clip's pose at t into the scene: a re-render, not an edit (dirty untouched).
void applyPose(ViewerState& st, const assets::AnimationClip& clip, double t) {
    assets::applyAnimation(st.doc.scene, clip, float(t));
    ++st.doc.version;
}
}   // namespace

const assets::AnimationClip* ViewerState::currentAnimation() const {
    if (anim.clip < 0 || size_t(anim.clip) >= anim.clips.size()) return nullptr;
    return &anim.clips[size_t(anim.clip)];
}

double ViewerState::animationEnd() const {
    const assets::AnimationClip* c = currentAnimation();
    return c ? std::max(double(c->duration), double(c->start)) : 0.0;
}

void ViewerState::selectAnimation(int index) {
    if (index < 0 || size_t(index) >= anim.clips.size()) return;
    anim.clip = index;
    anim.playing = false;
    anim.time = anim.clips[size_t(index)].start;
    applyPose(*this, anim.clips[size_t(index)], anim.time);
    ui.status = "Animation: " + (anim.clips[size_t(index)].name.empty() ? "clip " + std::to_string(index) : anim.clips[size_t(index)].name);
}

void ViewerState::setAnimationPlaying(bool play) {
    const assets::AnimationClip* c = currentAnimation();
    if (!c) {
        anim.playing = false;
        return;
    }
    if (play && !anim.loop && anim.time >= animationEnd()) anim.time = c->start;   // replay
    anim.playing = play;
    applyPose(*this, *c, anim.time);
}

void ViewerState::setAnimationTime(double t) {
    const assets::AnimationClip* c = currentAnimation();
    if (!c || !std::isfinite(t)) return;
    anim.time = std::clamp(t, double(c->start), animationEnd());
    applyPose(*this, *c, anim.time);
}

void ViewerState::advanceAnimation(double dt) {
    const assets::AnimationClip* c = currentAnimation();
    if (!c || !anim.playing) return;
    double start = c->start, end = animationEnd(), length = end - start;
    double t = anim.time + (std::isfinite(dt) ? std::max(dt, 0.0) : 0.0);
    if (t > end) {
        if (anim.loop && length > 0.0) {
            t = start + std::fmod(t - start, length);
        } else {   // not looping (or a single-key clip): stop at the end
            t = end;
            anim.playing = false;
        }
    }
    anim.time = std::clamp(t, start, end);
    applyPose(*this, *c, anim.time);
}

// --- config helpers --------------------------------------------------------------------------

float loadUiScale(const fs::path& dir) {
    std::string text;
    if (dir.empty() || !assets::readFileLimited(dir / "ui-scale.txt", 64, text).empty()) return 1.0f;
    char* end = nullptr;
    const float v = std::strtof(text.c_str(), &end);
    return std::isfinite(v) && v >= 0.5f && v <= 3.0f ? v : 1.0f;
}

std::string saveUiScale(const fs::path& dir, float scale) {
    if (dir.empty()) return {};
    std::error_code ec;
    fs::create_directories(dir, ec);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g\n", double(scale));
    return assets::writeFileAtomic(dir / "ui-scale.txt", buf, /*overwrite=*/true);
}

fs::path defaultConfigDir() {
    if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return fs::path(x) / "sceneviewer";
    if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".config" / "sceneviewer";
    return fs::temp_directory_path() / "sceneviewer";
}

std::vector<std::string> loadRecentFiles(const fs::path& dir) {
    std::vector<std::string> out;
    std::string text;
    if (!assets::readFileLimited(dir / "recent.txt", 1 << 20, text).empty()) return out;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line) && out.size() < 10)
        if (!line.empty()) out.push_back(line);
    return out;
}

std::string saveRecentFiles(const fs::path& dir, const std::vector<std::string>& files) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::string text;
    for (const auto& f : files) text += f + "\n";
    return assets::writeFileAtomic(dir / "recent.txt", text, /*overwrite=*/true);
}

namespace {
WindowRect centred(int width, int height, const WindowRect& area) {
    return {area.x + (area.width - width) / 2, area.y + (area.height - height) / 2, width, height};
}
}   // namespace

WindowRect placeWindow(const WindowRect& workArea, const std::optional<WindowRect>& remembered, int requestedWidth, int requestedHeight) {
    WindowRect r;
    if (requestedWidth > 0 && requestedHeight > 0)
        r = centred(requestedWidth, requestedHeight, workArea);
    else if (remembered && remembered->width > 0 && remembered->height > 0)
        r = *remembered;
    else
        r = centred(workArea.width * 85 / 100, workArea.height * 85 / 100, workArea);
    r.width = std::clamp(r.width, std::min(320, workArea.width), std::max(workArea.width, 1));
    r.height = std::clamp(r.height, std::min(240, workArea.height), std::max(workArea.height, 1));
    r.x = std::clamp(r.x, workArea.x, workArea.x + std::max(workArea.width - r.width, 0));
    r.y = std::clamp(r.y, workArea.y, workArea.y + std::max(workArea.height - r.height, 0));
    return r;
}

std::optional<WindowRect> loadWindowRect(const fs::path& dir, std::string* error) {
    std::string text;
    std::error_code ec;
    if (dir.empty() || !fs::exists(dir / "window.txt", ec)) return std::nullopt;
    std::string readError = assets::readFileLimited(dir / "window.txt", 4096, text);
    std::istringstream in(text);
    WindowRect r;
    if (readError.empty() && (in >> r.x >> r.y >> r.width >> r.height) && r.width >= 1 && r.height >= 1 && r.width <= 100000 && r.height <= 100000)
        return r;
    if (error) *error = (dir / "window.txt").string() + ": " + (readError.empty() ? "expected 'x y width height'" : readError) + "; ignored";
    return std::nullopt;
}

std::string saveWindowRect(const fs::path& dir, const WindowRect& r) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::string text = std::to_string(r.x) + " " + std::to_string(r.y) + " " + std::to_string(r.width) + " " + std::to_string(r.height) + "\n";
    return assets::writeFileAtomic(dir / "window.txt", text, /*overwrite=*/true);
}

fs::path screenshotPath(const fs::path& dir, const std::string& backend, const std::string& stem, const std::vector<std::string>& exports) {
    std::error_code ec;
    auto taken = [&](const fs::path& png) {
        if (fs::exists(fs::symlink_status(png, ec))) return true;
        for (const fs::path& f : aovFiles(png, exports))
            if (fs::exists(fs::symlink_status(f, ec))) return true;
        return false;
    };
    const std::string name = stem + "-" + backend;
    fs::path p = dir / (name + ".png");
    for (int i = 1; taken(p) && i < 1000000; ++i) p = dir / (name + "-" + std::to_string(i) + ".png");
    return p;
}

std::vector<std::string> screenshotExports(const ScreenshotDialogState& dialog) {
    std::vector<std::string> kinds;
    if (dialog.exportDepth) kinds.push_back("depth");
    if (dialog.exportNormal) kinds.push_back("normal");
    if (dialog.exportId) kinds.push_back("id");
    return kinds;
}

std::string screenshotSummary(const std::vector<ScreenshotResult>& results) {
    std::string saved, failed;
    int count = 0;
    fs::path dir;
    for (const ScreenshotResult& r : results) {
        if (!r.error.empty()) {
            std::string_view why = r.error;
            if (why.rfind(r.backend + ": ", 0) == 0) why.remove_prefix(r.backend.size() + 2);   // "gl: ..." from the renderer
            failed += "; " + r.backend + " failed: " + std::string(why);
            continue;
        }
        saved += (count++ ? ", " : "") + r.path.filename().string();
        dir = r.path.parent_path();
    }
    std::string line = count == 0   ? "Screenshot failed"
                       : count == 1 ? "Saved " + saved + " in " + dir.string()
                                    : "Saved " + std::to_string(count) + " screenshots in " + dir.string() + ": " + saved;
    std::string exports;
    for (const ScreenshotResult& r : results)
        if (r.error.empty() && !r.exports.empty()) {
            for (const std::string& k : r.exports) exports += (exports.empty() ? "" : ", ") + k;
            break;   // one batch, one set of choices
        }
    if (!exports.empty()) line += "; with " + exports + " and the camera .json";
    return count == 0 && !failed.empty() ? line + ": " + failed.substr(2) : line + failed;
}

std::pair<int, int> screenshotSize(const ScreenshotDialogState& dialog, const View& view) {
    if (dialog.windowSize) return {std::max(view.viewportWidth, 1), std::max(view.viewportHeight, 1)};
    return {std::clamp(dialog.width, 1, 16384), std::clamp(dialog.height, 1, 16384)};
}

std::string screenshotSizeLabel(const ScreenshotDialogState& dialog, const View& view) {
    ScreenshotDialogState viewport = dialog;
    viewport.windowSize = true;
    auto [w, h] = screenshotSize(viewport, view);
    return "Viewport size (" + std::to_string(w) + "x" + std::to_string(h) + ")###viewportSize";
}

fs::path absoluteFolder(const fs::path& folder) {
    std::error_code ec;
    fs::path dir = fs::absolute(folder.empty() ? fs::path(".") : folder, ec).lexically_normal();
    if (ec) return folder;
    if (!dir.has_filename() && dir != dir.root_path()) dir = dir.parent_path();   // "/a/b/" -> "/a/b"
    return dir;
}

fs::path prepareScreenshotFolder(const fs::path& folder, std::string* error) {
    std::error_code ec;
    fs::path dir = absoluteFolder(folder);
    fs::create_directories(dir, ec);
    if (!ec && !fs::is_directory(dir, ec)) ec = std::make_error_code(std::errc::not_a_directory);
    if (ec) {
        if (error) *error = "cannot use folder '" + folder.string() + "': " + ec.message();
        return {};
    }
    return dir;
}

}   // namespace ui
