// automation.cpp - the viewer's script commands (see automation.h). One per line, '#' starts a
// comment; output lines start with "viewer: ". A command that is unknown or cannot be done
// (bad arguments, no such node, no question to answer) stops the script with exit code 2.
//
// Frames and waiting
//   frames N              run N frames
//   wait                  until no load / screenshot is in flight and the shown backends have
//                         their full-resolution images (or errors)
//   wait load             until no load is in flight (renders of the new scene may not have
//                         started: what the user sees right after a load)
//   quit
// Input, through the paths the user's input takes
//   key [MOD+]...KEY      press for one frame: MOD ctrl|shift|alt|super, KEY a letter, a digit,
//                         F1..F12, Home, End, Delete, Escape, Enter, Space, Tab, Backspace,
//                         Insert, Left, Right, Up, Down, PageUp, PageDown, Kp1, Kp3, Kp5, Kp7,
//                         KpDecimal or a GLFW key code
//                         (key ctrl+z, key ctrl+shift+z, key Delete, key 2)
//   click X Y | click viewport X Y | click ITEM   left click at window pixel (X, Y) (ImGui
//                         coordinates, the menu bar at the top), at pixel (X, Y) of the 3D
//                         viewport (from its top-left corner), or at the centre of a widget the
//                         panels record (menu/edit, edit/undo, tree/crate, confirm/discard, ...)
//   click ctrl ...        the same with Ctrl held (adds to / takes out of the selection)
//   drag X0 Y0 X1 Y1      left drag in the 3D viewport (pixels from its top-left corner): press
//                         at (X0, Y0), move to (X1, Y1) over 8 frames, release (an orbit)
// The document (as the File and Edit menus do)
//   open PATH             File > Open, asking first when there are unsaved changes
//   answer save|discard|cancel   answers the unsaved-changes question
//   save-as PATH          File > Save As with PATH typed (relative to the document's folder,
//                         where the dialog starts; ".json" appended for another extension); asks
//                         before replacing an existing file
//   answer replace|cancel answers the replace question
//   set KEY VALUE         a parameter by its key in scenegraph/params.h (shading flat,
//                         fog.mode linear, fog.end 40, aa ssaa2, ambientLight 0.2,0.2,0.2),
//                         material.KEY of the selection (material.kd 0.3, material.baseColor
//                         [1,0,0]), light.KEY of the selected light, camera.KEY of the
//                         projection (camera.fovy 30); an undo step. A refused value prints "viewer: set KEY: refused: REASON" and
//                         the script goes on (the status line shows it too)
//   select NAME           select the first node of that name (depth-first)
//   undo | redo           Edit > Undo / Redo
// The view
//   backend NAME          single view with that backend
//   view single|split|split3|difference   as the View menu
//   diagnostic NAME       View > Diagnostic view: shaded, depth, normal, id, uv, triangles, overdraw, cost, shadow-map
//   overlay LIST|none     View > Overlays: grid, axes, lights, cameras, bounds, selection,
//                         grid-on-top (the grid over every surface, "Grid on top")
//   orbit DX DY | zoom STEPS | fit
//   panels hide|show      View > Viewport only
//   tab Inspector|Camera|Rendering|Compare
//   gl-worker on|off      run the GL backend on a worker thread (own headless context)
//   anim play|pause|time T   animation of the loaded file: play, pause, or pose at T seconds
// Output
//   print dirty           viewer: dirty yes|no
//   print tree            "viewer: tree", then one line per node, depth-first (parents before
//                         children, children in order), indented two spaces per level, the root
//                         ("root") unindented
//   print compare         viewer: compare MODE BACKEND... (MODE single|split|split3|difference,
//                         then the backends shown, left to right / A B)
//   print diff            viewer: diff |A - B|   mean M   max X   PSNR P   within T: W% (the
//                         difference view's figures, as its overlay and the Compare tab write
//                         them; only |A - B| until both full-resolution images are there)
//   print selection       viewer: selection NAME (or -)
//   print view            viewer: view MODE DIAGNOSTIC (e.g. single depth)
//   print legend          viewer: legend BACKEND TEXT (one line per shown backend: the legend of
//                         the diagnostic view as the viewport shows it, "-" for none)
//   print memory          viewer: memory N kB (resident set size, from /proc/self/status; -1 unknown)
//   print pixel           viewer: pixel BACKEND X Y rgb R G B node PATH triangle N depth D predicted R G B
//                         (one line per shown backend: the pixel inspector's probe)
//   print status          viewer: status TEXT (the status bar's line)
//   print viewport        viewer: viewport X Y W H (the 3D viewport in window pixels)
//   print camera          viewer: camera eye X Y Z centre X Y Z up X Y Z projection NAME (centre:
//                         the orbit pivot)
//   print undo            viewer: undo LABEL | redo LABEL (what Edit > Undo / Redo would do, "-")
//   print window          viewer: window X Y W H in work area X Y W H (screen coordinates)
//   print popup           viewer: popup yes|no (a menu, combo or dialog is open)
//   resize W H            sets the window's size, as the user dragging its border
//   stats                 time / triangles / rays of the shown backends
//   screenshot DIR        offscreen PNG per shown backend into DIR (as F12)
//   window-shot PATH      PNG of the whole window (UI included)
#include "automation.h"

