// undo_test.cpp - the undo history (ui/undo.h) on its own (undo/redo order, merging of drags,
// the saved state, limits, a history that no longer matches), through ViewerState (every kind
// of scene edit comes back exactly with undo and again with redo; the selection, the dirty
// flag across save, loads that clear or keep the history) and through the panels in headless
// ImGui frames (a drag is one step, Ctrl+Z / Ctrl+Shift+Z / Ctrl+Y, the Edit menu).
#include "ui/undo.h"
#include "scenegraph/params.h"
#include "ui/viewer_state.h"

#include "assets/demo.h"
#include "assets/scene_io.h"
#include "headless_ui.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <functional>

using namespace ui;
namespace fs = std::filesystem;

namespace {

// A rename of `id` from -> to, made to the scene and returned as a step.
UndoStep rename(sg::Scene& s, sg::NodeId id, const std::string& to) {
    UndoStep step;
    step.label = "Rename " + s.node(id).name;
    step.changes.push_back(NodeNameChange{id, s.node(id).name, to});
    s.setName(id, to);
    return step;
}

ViewerState demoState() {
    ViewerState st;
    st.view.viewportWidth = 800;
    st.view.viewportHeight = 600;
    st.setScene(assets::makeDemoScene(), {});
    return st;
}

std::vector<std::string> treeNames(const sg::Scene& s) {
    std::vector<std::string> out;
    for (sg::NodeId id : s.depthFirstOrder()) out.push_back(s.node(id).name);
    return out;
}

}   // namespace

// --- the stack on its own -----------------------------------------------------------------------

TEST(UndoStackTest, UndoAndRedoRunStepsBackwardsAndForwards) {
    sg::Scene s;
    sg::NodeId a = s.addNode("a");
    UndoStack h;
    EXPECT_FALSE(h.canUndo());
    EXPECT_EQ(h.undo(s), nullptr);
    h.push(rename(s, a, "b"));
    h.push(rename(s, a, "c"));
    EXPECT_EQ(h.undoLabel(), "Rename b");
    ASSERT_NE(h.undo(s), nullptr);
    EXPECT_EQ(s.node(a).name, "b");
    EXPECT_EQ(h.redoLabel(), "Rename b");
    ASSERT_NE(h.undo(s), nullptr);
    EXPECT_EQ(s.node(a).name, "a");
    EXPECT_EQ(h.undo(s), nullptr);   // nothing left
    ASSERT_NE(h.redo(s), nullptr);
    EXPECT_EQ(s.node(a).name, "b");
    // A new edit drops what could be redone.
    h.push(rename(s, a, "x"));
    EXPECT_FALSE(h.canRedo());
    EXPECT_EQ(h.undoCount(), 2u);
    h.push(UndoStep{"nothing", {}, sg::kNoNode, sg::kNoNode});   // no changes: ignored
    EXPECT_EQ(h.undoCount(), 2u);
}

TEST(UndoStackTest, SameKeyMergesWhileOpenAndNeverAcrossAClose) {
    sg::Scene s;
    sg::NodeId a = s.addNode("a");
    UndoStack h;
    for (const char* n : {"a1", "a2", "a3"}) h.push(rename(s, a, n), "drag");
    EXPECT_EQ(h.undoCount(), 1u) << "one drag, one step";
    h.closeMerge();   // mouse released
    h.push(rename(s, a, "a4"), "drag");
    EXPECT_EQ(h.undoCount(), 2u);
    h.push(rename(s, a, "a5"), "other");   // another target: a new step
    EXPECT_EQ(h.undoCount(), 3u);
    h.push(rename(s, a, "a6"));   // no key: never merges ...
    h.push(rename(s, a, "a7"));   // ... nor takes merges
    EXPECT_EQ(h.undoCount(), 5u);
    for (int i = 0; i < 4; ++i) h.undo(s);
    EXPECT_EQ(s.node(a).name, "a3");
    h.undo(s);
    EXPECT_EQ(s.node(a).name, "a") << "the merged step keeps the first before";
    // After an undo the last step is closed: the same key starts a new step.
    h.redo(s);
    h.push(rename(s, a, "b"), "drag");
    EXPECT_EQ(h.undoCount(), 2u);
}

