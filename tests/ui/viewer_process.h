// viewer_process.h - runs the real `viewer` window under Xvfb (xvfb-run) with an automation
// script, for the window tests: the command runs under `timeout` and the viewer's own
// --timeout, so a test never hangs. Output: DIR/log.txt (stdout and stderr), or with
// separateStdout stdout alone in DIR/out.txt (what `print` commands write) and stderr in
// DIR/log.txt.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <sys/wait.h>

namespace viewer_test {

inline bool haveXvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

// -noreset: without it Xvfb resets when the viewer disconnects and signals xvfb-run (SIGUSR1)
// again; landing during xvfb-run's clean-up, that made it fail with exit code 5 ("problem
// while cleaning up temporary directory"), mostly after short runs.
//
// Writes `script` to DIR/script.txt and runs `viewer ARGS --automate script.txt` in DIR with
// DIR/config as the per-user config folder, on a 1280x720 screen with a 1280x720 window, or
// on `screen` ("1366x768x24") with the window sized as the viewer decides when `screen` is
// given. Returns the exit code (-1: killed).
inline int runViewer(const std::filesystem::path& dir, const std::string& script, const std::string& args = "", bool separateStdout = false,
                     const std::string& screen = "") {
    std::filesystem::path scriptPath = dir / "script.txt";
    std::ofstream(scriptPath) << script;
    std::string size = screen.empty() ? " --window-size 1280x720" : "";
    std::string cmd = "cd '" + dir.string() + "' && XDG_CONFIG_HOME='" + (dir / "config").string() + "' timeout -k 5 240 xvfb-run -a -s '-screen 0 " +
                      (screen.empty() ? "1280x720x24" : screen) + " -noreset' '" VIEWER_EXE "' " + args + size + " --timeout 200 --automate '" +
                      scriptPath.string() + "'" +
                      (separateStdout ? " > '" + (dir / "out.txt").string() + "' 2> '" + (dir / "log.txt").string() + "'"
                                      : " > '" + (dir / "log.txt").string() + "' 2>&1");
    int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

inline std::string readLog(const std::filesystem::path& dir, const char* name = "log.txt") {
    std::ifstream in(dir / name);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

}   // namespace viewer_test
