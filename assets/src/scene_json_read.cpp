// scene_json_read.cpp - the native scene file's reader: JSON text -> sg::Scene, every value
// checked (kinds, ranges from the parameter tables, indices, sizes against the limits), an error
// naming the JSON path of the first bad value. The format is described in scene_json.cpp.
#include "assets/scene_io.h"

#include "assets/files.h"
#include "assets/image_io.h"
#include "scenegraph/params.h"
#include "scenegraph/setting_names.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace fs = std::filesystem;
using nlohmann::json;

#include "scene_json_internal.h"

namespace assets {

using namespace scene_json;

namespace {

struct ParseError {
    std::string path;   // JSON pointer, e.g. /nodes/3/transform
    std::string message;
};

// Deepest bracket nesting outside strings; stops early past `limit`.
int nestingDepth(std::string_view text, int limit) {
    int depth = 0, maxDepth = 0;
    bool inString = false, escape = false;
    for (char c : text) {
        if (inString) {
            if (escape)
                escape = false;
            else if (c == '\\')
                escape = true;
            else if (c == '"')
                inString = false;
            continue;
        }
        if (c == '"')
            inString = true;
        else if (c == '[' || c == '{') {
            maxDepth = std::max(maxDepth, ++depth);
            if (maxDepth > limit) return maxDepth;
        } else if (c == ']' || c == '}')
            --depth;
    }
    return maxDepth;
}

// Relative path inside `base`: no absolute paths, no "..", regular files only.
std::string confinedPath(const fs::path& base, const std::string& rel, fs::path& out) {
    fs::path p(rel);
    if (rel.empty()) return "empty file reference";
    if (p.is_absolute()) return "absolute file references are not allowed ('" + rel + "')";
    for (const auto& part : p)
        if (part == "..") return "file references must stay inside the scene's folder ('" + rel + "')";
    out = base / p;
    std::error_code ec;
    fs::path canonBase = fs::weakly_canonical(base, ec), canon = fs::weakly_canonical(out, ec);
    auto mismatch = std::mismatch(canonBase.begin(), canonBase.end(), canon.begin(), canon.end());
    if (mismatch.first != canonBase.end()) return "file reference leaves the scene's folder through a link ('" + rel + "')";
    return {};
}

// --- reading --------------------------------------------------------------------------------

class Reader {
public:
    Reader(const json& root, fs::path baseDir, std::vector<std::string>& warnings) : m_root(root), m_base(std::move(baseDir)), m_warnings(warnings) {}

    sg::Scene read();

private:
    [[noreturn]] void fail(const std::string& path, const std::string& msg) { throw ParseError{path, msg}; }