TEST(UndoStackTest, SavedStateFollowsUndoAndRedo) {
    sg::Scene s;
    sg::NodeId a = s.addNode("a");
    UndoStack h;
    EXPECT_TRUE(h.atSavedState());   // a fresh document is what was loaded
    h.push(rename(s, a, "b"));
    EXPECT_FALSE(h.atSavedState());
    h.undo(s);
    EXPECT_TRUE(h.atSavedState()) << "undone back to the loaded state";
    h.redo(s);
    EXPECT_FALSE(h.atSavedState());
    h.markSaved();
    EXPECT_TRUE(h.atSavedState());
    h.undo(s);
    EXPECT_FALSE(h.atSavedState());
    h.redo(s);
    EXPECT_TRUE(h.atSavedState());
    // An open drag saved, then dragged further: no longer the saved state.
    h.push(rename(s, a, "c"), "drag");
    h.markSaved();
    h.push(rename(s, a, "d"), "drag");
    EXPECT_FALSE(h.atSavedState());
    EXPECT_EQ(h.undoCount(), 3u) << "saving closes the open step";
    // Branching away from the saved state makes it unreachable.
    h.undo(s);
    EXPECT_TRUE(h.atSavedState());
    h.undo(s);
    h.push(rename(s, a, "other branch"));
    for (int i = 0; i < 5; ++i) h.undo(s);
    EXPECT_FALSE(h.atSavedState()) << "the loaded state, not the saved one";
    while (h.redo(s)) EXPECT_FALSE(h.atSavedState());
    // An edit outside the history: never the saved state until the next save.
    h.markSaved();
    h.forgetSaved();
    EXPECT_FALSE(h.atSavedState());
    h.clear();
    EXPECT_TRUE(h.atSavedState());
    EXPECT_FALSE(h.canUndo());
}

TEST(UndoStackTest, LimitsDropTheOldestStepsAndMoveTheBase) {
    sg::Scene s;
    sg::NodeId a = s.addNode("n0");
    UndoStack h;
    h.setLimits({3, size_t(1) << 30});
    for (int i = 1; i <= 5; ++i) h.push(rename(s, a, "n" + std::to_string(i)));
    EXPECT_EQ(h.undoCount(), 3u);
    while (h.undo(s)) {}
    EXPECT_EQ(s.node(a).name, "n2") << "the two oldest steps are gone";
    EXPECT_FALSE(h.atSavedState()) << "n0 was saved, n2 is not it";
    // A byte budget smaller than one step keeps the newest step only.
    UndoStack small;
    small.setLimits({100, 1});
    small.push(rename(s, a, "big1"));
    small.push(rename(s, a, "big2"));
    EXPECT_EQ(small.undoCount(), 1u);
    EXPECT_EQ(small.undoLabel(), "Rename big1");
    EXPECT_GT(small.bytes(), 0u);
    // Lowering the limit later drops done steps too.
    for (int i = 0; i < 3; ++i) h.redo(s);
    h.setLimits({1, size_t(1) << 30});
    EXPECT_EQ(h.undoCount(), 1u);
}

TEST(UndoStackTest, DetachedSubtreesCountTowardsTheByteBudget) {
    sg::Scene s;
    sg::NodeId top = s.addNode("top");
    for (int i = 0; i < 1000; ++i) s.addNode("child " + std::to_string(i), top);
    UndoStep step;
    step.label = "Delete top";
    step.changes.push_back(SubtreeChange{top, false, s.detach(top)});
    EXPECT_GT(approxBytes(step.changes[0]), 1000 * sizeof(sg::Node));
}

TEST(UndoStackTest, AChangeThatNoLongerAppliesClearsTheHistory) {
    sg::Scene s;
    sg::NodeId a = s.addNode("a");
    UndoStack h;
    h.push(rename(s, a, "b"));
    s.removeNode(a);   // behind the history's back
    std::string err;
    EXPECT_EQ(h.undo(s, &err), nullptr);
    EXPECT_NE(err.find("cleared"), std::string::npos) << err;
    EXPECT_FALSE(h.canUndo());
    EXPECT_FALSE(h.atSavedState());
}

// --- through ViewerState ------------------------------------------------------------------------

