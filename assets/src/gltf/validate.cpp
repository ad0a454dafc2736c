// validate.cpp - the validation pass: after tinygltf has parsed the file and before anything is
// allocated from its numbers, validate() checks every index, every byte range (overflow-checked),
// counts, finiteness, the node graph (cycles, double parents) and budgets. Each phase returns ""
// or the first problem, in one line naming the object by kind and index.
#include "gltf_internal.h"

#include <cmath>

namespace assets::detail::gltf {

namespace {

bool addOv(uint64_t a, uint64_t b, uint64_t& r) { return __builtin_add_overflow(a, b, &r); }
bool mulOv(uint64_t a, uint64_t b, uint64_t& r) { return __builtin_mul_overflow(a, b, &r); }

bool finiteAll(const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double d) { return std::isfinite(d) && std::abs(d) < 1e30; });
}

// Range-checks one accessor (base data and sparse substitution). "" when valid.
std::string checkAccessor(const tinygltf::Model& m, size_t i) {
    const tinygltf::Accessor& a = m.accessors[i];
    std::string id = "accessor " + std::to_string(i) + ": ";
    if (!componentSize(a.componentType)) return id + "invalid componentType " + std::to_string(a.componentType);
    if (!componentCount(a.type)) return id + "invalid type";
    size_t es = elementSize(a);
    if (a.bufferView >= 0) {
        if (size_t(a.bufferView) >= m.bufferViews.size())
            return id + "bufferView " + std::to_string(a.bufferView) + " does not exist (" + std::to_string(m.bufferViews.size()) + " bufferViews)";
        const tinygltf::BufferView& bv = m.bufferViews[size_t(a.bufferView)];
        uint64_t stride = bv.byteStride ? bv.byteStride : es;
        if (bv.byteStride && bv.byteStride < es)
            return id + "byteStride " + std::to_string(bv.byteStride) + " of bufferView " + std::to_string(a.bufferView) +
                   " is smaller than the element size " + std::to_string(es);
        if (a.count > 0) {
            uint64_t end = 0;
            if (mulOv(stride, uint64_t(a.count - 1), end) || addOv(end, a.byteOffset, end) || addOv(end, elementExtent(a), end) ||
                end > bv.byteLength)
                return id + "byteOffset+count*stride exceeds bufferView " + std::to_string(a.bufferView) + " (count " + std::to_string(a.count) +
                       ", stride " + std::to_string(stride) + ", byteOffset " + std::to_string(a.byteOffset) + ", length " +
                       std::to_string(bv.byteLength) + ")";
        }
    }
    if (a.sparse.isSparse) {
        const auto& s = a.sparse;
        if (s.count < 1 || uint64_t(s.count) > a.count)
            return id + "sparse count " + std::to_string(s.count) + " outside 1.." + std::to_string(a.count);
        int ics = componentSize(s.indices.componentType);
        if (s.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && s.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            s.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            return id + "sparse indices have an invalid componentType";
        struct Part {
            int view;
            int offset;
            uint64_t bytes;
            const char* what;
        };
        Part parts[2] = {{s.indices.bufferView, s.indices.byteOffset, uint64_t(s.count) * uint64_t(ics), "sparse indices"},
                         {s.values.bufferView, s.values.byteOffset, uint64_t(s.count) * es, "sparse values"}};
        for (const Part& p : parts) {
            if (p.view < 0 || size_t(p.view) >= m.bufferViews.size())
                return id + p.what + " bufferView " + std::to_string(p.view) + " does not exist";
            if (p.offset < 0) return id + p.what + " byteOffset is negative";
            uint64_t end;
            if (addOv(uint64_t(p.offset), p.bytes, end) || end > m.bufferViews[size_t(p.view)].byteLength)
                return id + p.what + " exceed bufferView " + std::to_string(p.view) + " (length " +
                       std::to_string(m.bufferViews[size_t(p.view)].byteLength) + ")";
        }
    }
    return {};
}

std::string checkTextureInfo(const tinygltf::Model& m, int index, const std::string& what) {
    if (index >= 0 && size_t(index) >= m.textures.size())
        return what + " texture " + std::to_string(index) + " does not exist (" + std::to_string(m.textures.size()) + " textures)";
    if (index < -1) return what + " texture index " + std::to_string(index) + " is invalid";
    return {};
}

// The validation phases below each return "" or the first problem (one line, naming the
// object by kind and index); validate() runs them in a fixed order, so the first problem
// reported for a file is the same whichever phases follow.
std::string itemId(const char* what, size_t i) { return std::string(what) + " " + std::to_string(i) + ": "; }

// Every bufferView lies inside an existing buffer and has a legal byteStride.
std::string checkBufferViews(const tinygltf::Model& m) {
    for (size_t i = 0; i < m.bufferViews.size(); ++i) {
        const auto& bv = m.bufferViews[i];
        if (bv.buffer < 0 || size_t(bv.buffer) >= m.buffers.size())
            return itemId("bufferView", i) + "buffer " + std::to_string(bv.buffer) + " does not exist (" + std::to_string(m.buffers.size()) +
                   " buffers)";
        uint64_t end;
        size_t have = m.buffers[size_t(bv.buffer)].data.size();
        if (addOv(bv.byteOffset, bv.byteLength, end) || end > have)
            return itemId("bufferView", i) + "byteOffset+byteLength (" + std::to_string(bv.byteOffset) + "+" + std::to_string(bv.byteLength) +
                   ") exceeds buffer " + std::to_string(bv.buffer) + " (" + std::to_string(have) + " bytes)";
        if (bv.byteStride != 0 && (bv.byteStride < 4 || bv.byteStride > 252 || bv.byteStride % 4 != 0))
            return itemId("bufferView", i) + "byteStride " + std::to_string(bv.byteStride) + " outside 4..252 or not a multiple of 4";
    }
    return {};
}

// Samplers have known wrap modes; textures refer to existing images and samplers.
std::string checkSamplersAndTextures(const tinygltf::Model& m) {
    for (size_t i = 0; i < m.samplers.size(); ++i) {
        const auto& s = m.samplers[i];
        for (int w : {s.wrapS, s.wrapT})
            if (w != TINYGLTF_TEXTURE_WRAP_REPEAT && w != TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE && w != TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT)
                return itemId("sampler", i) + "invalid wrap mode " + std::to_string(w);
    }
    for (size_t i = 0; i < m.textures.size(); ++i) {
        const auto& t = m.textures[i];
        if (t.source >= 0 && size_t(t.source) >= m.images.size())
            return itemId("texture", i) + "image " + std::to_string(t.source) + " does not exist (" + std::to_string(m.images.size()) + " images)";
        if (t.sampler >= 0 && size_t(t.sampler) >= m.samplers.size())
            return itemId("texture", i) + "sampler " + std::to_string(t.sampler) + " does not exist (" + std::to_string(m.samplers.size()) +
                   " samplers)";
    }
    return {};
}

// Material i: its texture references (core and KHR_materials_pbrSpecularGlossiness) exist,
// its colour factors are finite and of the right size.
std::string checkMaterial(const tinygltf::Model& m, size_t i) {
    const auto& mat = m.materials[i];
    std::string e;
    if (e.empty()) e = checkTextureInfo(m, mat.pbrMetallicRoughness.baseColorTexture.index, "baseColor");
    if (e.empty()) e = checkTextureInfo(m, mat.pbrMetallicRoughness.metallicRoughnessTexture.index, "metallicRoughness");
    if (e.empty()) e = checkTextureInfo(m, mat.normalTexture.index, "normal");
    if (e.empty()) e = checkTextureInfo(m, mat.occlusionTexture.index, "occlusion");
    if (e.empty()) e = checkTextureInfo(m, mat.emissiveTexture.index, "emissive");
    if (const tinygltf::Value* sg = extensionObject(mat.extensions, "KHR_materials_pbrSpecularGlossiness")) {
        if (sg->Has("diffuseTexture") && sg->Get("diffuseTexture").IsObject() && sg->Get("diffuseTexture").Has("index")) {
            double d = numberOr(sg->Get("diffuseTexture"), "index", -1);
            if (e.empty()) e = checkTextureInfo(m, d >= -1 && d < 2e9 ? int(d) : -2, "diffuse");
        }
    }
    if (!e.empty()) return itemId("material", i) + e;
    if (mat.pbrMetallicRoughness.baseColorFactor.size() != 4 || !finiteAll(mat.pbrMetallicRoughness.baseColorFactor))
        return itemId("material", i) + "baseColorFactor must be 4 finite numbers";
    if (!mat.emissiveFactor.empty() && (mat.emissiveFactor.size() != 3 || !finiteAll(mat.emissiveFactor)))
        return itemId("material", i) + "emissiveFactor must be 3 finite numbers";
    return {};
}

// Camera i: a known type with a usable projection (positive fov / magnification, ordered planes).
std::string checkCamera(const tinygltf::Model& m, size_t i) {
    const auto& c = m.cameras[i];
    if (c.type == "perspective") {
        const auto& p = c.perspective;
        if (!(p.yfov > 0 && std::isfinite(p.yfov))) return itemId("camera", i) + "yfov must be > 0";
        if (!(p.znear > 0 && std::isfinite(p.znear))) return itemId("camera", i) + "znear must be > 0";
        if (p.zfar != 0 && !(p.zfar > p.znear && std::isfinite(p.zfar))) return itemId("camera", i) + "zfar must be > znear";
    } else if (c.type == "orthographic") {
        const auto& o = c.orthographic;
        if (!(o.ymag != 0 && std::isfinite(o.ymag) && std::isfinite(o.xmag))) return itemId("camera", i) + "ymag must be finite and non-zero";
        if (!(o.znear >= 0 && o.zfar > o.znear && std::isfinite(o.zfar))) return itemId("camera", i) + "need 0 <= znear < zfar";
    } else {
        return itemId("camera", i) + "unknown type '" + c.type + "'";
    }
    return {};
}

// Light i (KHR_lights_punctual): a known type, finite colour and intensity, sane spot cones.
std::string checkLight(const tinygltf::Model& m, size_t i) {
    const auto& l = m.lights[i];
    if (l.type != "point" && l.type != "spot" && l.type != "directional") return itemId("light", i) + "unknown type '" + l.type + "'";
    if (!l.color.empty() && (l.color.size() != 3 || !finiteAll(l.color))) return itemId("light", i) + "color must be 3 finite numbers";
    if (!std::isfinite(l.intensity) || l.intensity < 0) return itemId("light", i) + "intensity must be finite and >= 0";
    if (l.type == "spot" && !(std::isfinite(l.spot.innerConeAngle) && std::isfinite(l.spot.outerConeAngle) && l.spot.innerConeAngle >= 0 &&
                              l.spot.outerConeAngle <= sg::kPi / 2 + 1e-6))
        return itemId("light", i) + "invalid spot cone angles";
    return {};
}

// Primitive p of mesh i: a valid mode, existing material and accessors, unsigned scalar
// indices, attributes of one element count and of the types the conversion reads. Adds a
// warning (not an error) for integer texture coordinates and for a missing POSITION.
std::string checkPrimitive(const tinygltf::Model& m, size_t i, size_t p, std::vector<std::string>& warnings) {
    const auto& prim = m.meshes[i].primitives[p];
    std::string id = "mesh " + std::to_string(i) + " primitive " + std::to_string(p) + ": ";
    if (prim.mode < 0 || prim.mode > 6) return id + "invalid mode " + std::to_string(prim.mode);
    if (prim.material >= 0 && size_t(prim.material) >= m.materials.size())
        return id + "material " + std::to_string(prim.material) + " does not exist (" + std::to_string(m.materials.size()) + " materials)";
    if (prim.material < -1) return id + "invalid material index";
    if (prim.indices >= 0) {
        if (size_t(prim.indices) >= m.accessors.size())
            return id + "indices accessor " + std::to_string(prim.indices) + " does not exist (" + std::to_string(m.accessors.size()) + " accessors)";
        const auto& a = m.accessors[size_t(prim.indices)];
        if (a.type != TINYGLTF_TYPE_SCALAR ||
            (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
             a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
            return id + "indices accessor " + std::to_string(prim.indices) + " must be unsigned byte/short/int scalars";
    } else if (prim.indices < -1) {
        return id + "invalid indices accessor";
    }
    int64_t count = -1;
    std::string countFrom;
    for (const auto& [name, ai] : prim.attributes) {
        if (ai < 0 || size_t(ai) >= m.accessors.size())
            return id + "attribute " + name + ": accessor " + std::to_string(ai) + " does not exist (" + std::to_string(m.accessors.size()) +
                   " accessors)";
        const auto& a = m.accessors[size_t(ai)];
        if (count < 0) {
            count = int64_t(a.count);
            countFrom = name;
        } else if (int64_t(a.count) != count) {
            return id + "attribute " + name + " has " + std::to_string(a.count) + " elements but " + countFrom + " has " + std::to_string(count);
        }
        bool isFloat = a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
        bool normInt =
            a.normalized && (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
        if (name == "POSITION" || name == "NORMAL") {
            if (a.type != TINYGLTF_TYPE_VEC3) return id + name + " must be VEC3";
        } else if (name == "TEXCOORD_0" || name == "TEXCOORD_1") {
            if (a.type != TINYGLTF_TYPE_VEC2) return id + name + " must be VEC2";
            if (!isFloat && !normInt) warnings.push_back(id + name + " uses non-normalized integers (read as plain numbers)");
        } else if (name == "COLOR_0") {
            if (a.type != TINYGLTF_TYPE_VEC3 && a.type != TINYGLTF_TYPE_VEC4) return id + "COLOR_0 must be VEC3 or VEC4";
        }
    }
    if (!prim.attributes.count("POSITION")) warnings.push_back(id + "no POSITION attribute; primitive skipped");
    return {};
}

// Primitive p of mesh i, skin and morph part: JOINTS_0/1 unsigned byte/short VEC4, WEIGHTS_0/1
// float or normalised unsigned byte/short VEC4, each set complete; morph targets with existing
// VEC3 POSITION/NORMAL/TANGENT accessors of the primitive's vertex count, within the budget
// of displacement vectors (`morphVectors` adds up over the file). Warns about what is ignored.
std::string checkSkinAndMorph(const tinygltf::Model& m, size_t i, size_t p, uint64_t& morphVectors, std::vector<std::string>& warnings) {
    const auto& prim = m.meshes[i].primitives[p];
    std::string id = "mesh " + std::to_string(i) + " primitive " + std::to_string(p) + ": ";
    auto accessorOf = [&](const std::map<std::string, int>& attrs, const char* name) -> const tinygltf::Accessor* {
        auto it = attrs.find(name);
        return it == attrs.end() ? nullptr : &m.accessors[size_t(it->second)];   // index checked by checkPrimitive
    };
    for (int set = 0; set < 2; ++set) {
        std::string jn = "JOINTS_" + std::to_string(set), wn = "WEIGHTS_" + std::to_string(set);
        const tinygltf::Accessor *j = accessorOf(prim.attributes, jn.c_str()), *w = accessorOf(prim.attributes, wn.c_str());
        if (!j && !w) continue;
        if (!j || !w) return id + jn + " and " + wn + " must come together";
        if (j->type != TINYGLTF_TYPE_VEC4 ||
            (j->componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && j->componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT))
            return id + jn + " must be unsigned byte or short VEC4";
        bool normInt = w->normalized &&
                       (w->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || w->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
        if (w->type != TINYGLTF_TYPE_VEC4 || (w->componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !normInt))
            return id + wn + " must be float or normalized unsigned byte/short VEC4";
    }
    if (prim.attributes.count("JOINTS_1") && !prim.attributes.count("JOINTS_0")) return id + "JOINTS_1 without JOINTS_0";
    if (prim.attributes.count("JOINTS_2")) warnings.push_back(id + "more than 8 joint influences per vertex (JOINTS_2...) are ignored");
    const tinygltf::Accessor* pos = accessorOf(prim.attributes, "POSITION");
    for (size_t k = 0; k < prim.targets.size(); ++k) {
        for (const auto& [name, ai] : prim.targets[k]) {
            std::string tid = id + "morph target " + std::to_string(k) + " " + name + ": ";
            if (name != "POSITION" && name != "NORMAL" && name != "TANGENT") {
                warnings.push_back(id + "morph target attribute " + name + " is ignored");
                continue;
            }
            if (ai < 0 || size_t(ai) >= m.accessors.size()) return tid + "accessor " + std::to_string(ai) + " does not exist";
            const auto& a = m.accessors[size_t(ai)];
            if (a.type != TINYGLTF_TYPE_VEC3) return tid + "must be VEC3";
            if (pos && a.count != pos->count)
                return tid + "has " + std::to_string(a.count) + " elements but POSITION has " + std::to_string(pos->count);
            morphVectors += a.count;
            if (morphVectors > kMaxMorphVectors)
                return tid + "morph target budget exceeded (" + std::to_string(morphVectors) + " > " + std::to_string(kMaxMorphVectors) + " vectors)";
        }
    }
    return {};
}

// Skin i: existing joints and skeleton; inverse bind matrices (if given) float MAT4, one per joint.
std::string checkSkin(const tinygltf::Model& m, size_t i) {
    const auto& sk = m.skins[i];
    for (int j : sk.joints)
        if (j < 0 || size_t(j) >= m.nodes.size()) return itemId("skin", i) + "joint " + std::to_string(j) + " does not exist";
    if (sk.skeleton < -1 || (sk.skeleton >= 0 && size_t(sk.skeleton) >= m.nodes.size()))
        return itemId("skin", i) + "skeleton " + std::to_string(sk.skeleton) + " does not exist";
    if (sk.inverseBindMatrices >= 0) {
        if (size_t(sk.inverseBindMatrices) >= m.accessors.size())
            return itemId("skin", i) + "inverseBindMatrices accessor " + std::to_string(sk.inverseBindMatrices) + " does not exist";
        const auto& a = m.accessors[size_t(sk.inverseBindMatrices)];
        if (a.type != TINYGLTF_TYPE_MAT4 || a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            return itemId("skin", i) + "inverseBindMatrices must be float MAT4";
        if (a.count < sk.joints.size())
            return itemId("skin", i) + std::to_string(a.count) + " inverse bind matrices for " + std::to_string(sk.joints.size()) + " joints";
    } else if (sk.inverseBindMatrices < -1) {
        return itemId("skin", i) + "invalid inverseBindMatrices accessor";
    }
    return {};
}

// Node i: existing mesh / camera / skin / light, finite transforms with an affine matrix, and
// existing children that have no other parent (recorded in parent[child] = i).
std::string checkNode(const tinygltf::Model& m, size_t i, std::vector<int32_t>& parent) {
    const auto& n = m.nodes[i];
    std::string id = "node " + std::to_string(i) + ": ";
    if (n.mesh >= 0 && size_t(n.mesh) >= m.meshes.size())
        return id + "mesh " + std::to_string(n.mesh) + " does not exist (" + std::to_string(m.meshes.size()) + " meshes)";
    if (n.camera >= 0 && size_t(n.camera) >= m.cameras.size())
        return id + "camera " + std::to_string(n.camera) + " does not exist (" + std::to_string(m.cameras.size()) + " cameras)";
    if (n.skin >= 0 && size_t(n.skin) >= m.skins.size()) return id + "skin " + std::to_string(n.skin) + " does not exist";
    int li = nodeLight(n);
    if (li == -2 || (li >= 0 && size_t(li) >= m.lights.size()))
        return id + "light " + std::to_string(li) + " does not exist (" + std::to_string(m.lights.size()) + " lights)";
    if (!n.matrix.empty() && (n.matrix.size() != 16 || !finiteAll(n.matrix))) return id + "matrix must be 16 finite numbers";
    if (!n.matrix.empty() && (n.matrix[3] != 0 || n.matrix[7] != 0 || n.matrix[11] != 0 || n.matrix[15] != 1))
        return id + "matrix is not affine (last row must be 0 0 0 1)";
    if (!n.translation.empty() && (n.translation.size() != 3 || !finiteAll(n.translation))) return id + "translation must be 3 finite numbers";
    if (!n.rotation.empty() && (n.rotation.size() != 4 || !finiteAll(n.rotation))) return id + "rotation must be 4 finite numbers";
    if (!n.scale.empty() && (n.scale.size() != 3 || !finiteAll(n.scale))) return id + "scale must be 3 finite numbers";
    for (int ch : n.children) {
        if (ch < 0 || size_t(ch) >= m.nodes.size())
            return id + "child " + std::to_string(ch) + " does not exist (" + std::to_string(m.nodes.size()) + " nodes)";
        if (size_t(ch) == i) return id + "is its own child";
        if (parent[size_t(ch)] >= 0)
            return "node " + std::to_string(ch) + " has two parents (" + std::to_string(parent[size_t(ch)]) + " and " + std::to_string(i) + ")";
        parent[size_t(ch)] = int32_t(i);
    }
    return {};
}

// The node hierarchy (single parents, from checkNode) is a forest. With single parents, a
// cycle is a set of nodes whose parent chain never ends. Walk each chain once (state:
// 0 unknown, 1 on current walk, 2 reaches a root).
std::string checkNodeCycles(const std::vector<int32_t>& parent) {
    std::vector<uint8_t> state(parent.size(), 0);
    std::vector<size_t> walk;
    for (size_t i = 0; i < parent.size(); ++i) {
        walk.clear();
        size_t k = i;
        while (state[k] == 0) {
            state[k] = 1;
            walk.push_back(k);
            if (parent[k] < 0) break;
            k = size_t(parent[k]);
        }
        if (state[k] == 1 && parent[k] >= 0) {
            // k is on the current walk and has a parent on it too: a cycle.
            return "node " + std::to_string(k) + ": node hierarchy contains a cycle";
        }
        for (size_t w : walk) state[w] = 2;
    }
    return {};
}

// Scenes list existing root nodes, each once; the default scene exists.
std::string checkScenes(const tinygltf::Model& m, const std::vector<int32_t>& parent) {
    for (size_t i = 0; i < m.scenes.size(); ++i) {
        std::vector<int> seen;
        for (int r : m.scenes[i].nodes) {
            if (r < 0 || size_t(r) >= m.nodes.size())
                return itemId("scene", i) + "node " + std::to_string(r) + " does not exist (" + std::to_string(m.nodes.size()) + " nodes)";
            if (parent[size_t(r)] >= 0)
                return itemId("scene", i) + "node " + std::to_string(r) + " is not a root node (its parent is " + std::to_string(parent[size_t(r)]) +
                       ")";
        }
        seen = m.scenes[i].nodes;
        std::sort(seen.begin(), seen.end());
        if (std::adjacent_find(seen.begin(), seen.end()) != seen.end()) return itemId("scene", i) + "lists a node twice";
    }
    if (m.defaultScene >= 0 && size_t(m.defaultScene) >= m.scenes.size())
        return "scene " + std::to_string(m.defaultScene) + " (the default scene) does not exist (" + std::to_string(m.scenes.size()) + " scenes)";
    return {};
}

}   // namespace

// Everything the conversion relies on. Returns "" or the first problem. The order of the
// phases is part of the behaviour (it decides which problem a broken file reports, and
// which primitive warnings are added before it): buffers, accessors, samplers/textures,
// materials, cameras, lights, meshes, their skin/morph attributes, nodes, hierarchy, scenes,
// skins.
std::string validate(const tinygltf::Model& m, std::vector<std::string>& warnings) {
    if (m.nodes.size() > kMaxNodes) return std::to_string(m.nodes.size()) + " nodes exceed the budget of " + std::to_string(kMaxNodes);
    if (std::string e = checkBufferViews(m); !e.empty()) return e;
    for (size_t i = 0; i < m.accessors.size(); ++i)
        if (std::string e = checkAccessor(m, i); !e.empty()) return e;
    if (std::string e = checkSamplersAndTextures(m); !e.empty()) return e;
    for (size_t i = 0; i < m.materials.size(); ++i)
        if (std::string e = checkMaterial(m, i); !e.empty()) return e;
    for (size_t i = 0; i < m.cameras.size(); ++i)
        if (std::string e = checkCamera(m, i); !e.empty()) return e;
    for (size_t i = 0; i < m.lights.size(); ++i)
        if (std::string e = checkLight(m, i); !e.empty()) return e;
    for (size_t i = 0; i < m.meshes.size(); ++i)
        for (size_t p = 0; p < m.meshes[i].primitives.size(); ++p)
            if (std::string e = checkPrimitive(m, i, p, warnings); !e.empty()) return e;
    uint64_t morphVectors = 0;
    for (size_t i = 0; i < m.meshes.size(); ++i)
        for (size_t p = 0; p < m.meshes[i].primitives.size(); ++p)
            if (std::string e = checkSkinAndMorph(m, i, p, morphVectors, warnings); !e.empty()) return e;
    // Nodes: indices, finite transforms, tree structure.
    std::vector<int32_t> parent(m.nodes.size(), -1);
    for (size_t i = 0; i < m.nodes.size(); ++i)
        if (std::string e = checkNode(m, i, parent); !e.empty()) return e;
    if (std::string e = checkNodeCycles(parent); !e.empty()) return e;
    if (std::string e = checkScenes(m, parent); !e.empty()) return e;
    for (size_t i = 0; i < m.skins.size(); ++i)
        if (std::string e = checkSkin(m, i); !e.empty()) return e;
    return {};
}

}   // namespace assets::detail::gltf
