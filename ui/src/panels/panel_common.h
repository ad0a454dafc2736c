// panel_common.h - what the panel files (ui/src/panels/*.cpp) share, in ui::panels_detail: the
// content scale (g_scale, px), the test hook that records widget rectangles (record), and the small
// widgets: sRGB colour editor, tooltips, combos and radio buttons over a name table, one parameter's
// widget from its table row (paramWidget / paramSection), matrix tables, section titles, help
// markers, Escape in dialogs, and which shown backends do not draw a feature. Internal to ui_core;
// the panels themselves are declared in ui/panels.h.
#pragma once

#include "scenegraph/params.h"
#include "scenegraph/setting_names.h"
#include "ui/panels.h"

#include <imgui.h>
#include <cstdio>

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <string_view>

namespace ui::panels_detail {

// Content scale (HiDPI), set by setupStyle; one variable for all the panel files (defined in
// panel_common.cpp). It stays a global on purpose: it describes the ImGui context's style and
// font atlas (ImGui's own globals), which setupStyle scales together; per-viewer state lives in
// ViewerState (PanelState for the panels).
extern float g_scale;
inline float px(float v) { return v * g_scale; }

// Records the last item's rectangle under `key` (test hook: click widgets by position).
void record(ViewerState& st, const std::string& key);

// A colour editor for a colour the scene stores linear: it shows and takes sRGB-encoded 0..255
// values (what the viewport and a colour picker show); only an edit writes back, so an
// untouched value never drifts. Values above 1 (HDR light colours) switch to floats.
bool srgbColorEdit(const char* label, sg::vec3& linear, ImGuiColorEditFlags flags = 0);

// Escape pressed this frame (no key repeat).
bool escapePressed();

// Escape in a modal dialog: Cancel (or OK), unless the same press closed a menu or combo in it.
bool escapeCancels(const ViewerState& st);

// The last item's tooltip (a table entry's help; nothing when empty).
void tooltip(std::string_view text);

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
    case sg::ParamKind::Text: {
        // Applied on Enter (a file name typed letter by letter is not a file until then).
        char buf[1024];
        std::snprintf(buf, sizeof buf, "%s", std::get<std::string>(v).c_str());
        if (ImGui::InputText(label.c_str(), buf, sizeof buf, ImGuiInputTextFlags_EnterReturnsTrue)) {
            v = std::string(buf);
            changed = std::get<std::string>(v) != std::get<std::string>(p.get(object));
        }
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
void matrixTable(const char* id, const sg::mat4& m);

// A titled separator (ImGui 1.86 has no SeparatorText).
void section(const char* title);

// A greyed "(?)" after the last item, `text` as its tooltip.
void helpMarker(const char* text);

}   // namespace ui::panels_detail