TEST(ViewerUndoTest, DeleteThenUndoBringsBackTheSameNodeSelectedAndClean) {
    ViewerState st = demoState();
    sg::NodeId crate = st.doc.scene.findByName("crate");
    ASSERT_NE(crate, sg::kNoNode);
    std::vector<std::string> tree = treeNames(st.doc.scene);
    sg::mat4 world = st.doc.scene.world(crate);
    st.selectNode(crate);
    ASSERT_TRUE(st.removeNode(crate));
    EXPECT_EQ(st.doc.selected, sg::kNoNode);
    EXPECT_TRUE(st.doc.dirty);
    EXPECT_EQ(st.doc.history.undoLabel(), "Delete crate");

    uint64_t version = st.doc.version;
    ASSERT_TRUE(st.undo());
    EXPECT_GT(st.doc.version, version);   // re-render
    EXPECT_TRUE(st.doc.scene.valid(crate)) << "the same id comes back";
    EXPECT_EQ(treeNames(st.doc.scene), tree) << "in the same place";
    EXPECT_EQ(st.doc.scene.world(crate), world);
    EXPECT_EQ(st.doc.selected, crate);
    EXPECT_FALSE(st.doc.dirty) << "back to the loaded scene";
    EXPECT_NE(st.ui.status.find("Undone"), std::string::npos);

    ASSERT_TRUE(st.redo());
    EXPECT_FALSE(st.doc.scene.valid(crate));
    EXPECT_EQ(st.doc.selected, sg::kNoNode) << "never a selection of a node that is gone";
    EXPECT_TRUE(st.doc.dirty);
    EXPECT_FALSE(st.redo());
}

// Every kind of edit: undo gives the scene before it, redo the scene after it (compared
// with sg::sceneDifference: names, structure, transforms, payloads, materials, settings).
TEST(ViewerUndoTest, EveryKindOfEditUndoesAndRedoesExactly) {
    ViewerState st = demoState();
    sg::NodeId crate = st.doc.scene.findByName("crate");
    sg::NodeId torus = st.doc.scene.findByName("torus");
    sg::NodeId sphere = st.doc.scene.findByName("red sphere");
    const std::vector<std::pair<std::string, std::function<void()>>> edits = {
        {"rename", [&] { st.renameNode(crate, "box"); }},
        {"hide", [&] { st.setVisible(crate, false); }},
        {"transform", [&] { st.setLocal(crate, sg::LocalTransform::fromTRS(sg::vec3(1, 2, 3))); }},
        {"payload",
         [&] {
             sg::Payload p = st.doc.scene.node(sphere).payload;
             std::get<sg::ImplicitPayload>(p).shape.radius = 2.5f;
             st.setPayload(sphere, p);
         }},
        {"material",
         [&] {
             sg::Material m = st.doc.scene.materials[0];
             m.kd = 0.123f;
             st.setMaterial(0, m);
         }},
        {"new material", [&] { EXPECT_GE(st.addMaterialFor(crate, sg::Material{}), 0); }},
        {"settings",
         [&] {
             sg::RenderSettings s = st.doc.scene.settings;
             s.shading = sg::ShadingModel::Flat;
             EXPECT_EQ(st.setSettings(s), "");
         }},
        {"ambient", [&] { EXPECT_EQ(st.setByName("ambientLight", "0.1,0.2,0.3"), ""); }},
        {"projection",
         [&] {
             sg::Projection p = st.projection();
             p.fovyDeg = 33.0f;
             st.setProjection(p);
         }},
        {"add group", [&] { st.addGroup(st.doc.scene.root()); }},
        {"add shape", [&] { st.addShape(sg::ImplicitType::Torus, st.doc.scene.root()); }},
        {"add csg", [&] { st.addCsg(sg::CsgOp::Union, st.doc.scene.root()); }},
        {"add light", [&] { st.addLight(sg::LightType::Spot, st.doc.scene.root()); }},
        {"add camera", [&] { st.addCamera(); }},
        {"duplicate", [&] { st.duplicateNode(torus); }},
        {"reparent", [&] { EXPECT_TRUE(st.reparent(crate, torus)); }},
        {"delete subtree", [&] { st.removeNode(st.doc.scene.findByName("turntable")); }},
        {"store view",
         [&] {
             st.view.camera.orbit(30, 10);
             st.storeViewInCamera();
         }},
        {"look through", [&] { st.useSceneCamera(st.addCamera()); }},
    };
    for (const auto& [name, edit] : edits) {
        SCOPED_TRACE(name);
        sg::Scene before = st.doc.scene;
        size_t steps = st.doc.history.undoCount();
        edit();
        ASSERT_GT(st.doc.history.undoCount(), steps);
        sg::Scene after = st.doc.scene;
        ASSERT_NE(sg::sceneDifference(before, after), "") << "the edit changed nothing";
        while (st.doc.history.undoCount() > steps) ASSERT_TRUE(st.undo());
        EXPECT_EQ(sg::sceneDifference(before, st.doc.scene), "");
        EXPECT_EQ(st.doc.scene.activeCamera, before.activeCamera);
        while (st.doc.history.canRedo()) ASSERT_TRUE(st.redo());
        EXPECT_EQ(sg::sceneDifference(after, st.doc.scene), "");
        EXPECT_EQ(st.doc.scene.activeCamera, after.activeCamera);
        EXPECT_EQ(st.doc.scene.depthFirstOrder().size(), st.doc.scene.nodeCount());
    }
    // All of it, undone in one go, is the demo again, and clean.
    while (st.undo()) {}
    EXPECT_EQ(sg::sceneDifference(assets::makeDemoScene(), st.doc.scene), "");
    EXPECT_FALSE(st.doc.dirty);
}

