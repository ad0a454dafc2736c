// dialogs.cpp - drawDialogs(): the modal dialogs. The file browser (Open, Save As), the
// screenshot / export dialog, the unsaved-changes, replace-file and error questions, and the
// Help > Controls window.
#include "panels/panel_common.h"

#include "assets/scene_io.h"

#include <imgui_stdlib.h>

#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace ui {

using namespace panels_detail;

namespace {

void openBrowser(bool saving, ViewerState& st) {
    FileBrowserState& browser = st.ui.panels.browser;
    browser.open = true;
    browser.justOpened = true;
    browser.saving = saving;
    browser.error.clear();
    std::error_code ec;
    const fs::path start = st.documentFolder();
    // Save As starts in the document's own folder; Open where the browser was last.
    if ((saving && !st.doc.path.empty()) || browser.dir.empty() || !fs::is_directory(browser.dir, ec)) browser.dir = start;
    browser.fileName = saving ? (st.doc.path.empty() ? st.doc.scene.name + ".json" : st.doc.path.stem().string() + ".json") : "";
}

void drawFileBrowser(ViewerState& st) {
    FileBrowserState& browser = st.ui.panels.browser;
    if (!browser.open) return;
    const char* title = browser.saving ? "Save scene as###browser" : "Open scene###browser";
    if (browser.justOpened) {
        ImGui::OpenPopup(title);
        browser.justOpened = false;
    }
    ImVec2 ds = ImGui::GetIO().DisplaySize;
    ImGui::SetNextWindowSize(ImVec2(std::min(px(640), ds.x * 0.9f), std::min(px(480), ds.y * 0.9f)), ImGuiCond_Appearing);
    ImGui::SetNextWindowPos(ImVec2(ds.x * 0.5f, ds.y * 0.5f), ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    bool keep = true;
    if (!ImGui::BeginPopupModal(title, &keep)) {
        if (!keep) {
            browser.open = false;
            if (browser.saving) st.saveAsCancelled();
        }
        return;
    }
    std::error_code ec;
    std::string dirText = browser.dir.string();
    if (ImGui::Button("Up")) browser.dir = browser.dir.parent_path();
    ImGui::SameLine();
    ImGui::SetNextItemWidth(-1);
    if (ImGui::InputText("##dir", &dirText, ImGuiInputTextFlags_EnterReturnsTrue) && fs::is_directory(dirText, ec)) browser.dir = dirText;

    std::vector<std::string> exts = assets::supportedSceneExtensions();
    std::vector<fs::directory_entry> dirs, files;
    for (fs::directory_iterator it(browser.dir, fs::directory_options::skip_permission_denied, ec), end; !ec && it != end; it.increment(ec)) {
        const fs::directory_entry& e = *it;
        std::string name = e.path().filename().string();
        if (name.empty() || name[0] == '.') continue;
        if (e.is_directory(ec))
            dirs.push_back(e);
        else {
            std::string ext = e.path().extension().string();
            std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
            if (std::find(exts.begin(), exts.end(), ext) != exts.end()) files.push_back(e);
        }
        if (dirs.size() + files.size() > 5000) break;
    }
    auto byName = [](const fs::directory_entry& x, const fs::directory_entry& y) { return x.path().filename() < y.path().filename(); };
    std::sort(dirs.begin(), dirs.end(), byName);
    std::sort(files.begin(), files.end(), byName);

    float footer = ImGui::GetFrameHeightWithSpacing() * 2.5f;
    fs::path chosen;
    ImGui::BeginChild("entries", ImVec2(0, -footer), true);
    for (const auto& d : dirs) {
        std::string label = "[dir] " + d.path().filename().string();
        if (ImGui::Selectable(label.c_str(), false, ImGuiSelectableFlags_AllowDoubleClick) && ImGui::IsMouseDoubleClicked(0)) browser.dir = d.path();
    }
    for (const auto& f : files) {
        std::string name = f.path().filename().string();
        if (ImGui::Selectable(name.c_str(), browser.fileName == name, ImGuiSelectableFlags_AllowDoubleClick)) {
            browser.fileName = name;
            if (ImGui::IsMouseDoubleClicked(0)) chosen = f.path();
        }
    }
    ImGui::EndChild();
    ImGui::SetNextItemWidth(-px(170));
    bool enter = ImGui::InputText("##file", &browser.fileName, ImGuiInputTextFlags_EnterReturnsTrue);
    ImGui::SameLine();
    if (ImGui::Button(browser.saving ? "Save" : "Open", ImVec2(px(75), 0)) || enter) {
        // A folder typed into the name field (relative to the listed one, or absolute; "~"
        // is home) is opened in the list instead of being taken as the file.
        std::error_code dirEc;
        fs::path typed = browser.fileName;
        if (browser.fileName == "~" || browser.fileName.rfind("~/", 0) == 0)
            if (const char* home = std::getenv("HOME"))
                typed = fs::path(home) / browser.fileName.substr(std::min<size_t>(2, browser.fileName.size()));
        const fs::path target = typed.is_absolute() ? typed : browser.dir / typed;
        if (!browser.fileName.empty() && fs::is_directory(target, dirEc)) {
            browser.dir = fs::weakly_canonical(target, dirEc);
            browser.fileName.clear();
        } else if (!browser.fileName.empty()) {
            chosen = target;
        }
    }
    record(st, "browser/accept");
    ImGui::SameLine();
    if (ImGui::Button("Cancel", ImVec2(px(75), 0)) || escapeCancels(st)) {
        browser.open = false;
        if (browser.saving) st.saveAsCancelled();
        ImGui::CloseCurrentPopup();
    }
    ImGui::TextDisabled(browser.saving ? "Native JSON scene (.json)" : "Formats: .json .gltf .glb .obj .off .ply .stl");
    if (!chosen.empty()) {
        browser.open = false;
        ImGui::CloseCurrentPopup();
        if (browser.saving)
            st.saveAs(chosen);
        else
            st.requestOpen(chosen);
    }
    ImGui::EndPopup();
}

// Width and height fields: the viewport's size, read-only, while "Viewport size" is ticked
// (so they show what will be written), else the custom size with presets.
void screenshotSizeFields(ScreenshotDialogState& dialog, const View& view) {
    bool viewport = dialog.windowSize;
    int w = viewport ? view.viewportWidth : dialog.width, h = viewport ? view.viewportHeight : dialog.height;
    ImGui::BeginDisabled(viewport);
    ImGui::InputInt("Width", &w);
    ImGui::InputInt("Height", &h);
    for (auto [pw, ph] : {std::pair{1280, 720}, std::pair{1920, 1080}, std::pair{3840, 2160}}) {
        if (pw != 1280) ImGui::SameLine();
        if (ImGui::SmallButton((std::to_string(pw) + "x" + std::to_string(ph)).c_str())) w = pw, h = ph;
    }
    ImGui::EndDisabled();
    if (viewport) return;
    dialog.width = std::clamp(w, 1, 16384);
    dialog.height = std::clamp(h, 1, 16384);
}

// The subfolders of `dir` by name (hidden ones left out; at most `limit`); none when it is not a
// readable folder.
std::vector<std::string> subfolders(const fs::path& dir, size_t limit) {
    std::vector<std::string> names;
    std::error_code ec;
    for (fs::directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end; !ec && it != end && names.size() < limit;
         it.increment(ec)) {
        std::string name = it->path().filename().string();
        if (!name.empty() && name[0] != '.' && it->is_directory(ec)) names.push_back(name);
    }
    std::sort(names.begin(), names.end());
    return names;
}

// The folder: typed, or chosen with Up and a click on one of its subfolders.
void screenshotFolderPicker(ViewerState& st, ScreenshotDialogState& dialog) {
    if (ImGui::Button("Up##shotFolder")) dialog.dirText = absoluteFolder(dialog.dirText).parent_path().string();
    record(st, "shot/up");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(px(360));
    ImGui::InputText("Folder", &dialog.dirText);
    record(st, "shot/folder");
    ImGui::BeginChild("shotFolders", ImVec2(px(420), px(110)), true);
    std::vector<std::string> names = subfolders(dialog.dirText, 500);
    std::error_code ec;
    if (names.empty()) ImGui::TextDisabled(fs::is_directory(dialog.dirText, ec) ? "(no subfolders)" : "(not a folder yet: Take makes it)");
    for (const std::string& name : names) {
        if (ImGui::Selectable(("[dir] " + name).c_str())) dialog.dirText = (absoluteFolder(dialog.dirText) / name).string();
        record(st, "shot/dir/" + name);
    }
    ImGui::EndChild();
}

// Take: the folder typed is checked (made when missing) before anything renders; a folder
// that cannot be used keeps the dialog open with the reason.
bool takeScreenshot(ViewerState& st, ScreenshotDialogState& dialog, std::string& error) {
    fs::path dir = prepareScreenshotFolder(dialog.dirText, &error);
    if (dir.empty()) return false;
    dialog.dir = dir;
    auto [w, h] = screenshotSize(dialog, st.view);
    st.ui.requests.screenshot = true;
    st.ui.requests.screenshotWidth = w;
    st.ui.requests.screenshotHeight = h;
    return true;
}

// The export boxes: depth / normal / id files and the camera sidecar next to each PNG.
void screenshotExportBoxes(ViewerState& st, ScreenshotDialogState& dialog) {
    ImGui::TextUnformatted("Export next to each PNG (with the camera sidecar .json):");
    ImGui::Checkbox("Depth (.depth.pfm)", &dialog.exportDepth);
    record(st, "shot/depth");
    ImGui::SameLine();
    ImGui::Checkbox("Normal (.normal.png)", &dialog.exportNormal);
    record(st, "shot/normal");
    ImGui::SameLine();
    ImGui::Checkbox("Id (.id.png)", &dialog.exportId);
    record(st, "shot/id");
}

void drawScreenshotDialog(ViewerState& st) {
    ScreenshotDialogState& dialog = st.ui.panels.shotDialog;
    if (st.ui.requests.screenshotDialog || st.ui.requests.exportDialog) {
        if (st.ui.requests.exportDialog && screenshotExports(dialog).empty()) dialog.exportDepth = dialog.exportNormal = dialog.exportId = true;
        st.ui.requests.screenshotDialog = st.ui.requests.exportDialog = false;
        dialog.open = true;
        dialog.error.clear();
        dialog.dirText = absoluteFolder(dialog.dir).string();
        ImGui::OpenPopup("Screenshot");
    }
    if (!ImGui::BeginPopupModal("Screenshot", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
    ImGui::Checkbox(screenshotSizeLabel(dialog, st.view).c_str(), &dialog.windowSize);
    record(st, "shot/viewportSize");
    screenshotSizeFields(dialog, st.view);
    ImGui::Checkbox("As the viewport shows it (diagnostic view, overlays)", &dialog.asShown);
    record(st, "shot/asShown");
    screenshotExportBoxes(st, dialog);
    screenshotFolderPicker(st, dialog);
    if (!dialog.error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.45f, 1.0f), "%s", dialog.error.c_str());
    ImGui::TextDisabled(
        "One PNG per backend shown, rendered offscreen;\nnamed screenshot-<backend>[-N].png, never overwriting.\nF12 saves into the same folder "
        "with the same choices.");
    if (ImGui::Button("Take", ImVec2(px(90), 0)) && takeScreenshot(st, dialog, dialog.error)) ImGui::CloseCurrentPopup();
    record(st, "shot/take");
    ImGui::SameLine();
    if (ImGui::Button("Cancel", ImVec2(px(90), 0)) || escapeCancels(st)) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
}

// Help > Controls: input and action in two table columns (the font is proportional, so
// space-padded text never lined up).
void drawControlsHelp(ViewerState& st) {
    static constexpr std::pair<const char*, const char*> kControls[] = {
        {"Click", "select (empty space clears), pin the pixel inspector"},
        {"Ctrl+click", "add to / take out of the selection"},
        {"Left drag", "orbit around the pivot"},
        {"Middle / Shift+left drag", "pan"},
        {"Wheel", "zoom"},
        {"Right drag + WASD", "fly (Q/E down/up, Shift faster)"},
        {"F", "fit scene / selection"},
        {"Home", "reset to the scene camera"},
        {"Keypad 1 / 3 / 7", "front / right / top view (Ctrl: back / left / bottom)"},
        {"Keypad 5", "perspective / orthographic"},
        {"Keypad .", "frame the selection"},
        {"Ctrl+Space", "viewport only (hide the panels)"},
        {"1 / 2 / 3", "backend gl / raster / raycast"},
        {"F12", "screenshot (as set in File > Screenshot at resolution...)"},
        {"Space", "play / pause the animation (viewport)"},
        {"F2", "rename selection"},
        {"Del, Ctrl+D", "delete / duplicate selection"},
        {"Ctrl+Z", "undo (Edit menu names the step)"},
        {"Ctrl+Shift+Z, Ctrl+Y", "redo"},
        {"Ctrl+N/O/S/Q", "new / open / save / quit"},
        {"Escape", "close a menu, list, dialog or this window"},
    };
    // Sized to its table, so no row is ever cut off (a fixed width clipped the longer actions).
    if (ImGui::Begin("Controls", &st.ui.panels.showHelp, ImGuiWindowFlags_AlwaysAutoResize)) {
        if (ImGui::BeginTable("controls", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
            for (const auto& [input, action] : kControls) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(input);
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(action);
            }
            ImGui::EndTable();
        }
        ImGui::TextUnformatted("Drag tree nodes onto others to re-parent.\nDrop files onto the window to open them.");
    }
    ImGui::End();
}

}   // namespace

void drawDialogs(ViewerState& st) {
    if (st.ui.requests.openDialog) {
        st.ui.requests.openDialog = false;
        openBrowser(false, st);
    }
    if (st.ui.requests.saveAsDialog) {
        st.ui.requests.saveAsDialog = false;
        openBrowser(true, st);
    }
    drawFileBrowser(st);
    drawScreenshotDialog(st);

    if (st.ui.confirmOpen && !ImGui::IsPopupOpen("Unsaved changes")) ImGui::OpenPopup("Unsaved changes");
    if (ImGui::BeginPopupModal("Unsaved changes", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        if (!st.ui.confirmOpen) ImGui::CloseCurrentPopup();   // answered elsewhere (automation's `answer`)
        const char* what = st.ui.pending == PendingAction::Quit  ? "quitting"
                           : st.ui.pending == PendingAction::New ? "starting a new scene"
                                                                 : "opening another file";
        ImGui::Text("The scene has unsaved changes.\nSave them before %s?", what);
        ImGui::Spacing();
        if (ImGui::Button("Save", ImVec2(px(90), 0))) {
            st.confirm(ConfirmChoice::Save);
            ImGui::CloseCurrentPopup();
        }
        record(st, "confirm/save");
        ImGui::SameLine();
        if (ImGui::Button("Discard", ImVec2(px(90), 0))) {
            st.confirm(ConfirmChoice::Discard);
            ImGui::CloseCurrentPopup();
        }
        record(st, "confirm/discard");
        ImGui::SameLine();
        if (ImGui::Button("Cancel", ImVec2(px(90), 0)) || escapeCancels(st)) {
            st.confirm(ConfirmChoice::Cancel);
            ImGui::CloseCurrentPopup();
        }
        record(st, "confirm/cancel");
        ImGui::EndPopup();
    }

    // Save As onto an existing file: nothing is replaced without this question.
    if (st.ui.replaceOpen && !ImGui::IsPopupOpen("Replace file?")) ImGui::OpenPopup("Replace file?");
    if (ImGui::BeginPopupModal("Replace file?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        if (!st.ui.replaceOpen) ImGui::CloseCurrentPopup();   // answered elsewhere (automation's `answer`)
        ImGui::Text("%s already exists.\nReplace it with this scene?", st.ui.replacePath.filename().string().c_str());
        ImGui::TextDisabled("%s", st.ui.replacePath.parent_path().string().c_str());
        ImGui::Spacing();
        if (ImGui::Button("Replace", ImVec2(px(90), 0))) {
            st.confirmReplace(true);
            ImGui::CloseCurrentPopup();
        }
        record(st, "replace/replace");
        ImGui::SameLine();
        if (ImGui::Button("Cancel", ImVec2(px(90), 0)) || escapeCancels(st)) {
            st.confirmReplace(false);
            ImGui::CloseCurrentPopup();
        }
        record(st, "replace/cancel");
        ImGui::EndPopup();
    }

    if (!st.ui.errorPopup.empty() && !ImGui::IsPopupOpen("Error")) ImGui::OpenPopup("Error");
    if (ImGui::BeginPopupModal("Error", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::PushTextWrapPos(px(520));
        ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.5f, 1.0f), "%s", st.ui.errorPopup.c_str());
        ImGui::PopTextWrapPos();
        if (ImGui::Button("OK", ImVec2(px(90), 0)) || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Enter)) || escapeCancels(st)) {
            st.ui.errorPopup.clear();
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }

    if (st.ui.panels.showHelp) drawControlsHelp(st);
}

}   // namespace ui
