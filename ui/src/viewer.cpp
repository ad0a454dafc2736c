// Placeholder until the window lands.
#include "ui/viewer.h"

#include <cstdio>

namespace ui {
int runViewer(const std::string&) {
    std::fprintf(stderr, "viewer: error: the interactive window is not built yet; use 'viewer render' or 'viewer demo-shots'\n");
    return 1;
}
}  // namespace ui