TEST(ViewerUndoTest, DeletingTheActiveCameraAndUndoingRestoresIt) {
    ViewerState st = demoState();
    sg::NodeId cam = st.doc.scene.activeCamera;
    ASSERT_TRUE(st.doc.scene.valid(cam));
    st.removeNode(cam);
    EXPECT_EQ(st.doc.scene.activeCamera, sg::kNoNode);
    st.undo();
    EXPECT_EQ(st.doc.scene.activeCamera, cam);
}

TEST(ViewerUndoTest, RefusedEditsMakeNoStep) {
    ViewerState st = demoState();
    sg::RenderSettings s = st.doc.scene.settings;
    s.fog = sg::FogMode::Linear;
    s.fogStart = 10.0f;
    s.fogEnd = 5.0f;
    EXPECT_NE(st.setSettings(s), "");
    EXPECT_NE(st.ui.status.find("refused"), std::string::npos);
    EXPECT_FALSE(st.renameNode(st.doc.scene.findByName("crate"), ""));
    EXPECT_FALSE(st.reparent(st.doc.scene.findByName("turntable"), st.doc.scene.findByName("torus")));
    st.setLocal(st.doc.scene.findByName("crate"), st.doc.scene.node(st.doc.scene.findByName("crate")).local);   // unchanged
    EXPECT_FALSE(st.doc.history.canUndo());
    EXPECT_FALSE(st.doc.dirty);
}

TEST(ViewerUndoTest, DirtyFlagFollowsTheSavedStateAcrossSave) {
    fs::path dir = testing_support::outputDir("ui") / "undo_save";
    fs::remove_all(dir);
    fs::create_directories(dir);
    ViewerState st = demoState();
    st.addShape(sg::ImplicitType::Sphere, st.doc.scene.root());
    ASSERT_EQ(st.saveAs(dir / "scene.json"), SaveOutcome::Saved);
    EXPECT_FALSE(st.doc.dirty);
    st.undo();   // the sphere goes: differs from the file
    EXPECT_TRUE(st.doc.dirty);
    st.redo();   // the file's state again
    EXPECT_FALSE(st.doc.dirty);
    st.undo();
    st.addGroup();   // another branch: the saved state is out of reach
    while (st.undo()) EXPECT_TRUE(st.doc.dirty);
}

TEST(ViewerUndoTest, LoadingClearsTheHistoryAFailedLoadKeepsIt) {
    fs::path dir = testing_support::outputDir("ui") / "undo_load";
    fs::remove_all(dir);
    fs::create_directories(dir);
    ASSERT_EQ(assets::saveSceneJson(assets::makeDemoScene(), dir / "demo.json", true), "");
    ViewerState st = demoState();
    st.removeNode(st.doc.scene.findByName("crate"));
    st.startLoad(dir / "missing.json");
    ASSERT_TRUE(st.pollLoad(/*wait=*/true));
    EXPECT_TRUE(st.doc.history.canUndo()) << "a failed load leaves the history alone";
    EXPECT_TRUE(st.doc.dirty);
    st.startLoad(dir / "demo.json");
    st.cancelLoad();
    ASSERT_TRUE(st.pollLoad(true));
    EXPECT_TRUE(st.doc.history.canUndo()) << "so does a cancelled one";
    st.startLoad(dir / "demo.json");
    ASSERT_TRUE(st.pollLoad(true));
    EXPECT_FALSE(st.doc.history.canUndo());
    EXPECT_FALSE(st.doc.history.canRedo());
    EXPECT_FALSE(st.doc.dirty);
    st.newScene();
    EXPECT_FALSE(st.doc.history.canUndo());
}

