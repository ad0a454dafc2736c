// compare_panel.cpp - drawComparePanel(): the Compare tab. View mode (single, split / wipe,
// difference), the backends shown, dividers, and the difference's threshold and figures.
#include "panels/panel_common.h"

#include "renderers/renderer.h"

namespace ui {

using namespace panels_detail;

void drawComparePanel(ViewerState& st) {
    CompareConfig& c = st.view.compare;
    int mode = int(c.mode);
    ImGui::RadioButton("Single", &mode, 0);
    record(st, "compare/single");
    ImGui::SameLine();
    ImGui::RadioButton("Split / wipe", &mode, 1);
    record(st, "compare/split");
    ImGui::SameLine();
    ImGui::RadioButton("Difference", &mode, 2);
    record(st, "compare/difference");
    if (ViewMode(mode) != c.mode) st.showView(ViewMode(mode));
    std::vector<std::string> names = rnd::rendererNames();
    auto backendCombo = [&](const char* label, std::string& value) {
        if (ImGui::BeginCombo(label, value.c_str())) {
            for (const auto& n : names)
                if (ImGui::Selectable(n.c_str(), n == value)) value = n;
            ImGui::EndCombo();
        }
    };
    section("Backends (one shared camera)");
    if (c.mode == ViewMode::Single) {
        std::string b = st.view.backend;
        backendCombo("Backend", b);
        if (b != st.view.backend) st.setBackend(b);
        ImGui::TextDisabled("Keys 1 / 2 / 3 switch backends.");
    } else if (c.mode == ViewMode::Split) {
        int count = c.count;
        if (ImGui::SliderInt("Count", &count, 2, 3)) st.showView(ViewMode::Split, count);
        const char* labels[] = {"Left", c.count == 3 ? "Middle" : "Right", "Right"};
        for (int i = 0; i < c.count; ++i) backendCombo(labels[i], c.split[size_t(i)]);
        ImGui::SliderFloat("Divider 1", &c.dividers[0], 0.0f, 1.0f);
        if (c.count == 3) ImGui::SliderFloat("Divider 2", &c.dividers[1], 0.0f, 1.0f);
        c.dividers[1] = std::max(c.dividers[1], c.dividers[0]);
        ImGui::TextDisabled("Drag the dividers in the viewport.");
    } else {
        backendCombo("A", c.diff[0]);
        backendCombo("B", c.diff[1]);
        if (c.diff[0] == c.diff[1]) ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.4f, 1.0f), "A and B are the same backend: nothing to compare.");
    }
    if (c.mode == ViewMode::Difference) {
        section("Difference");
        ImGui::Text("|%s - %s| per pixel", c.diff[0].c_str(), c.diff[1].c_str());
        ImGui::SliderInt("Threshold", &c.threshold, 0, 255);
        record(st, "compare/threshold");
        const DiffFigures& d = st.view.diff;   // the overlay writes the same texts
        if (d.valid) {
            ImGui::Text("Mean |a-b|  %s", d.meanText().c_str());
            ImGui::Text("Max  |a-b|  %d", d.max);
            ImGui::Text("PSNR        %s", d.psnrText().c_str());
            ImGui::Text("Within %d   %s of the pixels", c.threshold, d.withinText().c_str());
        } else {
            ImGui::TextDisabled("Waiting for both full-resolution images...");
        }
    }
}

}   // namespace ui
