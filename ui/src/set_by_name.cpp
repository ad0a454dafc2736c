// set_by_name.cpp - ViewerState::setByName: one scene value by its scene-JSON name (the
// automation's `set KEY VALUE`), and settingNames: the scene-JSON names of what differs
// between two RenderSettings (undo labels: "Change fog.mode").
//
// No parser of its own: the values the key may name (settings, ambient light, one material)
// go into a small scene, out through assets::serializeSceneJson, the key's JSON value is
// replaced, and the text comes back through assets::parseSceneJson, which checks names against
// the tables in scenegraph/setting_names.h, ranges and RenderSettings::validate exactly as it
// does for a scene file. Only what the key names is then applied, as one undoable edit.
#include "ui/viewer_state.h"

#include <nlohmann/json.hpp>

#include <algorithm>

namespace ui {

namespace {

using nlohmann::json;

// The JSON pointer of a key in a serialized scene: material.kd -> /materials/0/kd,
// ambientLight -> /ambientLight, fog.mode -> /settings/fog/mode.
std::string pointerOf(const std::string& key, bool material) {
    std::string rest = material ? key.substr(std::string("material.").size()) : key;
    for (char& c : rest)
        if (c == '.') c = '/';
    if (material) return "/materials/0/" + rest;
    if (key == "ambientLight") return "/ambientLight";
    return "/settings/" + rest;
}

// The material index of the selection's payload (-1: none, or no material of its own).
int selectedMaterial(const ViewerState& st) {
    if (!st.doc.scene.valid(st.doc.selected)) return -1;
    return std::visit(
        [](const auto& p) {
            if constexpr (requires { p.material; })
                return p.material;
            else
                return -1;
        },
        st.doc.scene.node(st.doc.selected).payload);
}

// The key set to `value` (JSON, or a bare word taken as a string) in `text`; "" or an error.
std::string patch(std::string& text, const std::string& key, const std::string& pointer, const std::string& value) {
    try {
        json j = json::parse(text);
        json::json_pointer ptr(pointer);
        if (!j.contains(ptr)) return "unknown setting '" + key + "' (names as in the scene file: shading, fog.mode, aa, material.kd, ...)";
        json v = json::parse(value, nullptr, /*allow_exceptions=*/false);
        j[ptr] = v.is_discarded() ? json(value) : v;
        text = j.dump();
        return {};
    } catch (const std::exception& e) { return "set " + key + ": " + e.what(); }
}

}   // namespace

std::string ViewerState::setByName(const std::string& key, const std::string& value) {
    bool isMaterial = key.rfind("material.", 0) == 0;
    sg::Scene values;   // only what the key may name
    values.settings = doc.scene.settings;
    values.ambientLight = doc.scene.ambientLight;
    int index = isMaterial ? selectedMaterial(*this) : -1;
    if (isMaterial) {
        if (index < 0 || size_t(index) >= doc.scene.materials.size()) return key + ": the selection has no material of its own";
        values.materials = {doc.scene.materials[size_t(index)]};
        // The texture index is checked against the textures, which are written as PNGs: only
        // carried along when the key names it.
        if (key == "material.diffuseTexture")
            values.textures = doc.scene.textures;
        else
            values.materials[0].diffuseTexture = -1;
    }
    std::string text = assets::serializeSceneJson(values);
    if (std::string err = patch(text, key, pointerOf(key, isMaterial), value); !err.empty()) return err;
    assets::LoadResult r = assets::parseSceneJson(text, "set " + key);
    if (!r.scene) {
        ui.status = "Setting refused: " + r.error;
        return r.error;
    }
    if (isMaterial) {
        sg::Material m = r.scene->materials.at(0);
        if (key != "material.diffuseTexture") m.diffuseTexture = doc.scene.materials[size_t(index)].diffuseTexture;
        setMaterial(index, m);
    } else if (key == "ambientLight") {
        setAmbientLight(r.scene->ambientLight);
    } else {
        return setSettings(r.scene->settings);   // also clears an earlier refusal
    }
    if (ui.status.rfind("Setting refused", 0) == 0) ui.status.clear();
    return {};
}

std::string settingNames(const sg::RenderSettings& a, const sg::RenderSettings& b) {
    sg::Scene sa, sb;
    sa.settings = a;
    sb.settings = b;
    json diff = json::diff(json::parse(assets::serializeSceneJson(sa)), json::parse(assets::serializeSceneJson(sb)));
    std::string names;
    for (const json& op : diff) {
        std::string path = op.value("path", "");
        if (path.rfind("/settings/", 0) != 0) continue;
        std::string name = path.substr(std::string("/settings/").size());
        std::replace(name.begin(), name.end(), '/', '.');
        if (names.find(name) == std::string::npos) names += (names.empty() ? "" : ", ") + name;
    }
    return names;
}

}   // namespace ui