#include "ui/panels.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace ui {

namespace {

// Resident set size of this process (VmRSS), for the soak test's `print memory`; -1 unknown.
long residentKilobytes() {
    FILE* f = std::fopen("/proc/self/status", "r");
    if (!f) return -1;
    char line[256];
    long kb = -1;
    while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "VmRSS: %ld kB", &kb) == 1) break;
    std::fclose(f);
    return kb;
}

}   // namespace

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

// A key name (case-insensitive) or a GLFW key code; -1 when unknown.
int keyCode(const std::string& name) {
    std::string k = lower(name);
    if (k.size() == 1 && k[0] >= 'a' && k[0] <= 'z') return GLFW_KEY_A + (k[0] - 'a');
    if (k.size() == 1 && k[0] >= '0' && k[0] <= '9') return GLFW_KEY_0 + (k[0] - '0');
    if (k.size() >= 2 && k[0] == 'f' && std::isdigit(static_cast<unsigned char>(k[1]))) {
        int n = std::atoi(k.c_str() + 1);
        if (n >= 1 && n <= 25) return GLFW_KEY_F1 + n - 1;
    }
    static constexpr std::pair<const char*, int> kNamed[] = {{"home", GLFW_KEY_HOME},
                                                             {"end", GLFW_KEY_END},
                                                             {"delete", GLFW_KEY_DELETE},
                                                             {"del", GLFW_KEY_DELETE},
                                                             {"escape", GLFW_KEY_ESCAPE},
                                                             {"esc", GLFW_KEY_ESCAPE},
                                                             {"enter", GLFW_KEY_ENTER},
                                                             {"return", GLFW_KEY_ENTER},
                                                             {"space", GLFW_KEY_SPACE},
                                                             {"tab", GLFW_KEY_TAB},
                                                             {"backspace", GLFW_KEY_BACKSPACE},
                                                             {"insert", GLFW_KEY_INSERT},
                                                             {"left", GLFW_KEY_LEFT},
                                                             {"right", GLFW_KEY_RIGHT},
                                                             {"up", GLFW_KEY_UP},
                                                             {"down", GLFW_KEY_DOWN},
                                                             {"pageup", GLFW_KEY_PAGE_UP},
                                                             {"pagedown", GLFW_KEY_PAGE_DOWN},
                                                             {"kp1", GLFW_KEY_KP_1},
                                                             {"kp3", GLFW_KEY_KP_3},
                                                             {"kp5", GLFW_KEY_KP_5},
                                                             {"kp7", GLFW_KEY_KP_7},
                                                             {"kpdecimal", GLFW_KEY_KP_DECIMAL}};
    for (const auto& [n, code] : kNamed)
        if (k == n) return code;
    if (!k.empty() && std::all_of(k.begin(), k.end(), [](unsigned char c) { return std::isdigit(c); })) {
        int code = std::atoi(k.c_str());
        return code > 0 && code <= GLFW_KEY_LAST ? code : -1;
    }
    return -1;
}

// The modifier keys of a GLFW mods mask, as key codes (pressed before the key, released after).
std::vector<int> modifierKeys(int mods) {
    std::vector<int> keys;
    if (mods & GLFW_MOD_CONTROL) keys.push_back(GLFW_KEY_LEFT_CONTROL);
    if (mods & GLFW_MOD_SHIFT) keys.push_back(GLFW_KEY_LEFT_SHIFT);
    if (mods & GLFW_MOD_ALT) keys.push_back(GLFW_KEY_LEFT_ALT);
    if (mods & GLFW_MOD_SUPER) keys.push_back(GLFW_KEY_LEFT_SUPER);
    return keys;
}

