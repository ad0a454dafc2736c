// style.cpp - setupStyle(): the viewer's ImGui style and font at the window's content scale
// (sets g_scale, which every panel's sizes go through).
#include "panels/panel_common.h"

#include <cmath>
#include <filesystem>

namespace fs = std::filesystem;

namespace ui {

using namespace panels_detail;

void setupStyle(float scale, const char* fontPath) {
    g_scale = std::clamp(scale, 0.5f, 4.0f);
    ImGuiIO& io = ImGui::GetIO();
    ImGui::GetStyle() = ImGuiStyle();   // sizes are scaled below: start from the defaults
    ImGui::StyleColorsDark();
    ImGuiStyle& s = ImGui::GetStyle();
    io.Fonts->Clear();
    s.WindowRounding = 0.0f;
    s.FrameRounding = 3.0f;
    s.GrabRounding = 3.0f;
    s.TabRounding = 3.0f;
    s.ScrollbarRounding = 3.0f;
    s.WindowBorderSize = 1.0f;
    s.FramePadding = ImVec2(6, 4);
    s.ItemSpacing = ImVec2(8, 5);
    s.IndentSpacing = 14.0f;
    ImVec4* c = s.Colors;
    c[ImGuiCol_WindowBg] = ImVec4(0.13f, 0.14f, 0.16f, 1.0f);
    c[ImGuiCol_ChildBg] = ImVec4(0.11f, 0.12f, 0.14f, 1.0f);
    c[ImGuiCol_MenuBarBg] = ImVec4(0.10f, 0.11f, 0.13f, 1.0f);
    c[ImGuiCol_Header] = ImVec4(0.22f, 0.36f, 0.56f, 0.70f);
    c[ImGuiCol_HeaderHovered] = ImVec4(0.26f, 0.42f, 0.66f, 0.80f);
    c[ImGuiCol_HeaderActive] = ImVec4(0.28f, 0.46f, 0.72f, 1.00f);
    c[ImGuiCol_FrameBg] = ImVec4(0.19f, 0.20f, 0.23f, 1.0f);
    c[ImGuiCol_TitleBgActive] = ImVec4(0.16f, 0.29f, 0.48f, 1.0f);
    s.ScaleAllSizes(g_scale);
    if (fontPath && fs::exists(fontPath)) {
        ImFontConfig cfg;
        cfg.OversampleH = 2;
        io.Fonts->AddFontFromFileTTF(fontPath, std::round(15.0f * g_scale), &cfg);
    } else {
        ImFontConfig cfg;
        cfg.SizePixels = std::round(13.0f * g_scale);
        io.Fonts->AddFontDefault(&cfg);
    }
}

}   // namespace ui