// `set KEY VALUE` (automation): names and values as in the scene file, checked by its reader,
// one undo step each, refusals with the reader's reason.
TEST(ViewerUndoTest, SetByNameTakesSceneFileNamesAndIsUndoable) {
    ViewerState st = demoState();
    EXPECT_EQ(st.setByName("shading", "flat"), "");
    EXPECT_EQ(st.doc.scene.settings.shading, sg::ShadingModel::Flat);
    EXPECT_EQ(st.doc.history.undoLabel(), "Change shading");
    EXPECT_EQ(st.setByName("fog.mode", "linear"), "");
    EXPECT_EQ(st.setByName("fog.end", "40"), "");
    EXPECT_EQ(st.doc.scene.settings.fogEnd, 40.0f);
    std::string err = st.setByName("fog.end", "1");
    EXPECT_NE(err.find("end > start"), std::string::npos) << err;
    EXPECT_NE(st.ui.status.find("refused"), std::string::npos) << st.ui.status;
    EXPECT_EQ(st.doc.scene.settings.fogEnd, 40.0f);
    EXPECT_NE(st.setByName("shading", "plastic").find("plastic"), std::string::npos);
    EXPECT_NE(st.setByName("no.such", "1").find("unknown setting"), std::string::npos);
    EXPECT_EQ(st.setByName("ambientLight", "[0.1, 0.2, 0.3]"), "");
    EXPECT_EQ(st.doc.scene.settings.ambientLight, sg::vec3(0.1f, 0.2f, 0.3f));
    EXPECT_EQ(st.doc.history.undoLabel(), "Change ambientLight");
    EXPECT_NE(st.setByName("ambientLight", "[-1, 0, 0]").find("ambientLight"), std::string::npos) << "out of range";
    EXPECT_NE(st.setByName("tessellation", "600").find("[4, 512]"), std::string::npos) << "the table's range";

    // camera.KEY: the projection; light.KEY: the selected light.
    EXPECT_EQ(st.setByName("camera.fovy", "30"), "");
    EXPECT_EQ(st.projection().fovyDeg, 30.0f);
    EXPECT_NE(st.setByName("camera.fovy", "200"), "");
    EXPECT_NE(st.setByName("light.intensity", "2").find("not a light"), std::string::npos);

    // material.FIELD: the selection's material.
    EXPECT_NE(st.setByName("material.kd", "0.5").find("no material"), std::string::npos) << "nothing selected";
    sg::NodeId crate = st.doc.scene.findByName("crate");
    st.selectNode(crate);
    int mat = std::get<sg::MeshInstance>(st.doc.scene.node(crate).payload).material;
    int texture = st.doc.scene.materials[size_t(mat)].diffuseTexture;
    ASSERT_GE(texture, 0);
    EXPECT_EQ(st.setByName("material.kd", "0.25"), "");
    EXPECT_EQ(st.setByName("material.baseColor", "[1, 0, 0]"), "");
    EXPECT_EQ(st.setByName("material.alphaMode", "mask"), "");
    const sg::Material& m = st.doc.scene.materials[size_t(mat)];
    EXPECT_EQ(m.kd, 0.25f);
    EXPECT_EQ(m.baseColor, sg::vec3(1, 0, 0));
    EXPECT_EQ(m.alphaMode, sg::AlphaMode::Mask);
    EXPECT_EQ(m.diffuseTexture, texture) << "untouched fields stay, the texture included";
    EXPECT_NE(st.setByName("material.diffuseTexture", "99"), "");
    EXPECT_EQ(st.setByName("material.diffuseTexture", "-1"), "");
    EXPECT_EQ(st.doc.scene.materials[size_t(mat)].diffuseTexture, -1);

    while (st.undo()) {}
    EXPECT_EQ(sg::sceneDifference(assets::makeDemoScene(), st.doc.scene), "");
}

