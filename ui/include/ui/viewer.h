// viewer.h - the interactive viewer window (GLFW + Dear ImGui).
#pragma once

#include <string>

namespace ui {

// Window options. The automation fields are hidden command-line options (see app/main.cpp):
// they let tests and docs drive the real window for a few frames and take screenshots.
struct ViewerOptions {
    std::string scene;           // file, or ""/"demo" for the bundled demo
    int width = 0, height = 0;   // --window-size; 0: the remembered size, else from the monitor's work area
    std::string backend;         // initial backend ("" = gl)
    std::string view;            // initial view: single, split, split3, difference
    // Automation: a script of commands, one per line (see viewer.cpp, "automation"), or the
    // shorthand --frames N [--screenshot out.png] = "frames N / wait / window-shot out.png / quit".
    std::string script;
    int frames = 0;
    std::string screenshot;
    double timeoutSeconds = 120;   // automation: give up (exit code 3) after this long
};

// Opens the window on options.scene (a file, or empty/"demo" for the bundled demo) and runs the
// event loop until the window closes. Returns the process exit code.
int runViewer(const ViewerOptions& options);

}   // namespace ui
