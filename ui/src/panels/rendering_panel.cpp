// rendering_panel.cpp - drawRenderingPanel(): the Rendering tab. The render-settings table
// section by section, with the per-backend anti-aliasing overrides and where GL renders.
#include "panels/panel_common.h"

#include "renderers/renderer.h"

namespace ui {

using namespace panels_detail;

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

}   // namespace ui
