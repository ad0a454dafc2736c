// undo.h - the document's undo history (no ImGui, no GL): steps made of recorded changes, the
// before and after of exactly what one edit changed, applied backwards (undo) or forwards
// (redo) to an sg::Scene.
//
// Why changes and not scene snapshots: sg::Scene's copy deep-copies meshes and density grids
// and gives every node a new uid (every backend cache would rebuild), so a snapshot per edit
// would cost the whole scene. A change costs what it touched: a payload, a transform, a
// material, the settings; a removed subtree is kept whole by sg::Scene::detach and put back
// with the same ids by reattach, so node ids in older steps, the selection and the active
// camera stay meaningful across undo and redo.
//
// Merging: a step pushed with the same non-empty merge key as the last one, while that one is
// still open, becomes part of it (it keeps the first before and takes the new after): a slider
// drag is one step. closeMerge() ends the open step; the panels call it on every frame in which
// no widget is active (the mouse was released), undo, redo and save call it too.
//
// Saved state: atSavedState() is true exactly when the scene is what was last saved or loaded
// (markSaved / clear), also after undoing back to it; redo away from it makes it false again.
// Every state has a serial (the last applied step's, or the base's when none is applied);
// steps that fall off the bottom (limits) move the base, so a saved state that can no longer
// be reached is never reported as reached.
//
// Limits: at most Limits::maxSteps steps and about Limits::maxBytes of recorded data (a
// deleted 100k-node subtree is large); the oldest steps go first, the newest always stays.
#pragma once

#include "scenegraph/scene.h"

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace ui {

struct NodeNameChange {
    sg::NodeId id;
    std::string before, after;
};
struct NodeVisibleChange {
    sg::NodeId id;
    bool before, after;
};
struct NodeLocalChange {
    sg::NodeId id;
    sg::LocalTransform before, after;
};
struct NodePayloadChange {
    sg::NodeId id;
    sg::Payload before, after;
};
// One material slot; nullopt: the slot does not exist (the before of an added material).
struct MaterialChange {
    int index;
    std::optional<sg::Material> before, after;
};
struct SettingsChange {
    sg::RenderSettings before, after;
};
struct ActiveCameraChange {
    sg::NodeId before, after;
};
// Nodes added (undo detaches the subtree into `stash`, redo reattaches it) or removed (the
// stash holds the subtree while the removal is done).
struct SubtreeChange {
    sg::NodeId id;
    bool added;
    sg::DetachedSubtree stash;
};
// A re-parent: where the node hung and its local transform, before and after.
struct NodePlace {
    sg::NodeId parent;
    size_t index;
    sg::LocalTransform local;
};
struct MoveChange {
    sg::NodeId id;
    NodePlace before, after;
};

using Change = std::variant<NodeNameChange, NodeVisibleChange, NodeLocalChange, NodePayloadChange, MaterialChange, SettingsChange, ActiveCameraChange,
                            SubtreeChange, MoveChange>;

// One user action: "Delete crate" (the menu shows "Undo Delete crate").
struct UndoStep {
    std::string label;
    std::vector<Change> changes;   // in the order they were made; undo runs them backwards
    sg::NodeId selectedBefore = sg::kNoNode, selectedAfter = sg::kNoNode;
};

class UndoStack {
public:
    struct Limits {
        size_t maxSteps = 500;
        size_t maxBytes = size_t(256) << 20;
    };

    // Records a step whose changes were already made to the scene. Drops the redo steps; a
    // step without changes is ignored. Merges into the open last step when mergeKey is
    // non-empty and equal to its key (see the top of this file).
    void push(UndoStep step, std::string_view mergeKey = {});
    void closeMerge() { m_open = false; }

    bool canUndo() const { return m_pos > 0; }
    bool canRedo() const { return m_pos < m_steps.size(); }
    size_t undoCount() const { return m_pos; }
    size_t redoCount() const { return m_steps.size() - m_pos; }
    // Label of the step undo / redo would apply ("" when none).
    std::string undoLabel() const { return canUndo() ? m_steps[m_pos - 1].step.label : std::string(); }
    std::string redoLabel() const { return canRedo() ? m_steps[m_pos].step.label : std::string(); }

    // Applies the last done step backwards / the next undone step forwards. Returns it (for
    // the selection), or null when there is none. A change that cannot be applied (the scene
    // was changed behind the history's back) clears the history and sets *error.
    const UndoStep* undo(sg::Scene& scene, std::string* error = nullptr);
    const UndoStep* redo(sg::Scene& scene, std::string* error = nullptr);

    void clear();         // a new document: no steps, and this state is the saved one
    void markSaved();     // the current state is the one on disk
    void forgetSaved();   // an edit outside the history: the saved state is out of reach
    bool atSavedState() const { return currentSerial() == m_savedSerial; }

    void setLimits(Limits limits);
    const Limits& limits() const { return m_limits; }
    size_t bytes() const { return m_bytes; }   // estimate of the recorded data

private:
    struct Entry {
        UndoStep step;
        uint64_t serial = 0;   // the state after this step
        size_t bytes = 0;
    };
    uint64_t currentSerial() const { return m_pos == 0 ? m_baseSerial : m_steps[m_pos - 1].serial; }
    void mergeIntoLast(UndoStep& step);
    void enforceLimits();
    const UndoStep* fail(const std::string& what, std::string* error);

    std::vector<Entry> m_steps;
    size_t m_pos = 0;   // steps [0, m_pos) are done, [m_pos, size) undone (redo)
    uint64_t m_nextSerial = 1;
    uint64_t m_baseSerial = 0;    // the state before m_steps[0]
    uint64_t m_savedSerial = 0;   // ~0: unreachable
    std::string m_mergeKey;
    bool m_open = false;   // the last step still takes merges
    size_t m_bytes = 0;
    Limits m_limits;
};

// Applies one change forwards (redo) or backwards (undo). False when it cannot (a node or a
// material slot it names is not there). Exposed for tests.
bool applyChange(Change& change, sg::Scene& scene, bool forward);
// Rough size of what a change keeps (heap included), for UndoStack::Limits::maxBytes.
size_t approxBytes(const Change& change);

}   // namespace ui
