// pixel_panel.cpp - drawPixelPanel(): the pixel inspector tab (see panels.h, pixel_probe.h).
#include "renderers/shading.h"
#include "ui/panels.h"

#include <imgui.h>

#include <cstdio>
#include <cstdlib>

namespace ui {

namespace {

void vecRow(const char* label, const sg::vec3& v) { ImGui::Text("%-12s %8.4f %8.4f %8.4f", label, double(v.x), double(v.y), double(v.z)); }

void swatch(const char* id, const uint8_t rgb[3]) {
    ImGui::ColorButton(id, ImVec4(rgb[0] / 255.0f, rgb[1] / 255.0f, rgb[2] / 255.0f, 1.0f),
                       ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoBorder, ImVec2(ImGui::GetFontSize() * 1.6f, ImGui::GetFontSize()));
}

void drawTerms(const ProbeResult& r) {
    const rnd::PixelTerms& t = r.terms;
    vecRow("albedo", t.albedo);
    if (!t.lit) {
        ImGui::TextDisabled("unlit (albedo + emissive)");
    } else {
        vecRow("ambient", t.ambient);
        vecRow("emissive", t.emissive);
        for (size_t i = 0; i < t.lights.size(); ++i) {
            const rnd::LightPart& l = t.lights[i];
            ImGui::Text("light %zu       shadow %.2f  n.l %.3f", i, double(l.visibility), double(l.nDotL));
            vecRow("  diffuse", l.diffuse);
            vecRow("  specular", l.specular);
        }
        if (!r.shadowsKnown) ImGui::TextDisabled("(shadows not known yet: rendering)");
    }
    ImGui::Text("%-12s %8.4f", "fog f(d)", double(t.fogVisibility));
    const uint8_t pred[3] = {rnd::toByteSRGB(t.predicted.x), rnd::toByteSRGB(t.predicted.y), rnd::toByteSRGB(t.predicted.z)};
    ImGui::Text("%-12s %3d %3d %3d", "sum (sRGB)", pred[0], pred[1], pred[2]);
    ImGui::SameLine();
    swatch("##pred", pred);
}

void drawResult(const ProbeResult& r) {
    ImGui::Text("pixel %d, %d   sRGB %3d %3d %3d", r.x, r.y, r.rgb[0], r.rgb[1], r.rgb[2]);
    ImGui::SameLine();
    swatch("##rgb", r.rgb);
    if (!r.valid) {
        ImGui::TextDisabled("No visibility for this image yet (preview, or the camera is moving).");
        return;
    }
    const sg::vec3 lin = rnd::srgbBytesToLinear(r.rgb);
    vecRow("linear", lin);
    const rnd::SurfaceAt& s = r.surface;
    if (!s.hit) {
        ImGui::TextDisabled("background");
        return;
    }
    ImGui::Text("node         %s", r.path.empty() ? "(unnamed)" : r.path.c_str());
    ImGui::Text("instance     %u   drawable %u", s.instance, s.drawable);
    if (s.triangle)
        ImGui::Text("triangle     %u", s.primitive);
    else
        ImGui::Text("%s", s.analytic ? "analytic shape" : "point / line");
    ImGui::Text("depth        %.5f", double(s.opticalDepth));
    vecRow("position", s.position);
    vecRow("normal", s.normal);
    if (s.triangle) vecRow("barycentric", s.barycentric);
    if (s.hasUv) ImGui::Text("%-12s %8.4f %8.4f", "uv", double(s.uv.x), double(s.uv.y));
    ImGui::Separator();
    drawTerms(r);
}

}   // namespace

void drawPixelPanel(ViewerState& st) {
    PixelProbeState& p = st.ui.panels.probe;
    if (p.pinned) {
        ImGui::Text("Pinned at %.0f%%, %.0f%% of the viewport", double(p.u * 100), double(p.v * 100));
        ImGui::SameLine();
        if (ImGui::SmallButton("Unpin")) {
            p.pinned = false;
            p.u = p.v = -1;
        }
    } else {
        ImGui::TextWrapped("Hover the viewport to inspect a pixel; click to pin it (and select its node).");
    }
    for (size_t i = 0; i < p.results.size(); ++i) {
        const ProbeResult& r = p.results[i];
        ImGui::PushID(int(i));
        if (ImGui::CollapsingHeader(r.backend.c_str(), ImGuiTreeNodeFlags_DefaultOpen)) drawResult(r);
        ImGui::PopID();
    }
    if (p.results.size() >= 2) {
        const ProbeResult &a = p.results[0], &b = p.results[1];
        ImGui::Separator();
        ImGui::Text("%s - %s: %+d %+d %+d (sRGB)", b.backend.c_str(), a.backend.c_str(), int(b.rgb[0]) - a.rgb[0], int(b.rgb[1]) - a.rgb[1],
                    int(b.rgb[2]) - a.rgb[2]);
        if (a.surface.hit && b.surface.hit && (a.surface.node != b.surface.node || a.surface.primitive != b.surface.primitive))
            ImGui::TextColored(ImVec4(1.0f, 0.7f, 0.4f, 1.0f), "they see different surfaces here");
    }
}

}   // namespace ui
