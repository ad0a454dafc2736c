// scene_json_write.cpp - the native scene file's writer: sg::Scene -> JSON text (every table
// row of the settings, cameras, lights and materials; meshes inline; textures as embedded
// PNGs), numbers written as the shortest text that reads back to the same float. The format is
// described in scene_json.cpp.
#include "assets/scene_io.h"

#include "assets/files.h"
#include "assets/image_io.h"
#include "scenegraph/params.h"
#include "scenegraph/setting_names.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace fs = std::filesystem;
using nlohmann::json;

#include "scene_json_internal.h"

namespace assets {

using namespace scene_json;

namespace {

// --- writing ----------------------------------------------------------------------------------

json vecJ(const sg::vec3& v) { return json::array({v.x, v.y, v.z}); }
json matJ(const sg::mat4& m) {
    json a = json::array();
    for (int i = 0; i < 16; ++i) a.push_back(m[i / 4][i % 4]);
    return a;
}
template <class T, int N>
json flat(const std::vector<T>& v) {
    json a = json::array();
    for (const T& x : v)
        for (int c = 0; c < N; ++c) {
            if constexpr (N == 1)
                a.push_back(x);
            else
                a.push_back(x[c]);
        }
    return a;
}

// Skin influences and morph targets of a mesh (only what it has).
void deformationJ(const sg::Mesh& m, json& mj) {
    if (!m.joints0.empty()) mj["joints0"] = flat<sg::u16vec4, 4>(m.joints0);
    if (!m.weights0.empty()) mj["weights0"] = flat<sg::vec4, 4>(m.weights0);
    if (!m.joints1.empty()) mj["joints1"] = flat<sg::u16vec4, 4>(m.joints1);
    if (!m.weights1.empty()) mj["weights1"] = flat<sg::vec4, 4>(m.weights1);
    if (!m.morphTargets.empty()) {
        json targets = json::array();
        for (const sg::MorphTarget& t : m.morphTargets) {
            json tj = json::object();
            if (!t.positions.empty()) tj["positions"] = flat<sg::vec3, 3>(t.positions);
            if (!t.normals.empty()) tj["normals"] = flat<sg::vec3, 3>(t.normals);
            if (!t.tangents.empty()) tj["tangents"] = flat<sg::vec3, 3>(t.tangents);
            targets.push_back(std::move(tj));
        }
        mj["morphTargets"] = std::move(targets);
    }
    if (!m.morphWeights.empty()) mj["morphWeights"] = m.morphWeights;
}

json implicitJ(const sg::ImplicitShape& s) {
    json j = {{"type", sg::toString(s.type)}};
    switch (s.type) {
    case sg::ImplicitType::Plane: j["planeHalfSize"] = s.planeHalfSize; break;
    case sg::ImplicitType::Sphere: j["radius"] = s.radius; break;
    case sg::ImplicitType::Box: j["halfExtents"] = vecJ(s.halfExtents); break;
    case sg::ImplicitType::Cylinder:
    case sg::ImplicitType::Cone:
        j["radius"] = s.radius;
        j["halfHeight"] = s.halfHeight;
        break;
    case sg::ImplicitType::Torus:
        j["majorRadius"] = s.majorRadius;
        j["minorRadius"] = s.minorRadius;
        break;
    case sg::ImplicitType::Quadric:
        j["quadric"] = matJ(s.quadric);
        j["bounds"] = {vecJ(s.quadricBounds.min), vecJ(s.quadricBounds.max)};
        break;
    }
    // Keep the parameters of the other types too, so switching type in the UI round-trips.
    j["radius"] = s.radius;
    j["halfExtents"] = vecJ(s.halfExtents);
    j["halfHeight"] = s.halfHeight;
    j["majorRadius"] = s.majorRadius;
    j["minorRadius"] = s.minorRadius;
    j["planeHalfSize"] = s.planeHalfSize;
    j["quadric"] = matJ(s.quadric);
    j["bounds"] = {vecJ(s.quadricBounds.min), vecJ(s.quadricBounds.max)};
    return j;
}

// Every row of T's parameter table into `obj` (a dotted key makes nested objects).
template <class T>
void writeParams(json& obj, const T& object) {
    for (const sg::Param<T>& row : sg::params<T>()) {
        json* dst = &obj;
        std::string_view key = row.key;
        for (size_t dot; (dot = key.find('.')) != std::string_view::npos; key.remove_prefix(dot + 1)) dst = &(*dst)[std::string(key.substr(0, dot))];
        json& out = (*dst)[std::string(key)];
        std::visit(
            [&](const auto& v) {
                if constexpr (std::is_same_v<std::decay_t<decltype(v)>, sg::vec3>)
                    out = vecJ(v);
                else
                    out = v;
            },
            row.get(object));
    }
}

json payloadJ(const sg::Payload& p) {
    json j;
    std::visit(
        [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, sg::MeshInstance>) {
                j["mesh"] = {{"mesh", v.mesh}, {"material", v.material}};
                if (v.skin >= 0) j["mesh"]["skin"] = v.skin;
                if (!v.weights.empty()) j["mesh"]["weights"] = v.weights;
            } else if constexpr (std::is_same_v<T, sg::Camera>) {
                const sg::Projection& pr = v.projection;
                json c = json::object();
                writeParams(c, pr);
                c["frustum"] = {pr.left, pr.right, pr.bottom, pr.top};
                c["focusDistance"] = v.focusDistance;
                j["camera"] = c;
            } else if constexpr (std::is_same_v<T, sg::Light>) {
                json l = json::object();
                writeParams(l, v);
                j["light"] = l;
            } else if constexpr (std::is_same_v<T, sg::ImplicitPayload>) {
                json s = implicitJ(v.shape);
                s["material"] = v.material;
                j["implicit"] = s;
            } else if constexpr (std::is_same_v<T, sg::CsgPayload>) {
                j["csg"] = {{"op", sg::toString(v.csg.op)}, {"material", v.material}};
            } else if constexpr (std::is_same_v<T, sg::ParametricPayload>) {
                std::vector<sg::vec3> pts(v.surface.control.begin(), v.surface.control.end());
                j["parametric"] = {{"type", sg::toString(v.surface.type)},
                                   {"majorRadius", v.surface.majorRadius},
                                   {"minorRadius", v.surface.minorRadius},
                                   {"control", flat<sg::vec3, 3>(pts)},
                                   {"material", v.material}};
            } else if constexpr (std::is_same_v<T, sg::GridPayload>) {
                if (v.grid)
                    j["grid"] = {{"dims", {v.grid->dims.x, v.grid->dims.y, v.grid->dims.z}},
                                 {"values", v.grid->values},
                                 {"iso", v.grid->isoValue},
                                 {"bounds", {vecJ(v.grid->bounds.min), vecJ(v.grid->bounds.max)}},
                                 {"material", v.material}};
            }
        },
        p);
    return j;
}

// Pretty printer: objects one key per line, arrays of plain values on one line, floats in
// their shortest form that reads back to the same float (the scene stores floats). "Reads
// back" as the reader reads it: the JSON parser makes a double, the scene takes its float
// (not strtof's direct rounding, which could differ for a decimal a hair from halfway between
// two floats); 9 significant digits always do.
void appendNumber(std::string& out, double d) {
    float f = float(d);
    char buf[32];
    for (int prec = 6; prec <= 9; ++prec) {
        std::snprintf(buf, sizeof buf, "%.*g", prec, double(f));
        if (float(std::strtod(buf, nullptr)) == f) break;
    }
    std::string s = buf;
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";   // keep it a float in JSON terms
    out += s;
}

void pretty(std::string& out, const json& j, int indent) {
    auto pad = [&](int n) { out.append(size_t(n) * 2, ' '); };
    switch (j.type()) {
    case json::value_t::object: {
        if (j.empty()) {
            out += "{}";
            return;
        }
        out += "{\n";
        size_t i = 0;
        for (auto it = j.begin(); it != j.end(); ++it, ++i) {
            pad(indent + 1);
            out += json(it.key()).dump();
            out += ": ";
            pretty(out, it.value(), indent + 1);
            out += i + 1 < j.size() ? ",\n" : "\n";
        }
        pad(indent);
        out += "}";
        return;
    }
    case json::value_t::array: {
        bool flatArray = std::all_of(j.begin(), j.end(), [](const json& e) { return e.is_primitive(); });
        if (flatArray) {
            out += "[";
            for (size_t i = 0; i < j.size(); ++i) {
                if (i) out += ", ";
                pretty(out, j[i], indent);
            }
            out += "]";
            return;
        }
        out += "[\n";
        for (size_t i = 0; i < j.size(); ++i) {
            pad(indent + 1);
            pretty(out, j[i], indent + 1);
            out += i + 1 < j.size() ? ",\n" : "\n";
        }
        pad(indent);
        out += "]";
        return;
    }
    case json::value_t::number_float: appendNumber(out, j.get<double>()); return;
    default: out += j.dump(); return;
    }
}

// The JSON pointer of the first number that is not finite ("" when there is none), and which.
std::string findNonFinite(const json& j, const std::string& path, std::string& what) {
    if (j.is_number_float()) {
        const double d = j.get<double>();
        if (std::isfinite(d)) return {};
        what = std::isnan(d) ? "NaN" : d > 0 ? "+infinity" : "-infinity";
        return path.empty() ? "/" : path;
    }
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end(); ++it)
            if (std::string at = findNonFinite(it.value(), path + "/" + it.key(), what); !at.empty()) return at;
    } else if (j.is_array()) {
        for (size_t i = 0; i < j.size(); ++i)
            if (std::string at = findNonFinite(j[i], path + "/" + std::to_string(i), what); !at.empty()) return at;
    }
    return {};
}