void printTree(const sg::Scene& scene) {
    std::printf("viewer: tree\n");
    std::vector<int> depth(scene.idCapacity(), 0);
    for (sg::NodeId id : scene.depthFirstOrder()) {
        const sg::Node& n = scene.node(id);
        if (scene.valid(n.parent)) depth[id] = depth[n.parent] + 1;
        std::printf("%s%s\n", std::string(size_t(depth[id]) * 2, ' ').c_str(), n.name.c_str());
    }
}

std::string restOfLine(std::istringstream& in) {
    std::string s;
    std::getline(in >> std::ws, s);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
    return s;
}

}   // namespace

bool Automation::step(AutomationHost& host) {
    if (!m_mouse.empty()) return true;   // a click in progress: overrideMouse plays it (a held Ctrl stays down)
    for (auto it = m_held.rbegin(); it != m_held.rend(); ++it) host.keyEvent(it->first, /*press=*/false, it->second);
    m_held.clear();
    if (m_waitFrames > 0) {
        --m_waitFrames;
        return true;
    }
    if (m_waitingLoad) {
        if (host.state().loadInProgress()) return true;
        m_waitingLoad = false;
    } else if (m_waiting) {
        host.pollScreenshots();
        if (!host.idle()) return true;
        m_waiting = false;
        m_waitFrames = 2;   // let the UI show the final images
        return true;
    }
    while (m_pc < lines.size()) {
        std::istringstream in(lines[m_pc++]);
        std::string cmd;
        in >> cmd;
        if (cmd.empty() || cmd[0] == '#') continue;
        Next next = runCommand(cmd, in, host);
        std::fflush(stdout);
        if (next == Next::Yield) return true;
        if (next == Next::Quit) return false;
    }
    return false;   // script finished
}

void Automation::overrideMouse() {
    if (m_mouse.empty()) return;
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = ImVec2(m_mouse.front().x, m_mouse.front().y);
    io.MouseDown[0] = m_mouse.front().down;
    m_mouse.pop_front();
}

Automation::Next Automation::fail(const std::string& message) {
    std::fprintf(stderr, "viewer: automation: line %zu: %s\n", m_pc, message.c_str());
    failed = true;
    return Next::Quit;
}

Automation::Next Automation::runCommand(const std::string& cmd, std::istringstream& in, AutomationHost& host) {
    if (cmd == "frames") {
        in >> m_waitFrames;
        return Next::Yield;
    }
    if (cmd == "wait") {
        std::string what = restOfLine(in);
        if (!what.empty() && what != "load") return fail("wait " + what + ": expected wait or wait load");
        (what.empty() ? m_waiting : m_waitingLoad) = true;
        return Next::Yield;
    }
    if (cmd == "quit") return Next::Quit;
    if (cmd == "key") return keyCommand(restOfLine(in), host);
    if (cmd == "click") return clickCommand(in, host);
    if (cmd == "drag") return dragCommand(restOfLine(in), host.state());
    if (cmd == "print") return printCommand(restOfLine(in), host);
    if (cmd == "resize") {
        int w = 0, h = 0;
        if (!(in >> w >> h) || w < 1 || h < 1) return fail("resize: expected WIDTH HEIGHT");
        host.resizeWindow(w, h);
        m_waitFrames = 2;   // the new size reaches ImGui on the next frame
        return Next::Yield;
    }
    if (cmd == "stats") {
        host.printStats();
        return Next::Continue;
    }
    if (cmd == "screenshot") {
        std::string dir = restOfLine(in);
        host.startScreenshots(dir.empty() ? "." : dir);
        m_waiting = true;
        return Next::Yield;
    }
    if (cmd == "window-shot") {
        windowShot = restOfLine(in);
        return windowShot.empty() ? fail("window-shot: no path") : Next::Yield;
    }
    if (cmd == "open" || cmd == "answer" || cmd == "save-as" || cmd == "set" || cmd == "select" || cmd == "undo" || cmd == "redo")
        return documentCommand(cmd, in, host.state());
    return viewCommand(cmd, in, host.state());
}

