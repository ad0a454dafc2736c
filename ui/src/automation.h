// automation.h - the viewer's hidden scripting (viewer --automate script.txt): one command per
// line, run on the UI thread between frames, for tests and documentation screenshots. Keys and
// clicks go in through the same paths as the user's (the GLFW backend's key callback, ImGui's
// mouse state), so the real shortcut and widget code runs. The commands are listed in
// ui/README.md ("Automation") and at the top of automation.cpp.
#pragma once

#include "ui/viewer_state.h"

#include <deque>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace ui {

// What a script needs from the window; viewer.cpp implements it.
class AutomationHost {
public:
    virtual ViewerState& state() = 0;
    // No load or screenshot in flight and every shown backend has its full-resolution image
    // (or an error).
    virtual bool idle() = 0;
    virtual void pollScreenshots() = 0;
    virtual void startScreenshots(const std::filesystem::path& dir) = 0;
    virtual void printStats() = 0;   // one line per shown backend: time, triangles, rays
    // A key event as GLFW delivers it (through the platform backend's key callback).
    virtual void keyEvent(int glfwKey, bool press, int glfwMods) = 0;
    virtual WindowRect windowRect() = 0;   // the window's position and size (screen coordinates)
    virtual WindowRect workArea() = 0;     // of the monitor it is on, less the window's frame
    virtual void resizeWindow(int width, int height) = 0;

protected:
    ~AutomationHost() = default;
};

class Automation {
public:
    std::vector<std::string> lines;
    bool failed = false;      // a command was unknown or could not be done (exit code 2)
    std::string windowShot;   // set for one frame: the window is read back after rendering

    // Runs commands until one needs frames to pass. Returns false to stop (end of script,
    // `quit`, or a failure).
    bool step(AutomationHost& host);
    // Called each frame between the platform backend's NewFrame and ImGui::NewFrame: a
    // scripted click sets the mouse position and button here.
    void overrideMouse();

private:
    enum class Next { Continue, Yield, Quit };   // after a command: next line, let frames pass, stop
    struct MouseFrame {
        float x, y;
        bool down;
    };

    Next runCommand(const std::string& cmd, std::istringstream& in, AutomationHost& host);
    Next keyCommand(const std::string& spec, AutomationHost& host);
    Next clickCommand(std::istringstream& in, AutomationHost& host);
    Next dragCommand(const std::string& args, const ViewerState& st);
    Next printCommand(const std::string& what, AutomationHost& host);
    Next documentCommand(const std::string& cmd, std::istringstream& in, ViewerState& st);
    Next viewCommand(const std::string& cmd, std::istringstream& in, ViewerState& st);
    Next fail(const std::string& message);

    size_t m_pc = 0;   // next line
    int m_waitFrames = 0;
    bool m_waiting = false;                    // `wait`: until host.idle()
    bool m_waitingLoad = false;                // `wait load`: until no load is in flight
    std::vector<std::pair<int, int>> m_held;   // keys pressed last frame (key, mods), released next step
    std::deque<MouseFrame> m_mouse;            // one per frame, consumed by overrideMouse
};

}   // namespace ui
