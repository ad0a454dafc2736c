// headless_ui.h - the viewer's panels in headless Dear ImGui frames for tests: a context with
// a built font atlas and a 1600x900 display, the demo scene, and helpers that click recorded
// widget rectangles (ViewerState::hooks.itemRects) and press keys the way the window does.
#pragma once

#include "ui/panels.h"

#include "assets/demo.h"

#include <imgui.h>

#include <stdexcept>
#include <string>

namespace ui {

class Headless {
public:
    Headless() {
        ImGui::CreateContext();
        ImGuiIO& io = ImGui::GetIO();
        io.IniFilename = nullptr;
        io.DisplaySize = ImVec2(1600, 900);
        io.DeltaTime = 1.0f / 60.0f;
        setupStyle(1.0f, nullptr);
        unsigned char* pixels = nullptr;
        int w = 0, h = 0;
        io.Fonts->GetTexDataAsRGBA32(&pixels, &w, &h);
        st.view.viewportWidth = 800;
        st.view.viewportHeight = 600;
        st.setScene(assets::makeDemoScene(), {});
        view.slots.resize(1);
        view.slots[0].status.backend = "gl";
        view.slots[0].status.error = "not built";
        frame();
        frame();
    }
    ~Headless() { ImGui::DestroyContext(); }

    void frame() {
        ImGui::NewFrame();
        drawUi(st, view, t, 1.0f / 60.0f);
        ImGui::Render();
        t += 1.0 / 60.0;
    }
    const ItemRect& rect(const std::string& key) {
        auto it = st.hooks.itemRects.find(key);
        if (it == st.hooks.itemRects.end()) throw std::runtime_error("no item '" + key + "'");
        return it->second;
    }
    void moveTo(float x, float y) {
        ImGui::GetIO().MousePos = ImVec2(x, y);
        frame();
    }
    void click(const std::string& key) {
        const ItemRect r = rect(key);
        moveTo(r.cx(), r.cy());
        ImGui::GetIO().MouseDown[0] = true;
        frame();
        ImGui::GetIO().MouseDown[0] = false;
        frame();
        frame();
    }
    void press(int key, bool ctrl = false, bool shift = false) {
        ImGuiIO& io = ImGui::GetIO();
        io.KeyCtrl = ctrl;
        io.KeyShift = shift;
        io.KeysDown[key] = true;
        frame();
        io.KeysDown[key] = false;
        io.KeyCtrl = io.KeyShift = false;
        frame();
    }
    // Left-drags from the centre of a recorded widget by dx pixels in `steps` frames, then
    // releases. Half a second passes first, so two drags in a row are not a double click
    // (which turns a drag widget into a text field).
    void drag(const std::string& key, float dx, int steps = 5) {
        for (int i = 0; i < 30; ++i) frame();
        const ItemRect r = rect(key);
        moveTo(r.cx(), r.cy());
        ImGui::GetIO().MouseDown[0] = true;
        frame();
        for (int i = 1; i <= steps; ++i) moveTo(r.cx() + dx * float(i) / float(steps), r.cy());
        ImGui::GetIO().MouseDown[0] = false;
        frame();
        frame();
    }

    ViewerState st;
    ViewportInput view;
    double t = 0;
};

}   // namespace ui
