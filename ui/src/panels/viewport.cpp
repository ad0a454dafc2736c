// viewport.cpp - drawViewport(): the 3D viewport. The backends' images (single, split with
// draggable dividers, difference heat map with its legend), the stats overlay, camera input
// (orbit, pan, zoom, fly), click-to-pick and the pixel inspector's probe.
#include "panels/panel_common.h"

#include "renderers/framebuffer.h"
#include "scenegraph/scene_defaults.h"

#include <array>
#include <cstdio>

namespace ui {

using namespace panels_detail;

namespace {

void centeredText(ImDrawList* dl, ImVec2 a, ImVec2 b, const std::string& text, ImU32 col) {
    float wrap = std::max(b.x - a.x - px(24), px(50));
    ImVec2 sz = ImGui::CalcTextSize(text.c_str(), nullptr, false, wrap);
    ImVec2 p((a.x + b.x - sz.x) * 0.5f, (a.y + b.y - sz.y) * 0.5f);
    dl->AddRectFilled(ImVec2(p.x - px(10), p.y - px(8)), ImVec2(p.x + sz.x + px(10), p.y + sz.y + px(8)), IM_COL32(20, 20, 24, 220), px(4));
    dl->AddText(nullptr, 0.0f, p, col, text.c_str(), nullptr, wrap);
}

// Draws one backend's image over [a, b] showing the u-range [u0, u1] of the image.
void drawSlotImage(ImDrawList* dl, const SlotView& v, ImVec2 a, ImVec2 b, float u0, float u1) {
    if (v.texture && v.width > 0) {
        dl->AddImage(v.texture, a, b, ImVec2(u0, 0), ImVec2(u1, 1));
    } else {
        dl->AddRectFilled(a, b, IM_COL32(24, 25, 29, 255));
    }
    std::string msg;
    if (!v.status.error.empty())
        msg = v.status.backend + ": " + v.status.error;
    else if (!v.texture)
        msg = v.status.backend + ": rendering...";
    if (!msg.empty()) centeredText(dl, a, b, msg, v.status.error.empty() ? IM_COL32(200, 200, 210, 255) : IM_COL32(255, 150, 120, 255));
}

std::string slotStats(const SlotView& v) {
    if (!v.texture && v.status.error.empty()) return v.status.backend + "  rendering...";   // no figures of a picture not shown
    char buf[256];
    const rnd::RenderStats& s = v.status.stats;
    std::string extra;
    if (s.rays > 0 && s.milliseconds > 0) {
        char r[64];
        std::snprintf(r, sizeof r, "  %.2f Mrays/s", double(s.rays) / (s.milliseconds * 1000.0));
        extra += r;
    }
    if (v.status.level > 1) extra += "  (1/" + std::to_string(v.status.level) + " res)";
    if (v.status.refining && s.config.samplesPerPixel == 1 && s.config.aaAsked != "none")   // a one-sample step of an anti-aliased image
        extra += "  1 sample/pixel, " + s.config.aaAsked + " follows";
    else if (s.ok || !s.config.aaUsed.empty())
        extra += "  " + s.config.describe();
    if (!s.config.unsupported.empty()) {
        extra += "  no";
        for (const std::string& u : s.config.unsupported) extra += " " + u;
    }
    // The progress first, after the name: a long line is cut at the viewport's edge, never it.
    // Tessellating shapes anew (a new tessellation level) comes before the image and can take
    // seconds: said as such, with its own percentage.
    const std::string percent = std::to_string(int(v.status.progress * 100)) + "%  ";
    const std::string progress = !v.status.rendering ? "" : v.status.shapes ? "rebuilding shapes " + percent : percent;
    std::snprintf(buf, sizeof buf, "%-8s %s%7.1f ms  %6.1fk tris%s", v.status.backend.c_str(), progress.c_str(), s.milliseconds,
                  double(s.triangles) / 1000.0, extra.c_str());
    return buf;
}

void cameraInput(ViewerState& st, ImVec2 a, ImVec2 b, double time, float dt) {
    ImGuiIO& io = ImGui::GetIO();
    bool hovered = ImGui::IsItemHovered();
    bool active = ImGui::IsItemActive();
    const sg::Projection& proj = st.projection();
    bool ortho = proj.type != sg::ProjectionType::Perspective;
    bool moved = false;
    // Divider drag (split view) takes precedence over the camera when grabbed near a divider.
    int& dragDivider = st.ui.panels.dragDivider;
    if (st.view.compare.mode == ViewMode::Split && ImGui::IsItemClicked(ImGuiMouseButton_Left)) {
        dragDivider = -1;
        for (int i = 0; i < st.view.compare.count - 1; ++i) {
            float x = a.x + st.view.compare.dividers[i] * (b.x - a.x);
            if (std::abs(io.MousePos.x - x) < px(6)) dragDivider = i;
        }
    }
    if (!io.MouseDown[0]) dragDivider = -1;
    if (dragDivider >= 0 && active) {
        float f = std::clamp((io.MousePos.x - a.x) / std::max(b.x - a.x, 1.0f), 0.0f, 1.0f);
        st.view.compare.dividers[dragDivider] = f;
        if (dragDivider == 0)
            st.view.compare.dividers[1] = std::max(st.view.compare.dividers[1], f);
        else
            st.view.compare.dividers[0] = std::min(st.view.compare.dividers[0], f);
        return;
    }
    if (active && (io.MouseDelta.x != 0 || io.MouseDelta.y != 0)) {
        bool panning = io.MouseDown[2] || (io.MouseDown[0] && io.KeyShift);
        if (io.MouseDown[1]) {
            st.view.camera.look(io.MouseDelta.x, io.MouseDelta.y);
            moved = true;
        } else if (panning) {
            st.view.camera.pan(
                io.MouseDelta.x, io.MouseDelta.y,
                st.view.camera.panScale(proj.effectiveFovyDeg((b.x - a.x) / std::max(b.y - a.y, 1.0f)), b.y - a.y, ortho, proj.orthoHalfHeight));
            moved = true;
        } else if (io.MouseDown[0]) {
            st.view.camera.orbit(io.MouseDelta.x, io.MouseDelta.y);
            moved = true;
        }
    }
    if (hovered && io.MouseWheel != 0.0f) {
        st.view.camera.zoom(io.MouseWheel);
        moved = true;
    }
    // Fly mode: right mouse held + WASD (QE down/up), Shift = faster.
    bool wasFlying = st.view.flyMode;
    st.view.flyMode = active && io.MouseDown[1];
    if (st.view.flyMode && !wasFlying) st.view.flySpeed = sg::flySpeedFor(st.doc.scene);   // the scene's size, once per flight
    if (st.view.flyMode) {
        float speed = st.view.flySpeed * dt * (io.KeyShift ? 4.0f : 1.0f);
        sg::vec3 o(0.0f);
        if (ImGui::IsKeyDown(keys::W)) o.z += speed;
        if (ImGui::IsKeyDown(keys::S)) o.z -= speed;
        if (ImGui::IsKeyDown(keys::D)) o.x += speed;
        if (ImGui::IsKeyDown(keys::A)) o.x -= speed;
        if (ImGui::IsKeyDown(keys::E)) o.y += speed;
        if (ImGui::IsKeyDown(keys::Q)) o.y -= speed;
        if (o != sg::vec3(0.0f)) {
            st.view.camera.fly(o);
            moved = true;
        }
    }
    if (moved) {
        st.view.lastInteraction = time;
        st.markViewChanged();
    }
}

// The viewport's parts, each drawn over [a, a + avail].

// Split view: each backend's image over its part of the width, its name on top, the dividers.
void drawSplitView(ImDrawList* dl, const ViewerState& st, const ViewportInput& view, ImVec2 a, ImVec2 avail) {
    ImVec2 b(a.x + avail.x, a.y + avail.y);
    int n = std::min<int>(int(view.slots.size()), std::clamp(st.view.compare.count, 2, 3));
    float edges[4] = {0.0f, st.view.compare.dividers[0], n == 3 ? st.view.compare.dividers[1] : 1.0f, 1.0f};
    if (n == 2) edges[2] = 1.0f;
    for (int i = 0; i < n; ++i) {
        float u0 = edges[i], u1 = edges[i + 1];
        if (u1 <= u0) continue;
        ImVec2 p0(a.x + u0 * avail.x, a.y), p1(a.x + u1 * avail.x, b.y);
        drawSlotImage(dl, view.slots[i], p0, p1, u0, u1);
        // Backend label at the top of its region.
        const std::string& name = view.slots[i].status.backend;
        ImVec2 ts = ImGui::CalcTextSize(name.c_str());
        ImVec2 lp(p0.x + (p1.x - p0.x - ts.x) * 0.5f, a.y + px(8));
        dl->AddRectFilled(ImVec2(lp.x - px(6), lp.y - px(3)), ImVec2(lp.x + ts.x + px(6), lp.y + ts.y + px(3)), IM_COL32(0, 0, 0, 160), px(3));
        dl->AddText(lp, IM_COL32(255, 255, 255, 255), name.c_str());
    }
    for (int i = 0; i + 1 < n; ++i) {
        float x = a.x + st.view.compare.dividers[i] * avail.x;
        dl->AddLine(ImVec2(x, a.y), ImVec2(x, b.y), IM_COL32(255, 255, 255, 200), px(2));
        dl->AddCircleFilled(ImVec2(x, (a.y + b.y) * 0.5f), px(7), IM_COL32(255, 255, 255, 230));
        dl->AddCircle(ImVec2(x, (a.y + b.y) * 0.5f), px(7), IM_COL32(40, 40, 40, 255), 0, px(1.5f));
    }
}

// The heat map's colours for a largest-channel difference of 0..64 (64 and above look the
// same), and of a pixel within the threshold (a dimmed grey copy of image A, here of mid grey):
// taken from rnd::diffImage itself on a ramp, so the legend cannot drift from the image.
struct HeatColours {
    std::array<ImU32, 65> ramp;
    ImU32 within;
};
HeatColours heatColours() {
    rnd::Framebuffer x, y;
    x.resize(66, 1);
    y.resize(66, 1);
    std::fill(x.color.begin(), x.color.end(), uint8_t(0));
    std::fill(y.color.begin(), y.color.end(), uint8_t(0));
    for (int i = 0; i < 66; ++i) x.color[size_t(i) * 4 + 3] = y.color[size_t(i) * 4 + 3] = 255;
    for (int v = 0; v <= 64; ++v) y.color[size_t(v) * 4] = uint8_t(v);   // pixel v differs by v
    for (int c = 0; c < 3; ++c) x.color[65 * 4 + size_t(c)] = y.color[65 * 4 + size_t(c)] = 128;
    rnd::Framebuffer d = rnd::diffImage(x, y, 0);
    auto colour = [&](int i) { return IM_COL32(d.color[size_t(i) * 4], d.color[size_t(i) * 4 + 1], d.color[size_t(i) * 4 + 2], 255); };
    HeatColours h{};
    for (int v = 0; v <= 64; ++v) h.ramp[size_t(v)] = colour(v);
    h.within = colour(65);
    return h;
}

// A box in window pixels (an overlay's), Min = Max: none.
struct OverlayBox {
    ImVec2 Min{0, 0}, Max{0, 0};
};

// Legend (top right of the heat map): what grey and the red-to-white ramp mean; below the stats
// box (`avoid`, empty when it is hidden) where the viewport is too narrow for both side by side.
void drawDiffLegend(ImDrawList* dl, ViewerState& st, ImVec2 a, ImVec2 avail, const OverlayBox& avoid) {
    const HeatColours heat = heatColours();
    int t = std::clamp(st.view.compare.threshold, 0, 255);
    const std::string title = "|A - B|, largest channel (0-255)", within = "0-" + std::to_string(t) + ": within threshold (A, dimmed)";
    float lh = ImGui::GetTextLineHeight(), barH = px(12), pad = px(8);
    float w = std::max(ImGui::CalcTextSize(title.c_str()).x, px(26) + ImGui::CalcTextSize(within.c_str()).x) + 2 * pad;
    ImVec2 o(a.x + std::max(avail.x - w - px(10), 0.0f), a.y + px(10));
    if (avoid.Max.x > avoid.Min.x && o.x < avoid.Max.x + px(10)) o.y = avoid.Max.y + px(10);
    ImVec2 end(o.x + w, o.y + pad * 2 + lh * 3 + barH + px(8));
    dl->AddRectFilled(o, end, IM_COL32(0, 0, 0, 190), px(4));
    ImU32 text = IM_COL32(230, 230, 235, 255);
    float x0 = o.x + pad, x1 = end.x - pad, y = o.y + pad;
    dl->AddText(ImVec2(x0, y), text, title.c_str());
    y += lh + px(2);
    dl->AddRectFilled(ImVec2(x0, y + px(2)), ImVec2(x0 + px(18), y + lh - px(2)), heat.within);
    dl->AddRect(ImVec2(x0, y + px(2)), ImVec2(x0 + px(18), y + lh - px(2)), IM_COL32(120, 120, 120, 255));
    dl->AddText(ImVec2(x0 + px(26), y), text, within.c_str());
    y += lh + px(4);
    int from = std::min(t + 1, 64);   // the ramp from the first highlighted difference
    int steps = std::max(64 - from, 1);
    for (int i = 0; i < steps; ++i) {
        float u0 = x0 + (x1 - x0) * float(i) / float(steps), u1 = x0 + (x1 - x0) * float(i + 1) / float(steps);
        ImU32 c0 = heat.ramp[size_t(std::min(from + i, 64))], c1 = heat.ramp[size_t(std::min(from + i + 1, 64))];
        dl->AddRectFilledMultiColor(ImVec2(u0, y), ImVec2(u1, y + barH), c0, c1, c1, c0);
    }
    y += barH + px(2);
    std::string left = std::to_string(t + 1), right = t + 1 >= 64 ? "" : "64+";
    dl->AddText(ImVec2(x0, y), text, left.c_str());
    dl->AddText(ImVec2(x1 - ImGui::CalcTextSize(right.c_str()).x, y), text, right.c_str());
    st.hooks.itemRects["diff/legend"] = ItemRect{o.x, o.y, end.x, end.y};
}

// Difference view: the heat map (or why there is none yet), its legend and the figures at the
// bottom (DiffFigures::summary, as the Compare tab writes them).
void drawDifferenceView(ImDrawList* dl, ViewerState& st, const ViewportInput& view, ImVec2 a, ImVec2 avail, const OverlayBox& statsBox) {
    ImVec2 b(a.x + avail.x, a.y + avail.y);
    SlotView d = view.diff;
    if (!d.texture) {
        // No diff yet: say why (an error of either side, or still rendering).
        std::string msg = "Waiting for both images...";
        for (const SlotView& s : view.slots)
            if (!s.status.error.empty()) msg = s.status.backend + ": " + s.status.error;
        dl->AddRectFilled(a, b, IM_COL32(24, 25, 29, 255));
        centeredText(dl, a, b, msg, IM_COL32(255, 170, 140, 255));
    } else {
        dl->AddImage(d.texture, a, b);
        drawDiffLegend(dl, st, a, avail, statsBox);
    }
    if (view.slots.size() >= 2) {
        std::string line = st.view.diff.summary(view.slots[0].status.backend, view.slots[1].status.backend, st.view.compare.threshold);
        ImVec2 ts = ImGui::CalcTextSize(line.c_str());
        ImVec2 lp(a.x + (avail.x - ts.x) * 0.5f, b.y - ts.y - px(12));
        dl->AddRectFilled(ImVec2(lp.x - px(8), lp.y - px(4)), ImVec2(lp.x + ts.x + px(8), lp.y + ts.y + px(4)), IM_COL32(0, 0, 0, 180), px(3));
        dl->AddText(lp, IM_COL32(255, 230, 160, 255), line.c_str());
    }
}

// The stats overlay's lines (one per shown backend, the viewport size, the diagnostic legend).
std::vector<std::string> statsLines(const ViewerState& st, const ViewportInput& view) {
    std::vector<std::string> lines;
    for (const SlotView& v : view.slots) lines.push_back(slotStats(v));
    char buf[128];
    std::snprintf(buf, sizeof buf, "%d x %d   %s", st.view.viewportWidth, st.view.viewportHeight, st.view.flyMode ? "FLY (WASD QE)" : "");
    lines.emplace_back(buf);
    if (!view.slots.empty() && !view.slots[0].legend.empty()) lines.push_back(view.slots[0].legend);   // the diagnostic view's
    return lines;
}

// Where the stats overlay's box goes (top left; clipped to the viewport's width).
OverlayBox statsBoxOf(const ViewerState& st, const std::vector<std::string>& lines, ImVec2 a, ImVec2 avail) {
    const float h = ImGui::GetTextLineHeightWithSpacing();
    float w = 0;
    for (auto& l : lines) w = std::max(w, ImGui::CalcTextSize(l.c_str()).x);
    const ImVec2 o(a.x + px(10), a.y + (st.view.compare.mode == ViewMode::Split ? px(36) : px(10)));
    return OverlayBox{o, ImVec2(std::min(o.x + w + px(16), a.x + avail.x), o.y + h * float(lines.size()) + px(10))};
}

// Stats overlay (top-left): one line per shown backend and the viewport size; progress bars
// at the bottom for renders in flight.
void drawStatsOverlay(ImDrawList* dl, const ViewerState& st, const ViewportInput& view, ImVec2 a, ImVec2 avail) {
    ImVec2 b(a.x + avail.x, a.y + avail.y);
    const std::vector<std::string> lines = statsLines(st, view);
    const float h = ImGui::GetTextLineHeightWithSpacing();
    const OverlayBox box = statsBoxOf(st, lines, a, avail);
    const ImVec2 o = box.Min;
    dl->AddRectFilled(box.Min, box.Max, IM_COL32(0, 0, 0, 150), px(4));
    for (size_t i = 0; i < lines.size(); ++i) {
        bool rendering = i < view.slots.size() && view.slots[i].status.rendering;
        dl->AddText(ImVec2(o.x + px(8), o.y + px(5) + h * i), rendering ? IM_COL32(255, 220, 120, 255) : IM_COL32(220, 230, 240, 255),
                    lines[i].c_str());
    }
    // Progress bars for renders in flight.
    for (size_t i = 0; i < view.slots.size(); ++i) {
        if (!view.slots[i].status.rendering) continue;
        float y = b.y - px(4) - px(5) * i;
        dl->AddRectFilled(ImVec2(a.x, y - px(3)), ImVec2(a.x + avail.x * view.slots[i].status.progress, y), IM_COL32(90, 170, 255, 220));
    }
}

}   // namespace

namespace {

// The shown image under viewport fraction u (single: the one image; split: the part under the
// cursor; difference: A).
const SlotView* slotUnder(const ViewerState& st, const ViewportInput& view, float u) {
    if (view.slots.empty()) return nullptr;
    if (st.view.compare.mode != ViewMode::Split) return &view.slots[0];
    const int n = std::min<int>(int(view.slots.size()), std::clamp(st.view.compare.count, 2, 3));
    if (u < st.view.compare.dividers[0]) return &view.slots[0];
    if (n == 3 && u >= st.view.compare.dividers[1]) return &view.slots[2];
    return &view.slots[1];
}

// A left click (no drag, no modifier that pans) in the viewport: pick the node under it
// (nothing there clears the selection; as soon as the image under it has its visibility) and
// pin the pixel inspector there.
void pickAndProbe(ViewerState& st, const ViewportInput& view, ImVec2 a, ImVec2 avail) {
    ImGuiIO& io = ImGui::GetIO();
    const float u = (io.MousePos.x - a.x) / avail.x, v = (io.MousePos.y - a.y) / avail.y;
    const bool inside = u >= 0 && v >= 0 && u < 1 && v < 1;
    PixelProbeState& probe = st.ui.panels.probe;
    if (inside && ImGui::IsItemDeactivated() && ImGui::IsMouseReleased(ImGuiMouseButton_Left) && io.MouseDragMaxDistanceSqr[0] < px(3) * px(3) &&
        !io.KeyShift) {
        probe.pinned = true;
        probe.u = u;
        probe.v = v;
        probe.pickPending = true;
        probe.pickAdds = io.KeyCtrl;
        probe.pickViewVersion = st.view.version;
        probe.pickDocVersion = st.doc.version;
    } else if (!probe.pinned) {
        probe.u = inside && ImGui::IsItemHovered() ? u : -1.0f;
        probe.v = inside && ImGui::IsItemHovered() ? v : -1.0f;
    }
    if (probe.pickPending && (probe.pickViewVersion != st.view.version || probe.pickDocVersion != st.doc.version)) probe.pickPending = false;
    if (probe.pickPending)
        if (const SlotView* s = slotUnder(st, view, probe.u); s && s->probe.image && s->probe.image->has(rnd::Aov::Visibility)) {
            const sg::NodeId picked = pickAt(s->probe, probe.u, probe.v);
            if (probe.pickAdds)
                st.toggleSelected(picked);   // Ctrl+click: adds or takes out; on empty space nothing changes
            else
                st.selectNode(picked);
            probe.pickPending = false;
        }
    probe.results.clear();
    if (probe.u < 0) return;
    for (const SlotView& s : view.slots) probe.results.push_back(probeAt(st, s.probe, probe.u, probe.v));
}

}   // namespace

void drawViewport(ViewerState& st, const ViewportInput& view, double time, float dt) {
    ImVec2 a = ImGui::GetCursorScreenPos();
    ImVec2 avail = ImGui::GetContentRegionAvail();
    avail.x = std::max(avail.x, 1.0f);
    avail.y = std::max(avail.y, 1.0f);
    ImVec2 b(a.x + avail.x, a.y + avail.y);
    // Render at framebuffer pixels (HiDPI: DisplayFramebufferScale).
    ImVec2 fbs = ImGui::GetIO().DisplayFramebufferScale;
    st.view.viewportWidth = std::max(1, int(avail.x * fbs.x));
    st.view.viewportHeight = std::max(1, int(avail.y * fbs.y));

    ImGui::InvisibleButton("##viewport", avail,
                           ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight | ImGuiButtonFlags_MouseButtonMiddle);
    record(st, "viewport");
    cameraInput(st, a, b, time, dt);
    pickAndProbe(st, view, a, avail);
    // Space: play / pause the animation while the pointer is over the viewport or it has focus
    // (not while typing, not with Ctrl: Ctrl+Space is Viewport only).
    if (!st.anim.clips.empty() && (ImGui::IsWindowHovered() || ImGui::IsWindowFocused()) && !ImGui::GetIO().WantTextInput &&
        !ImGui::GetIO().KeyCtrl && ImGui::IsKeyPressed(keys::Space, false))
        st.toggleAnimation();

    ImDrawList* dl = ImGui::GetWindowDrawList();
    dl->PushClipRect(a, b, true);
    switch (st.view.compare.mode) {
    case ViewMode::Single:
        if (!view.slots.empty()) drawSlotImage(dl, view.slots[0], a, b, 0, 1);
        break;
    case ViewMode::Split: drawSplitView(dl, st, view, a, avail); break;
    case ViewMode::Difference:
        drawDifferenceView(dl, st, view, a, avail, st.ui.panels.showOverlay ? statsBoxOf(st, statsLines(st, view), a, avail) : OverlayBox{});
        break;
    }
    // The pixel the inspector is pinned to: a ring with a gap at its centre (the pixel stays
    // visible), dark under light so it shows on any image.
    if (const PixelProbeState& probe = st.ui.panels.probe; probe.pinned && probe.u >= 0.0f) {
        const ImVec2 c(a.x + probe.u * avail.x, a.y + probe.v * avail.y);
        for (int pass = 0; pass < 2; ++pass) {
            const ImU32 col = pass == 0 ? IM_COL32(0, 0, 0, 200) : IM_COL32(255, 255, 255, 230);
            const float w = pass == 0 ? px(3) : px(1.5f);
            dl->AddCircle(c, px(7), col, 24, w);
            for (const ImVec2 d : {ImVec2(1, 0), ImVec2(-1, 0), ImVec2(0, 1), ImVec2(0, -1)})
                dl->AddLine(ImVec2(c.x + d.x * px(3), c.y + d.y * px(3)), ImVec2(c.x + d.x * px(11), c.y + d.y * px(11)), col, w);
        }
    }
    if (st.ui.panels.showOverlay) drawStatsOverlay(dl, st, view, a, avail);
    dl->PopClipRect();
}

}   // namespace ui