TEST(ViewerUndoTest, SettingNamesAreTheSceneFileNames) {
    sg::RenderSettings a, b = a;
    EXPECT_EQ(sg::changedParams(a, b), "");
    b.fog = sg::FogMode::Exp;
    b.fogDensity = 0.2f;
    b.shadows = !a.shadows;
    std::string names = sg::changedParams(a, b);
    EXPECT_NE(names.find("fog.mode"), std::string::npos) << names;
    EXPECT_NE(names.find("fog.density"), std::string::npos) << names;
    EXPECT_NE(names.find("shadows"), std::string::npos) << names;
}

// --- through the panels ------------------------------------------------------------------------

TEST(UndoPanelsTest, ADragIsOneStepAndCtrlZUndoesIt) {
    Headless h;
    sg::NodeId crate = h.st.doc.scene.findByName("crate");
    h.click("tree/crate");
    h.click("tab/Inspector");
    sg::vec3 t0 = h.st.doc.scene.node(crate).local.translation;
    h.drag("inspector/translation", 60.0f, 6);
    EXPECT_NE(h.st.doc.scene.node(crate).local.translation, t0);
    EXPECT_EQ(h.st.doc.history.undoCount(), 1u) << "six frames of one drag: one step";
    sg::vec3 t1 = h.st.doc.scene.node(crate).local.translation;
    h.drag("inspector/translation", 40.0f, 4);   // a second drag: a second step
    EXPECT_EQ(h.st.doc.history.undoCount(), 2u);
    h.press(keys::Z, /*ctrl=*/true);
    EXPECT_EQ(h.st.doc.scene.node(crate).local.translation, t1);
    h.press(keys::Z, true);
    EXPECT_EQ(h.st.doc.scene.node(crate).local.translation, t0);
    EXPECT_FALSE(h.st.doc.dirty);
    h.press(keys::Z, true, /*shift=*/true);
    EXPECT_EQ(h.st.doc.scene.node(crate).local.translation, t1);
    h.press(keys::Y, true);
    EXPECT_TRUE(h.st.doc.dirty);
    EXPECT_FALSE(h.st.doc.history.canRedo());
}

TEST(UndoPanelsTest, MaterialSliderDragAndNewMaterialAreOneStepEach) {
    Headless h;
    sg::NodeId crate = h.st.doc.scene.findByName("crate");
    h.click("tree/crate");
    h.click("tab/Inspector");
    int mat = std::get<sg::MeshInstance>(h.st.doc.scene.node(crate).payload).material;
    float kd = h.st.doc.scene.materials[size_t(mat)].kd;
    h.drag("material/kd", -80.0f, 5);
    EXPECT_NE(h.st.doc.scene.materials[size_t(mat)].kd, kd);
    EXPECT_EQ(h.st.doc.history.undoCount(), 1u);
    size_t materials = h.st.doc.scene.materials.size();
    h.click("material/new");
    EXPECT_EQ(h.st.doc.scene.materials.size(), materials + 1);
    EXPECT_EQ(h.st.doc.history.undoCount(), 2u) << "the material and the node's index: one step";
    h.press(keys::Z, true);
    EXPECT_EQ(h.st.doc.scene.materials.size(), materials);
    EXPECT_EQ(std::get<sg::MeshInstance>(h.st.doc.scene.node(crate).payload).material, mat);
    h.press(keys::Z, true);
    EXPECT_EQ(h.st.doc.scene.materials[size_t(mat)].kd, kd);
}

TEST(UndoPanelsTest, DeleteKeyThenEditMenuUndo) {
    Headless h;
    sg::NodeId crate = h.st.doc.scene.findByName("crate");
    h.click("tree/crate");
    h.press(keys::Delete);
    EXPECT_FALSE(h.st.doc.scene.valid(crate));
    h.click("menu/edit");
    h.click("edit/undo");
    EXPECT_TRUE(h.st.doc.scene.valid(crate));
    EXPECT_EQ(h.st.doc.selected, crate);
    // Nothing left to undo: the item is greyed and does nothing.
    h.click("menu/edit");
    h.click("edit/undo");
    EXPECT_TRUE(h.st.doc.scene.valid(crate));
    EXPECT_TRUE(h.st.doc.history.canRedo());
}