// ctrl+shift+z: the modifiers go down first, the key last; all are released on the next step.
Automation::Next Automation::keyCommand(const std::string& spec, AutomationHost& host) {
    int mods = 0;
    std::string key = spec;
    for (size_t plus; (plus = key.find('+')) != std::string::npos && plus + 1 < key.size(); key = key.substr(plus + 1)) {
        std::string m = lower(key.substr(0, plus));
        int bit = m == "ctrl" || m == "control" ? GLFW_MOD_CONTROL
                  : m == "shift"                ? GLFW_MOD_SHIFT
                  : m == "alt"                  ? GLFW_MOD_ALT
                  : m == "super"                ? GLFW_MOD_SUPER
                                                : 0;
        if (!bit) return fail("key " + spec + ": unknown modifier '" + m + "' (ctrl, shift, alt, super)");
        mods |= bit;
    }
    int code = keyCode(key);
    if (code < 0) return fail("key " + spec + ": unknown key '" + key + "'");
    int held = 0;
    for (int m : modifierKeys(mods)) {
        held |= m == GLFW_KEY_LEFT_CONTROL ? GLFW_MOD_CONTROL
                : m == GLFW_KEY_LEFT_SHIFT ? GLFW_MOD_SHIFT
                : m == GLFW_KEY_LEFT_ALT   ? GLFW_MOD_ALT
                                           : GLFW_MOD_SUPER;
        host.keyEvent(m, /*press=*/true, held);
        m_held.emplace_back(m, held);
    }
    host.keyEvent(code, true, mods);
    m_held.emplace_back(code, mods);
    m_waitFrames = 1;   // down for one frame, then released; one more frame sees the result
    return Next::Yield;
}

// Three frames at the point: hover, press, release (ImGui acts on the release for menus and
// buttons, on the press for tree nodes and the viewport).
Automation::Next Automation::clickCommand(std::istringstream& in, AutomationHost& host) {
    const ViewerState& st = host.state();
    std::string first = restOfLine(in);
    const bool ctrl = first.rfind("ctrl ", 0) == 0;   // Ctrl held from the hover to the release
    if (ctrl) first = first.substr(5);
    float x = 0, y = 0;
    std::istringstream xy(first);
    if (first.rfind("viewport ", 0) == 0) {   // relative to the 3D viewport's top-left corner
        auto vp = st.hooks.itemRects.find("viewport");
        std::istringstream rel(first.substr(9));
        if (vp == st.hooks.itemRects.end() || !(rel >> x >> y)) return fail("click " + first + ": expected viewport X Y, after a frame was drawn");
        x += vp->second.x0;
        y += vp->second.y0;
    } else if (!(xy >> x >> y)) {
        auto it = st.hooks.itemRects.find(first);
        if (it == st.hooks.itemRects.end()) return fail("click " + first + ": not X Y, and no widget of that name was drawn");
        x = it->second.cx();
        y = it->second.cy();
    }
    m_mouse = {{x, y, false}, {x, y, true}, {x, y, false}};
    if (ctrl) {
        host.keyEvent(GLFW_KEY_LEFT_CONTROL, /*press=*/true, GLFW_MOD_CONTROL);
        m_held.emplace_back(GLFW_KEY_LEFT_CONTROL, GLFW_MOD_CONTROL);   // released once the clicks are played
    }
    m_waitFrames = 1;
    return Next::Yield;
}

// Hover, press, 8 moving frames held down, release: what a user's orbit drag gives ImGui.
Automation::Next Automation::dragCommand(const std::string& args, const ViewerState& st) {
    auto vp = st.hooks.itemRects.find("viewport");
    float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    std::istringstream in(args);
    if (vp == st.hooks.itemRects.end() || !(in >> x0 >> y0 >> x1 >> y1))
        return fail("drag " + args + ": expected X0 Y0 X1 Y1 in the viewport, after a frame was drawn");
    const float ox = vp->second.x0, oy = vp->second.y0;
    constexpr int kSteps = 8;
    m_mouse = {{ox + x0, oy + y0, false}, {ox + x0, oy + y0, true}};
    for (int i = 1; i <= kSteps; ++i) {
        float t = float(i) / kSteps;
        m_mouse.push_back({ox + x0 + t * (x1 - x0), oy + y0 + t * (y1 - y0), true});
    }
    m_mouse.push_back({ox + x1, oy + y1, false});
    m_waitFrames = 0;
    return Next::Yield;
}

