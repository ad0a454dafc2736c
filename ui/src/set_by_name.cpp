// set_by_name.cpp - ViewerState::setByName: one parameter by its key in the tables of
// scenegraph/params.h (the automation's `set KEY VALUE`). The key names the table: a render
// setting as is (fog.mode), `material.KEY`, `light.KEY` or `camera.KEY`; the value is parsed by
// sg::parseParamText and checked against the row's range (and RenderSettings::validate), then
// applied through the same setter the panels use, as one undoable edit.
#include "ui/viewer_state.h"

#include "scenegraph/params.h"

namespace ui {

namespace {

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

template <class T>
std::string unknownKey(const std::string& key, const std::string& prefix) {
    std::string names;
    for (const sg::Param<T>& p : sg::params<T>()) names += (names.empty() ? "" : ", ") + prefix + std::string(p.key);
    return "unknown setting '" + key + "' (known: " + names + ")";
}

// `object` with `key` set from `value`; "" or the refusal.
template <class T>
std::string setIn(T& object, const std::string& key, const std::string& prefix, const std::string& value) {
    const sg::Param<T>* p = sg::findParam<T>(std::string_view(key).substr(prefix.size()));
    if (!p) return unknownKey<T>(key, prefix);
    return sg::setParamFromText(object, *p, value);
}

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// A material's texture references: indices into the scene's textures, -1 = none (not table
// rows: their range is the scene's texture count).
int* textureSlot(sg::Material& m, std::string_view key) {
    if (key == "diffuseTexture") return &m.diffuseTexture;
    if (key == "emissiveTexture") return &m.emissiveTexture;
    if (key == "occlusionTexture") return &m.occlusionTexture;
    if (key == "normalTexture") return &m.normalTexture;
    if (key == "metallicRoughnessTexture") return &m.metallicRoughnessTexture;
    return nullptr;
}

}   // namespace

std::string ViewerState::setByName(const std::string& key, const std::string& value) {
    auto refused = [&](const std::string& err) {
        ui.status = "Setting refused: " + err;
        return err;
    };
    if (startsWith(key, "material.")) {
        int index = selectedMaterial(*this);
        if (index < 0 || size_t(index) >= doc.scene.materials.size()) return key + ": the selection has no material of its own";
        sg::Material m = doc.scene.materials[size_t(index)];
        if (int* slot = textureSlot(m, std::string_view(key).substr(9))) {
            std::string err;
            std::optional<sg::ParamValue> v = sg::parseParamText(sg::ParamKind::Int, value, err);
            const int last = int(doc.scene.textures.size()) - 1;
            if (!v || std::get<int>(*v) < -1 || std::get<int>(*v) > last)
                return refused(key + ": expected a texture index in [-1, " + std::to_string(last) + "] (-1 = none)");
            *slot = std::get<int>(*v);
        } else if (!sg::findParam<sg::Material>(std::string_view(key).substr(9))) {
            return unknownKey<sg::Material>(key, "material.");
        } else if (std::string err = setIn(m, key, "material.", value); !err.empty()) {
            return refused(err);
        }
        setMaterial(index, m);
    } else if (startsWith(key, "light.")) {
        if (!doc.scene.valid(doc.selected) || !std::holds_alternative<sg::Light>(doc.scene.node(doc.selected).payload))
            return key + ": the selection is not a light";
        if (!sg::findParam<sg::Light>(std::string_view(key).substr(6))) return unknownKey<sg::Light>(key, "light.");
        sg::Payload payload = doc.scene.node(doc.selected).payload;
        if (std::string err = setIn(std::get<sg::Light>(payload), key, "light.", value); !err.empty()) return refused(err);
        setPayload(doc.selected, payload);
    } else if (startsWith(key, "camera.")) {
        if (!sg::findParam<sg::Projection>(std::string_view(key).substr(7))) return unknownKey<sg::Projection>(key, "camera.");
        sg::Projection p = projection();
        if (std::string err = setIn(p, key, "camera.", value); !err.empty()) return refused(err);
        if (!(p.zNear < p.zFar)) return refused("camera needs near < far");
        setProjection(p);
    } else {
        if (!sg::findParam<sg::RenderSettings>(key)) return unknownKey<sg::RenderSettings>(key, "");
        sg::RenderSettings s = doc.scene.settings;
        if (std::string err = setIn(s, key, "", value); !err.empty()) return refused(err);
        return setSettings(s);   // validates the rules between values; clears an earlier refusal
    }
    if (ui.status.rfind("Setting refused", 0) == 0) ui.status.clear();
    return {};
}

}   // namespace ui
