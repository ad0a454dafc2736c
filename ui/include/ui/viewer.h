// viewer.h - the interactive viewer window (GLFW + Dear ImGui).
#pragma once

#include <string>

namespace ui {

// Opens the window on `scenePath` (a file, or empty/"demo" for the bundled demo) and runs the
// event loop until the window closes. Returns the process exit code.
int runViewer(const std::string& scenePath);

}  // namespace ui
