// viewer_state.cpp - the viewer's pure state and actions (see viewer_state.h): scene edits as
// undo steps, backend, view modes, difference figures, camera. Files, animation playback and
// the per-user config are in viewer_state_files.cpp.
#include "ui/viewer_state.h"

#include "assets/files.h"
#include "renderers/environment.h"
#include "renderers/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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
    // A new environment file is read now (and kept for the renderers): one that cannot be read
    // is refused with the reason, the scene keeps the environment it had.
    if (err.empty() && s.environment != doc.scene.settings.environment && s.reflection == sg::ReflectionModel::Pbr && s.environment != "none" &&
        s.environment != "default")
        rnd::environmentFor(s, &err);
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
    case AxisView::Isometric:   // along -(1, 1, 1): the three axes equally foreshortened (projection.h)
        yaw = sg::radians(sg::kIsometricYawDeg);
        pitch = sg::radians(sg::kIsometricPitchDeg);
        break;
    }
    view.camera.yaw = yaw;
    view.camera.pitch = pitch;
    markViewChanged();
    if (v != AxisView::Isometric) return;
    // Isometric is a parallel projection: a perspective one becomes orthographic with the same
    // framing at the pivot (as keypad 5 switches), an oblique one orthographic.
    if (projection().type == sg::ProjectionType::Perspective) {
        togglePerspective();
    } else if (projection().type == sg::ProjectionType::Oblique) {
        sg::Projection p = projection();
        p.type = sg::ProjectionType::Orthographic;
        setProjection(p, "");
    }
    ui.status = "Isometric view (orthographic)";
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

}   // namespace ui