json sceneJson(const sg::Scene& s) {
    json j;
    j["format"] = "sceneviewer";
    j["version"] = 1;
    j["name"] = s.name;
    j["settings"] = json::object();
    writeParams(j["settings"], s.settings);   // aaRate too: kept while AA is off, so switching it back on restores it
    j["textures"] = json::array();
    for (const auto& t : s.textures) {
        json tj = {{"name", t->name}, {"wrapS", sg::nameOf(t->wrapS)}, {"wrapT", sg::nameOf(t->wrapT)}, {"filter", sg::nameOf(t->filter)}};
        if (!t->srgb) tj["srgb"] = false;
        std::string png;
        encodePng(t->width, t->height, t->rgba.data(), png);
        tj["png"] = base64Encode(png);
        j["textures"].push_back(tj);
    }
    j["materials"] = json::array();
    for (const auto& m : s.materials) {
        json mj = {{"name", m.name},
                   {"diffuseTexture", m.diffuseTexture},
                   {"emissiveTexture", m.emissiveTexture},
                   {"occlusionTexture", m.occlusionTexture},
                   {"normalTexture", m.normalTexture},
                   {"metallicRoughnessTexture", m.metallicRoughnessTexture}};
        writeParams(mj, m);
        j["materials"].push_back(mj);
        if (m.uv1Maps) {
            json names = json::array();
            for (const MapBitName& e : kMapBitNames)
                if (m.uv1Maps & e.bit) names.push_back(e.name);
            j["materials"].back()["uv1Maps"] = names;
        }
    }
    j["meshes"] = json::array();
    for (const auto& m : s.meshes) {
        const char* mode = m->mode == sg::PrimitiveMode::Triangles ? "triangles" : m->mode == sg::PrimitiveMode::Lines ? "lines" : "points";
        json mj = {{"name", m->name}, {"mode", mode}, {"positions", flat<sg::vec3, 3>(m->positions)}, {"indices", m->indices}};
        if (!m->normals.empty()) mj["normals"] = flat<sg::vec3, 3>(m->normals);
        if (!m->uv0.empty()) mj["uv0"] = flat<sg::vec2, 2>(m->uv0);
        if (!m->uv1.empty()) mj["uv1"] = flat<sg::vec2, 2>(m->uv1);
        if (!m->colors.empty()) mj["colors"] = flat<sg::vec4, 4>(m->colors);
        if (!m->tangents.empty()) mj["tangents"] = flat<sg::vec4, 4>(m->tangents);
        deformationJ(*m, mj);
        j["meshes"].push_back(std::move(mj));
    }
    const auto& order = s.depthFirstOrder();
    std::vector<int64_t> indexOf(s.idCapacity(), -1);
    for (size_t i = 0; i < order.size(); ++i) indexOf[order[i]] = int64_t(i);
    j["nodes"] = json::array();
    for (sg::NodeId id : order) {
        const sg::Node& n = s.node(id);
        json nj = payloadJ(n.payload);
        nj["name"] = n.name;
        if (n.parent != sg::kNoNode) nj["parent"] = indexOf[n.parent];
        if (!n.visible) nj["visible"] = false;
        if (n.local.mode == sg::LocalTransform::Mode::Matrix) {
            nj["transform"] = {{"matrix", matJ(n.local.matrix)}};
        } else {
            const sg::quat& q = n.local.rotation;
            nj["transform"] = {{"translation", vecJ(n.local.translation)}, {"rotation", {q.x, q.y, q.z, q.w}}, {"scale", vecJ(n.local.scale)}};
        }
        j["nodes"].push_back(std::move(nj));
    }
    if (!s.skins.empty()) {
        j["skins"] = json::array();
        auto index = [&](sg::NodeId n) { return s.valid(n) && indexOf[n] >= 0 ? json(indexOf[n]) : json(nullptr); };
        for (const sg::Skin& sk : s.skins) {
            json joints = json::array(), ibm = json::array();
            for (size_t i = 0; i < sk.joints.size(); ++i) {
                joints.push_back(index(sk.joints[i]));   // null: a joint no longer in the scene
                const sg::mat4 m = i < sk.inverseBind.size() ? sk.inverseBind[i] : sg::mat4(1.0f);
                for (int c = 0; c < 16; ++c) ibm.push_back(m[c / 4][c % 4]);
            }
            j["skins"].push_back({{"name", sk.name}, {"joints", joints}, {"inverseBindMatrices", ibm}, {"skeleton", index(sk.skeleton)}});
        }
    }
    j["activeCamera"] = s.valid(s.activeCamera) ? json(indexOf[s.activeCamera]) : json(nullptr);
    return j;
}

}   // namespace

// A NaN or an infinity is refused, not written: JSON has no spelling for it (what printf gives,
// "nan", makes a file nobody can open), and writing null to read back as a default would
// replace the user's value with another one without a word, in a file that then looks fine.
// Refused, the save changes nothing on disk and the error names the value, so it can be fixed.
std::string serializeSceneJson(const sg::Scene& s, std::string* error) {
    const json j = sceneJson(s);
    std::string what;
    if (std::string at = findNonFinite(j, "", what); !at.empty()) {
        if (error) *error = at + ": " + what + " cannot be saved (a scene file holds finite numbers only)";
        return {};
    }
    std::string out;
    pretty(out, j, 0);
    return out + "\n";
}

std::string saveSceneJson(const sg::Scene& scene, const fs::path& path, bool overwrite) {
    std::string error;
    std::string text = serializeSceneJson(scene, &error);
    if (!error.empty()) return path.string() + ": " + error;
    return writeFileAtomic(path, text, overwrite);
}

}   // namespace assets
