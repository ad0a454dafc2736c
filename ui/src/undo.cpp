// undo.cpp - the undo history (see undo.h): applying changes, merging, the saved state, limits.
#include "ui/undo.h"

#include <algorithm>
#include <type_traits>

namespace ui {

// --- applying changes --------------------------------------------------------------------------

namespace {

template <class... F>
struct Overloaded : F... {
    using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

bool applyMaterial(const MaterialChange& c, sg::Scene& scene, bool forward) {
    const std::optional<sg::Material>& to = forward ? c.after : c.before;
    auto& mats = scene.materials;
    if (c.index < 0) return false;
    size_t i = size_t(c.index);
    if (to) {
        if (i == mats.size())
            mats.push_back(*to);   // an added slot comes back
        else if (i < mats.size())
            mats[i] = *to;
        else
            return false;
        return true;
    }
    if (i + 1 != mats.size()) return false;   // only the last slot (the one added) goes away
    mats.pop_back();
    return true;
}

bool applySubtree(SubtreeChange& c, sg::Scene& scene, bool forward) {
    bool insert = forward == c.added;   // redo of an addition, undo of a removal
    if (insert) {
        if (!scene.reattach(std::move(c.stash))) return false;
        c.stash = sg::DetachedSubtree{};
        return true;
    }
    c.stash = scene.detach(c.id);
    return c.stash.id == c.id;
}

bool applyMove(const MoveChange& c, sg::Scene& scene, bool forward) {
    const NodePlace& to = forward ? c.after : c.before;
    sg::DetachedSubtree d = scene.detach(c.id);
    if (d.id != c.id) return false;
    sg::DetachedSubtree keep = d;   // when the target is refused, put it back where it was
    d.parent = to.parent;
    d.index = to.index;
    if (!scene.reattach(std::move(d))) {
        scene.reattach(std::move(keep));
        return false;
    }
    scene.setLocal(c.id, to.local);
    return true;
}

}   // namespace

bool applyChange(Change& change, sg::Scene& scene, bool forward) {
    return std::visit(Overloaded{
                          [&](NodeNameChange& c) {
                              if (!scene.valid(c.id)) return false;
                              scene.setName(c.id, forward ? c.after : c.before);
                              return true;
                          },
                          [&](NodeVisibleChange& c) {
                              if (!scene.valid(c.id)) return false;
                              scene.setVisible(c.id, forward ? c.after : c.before);
                              return true;
                          },
                          [&](NodeLocalChange& c) {
                              if (!scene.valid(c.id)) return false;
                              scene.setLocal(c.id, forward ? c.after : c.before);
                              return true;
                          },
                          [&](NodePayloadChange& c) {
                              if (!scene.valid(c.id)) return false;
                              scene.setPayload(c.id, forward ? c.after : c.before);
                              return true;
                          },
                          [&](MaterialChange& c) { return applyMaterial(c, scene, forward); },
                          [&](SettingsChange& c) {
                              scene.settings = forward ? c.after : c.before;
                              return true;
                          },
                          [&](ActiveCameraChange& c) {
                              sg::NodeId to = forward ? c.after : c.before;
                              if (to != sg::kNoNode && !scene.valid(to)) return false;
                              scene.activeCamera = to;
                              return true;
                          },
                          [&](SubtreeChange& c) { return applySubtree(c, scene, forward); },
                          [&](MoveChange& c) { return applyMove(c, scene, forward); },
                      },
                      change);
}

namespace {

size_t payloadBytes(const sg::Payload& p) {
    size_t n = sizeof(sg::Payload);
    if (const auto* g = std::get_if<sg::GridPayload>(&p); g && g->grid) n += g->grid->values.size() * sizeof(float);
    return n;
}

size_t nodeBytes(const sg::Node& n) {
    return sizeof(sg::Node) + n.name.capacity() + n.children.capacity() * sizeof(sg::NodeId) + payloadBytes(n.payload) - sizeof(sg::Payload);
}

}   // namespace

size_t approxBytes(const Change& change) {
    return sizeof(Change) + std::visit(Overloaded{
                                           [](const NodeNameChange& c) { return c.before.capacity() + c.after.capacity(); },
                                           [](const NodePayloadChange& c) { return payloadBytes(c.before) + payloadBytes(c.after); },
                                           [](const MaterialChange& c) {
                                               size_t n = 0;
                                               if (c.before) n += sizeof(sg::Material) + c.before->name.capacity();
                                               if (c.after) n += sizeof(sg::Material) + c.after->name.capacity();
                                               return n;
                                           },
                                           [](const SubtreeChange& c) {
                                               size_t n = 0;
                                               for (const auto& [id, node] : c.stash.nodes) n += sizeof(id) + nodeBytes(node);
                                               return n;
                                           },
                                           [](const auto&) { return size_t(0); },
                                       },
                                       change);
}

// --- the stack ---------------------------------------------------------------------------------

namespace {

// The thing a change edits: the same kind and the same node / slot.
bool sameTarget(const Change& a, const Change& b) {
    if (a.index() != b.index()) return false;
    return std::visit(
        [&](const auto& x) {
            using T = std::decay_t<decltype(x)>;
            const T& y = std::get<T>(b);
            if constexpr (std::is_same_v<T, MaterialChange>)
                return x.index == y.index;
            else if constexpr (std::is_same_v<T, SettingsChange> || std::is_same_v<T, ActiveCameraChange>)
                return true;
            else if constexpr (std::is_same_v<T, SubtreeChange> || std::is_same_v<T, MoveChange>)
                return false;   // structure never merges
            else
                return x.id == y.id;
        },
        a);
}

// a keeps its before and takes b's after (same target).
void takeAfter(Change& a, Change&& b) {
    std::visit(
        [&](auto& x) {
            using T = std::decay_t<decltype(x)>;
            if constexpr (!std::is_same_v<T, SubtreeChange> && !std::is_same_v<T, MoveChange>) x.after = std::move(std::get<T>(b).after);
        },
        a);
}

}   // namespace

void UndoStack::push(UndoStep step, std::string_view mergeKey) {
    if (step.changes.empty()) return;
    // New history from here: the undone steps are gone.
    for (size_t i = m_pos; i < m_steps.size(); ++i) m_bytes -= m_steps[i].bytes;
    m_steps.resize(m_pos);
    if (!mergeKey.empty() && m_open && mergeKey == m_mergeKey && !m_steps.empty()) {
        mergeIntoLast(step);
    } else {
        Entry e;
        for (const Change& c : step.changes) e.bytes += approxBytes(c);
        e.step = std::move(step);
        e.serial = m_nextSerial++;
        m_bytes += e.bytes;
        m_steps.push_back(std::move(e));
        m_pos = m_steps.size();
    }
    m_mergeKey = std::string(mergeKey);
    m_open = !mergeKey.empty();
    enforceLimits();
}

void UndoStack::mergeIntoLast(UndoStep& step) {
    Entry& last = m_steps.back();
    for (Change& c : step.changes) {
        auto it = std::find_if(last.step.changes.begin(), last.step.changes.end(), [&](const Change& o) { return sameTarget(o, c); });
        if (it != last.step.changes.end())
            takeAfter(*it, std::move(c));
        else
            last.step.changes.push_back(std::move(c));
    }
    last.step.selectedAfter = step.selectedAfter;
    m_bytes -= last.bytes;
    last.bytes = 0;
    for (const Change& c : last.step.changes) last.bytes += approxBytes(c);
    m_bytes += last.bytes;
    last.serial = m_nextSerial++;   // a state never seen before (not the saved one)
}

void UndoStack::enforceLimits() {
    size_t drop = 0;
    size_t bytes = m_bytes;
    while (drop < m_pos && m_steps.size() - drop > 1 && (m_steps.size() - drop > m_limits.maxSteps || bytes > m_limits.maxBytes)) {
        bytes -= m_steps[drop].bytes;
        ++drop;
    }
    if (drop == 0) return;
    m_baseSerial = m_steps[drop - 1].serial;   // undoing everything now ends in this state
    m_steps.erase(m_steps.begin(), m_steps.begin() + std::ptrdiff_t(drop));
    m_pos -= std::min(m_pos, drop);
    m_bytes = bytes;
}

const UndoStep* UndoStack::fail(const std::string& what, std::string* error) {
    clear();
    m_savedSerial = ~uint64_t(0);   // the scene is in an unknown state: never "saved"
    if (error) *error = what + " failed: the scene no longer matches the history, which was cleared";
    return nullptr;
}

const UndoStep* UndoStack::undo(sg::Scene& scene, std::string* error) {
    m_open = false;
    if (!canUndo()) return nullptr;
    Entry& e = m_steps[m_pos - 1];
    for (size_t i = e.step.changes.size(); i-- > 0;)
        if (!applyChange(e.step.changes[i], scene, /*forward=*/false)) return fail("Undo " + e.step.label, error);
    --m_pos;
    return &e.step;
}

const UndoStep* UndoStack::redo(sg::Scene& scene, std::string* error) {
    m_open = false;
    if (!canRedo()) return nullptr;
    Entry& e = m_steps[m_pos];
    for (Change& c : e.step.changes)
        if (!applyChange(c, scene, /*forward=*/true)) return fail("Redo " + e.step.label, error);
    ++m_pos;
    return &e.step;
}

void UndoStack::clear() {
    m_steps.clear();
    m_pos = 0;
    m_bytes = 0;
    m_baseSerial = m_nextSerial++;
    m_savedSerial = m_baseSerial;
    m_open = false;
    m_mergeKey.clear();
}

void UndoStack::markSaved() {
    m_savedSerial = currentSerial();
    m_open = false;
}

void UndoStack::forgetSaved() { m_savedSerial = ~uint64_t(0); }

void UndoStack::setLimits(Limits limits) {
    m_limits = limits;
    m_limits.maxSteps = std::max<size_t>(m_limits.maxSteps, 1);
    enforceLimits();
}

}   // namespace ui