    const json& member(const json& obj, const std::string& path, const char* key) {
        if (!obj.is_object()) fail(path, "expected an object");
        auto it = obj.find(key);
        if (it == obj.end()) fail(path, std::string("missing \"") + key + "\"");
        return *it;
    }
    const json* optional(const json& obj, const char* key) {
        auto it = obj.find(key);
        return it == obj.end() || it->is_null() ? nullptr : &*it;
    }
    // The float a number of the file stands for, as the writer meant it: every finite float,
    // up to the largest (3.40282347e+38, which reads as a double a hair above FLT_MAX and
    // rounds to it), comes back; a number that would round to infinity is refused.
    float toFloat(double d, const std::string& path) {
        constexpr double kRoundsToInfinity = 0x1.ffffffp+127;   // halfway from FLT_MAX to 2^128
        if (!std::isfinite(d) || std::abs(d) >= kRoundsToInfinity) fail(path, "number is not finite as a float (beyond +-3.40282347e+38)");
        constexpr float kMax = std::numeric_limits<float>::max();
        if (std::abs(d) > double(kMax)) return d > 0 ? kMax : -kMax;   // what rounding gives, without an out-of-range conversion
        return float(d);
    }
    float number(const json& v, const std::string& path) {
        if (!v.is_number()) fail(path, "expected a number");
        return toFloat(v.get<double>(), path);
    }
    int integer(const json& v, const std::string& path, long long lo, long long hi) {
        if (!v.is_number_integer()) fail(path, "expected an integer");
        long long x = v.get<long long>();
        if (x < lo || x > hi) fail(path, "value " + std::to_string(x) + " out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return int(x);
    }
    bool boolean(const json& v, const std::string& path) {
        if (!v.is_boolean()) fail(path, "expected true or false");
        return v.get<bool>();
    }
    std::string string(const json& v, const std::string& path) {
        if (!v.is_string()) fail(path, "expected a string");
        return v.get<std::string>();
    }
    template <int N>
    glm::vec<N, float> vec(const json& v, const std::string& path) {
        if (!v.is_array() || v.size() != N) fail(path, "expected " + std::to_string(N) + " numbers");
        glm::vec<N, float> out;
        for (int i = 0; i < N; ++i) out[i] = number(v[i], path + "/" + std::to_string(i));
        return out;
    }
    sg::mat4 mat(const json& v, const std::string& path) {
        if (!v.is_array() || v.size() != 16) fail(path, "expected 16 numbers (column-major 4x4)");
        sg::mat4 m;
        for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = number(v[i], path + "/" + std::to_string(i));
        return m;
    }
    template <class E>
    E enumValue(const json& v, const std::string& path, const char* valid) {
        std::string s = string(v, path);
        E e{};
        if (!sg::parse(s, e)) fail(path, "unknown value \"" + s + "\" (valid: " + valid + ")");
        return e;
    }
    // A value named in its table (setting_names.h); the error lists the table's names.
    template <class E>
    E named(const json& v, const std::string& path) {
        std::string s = string(v, path);
        E e{};
        if (!sg::parseName(s, e)) fail(path, "unknown value \"" + s + "\" (valid: " + sg::nameList<E>() + ")");
        return e;
    }
    // Every row of T's parameter table (scenegraph/params.h) present in `obj`: its kind and
    // range checked, the error naming the JSON path; absent keys leave `object` alone.
    template <class T>
    void readParams(const json& obj, const std::string& p, T& object) {
        if (!obj.is_object()) fail(p, "expected an object");
        for (const sg::Param<T>& row : sg::params<T>()) {
            const json* v = &obj;
            std::string path = p;
            std::string_view key = row.key;
            while (v) {
                const size_t dot = key.find('.');
                const std::string part(key.substr(0, dot));
                if (!v->is_object()) fail(path, "expected an object");
                v = optional(*v, part.c_str());
                path += "/" + part;
                if (dot == std::string_view::npos) break;
                key.remove_prefix(dot + 1);
            }
            if (!v) continue;
            sg::ParamValue value;
            switch (row.kind) {
            case sg::ParamKind::Bool: value = boolean(*v, path); break;
            case sg::ParamKind::Int: value = integer(*v, path, (long long)row.min, (long long)row.max); break;
            case sg::ParamKind::Float: value = number(*v, path); break;
            case sg::ParamKind::Color: value = sg::vec3(vec<3>(*v, path)); break;
            case sg::ParamKind::Choice:
            case sg::ParamKind::Text: value = string(*v, path); break;
            }
            if (row.kind == sg::ParamKind::Choice) {
                std::string names;
                for (const sg::ParamChoice& c : row.choices) names += (names.empty() ? "" : ", ") + std::string(c.name);
                if (!row.set(object, value)) fail(path, "unknown value \"" + std::get<std::string>(value) + "\" (valid: " + names + ")");
                continue;
            }
            if (std::string err = sg::checkValue(row, value); !err.empty()) {
                std::string_view why = std::string_view(err).substr(row.key.size());
                while (!why.empty() && (why.front() == ':' || why.front() == ' ')) why.remove_prefix(1);
                fail(path, std::string(why));
            }
            row.set(object, value);
        }
    }
    // Optional field helpers: leave `dst` alone when the key is absent.
    void optFloat(const json& o, const std::string& p, const char* k, float& dst) {
        if (auto* v = optional(o, k)) dst = number(*v, p + "/" + k);
    }
    void optBool(const json& o, const std::string& p, const char* k, bool& dst) {
        if (auto* v = optional(o, k)) dst = boolean(*v, p + "/" + k);
    }
    void optVec3(const json& o, const std::string& p, const char* k, sg::vec3& dst) {
        if (auto* v = optional(o, k)) dst = vec<3>(*v, p + "/" + k);
    }
    void optInt(const json& o, const std::string& p, const char* k, int& dst, long long lo, long long hi) {
        if (auto* v = optional(o, k)) dst = integer(*v, p + "/" + k, lo, hi);
    }

    template <class T, int N>
    void floatArray(const json& o, const std::string& p, const char* k, std::vector<T>& dst, size_t maxElems) {
        const json* v = optional(o, k);
        if (!v) return;
        std::string path = p + "/" + k;
        if (!v->is_array() || v->size() % N != 0) fail(path, "expected a flat array of " + std::to_string(N) + "-component values");
        if (v->size() / N > maxElems) fail(path, "too many elements (" + std::to_string(v->size() / N) + ")");
        dst.resize(v->size() / N);
        for (size_t i = 0; i < dst.size(); ++i)
            for (int c = 0; c < N; ++c) {
                const json& x = (*v)[i * N + c];
                if (!x.is_number()) fail(path + "/" + std::to_string(i * N + c), "expected a number");
                const float f = toFloat(x.get<double>(), path + "/" + std::to_string(i * N + c));
                if constexpr (N == 1)
                    dst[i] = f;
                else
                    dst[i][c] = f;
            }
    }

    void readSettings(const json& j, const std::string& p, sg::RenderSettings& s);
    sg::Material readMaterial(const json& j, const std::string& p, size_t textureCount);
    std::shared_ptr<sg::Texture> readTexture(const json& j, const std::string& p);
    std::shared_ptr<sg::Mesh> readMesh(const json& j, const std::string& p);
    void readDeformation(const json& j, const std::string& p, sg::Mesh& m);
    void readJoints(const json& o, const std::string& p, const char* k, std::vector<sg::u16vec4>& dst);
    sg::Skin readSkin(const json& j, const std::string& p, const std::vector<sg::NodeId>& idOf);
    sg::Payload readPayload(const json& j, const std::string& p, const sg::Scene& s);
    sg::LocalTransform readTransform(const json& j, const std::string& p);
    sg::ImplicitShape readImplicit(const json& j, const std::string& p);

    const json& m_root;
    fs::path m_base;
    std::vector<std::string>& m_warnings;
};

void Reader::readSettings(const json& j, const std::string& p, sg::RenderSettings& s) {
    if (!j.is_object()) fail(p, "expected an object");
    // Older files: a bool instead of the culling mode (a "culling" in the same file wins).
    if (auto* v = optional(j, "cullBackFaces")) s.culling = boolean(*v, p + "/cullBackFaces") ? sg::CullMode::On : sg::CullMode::Off;
    readParams(j, p, s);
    std::string err = s.validate();
    if (!err.empty()) fail(p, err);
}

sg::Material Reader::readMaterial(const json& j, const std::string& p, size_t textureCount) {
    if (!j.is_object()) fail(p, "expected an object");
    sg::Material m;
    if (auto* v = optional(j, "name")) m.name = string(*v, p + "/name");
    readParams(j, p, m);
    // The texture references (indices into "textures"), checked against the texture count.
    optInt(j, p, "diffuseTexture", m.diffuseTexture, -1, (long long)textureCount - 1);
    optInt(j, p, "emissiveTexture", m.emissiveTexture, -1, (long long)textureCount - 1);
    optInt(j, p, "occlusionTexture", m.occlusionTexture, -1, (long long)textureCount - 1);
    optInt(j, p, "normalTexture", m.normalTexture, -1, (long long)textureCount - 1);
    optInt(j, p, "metallicRoughnessTexture", m.metallicRoughnessTexture, -1, (long long)textureCount - 1);
    if (const json* v = optional(j, "uv1Maps")) {
        if (!v->is_array()) fail(p + "/uv1Maps", "expected an array of map names");
        for (const json& name : *v) {
            const auto* e = name.is_string() ? findMapBit(name.get<std::string>()) : nullptr;
            if (!e) fail(p + "/uv1Maps", "expected names among emissive, occlusion, metallicRoughness, normal");
            m.uv1Maps |= e->bit;
        }
    }
    return m;
}

std::shared_ptr<sg::Texture> Reader::readTexture(const json& j, const std::string& p) {
    if (!j.is_object()) fail(p, "expected an object");
    ImageLoad img;
    if (auto* f = optional(j, "file")) {
        fs::path full;
        std::string why = confinedPath(m_base, string(*f, p + "/file"), full);
        if (!why.empty()) fail(p + "/file", why);
        img = loadImage(full);
        if (!img.texture) {
            // Recoverable: a missing texture becomes a magenta placeholder and a warning.
            m_warnings.push_back(img.error + " (texture " + p + " replaced by a placeholder)");
            auto t = std::make_shared<sg::Texture>();
            t->width = t->height = 2;
            t->rgba = {255, 0, 255, 255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 0, 255, 255};
            img.texture = t;
        }
        img.texture->sourcePath = string(*f, p + "/file");
    } else if (auto* b = optional(j, "png")) {
        std::string bytes;
        if (!base64Decode(string(*b, p + "/png"), bytes)) fail(p + "/png", "invalid base64");
        img = decodeImage(bytes.data(), bytes.size(), "embedded image");
        if (!img.texture) fail(p + "/png", img.error);
    } else {
        fail(p, "a texture needs \"file\" or \"png\"");
    }
    auto t = img.texture;
    if (auto* v = optional(j, "name")) t->name = string(*v, p + "/name");
    if (auto* v = optional(j, "wrapS")) t->wrapS = named<sg::WrapMode>(*v, p + "/wrapS");
    if (auto* v = optional(j, "wrapT")) t->wrapT = named<sg::WrapMode>(*v, p + "/wrapT");
    if (auto* v = optional(j, "filter")) t->filter = named<sg::FilterMode>(*v, p + "/filter");
    optBool(j, p, "srgb", t->srgb);
    return t;
}

std::shared_ptr<sg::Mesh> Reader::readMesh(const json& j, const std::string& p) {
    if (!j.is_object()) fail(p, "expected an object");
    auto m = std::make_shared<sg::Mesh>();
    if (auto* f = optional(j, "file")) {
        fs::path full;
        std::string rel = string(*f, p + "/file");
        std::string why = confinedPath(m_base, rel, full);
        if (!why.empty()) fail(p + "/file", why);
        std::string ext = full.extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        if (ext == ".json") fail(p + "/file", "a mesh file reference must be a mesh (.obj .off .ply .stl .gltf .glb)");
        LoadResult sub = loadScene(full);
        if (!sub.scene) fail(p + "/file", sub.error);
        for (auto& w : sub.warnings) m_warnings.push_back(w);
        // Merge all meshes of the referenced file (baked with their node transforms).
        const sg::Scene& s = *sub.scene;
        for (sg::NodeId id : s.depthFirstOrder()) {
            auto* mi = std::get_if<sg::MeshInstance>(&s.node(id).payload);
            if (!mi || mi->mesh < 0 || size_t(mi->mesh) >= s.meshes.size()) continue;
            const sg::Mesh& src = *s.meshes[mi->mesh];
            if (src.mode != sg::PrimitiveMode::Triangles) continue;
            sg::mat4 w = s.world(id);
            sg::mat3 n = sg::normalMatrix(w);
            uint32_t base = uint32_t(m->positions.size());
            for (size_t i = 0; i < src.positions.size(); ++i) {
                m->positions.push_back(sg::vec3(w * sg::vec4(src.positions[i], 1.0f)));
                m->normals.push_back(src.normals.empty() ? sg::vec3(0, 1, 0) : glm::normalize(n * src.normals[i]));
                m->uv0.push_back(src.uv0.empty() ? sg::vec2(0.0f) : src.uv0[i]);
            }
            for (uint32_t i : src.indices) m->indices.push_back(base + i);
        }
        m->name = rel;
    } else {
        if (auto* v = optional(j, "mode")) {
            std::string s = string(*v, p + "/mode");
            if (s == "triangles")
                m->mode = sg::PrimitiveMode::Triangles;
            else if (s == "lines")
                m->mode = sg::PrimitiveMode::Lines;
            else if (s == "points")
                m->mode = sg::PrimitiveMode::Points;
            else
                fail(p + "/mode", "unknown mode \"" + s + "\" (valid: triangles, lines, points)");
        }
        floatArray<sg::vec3, 3>(j, p, "positions", m->positions, kMaxVertices);
        floatArray<sg::vec3, 3>(j, p, "normals", m->normals, kMaxVertices);
        floatArray<sg::vec2, 2>(j, p, "uv0", m->uv0, kMaxVertices);
        floatArray<sg::vec2, 2>(j, p, "uv1", m->uv1, kMaxVertices);
        floatArray<sg::vec4, 4>(j, p, "colors", m->colors, kMaxVertices);
        floatArray<sg::vec4, 4>(j, p, "tangents", m->tangents, kMaxVertices);
        readDeformation(j, p, *m);
        if (auto* v = optional(j, "indices")) {
            if (!v->is_array()) fail(p + "/indices", "expected an array of integers");
            if (v->size() > kMaxIndices) fail(p + "/indices", "too many indices");
            m->indices.resize(v->size());
            for (size_t i = 0; i < v->size(); ++i) {
                const json& x = (*v)[i];
                if (!x.is_number_unsigned() || x.get<uint64_t>() > 0xFFFFFFFFull)
                    fail(p + "/indices/" + std::to_string(i), "expected a non-negative 32-bit integer");
                m->indices[i] = uint32_t(x.get<uint64_t>());
            }
        }
        std::string err = m->validate();
        if (!err.empty()) fail(p, err);
    }
    if (auto* v = optional(j, "name")) m->name = string(*v, p + "/name");
    return m;
}

// Skin influences and morph targets of an inline mesh (checked by Mesh::validate).
void Reader::readDeformation(const json& j, const std::string& p, sg::Mesh& m) {
    readJoints(j, p, "joints0", m.joints0);
    readJoints(j, p, "joints1", m.joints1);
    floatArray<sg::vec4, 4>(j, p, "weights0", m.weights0, kMaxVertices);
    floatArray<sg::vec4, 4>(j, p, "weights1", m.weights1, kMaxVertices);
    if (auto* t = optional(j, "morphTargets")) {
        std::string tp = p + "/morphTargets";
        if (!t->is_array()) fail(tp, "expected an array");
        if (t->size() > kMaxMorphTargets) fail(tp, "too many morph targets (" + std::to_string(t->size()) + ")");
        m.morphTargets.resize(t->size());
        for (size_t k = 0; k < t->size(); ++k) {
            std::string kp = tp + "/" + std::to_string(k);
            if (!(*t)[k].is_object()) fail(kp, "expected an object");
            floatArray<sg::vec3, 3>((*t)[k], kp, "positions", m.morphTargets[k].positions, kMaxVertices);
            floatArray<sg::vec3, 3>((*t)[k], kp, "normals", m.morphTargets[k].normals, kMaxVertices);
            floatArray<sg::vec3, 3>((*t)[k], kp, "tangents", m.morphTargets[k].tangents, kMaxVertices);
        }
    }
    floatArray<float, 1>(j, p, "morphWeights", m.morphWeights, kMaxMorphTargets);
}

void Reader::readJoints(const json& o, const std::string& p, const char* k, std::vector<sg::u16vec4>& dst) {
    const json* v = optional(o, k);
    if (!v) return;
    std::string path = p + "/" + k;
    if (!v->is_array() || v->size() % 4 != 0) fail(path, "expected a flat array of 4 joint numbers per vertex");
    if (v->size() / 4 > kMaxVertices) fail(path, "too many elements (" + std::to_string(v->size() / 4) + ")");
    dst.resize(v->size() / 4);
    for (size_t i = 0; i < v->size(); ++i) {
        const json& x = (*v)[i];
        if (!x.is_number_unsigned() || x.get<uint64_t>() > 65535) fail(path + "/" + std::to_string(i), "expected an integer in [0, 65535]");
        dst[i / 4][int(i % 4)] = uint16_t(x.get<uint64_t>());
    }
}

sg::Skin Reader::readSkin(const json& j, const std::string& p, const std::vector<sg::NodeId>& idOf) {
    if (!j.is_object()) fail(p, "expected an object");
    sg::Skin skin;
    if (auto* v = optional(j, "name")) skin.name = string(*v, p + "/name");
    if (auto* v = optional(j, "joints")) {
        if (!v->is_array()) fail(p + "/joints", "expected an array of node indices");
        for (size_t i = 0; i < v->size(); ++i) {
            const json& x = (*v)[i];   // null: a joint that is not in the scene (poses as the identity)
            skin.joints.push_back(x.is_null() ? sg::kNoNode
                                              : idOf[size_t(integer(x, p + "/joints/" + std::to_string(i), 0, (long long)idOf.size() - 1))]);
        }
    }
    std::vector<float> ibm;
    floatArray<float, 1>(j, p, "inverseBindMatrices", ibm, 16 * kMaxVertices);
    if (ibm.size() != 16 * skin.joints.size())
        fail(p + "/inverseBindMatrices",
             "expected 16 numbers per joint (" + std::to_string(16 * skin.joints.size()) + "), found " + std::to_string(ibm.size()));
    skin.inverseBind.resize(skin.joints.size());
    for (size_t i = 0; i < ibm.size(); ++i) skin.inverseBind[i / 16][int(i % 16 / 4)][int(i % 4)] = ibm[i];
    if (auto* v = optional(j, "skeleton")) skin.skeleton = idOf[size_t(integer(*v, p + "/skeleton", 0, (long long)idOf.size() - 1))];
    return skin;
}

sg::LocalTransform Reader::readTransform(const json& j, const std::string& p) {
    if (!j.is_object()) fail(p, "expected an object");
    if (auto* m = optional(j, "matrix")) {
        sg::mat4 mm = mat(*m, p + "/matrix");
        if (mm[0][3] != 0 || mm[1][3] != 0 || mm[2][3] != 0 || mm[3][3] != 1) fail(p + "/matrix", "must be affine (last row 0 0 0 1)");
        return sg::LocalTransform::fromMatrix(mm);
    }
    sg::LocalTransform t;
    optVec3(j, p, "translation", t.translation);
    if (auto* r = optional(j, "rotation")) {
        sg::vec4 q = vec<4>(*r, p + "/rotation");
        float len = glm::length(q);
        if (len < 1e-6f) fail(p + "/rotation", "quaternion has zero length");
        t.rotation = sg::quat(q.w, q.x, q.y, q.z);
        if (std::abs(len - 1.0f) > 1e-3f) t.rotation = glm::normalize(t.rotation);
    }
    optVec3(j, p, "scale", t.scale);
    return t;
}

sg::ImplicitShape Reader::readImplicit(const json& j, const std::string& p) {
    sg::ImplicitShape s;
    s.type = enumValue<sg::ImplicitType>(member(j, p, "type"), p + "/type", "plane, sphere, box, cylinder, cone, torus, quadric");
    optFloat(j, p, "radius", s.radius);
    optVec3(j, p, "halfExtents", s.halfExtents);
    optFloat(j, p, "halfHeight", s.halfHeight);
    optFloat(j, p, "majorRadius", s.majorRadius);
    optFloat(j, p, "minorRadius", s.minorRadius);
    optFloat(j, p, "planeHalfSize", s.planeHalfSize);
    if (auto* q = optional(j, "quadric")) s.quadric = mat(*q, p + "/quadric");
    if (auto* b = optional(j, "bounds")) {
        if (!b->is_array() || b->size() != 2) fail(p + "/bounds", "expected [[min], [max]]");
        s.quadricBounds.min = vec<3>((*b)[0], p + "/bounds/0");
        s.quadricBounds.max = vec<3>((*b)[1], p + "/bounds/1");
    }
    auto positive = [&](float v, const char* what) {
        if (!(v > 0.0f) || v > 1e6f) fail(p + "/" + what, "must be positive and below 1e6");
    };
    positive(s.radius, "radius");
    positive(s.halfHeight, "halfHeight");
    positive(s.majorRadius, "majorRadius");
    positive(s.minorRadius, "minorRadius");
    positive(s.planeHalfSize, "planeHalfSize");
    for (int a = 0; a < 3; ++a) positive(s.halfExtents[a], "halfExtents");
    if (s.quadricBounds.empty()) fail(p + "/bounds", "min must not exceed max");
    return s;
}

sg::Payload Reader::readPayload(const json& j, const std::string& p, const sg::Scene& s) {
    static const char* kinds[] = {"mesh", "camera", "light", "implicit", "csg", "parametric", "grid"};
    const char* found = nullptr;
    for (const char* k : kinds)
        if (j.contains(k)) {
            if (found) fail(p, std::string("a node has at most one payload (found \"") + found + "\" and \"" + k + "\")");
            found = k;
        }
    for (auto it = j.begin(); it != j.end(); ++it) {
        static const char* known[] = {"name", "parent", "visible", "transform", "mesh", "camera", "light", "implicit", "csg", "parametric", "grid"};
        if (std::find_if(std::begin(known), std::end(known), [&](const char* k) { return it.key() == k; }) == std::end(known))
            fail(p + "/" + it.key(), "unknown node field (valid payloads: mesh, camera, light, implicit, csg, parametric, grid)");
    }
    if (!found) return std::monostate{};
    std::string kp = p + "/" + found;
    const json& v = j[found];
    if (!v.is_object()) fail(kp, "expected an object");
    long long maxMat = (long long)s.materials.size() - 1;
    std::string k = found;
    if (k == "mesh") {
        sg::MeshInstance mi;
        mi.mesh = integer(member(v, kp, "mesh"), kp + "/mesh", 0, (long long)s.meshes.size() - 1);
        optInt(v, kp, "material", mi.material, -1, maxMat);
        optInt(v, kp, "skin", mi.skin, -1, (long long)s.skins.size() - 1);
        floatArray<float, 1>(v, kp, "weights", mi.weights, kMaxMorphTargets);
        return mi;
    }
    if (k == "camera") {
        sg::Camera c;
        sg::Projection& pr = c.projection;
        readParams(v, kp, pr);
        if (auto* fr = optional(v, "frustum")) {
            sg::vec4 f = vec<4>(*fr, kp + "/frustum");
            pr.left = f[0];
            pr.right = f[1];
            pr.bottom = f[2];
            pr.top = f[3];
        }
        optFloat(v, kp, "focusDistance", c.focusDistance);
        if (!(pr.zFar > pr.zNear)) fail(kp, "needs 0 < near < far");
        if (pr.useFrustum && (!(pr.right > pr.left) || !(pr.top > pr.bottom))) fail(kp + "/frustum", "needs left < right and bottom < top");
        return c;
    }
    if (k == "light") {
        sg::Light l;
        readParams(v, kp, l);
        return l;
    }
    if (k == "implicit") {
        sg::ImplicitPayload ip;
        ip.shape = readImplicit(v, kp);
        optInt(v, kp, "material", ip.material, -1, maxMat);
        return ip;
    }
    if (k == "csg") {
        sg::CsgPayload cp;
        cp.csg.op = enumValue<sg::CsgOp>(member(v, kp, "op"), kp + "/op", "union, intersection, difference");
        optInt(v, kp, "material", cp.material, -1, maxMat);
        return cp;
    }
    if (k == "parametric") {
        sg::ParametricPayload pp;
        pp.surface.type = enumValue<sg::ParametricType>(member(v, kp, "type"), kp + "/type", "torus, bezier");
        optFloat(v, kp, "majorRadius", pp.surface.majorRadius);
        optFloat(v, kp, "minorRadius", pp.surface.minorRadius);
        if (auto* c = optional(v, "control")) {
            std::vector<sg::vec3> pts;
            floatArray<sg::vec3, 3>(v, kp, "control", pts, 16);
            if (pts.size() != 16) fail(kp + "/control", "a bicubic patch needs 16 control points (48 numbers)");
            std::copy(pts.begin(), pts.end(), pp.surface.control.begin());
            (void)c;
        } else if (pp.surface.type == sg::ParametricType::BezierPatch) {
            fail(kp, "missing \"control\"");
        }
        optInt(v, kp, "material", pp.material, -1, maxMat);
        return pp;
    }
    // grid
    sg::GridPayload gp;
    auto g = std::make_shared<sg::DensityGrid>();
    g->dims = glm::ivec3(vec<3>(member(v, kp, "dims"), kp + "/dims"));
    sg::vec3 dimsF = vec<3>(v["dims"], kp + "/dims");
    for (int a = 0; a < 3; ++a)
        if (dimsF[a] != std::floor(dimsF[a]) || dimsF[a] < 2 || dimsF[a] > 1024) fail(kp + "/dims", "each dimension must be an integer in [2, 1024]");
    size_t count = size_t(g->dims.x) * g->dims.y * g->dims.z;
    if (count > kMaxGridValues) fail(kp + "/dims", "grid too large (" + std::to_string(count) + " values)");
    floatArray<float, 1>(v, kp, "values", g->values, kMaxGridValues);
    if (g->values.size() != count) fail(kp + "/values", "expected " + std::to_string(count) + " values, found " + std::to_string(g->values.size()));
    optFloat(v, kp, "iso", g->isoValue);
    if (auto* b = optional(v, "bounds")) {
        if (!b->is_array() || b->size() != 2) fail(kp + "/bounds", "expected [[min], [max]]");
        g->bounds.min = vec<3>((*b)[0], kp + "/bounds/0");
        g->bounds.max = vec<3>((*b)[1], kp + "/bounds/1");
        for (int a = 0; a < 3; ++a)
            if (!(g->bounds.max[a] > g->bounds.min[a])) fail(kp + "/bounds", "min must be below max");
    }
    gp.grid = std::move(g);
    optInt(v, kp, "material", gp.material, -1, maxMat);
    return gp;
}

sg::Scene Reader::read() {
    const json& j = m_root;
    if (!j.is_object()) fail("", "the top level must be an object");
    if (auto* f = optional(j, "format"); f && string(*f, "/format") != "sceneviewer")
        fail("/format", "not a scene-viewer scene file (format \"" + f->get<std::string>() + "\")");
    if (auto* v = optional(j, "version")) {
        int ver = integer(*v, "/version", 0, 1000000);
        if (ver > 1) fail("/version", "file version " + std::to_string(ver) + " is newer than this viewer (1)");
    }
    sg::Scene s;
    if (auto* v = optional(j, "name")) s.name = string(*v, "/name");
    // Older files keep the ambient light at the top level; "settings" has it now (and wins).
    if (auto* v = optional(j, "ambientLight")) {
        s.settings.ambientLight = vec<3>(*v, "/ambientLight");
        const sg::Param<sg::RenderSettings>& row = *sg::findParam<sg::RenderSettings>("ambientLight");
        if (std::string err = sg::checkValue(row, s.settings.ambientLight); !err.empty()) fail("/ambientLight", err.substr(row.key.size() + 2));
    }
    if (auto* v = optional(j, "settings")) readSettings(*v, "/settings", s.settings);

    auto array = [&](const char* key) -> const json* {
        const json* v = optional(j, key);
        if (v && !v->is_array()) fail(std::string("/") + key, "expected an array");
        return v;
    };
    if (auto* a = array("textures"))
        for (size_t i = 0; i < a->size(); ++i) s.textures.push_back(readTexture((*a)[i], "/textures/" + std::to_string(i)));
    if (auto* a = array("materials"))
        for (size_t i = 0; i < a->size(); ++i) s.materials.push_back(readMaterial((*a)[i], "/materials/" + std::to_string(i), s.textures.size()));
    if (auto* a = array("meshes"))
        for (size_t i = 0; i < a->size(); ++i) s.meshes.push_back(readMesh((*a)[i], "/meshes/" + std::to_string(i)));

    const json* skins = array("skins");
    s.skins.resize(skins ? skins->size() : 0);   // filled once the nodes (their joints) exist
    const json* nodes = array("nodes");
    if ((!nodes || nodes->empty()) && skins && !skins->empty()) fail("/skins", "skins need nodes");
    if (!nodes || nodes->empty()) return s;   // an empty scene is valid
    size_t n = nodes->size();
    if (n > kMaxNodes) fail("/nodes", "too many nodes (" + std::to_string(n) + ")");
    // Parents first: validate indices, detect cycles, then create nodes in an order where each
    // parent exists before its children.
    std::vector<int64_t> parent(n, -1);
    for (size_t i = 0; i < n; ++i) {
        std::string p = "/nodes/" + std::to_string(i);
        const json& nj = (*nodes)[i];
        if (!nj.is_object()) fail(p, "expected an object");
        const json* pv = optional(nj, "parent");
        if (i == 0) {
            if (pv) fail(p + "/parent", "node 0 is the root and has no parent");
            continue;
        }
        if (!pv) fail(p, "missing \"parent\" (only node 0, the root, has none)");
        parent[i] = integer(*pv, p + "/parent", 0, (long long)n - 1);
        if (size_t(parent[i]) == i) fail(p + "/parent", "a node cannot be its own parent");
    }
    // Children lists in file order, then an iterative walk from the root; nodes never reached
    // are part of a cycle.
    std::vector<std::vector<uint32_t>> children(n);
    for (size_t i = 1; i < n; ++i) children[size_t(parent[i])].push_back(uint32_t(i));
    std::vector<sg::NodeId> idOf(n, sg::kNoNode);
    idOf[0] = s.root();
    std::vector<uint32_t> stack{0};
    size_t reached = 1;
    while (!stack.empty()) {
        uint32_t i = stack.back();
        stack.pop_back();
        for (uint32_t c : children[i]) {
            idOf[c] = s.addNode("", idOf[i]);
            ++reached;
            stack.push_back(c);
        }
    }
    if (reached != n) {
        for (size_t i = 0; i < n; ++i)
            if (idOf[i] == sg::kNoNode) fail("/nodes/" + std::to_string(i) + "/parent", "the parent chain forms a cycle");
    }
    for (size_t i = 0; i < n; ++i) {
        std::string p = "/nodes/" + std::to_string(i);
        const json& nj = (*nodes)[i];
        sg::NodeId id = idOf[i];
        if (auto* v = optional(nj, "name"))
            s.setName(id, string(*v, p + "/name"));
        else if (i == 0)
            s.setName(id, "root");
        if (auto* v = optional(nj, "visible")) s.setVisible(id, boolean(*v, p + "/visible"));
        if (auto* v = optional(nj, "transform")) s.setLocal(id, readTransform(*v, p + "/transform"));
        s.setPayload(id, readPayload(nj, p, s));
    }
    for (size_t i = 0; skins && i < skins->size(); ++i) s.skins[i] = readSkin((*skins)[i], "/skins/" + std::to_string(i), idOf);
    if (auto* v = optional(j, "activeCamera")) {
        int c = integer(*v, "/activeCamera", 0, (long long)n - 1);
        if (!std::holds_alternative<sg::Camera>(s.node(idOf[c]).payload)) fail("/activeCamera", "node " + std::to_string(c) + " is not a camera");
        s.activeCamera = idOf[c];
    }
    return s;
}

}   // namespace

LoadResult parseSceneJson(std::string_view text, const fs::path& path) {
    LoadResult r;
    std::string file = path.string();
    int depth = nestingDepth(text, kMaxNesting);
    if (depth > kMaxNesting) {
        r.error = file + ": JSON nested deeper than " + std::to_string(kMaxNesting) + " levels";
        return r;
    }
    json j;
    try {
        j = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
    } catch (const json::out_of_range& e) {   // thrown even without exceptions, e.g. 1e999
        std::string what = e.what();
        auto pos = what.find("number overflow");
        r.error = file + ": number is not finite (" + (pos == std::string::npos ? what : what.substr(pos)) + ")";
        return r;
    }
    if (j.is_discarded()) {
        // Re-parse with exceptions for the position and reason of the syntax error.
        try {
            json again = json::parse(text.begin(), text.end());
            (void)again;
        } catch (const json::parse_error& e) {
            std::string what = e.what();
            auto pos = what.find("parse error");
            r.error = file + ": JSON syntax error: " + (pos == std::string::npos ? what : what.substr(pos));
            return r;
        } catch (const json::exception& e) {   // e.g. 1e999: "number overflow"
            std::string what = e.what();
            auto pos = what.find("number overflow");
            r.error = file + ": " + (pos == std::string::npos ? what : "number is not finite (" + what.substr(pos) + ")");
            return r;
        }
        r.error = file + ": JSON syntax error";
        return r;
    }
    try {
        Reader reader(j, path.parent_path(), r.warnings);
        r.scene = reader.read();
    } catch (const ParseError& e) {
        r.error = file + ": " + (e.path.empty() ? std::string("/") : e.path) + ": " + e.message;
    } catch (const std::bad_alloc&) { r.error = file + ": out of memory while loading"; }
    return r;
}

LoadResult loadSceneJson(const fs::path& path) {
    std::string text;
    std::string err = readFileLimited(path, kMaxFileBytes, text);
    if (!err.empty()) {
        LoadResult r;
        r.error = err;
        return r;
    }
    return parseSceneJson(text, path);
}

}   // namespace assets