Automation::Next Automation::printCommand(const std::string& what, AutomationHost& host) {
    const ViewerState& st = host.state();
    if (what == "window") {
        WindowRect w = host.windowRect(), a = host.workArea();
        std::printf("viewer: window %d %d %d %d in work area %d %d %d %d\n", w.x, w.y, w.width, w.height, a.x, a.y, a.width, a.height);
    } else if (what == "popup") {
        std::printf("viewer: popup %s\n", ImGui::IsPopupOpen(nullptr, ImGuiPopupFlags_AnyPopupId) ? "yes" : "no");
    } else if (what == "dirty") {
        std::printf("viewer: dirty %s\n", st.doc.dirty ? "yes" : "no");
    } else if (what == "tree") {
        printTree(st.doc.scene);
    } else if (what == "compare") {
        std::string line = "viewer: compare " + st.viewName();
        for (const std::string& b : visibleBackends(st)) line += " " + b;
        std::printf("%s\n", line.c_str());
    } else if (what == "diff") {
        std::vector<std::string> b = visibleBackends(st);
        if (st.view.compare.mode != ViewMode::Difference || b.size() < 2) return fail("print diff: not in the difference view");
        std::printf("viewer: diff %s\n", st.view.diff.summary(b[0], b[1], st.view.compare.threshold).c_str());
    } else if (what == "selection") {
        std::string names;   // the active node first
        for (sg::NodeId id : st.selection()) names += (names.empty() ? "" : ", ") + st.doc.scene.node(id).name;
        std::printf("viewer: selection %s\n", names.empty() ? "-" : names.c_str());
    } else if (what == "memory") {
        std::printf("viewer: memory %ld kB\n", residentKilobytes());
    } else if (what == "view") {
        std::printf("viewer: view %s %s\n", st.viewName().c_str(), std::string(rnd::nameOf(st.view.diagnostic)).c_str());
    } else if (what == "pixel") {
        const PixelProbeState& p = st.ui.panels.probe;
        if (p.results.empty()) return fail("print pixel: nothing probed (hover or click the viewport first)");
        std::istringstream lines(probeSummary(p));
        for (std::string line; std::getline(lines, line);) std::printf("viewer: pixel %s\n", line.c_str());
    } else if (what == "legend") {
        for (const std::string& b : visibleBackends(st)) {
            auto it = st.view.legends.find(b);
            std::printf("viewer: legend %s %s\n", b.c_str(), it == st.view.legends.end() || it->second.empty() ? "-" : it->second.c_str());
        }
    } else if (what == "viewport") {
        const ItemRect& r = st.hooks.viewportRect;
        std::printf("viewer: viewport %d %d %d %d\n", int(std::lround(r.x0)), int(std::lround(r.y0)), int(std::lround(r.x1 - r.x0)),
                    int(std::lround(r.y1 - r.y0)));
    } else if (what == "camera") {
        const sg::vec3 e = st.view.camera.eye(), c = st.view.camera.pivot, u = st.view.camera.up();
        std::printf("viewer: camera eye %.4g %.4g %.4g centre %.4g %.4g %.4g up %.4g %.4g %.4g projection %s\n", e.x, e.y, e.z, c.x, c.y, c.z, u.x,
                    u.y, u.z, std::string(sg::nameOf(st.projection().type)).c_str());
    } else if (what == "status") {
        std::printf("viewer: status %s\n", st.ui.status.c_str());
    } else if (what == "undo") {
        const UndoStack& h = st.doc.history;
        std::printf("viewer: undo %s | redo %s\n", h.canUndo() ? h.undoLabel().c_str() : "-", h.canRedo() ? h.redoLabel().c_str() : "-");
    } else {
        return fail("print " + what +
                    ": expected dirty, tree, compare, diff, selection, pixel, view, legend, memory, status, undo, viewport, camera, window or popup");
    }
    return Next::Continue;
}

