// animation_panel.cpp - drawAnimationPanel(): the animation bar above the right panel's tabs
// (clip, Play / Pause, loop, time); nothing for a scene without clips.
#include "panels/panel_common.h"

namespace ui {

using namespace panels_detail;

void drawAnimationPanel(ViewerState& st) {
    if (st.anim.clips.empty()) return;
    section("Animation");
    const assets::AnimationClip* cur = st.currentAnimation();
    auto clipName = [&](int i) {
        const std::string& n = st.anim.clips[size_t(i)].name;
        return n.empty() ? "clip " + std::to_string(i) : n;
    };
    if (ImGui::BeginCombo("Clip", cur ? clipName(st.anim.clip).c_str() : "-")) {
        for (int i = 0; i < int(st.anim.clips.size()); ++i) {
            ImGui::PushID(i);
            if (ImGui::Selectable(clipName(i).c_str(), i == st.anim.clip) && i != st.anim.clip) st.selectAnimation(i);
            ImGui::PopID();
        }
        ImGui::EndCombo();
    }
    record(st, "anim/clip");
    if (!cur) return;
    if (ImGui::Button(st.anim.playing ? "Pause###animPlay" : "Play###animPlay", ImVec2(px(64), 0))) st.toggleAnimation();
    record(st, "anim/play");
    ImGui::SameLine();
    ImGui::Checkbox("Loop", &st.anim.loop);
    record(st, "anim/loop");
    ImGui::SameLine();
    ImGui::TextDisabled("(Space in the viewport)");
    float t = float(st.anim.time);
    float t0 = cur->start, t1 = float(st.animationEnd());
    if (ImGui::SliderFloat("Time", &t, t0, std::max(t1, t0 + 1e-3f), "%.2f s")) st.setAnimationTime(t);
    record(st, "anim/time");
}

}   // namespace ui
