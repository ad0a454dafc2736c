// panel_common.cpp - the panels' shared helpers (see panel_common.h): the content scale, the
// widget-rectangle hook, small widgets, Escape in dialogs; and the public backendCapabilities /
// visibleBackends (panels.h) the menus and the window decide from.
#include "panels/panel_common.h"

#include "renderers/renderer.h"
#include "ui/colour.h"

#include <map>
#include <mutex>

namespace ui {

namespace panels_detail {

float g_scale = 1.0f;

void record(ViewerState& st, const std::string& key) {
    ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
    st.hooks.itemRects[key] = ItemRect{a.x, a.y, b.x, b.y};
}

bool srgbColorEdit(const char* label, sg::vec3& linear, ImGuiColorEditFlags flags) {
    sg::vec3 shown = srgbFromLinear(linear);
    if (std::max({shown.x, shown.y, shown.z}) > 1.0f) flags |= ImGuiColorEditFlags_Float | ImGuiColorEditFlags_HDR;
    if (!ImGui::ColorEdit3(label, &shown.x, flags)) return false;
    linear = linearFromSrgb(shown);
    return true;
}

bool escapePressed() { return ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape), false); }

bool escapeCancels(const ViewerState& st) { return escapePressed() && !st.ui.panels.escapeClosedPopup; }

void tooltip(std::string_view text) {
    if (!text.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%.*s", int(text.size()), text.data());
}

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

std::string backendsWithout(const ViewerState& st, sg::Feature feature) {
    std::string names;
    for (const std::string& b : visibleBackends(st))
        if (!rnd::hasFeature(backendCapabilities(b), feature) && names.find(b) == std::string::npos) names += (names.empty() ? "" : ", ") + b;
    return names;
}

}   // namespace panels_detail

const rnd::Capabilities& backendCapabilities(const std::string& backend) {
    static std::mutex mutex;
    static std::map<std::string, rnd::Capabilities> known;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = known.find(backend);
    if (it == known.end()) {
        rnd::Capabilities c;
        if (auto r = rnd::makeRenderer(backend)) c = r->capabilities();   // the same as any instance's, rendered or not
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

}   // namespace ui