Automation::Next Automation::documentCommand(const std::string& cmd, std::istringstream& in, ViewerState& st) {
    if (cmd == "undo" || cmd == "redo") {
        if (!(cmd == "undo" ? st.undo() : st.redo())) std::printf("viewer: %s: nothing to %s\n", cmd.c_str(), cmd.c_str());
        return Next::Continue;
    }
    std::string arg = restOfLine(in);
    if (cmd == "open") {
        if (arg.empty()) return fail("open: no path");
        st.requestOpen(arg);
    } else if (cmd == "save-as") {
        if (arg.empty()) return fail("save-as: no path");
        const fs::path typed = arg;
        st.saveAs(typed.is_absolute() ? typed : st.documentFolder() / typed);
        m_waitFrames = 2;   // a question opens on the next frame
        return Next::Yield;
    } else if (cmd == "answer" && st.ui.replaceOpen) {
        if (arg != "replace" && arg != "cancel") return fail("answer " + arg + ": the replace question expects replace or cancel");
        st.confirmReplace(arg == "replace");
    } else if (cmd == "answer") {
        ConfirmChoice c = arg == "save" ? ConfirmChoice::Save : arg == "discard" ? ConfirmChoice::Discard : ConfirmChoice::Cancel;
        if (arg != "save" && arg != "discard" && arg != "cancel") return fail("answer " + arg + ": expected save, discard or cancel");
        if (st.ui.pending == PendingAction::None) return fail("answer " + arg + ": no question is pending");
        st.confirm(c);
    } else if (cmd == "select") {
        sg::NodeId id = st.doc.scene.findByName(arg);
        if (id == sg::kNoNode) return fail("select " + arg + ": no node of that name");
        st.selectNode(id);
    } else {   // set KEY VALUE
        std::istringstream kv(arg);
        std::string key;
        kv >> key;
        std::string value = restOfLine(kv);
        if (key.empty() || value.empty()) return fail("set: expected KEY VALUE");
        std::string err = st.setByName(key, value);
        if (err.find("unknown setting") != std::string::npos || err.find("no material") != std::string::npos ||
            err.find("not a light") != std::string::npos)
            return fail(err);
        if (!err.empty()) std::printf("viewer: set %s: refused: %s\n", key.c_str(), err.c_str());
    }
    return Next::Continue;
}

Automation::Next Automation::viewCommand(const std::string& cmd, std::istringstream& in, ViewerState& st) {
    std::string arg = restOfLine(in);
    std::istringstream args(arg);
    if (cmd == "backend") {
        st.setBackend(arg);
        st.showView(ViewMode::Single);
    } else if (cmd == "view") {
        if (!st.showView(arg)) return fail("view " + arg + ": expected single, split, split3 or difference");
    } else if (cmd == "diagnostic") {
        if (!rnd::parseDiagnosticView(arg, st.view.diagnostic)) {
            std::string names;
            for (std::string_view n : rnd::diagnosticViewNames()) names += (names.empty() ? "" : ", ") + std::string(n);
            return fail("diagnostic " + arg + ": expected " + names);
        }
    } else if (cmd == "overlay") {
        rnd::OverlayOptions o;
        std::string err;
        if (arg != "none" && !rnd::parseOverlayList(arg, o, err)) return fail("overlay " + arg + ": " + err);
        st.view.overlays = o;
    } else if (cmd == "orbit") {
        float dx = 0, dy = 0;
        args >> dx >> dy;
        st.view.camera.orbit(dx, dy);
        st.markViewChanged();
    } else if (cmd == "zoom") {
        float s = 0;
        args >> s;
        st.view.camera.zoom(s);
        st.markViewChanged();
    } else if (cmd == "fit") {
        st.fitView(false);
    } else if (cmd == "gl-worker") {
        st.view.glOnWorker = arg == "on";
    } else if (cmd == "panels") {
        if (arg != "hide" && arg != "show") return fail("panels " + arg + ": expected hide or show");
        st.view.panelsHidden = arg == "hide";
        m_waitFrames = 2;
        return Next::Yield;
    } else if (cmd == "tab") {
        st.hooks.requestedTab = arg;
    } else if (cmd == "anim") {
        std::string what;
        double t = 0;
        args >> what >> t;
        if (what == "play" || what == "pause")
            st.setAnimationPlaying(what == "play");
        else if (what == "time")
            st.setAnimationTime(t);
        else
            return fail("anim " + arg + ": expected play, pause or time T");
    } else {
        return fail("unknown command '" + cmd + "'");
    }
    return Next::Continue;
}

}   // namespace ui
