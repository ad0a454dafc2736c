// extensions.cpp - the glTF extensions the importer honours: the extensionsRequired check (with
// the asset version), and readers for the JSON values inside extension objects (used by the
// validation, the materials and the lights).
#include "gltf_internal.h"

#include <cmath>
#include <iterator>

namespace assets::detail::gltf {

const tinygltf::Value* extensionObject(const tinygltf::ExtensionMap& ext, const char* name) {
    auto it = ext.find(name);
    if (it == ext.end() || !it->second.IsObject()) return nullptr;
    return &it->second;
}
double numberOr(const tinygltf::Value& obj, const char* key, double def) {
    if (!obj.Has(key)) return def;
    const tinygltf::Value& v = obj.Get(key);
    if (!v.IsNumber()) return def;
    double d = v.GetNumberAsDouble();
    return std::isfinite(d) ? d : def;
}
bool numberArray(const tinygltf::Value& obj, const char* key, size_t n, double* out) {
    if (!obj.Has(key)) return false;
    const tinygltf::Value& v = obj.Get(key);
    if (!v.IsArray() || v.ArrayLen() != n) return false;
    for (size_t i = 0; i < n; ++i) {
        const tinygltf::Value& e = v.Get(int(i));
        if (!e.IsNumber() || !std::isfinite(e.GetNumberAsDouble())) return false;
        out[i] = e.GetNumberAsDouble();
    }
    return true;
}
int nodeLight(const tinygltf::Node& n) {
    const tinygltf::Value* e = extensionObject(n.extensions, "KHR_lights_punctual");
    if (!e || !e->Has("light") || !e->Get("light").IsNumber()) return -1;
    double d = e->Get("light").GetNumberAsDouble();
    if (!(d >= 0 && d < 2e9)) return -2;   // invalid marker
    return int(d);
}

namespace {
const char* const kSupported[] = {
    "KHR_materials_unlit", "KHR_texture_transform",  "KHR_lights_punctual",  "KHR_materials_pbrSpecularGlossiness", "KHR_materials_emissive_strength",
    "KHR_materials_ior",   "KHR_materials_specular", "KHR_mesh_quantization"};   // quantized attributes: any component type is read
}   // namespace

bool honouredExtension(const std::string& ext) {
    return std::any_of(std::begin(kSupported), std::end(kSupported), [&](const char* s) { return ext == s; });
}

std::string checkRequiredExtensions(const tinygltf::Model& model) {
    for (const std::string& ext : model.extensionsRequired)
        if (!honouredExtension(ext)) return "requires the unsupported extension " + ext;
    if (model.asset.version.rfind("2.", 0) != 0) return "glTF version '" + model.asset.version + "' is not 2.x";
    return {};
}

}   // namespace assets::detail::gltf
