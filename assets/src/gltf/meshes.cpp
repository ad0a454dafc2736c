// meshes.cpp - glTF meshes -> our meshes, one per primitive (built when a node first uses its
// glTF mesh): vertex and triangle budgets, attributes with the material's UV channels baked in,
// joints / weights and morph targets, topology (strips, fans, loops unrolled), vertices with
// unusable positions dropped, normals and tangents computed where missing; and the skins.
#include "gltf_internal.h"

#include <cmath>

namespace assets::detail::gltf {

namespace {

// The accessor of the primitive's attribute `name`, -1 when it has none.
int attribute(const tinygltf::Primitive& prim, const char* name) {
    auto it = prim.attributes.find(name);
    return it == prim.attributes.end() ? -1 : it->second;
}

// unweld() for the per-vertex skin and morph data (`copy` gathers by the old indices).
// (Base tangents need none: unweld runs only for a primitive without normals, whose
// tangents are then dropped.)
template <class Copy>
void unweldDeformation(sg::Mesh& mesh, Copy& copy) {
    sg::Mesh o;
    copy(o.joints0, mesh.joints0);
    copy(o.joints1, mesh.joints1);
    copy(o.weights0, mesh.weights0);
    copy(o.weights1, mesh.weights1);
    o.morphTargets.resize(mesh.morphTargets.size());
    for (size_t k = 0; k < mesh.morphTargets.size(); ++k) {
        copy(o.morphTargets[k].positions, mesh.morphTargets[k].positions);
        copy(o.morphTargets[k].normals, mesh.morphTargets[k].normals);
        copy(o.morphTargets[k].tangents, mesh.morphTargets[k].tangents);
    }
    mesh.joints0 = std::move(o.joints0);
    mesh.joints1 = std::move(o.joints1);
    mesh.weights0 = std::move(o.weights0);
    mesh.weights1 = std::move(o.weights1);
    mesh.morphTargets = std::move(o.morphTargets);
}

// Gives every triangle corner its own vertex (so computeNormals yields flat normals).
void unweld(sg::Mesh& mesh) {
    sg::Mesh o;
    auto copy = [&](auto& dst, const auto& srcv) {
        if (srcv.empty()) return;
        dst.reserve(mesh.indices.size());
        for (uint32_t i : mesh.indices) dst.push_back(srcv[i]);
    };
    copy(o.positions, mesh.positions);
    copy(o.normals, mesh.normals);
    copy(o.uv0, mesh.uv0);
    copy(o.uv1, mesh.uv1);
    copy(o.colors, mesh.colors);
    mesh.positions = std::move(o.positions);
    mesh.normals = std::move(o.normals);
    mesh.uv0 = std::move(o.uv0);
    mesh.uv1 = std::move(o.uv1);
    mesh.colors = std::move(o.colors);
    unweldDeformation(mesh, copy);
    for (size_t i = 0; i < mesh.indices.size(); ++i) mesh.indices[i] = uint32_t(i);
}

}   // namespace

// Counts what the primitive will add against the vertex and triangle budgets before anything
// large is read; "" or the reason.
std::string Converter::checkBudgets(const tinygltf::Primitive& prim, const std::string& id, size_t nv, size_t nIdx) {
    if (vertices + nv > kMaxVertices)
        return id + "vertex budget exceeded (" + std::to_string(vertices + nv) + " > " + std::to_string(kMaxVertices) + ")";
    uint64_t tris = 0;
    if (prim.mode == TINYGLTF_MODE_TRIANGLES)
        tris = nIdx / 3;
    else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP || prim.mode == TINYGLTF_MODE_TRIANGLE_FAN)
        tris = nIdx >= 3 ? nIdx - 2 : 0;
    if (triangles + tris > kMaxTriangles)
        return id + "triangle budget exceeded (" + std::to_string(triangles + tris) + " > " + std::to_string(kMaxTriangles) + ")";
    if (nIdx > 3 * kMaxTriangles) return id + "index count " + std::to_string(nIdx) + " exceeds the budget";
    vertices += nv;
    return {};
}

// POSITION, NORMAL, TEXCOORD_0/1 and COLOR_0 into `mesh`; the diffuse texture's UV set goes
// to uv0 with its KHR_texture_transform applied, and v is flipped into our convention.
std::string Converter::readAttributes(const tinygltf::Primitive& prim, const std::string& id, sg::Mesh& mesh) {
    std::string e = readVectors(m, size_t(attribute(prim, "POSITION")), 3, progress, mesh.positions);
    if (!e.empty()) return prefixed(id, e);
    if (int a = attribute(prim, "NORMAL"); a >= 0) {
        if (!(e = readVectors(m, size_t(a), 3, progress, mesh.normals)).empty()) return prefixed(id, e);
        for (auto& n : mesh.normals)
            if (!sg::isFinite(n)) n = sg::vec3(0, 0, 1);
    }
    int uvA = attribute(prim, "TEXCOORD_0"), uvB = attribute(prim, "TEXCOORD_1");
    if (uvA >= 0 && !(e = readVectors(m, size_t(uvA), 2, progress, mesh.uv0)).empty()) return prefixed(id, e);
    if (uvB >= 0 && !(e = readVectors(m, size_t(uvB), 2, progress, mesh.uv1)).empty()) return prefixed(id, e);
    if (int a = attribute(prim, "COLOR_0"); a >= 0) {
        if (!(e = readVectors(m, size_t(a), 4, progress, mesh.colors, 1.0f)).empty()) return prefixed(id, e);
        if (m.accessors[size_t(a)].type == TINYGLTF_TYPE_VEC3)
            for (auto& c : mesh.colors) c.a = 1.0f;
    }
    if (int a = attribute(prim, "TANGENT"); a >= 0 && !mesh.normals.empty()) {
        if (!(e = readVectors(m, size_t(a), 4, progress, mesh.tangents, 1.0f)).empty()) return prefixed(id, e);
        for (auto& t : mesh.tangents)
            if (!sg::isFinite(sg::vec3(t)) || !std::isfinite(t.w) || glm::length(sg::vec3(t)) < 1e-12f) t = sg::vec4(1, 0, 0, 1);
        for (auto& t : mesh.tangents) t.w = t.w < 0.0f ? -1.0f : 1.0f;
    }
    if (prim.material >= 0) bakeUvChannels(id, materials[size_t(prim.material)], mesh);
    // glTF puts uv (0,0) at the image's first (top-left) pixel, v down; our textures follow
    // GL and OBJ (v = 0 at the bottom row, sg::Texture row 0 at v = 1): v -> 1 - v, after
    // KHR_texture_transform, which is defined in glTF's uv space.
    for (auto& uv : mesh.uv0) uv.y = 1.0f - uv.y;
    for (auto& uv : mesh.uv1) uv.y = 1.0f - uv.y;
    return {};
}

// The material's UV channels (chooseUvChannels) into the mesh: uv0 = channel 0's set with
// its transform applied; uv1 = channel 1's likewise, or, with one channel, the other set as
// read. A channel whose set the primitive lacks reads TEXCOORD_0 (one warning).
void Converter::bakeUvChannels(const std::string& id, const MaterialInfo& info, sg::Mesh& mesh) {
    if (info.channels == 0) return;
    const std::vector<sg::vec2> raw[2] = {std::move(mesh.uv0), std::move(mesh.uv1)};
    auto setOf = [&](const UvChannel& c) {
        if (!raw[c.texCoord].empty() || raw[0].empty()) return c.texCoord;
        warnOnce(id + "its material samples TEXCOORD_" + std::to_string(c.texCoord) + ", which it does not have (using TEXCOORD_0)");
        return 0;
    };
    auto baked = [&](const UvChannel& c, int set) {
        std::vector<sg::vec2> uv = raw[set];
        if (c.transform != sg::mat3(1.0f))
            for (auto& p : uv) p = sg::vec2(c.transform * sg::vec3(p, 1.0f));
        return uv;
    };
    const int set0 = setOf(info.channel[0]);
    mesh.uv0 = baked(info.channel[0], set0);
    mesh.uv1 = info.channels == 2 ? baked(info.channel[1], setOf(info.channel[1])) : raw[set0 == 1 ? 0 : 1];
}

// JOINTS_0/1 + WEIGHTS_0/1, the morph targets' POSITION/NORMAL/TANGENT displacements and
// the mesh's default weights (`meshWeights`, glTF mesh.weights) into `mesh`.
std::string Converter::readSkinAndMorph(const tinygltf::Primitive& prim, const std::string& id, const std::vector<double>& meshWeights,
                                        sg::Mesh& mesh) {
    std::string e;
    for (int set = 0; set < 2; ++set) {
        int ja = attribute(prim, set ? "JOINTS_1" : "JOINTS_0"), wa = attribute(prim, set ? "WEIGHTS_1" : "WEIGHTS_0");
        if (ja < 0 || wa < 0) continue;   // validate() made sure they come together
        std::vector<sg::vec4> j;
        if (!(e = readVectors(m, size_t(ja), 4, progress, j)).empty()) return prefixed(id, e);
        auto& joints = set ? mesh.joints1 : mesh.joints0;
        joints.resize(j.size());
        for (size_t v = 0; v < j.size(); ++v) joints[v] = sg::u16vec4(glm::clamp(j[v], sg::vec4(0.0f), sg::vec4(65535.0f)));
        auto& weights = set ? mesh.weights1 : mesh.weights0;
        if (!(e = readVectors(m, size_t(wa), 4, progress, weights)).empty()) return prefixed(id, e);
        for (auto& w : weights)
            if (!(std::isfinite(w.x + w.y + w.z + w.w)))
                w = sg::vec4(0.0f);   // that set then has no influence
            else
                w = glm::max(w, sg::vec4(0.0f));
    }
    if (mesh.joints0.empty()) mesh.joints1.clear(), mesh.weights1.clear();
    mesh.morphTargets.resize(prim.targets.size());
    for (size_t k = 0; k < prim.targets.size(); ++k) {
        sg::MorphTarget& t = mesh.morphTargets[k];
        for (auto [name, dst] :
             {std::pair<const char*, std::vector<sg::vec3>*>{"POSITION", &t.positions}, {"NORMAL", &t.normals}, {"TANGENT", &t.tangents}}) {
            auto it = prim.targets[k].find(name);
            if (it == prim.targets[k].end()) continue;
            if (!(e = readVectors(m, size_t(it->second), 3, progress, *dst)).empty()) return prefixed(id, e);
            for (auto& d : *dst)
                if (!sg::isFinite(d)) d = sg::vec3(0.0f);
        }
    }
    if (!meshWeights.empty() && meshWeights.size() != prim.targets.size())
        warnOnce(id + std::to_string(meshWeights.size()) + " mesh weights for " + std::to_string(prim.targets.size()) +
                 " morph targets; weights ignored");
    else
        for (double w : meshWeights) mesh.morphWeights.push_back(std::isfinite(w) ? float(w) : 0.0f);
    return {};
}

// The primitive's topology as our index list (points, line segments or triangles): strips,
// loops and fans unrolled, degenerate strip/fan triangles skipped.
void Converter::assembleIndices(int mode, const std::string& id, size_t nIdx, const std::vector<uint32_t>* src, sg::Mesh& mesh) {
    auto at = [&](size_t i) -> uint32_t { return src ? (*src)[i] : uint32_t(i); };
    auto& out = mesh.indices;
    if (mode == TINYGLTF_MODE_POINTS) {
        mesh.mode = sg::PrimitiveMode::Points;
        out.resize(nIdx);
        for (size_t i = 0; i < nIdx; ++i) out[i] = at(i);
    } else if (mode == TINYGLTF_MODE_LINE) {
        mesh.mode = sg::PrimitiveMode::Lines;
        if (nIdx % 2) warnOnce(id + "odd LINES index count; last index ignored");
        out.resize(nIdx / 2 * 2);
        for (size_t i = 0; i < out.size(); ++i) out[i] = at(i);
    } else if (mode == TINYGLTF_MODE_LINE_STRIP || mode == TINYGLTF_MODE_LINE_LOOP) {
        mesh.mode = sg::PrimitiveMode::Lines;
        for (size_t i = 0; i + 1 < nIdx; ++i) out.insert(out.end(), {at(i), at(i + 1)});
        if (mode == TINYGLTF_MODE_LINE_LOOP && nIdx >= 2) out.insert(out.end(), {at(nIdx - 1), at(0)});
    } else if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (nIdx % 3) warnOnce(id + "index count is not a multiple of 3; last " + std::to_string(nIdx % 3) + " ignored");
        out.resize(nIdx / 3 * 3);
        for (size_t i = 0; i < out.size(); ++i) out[i] = at(i);
    } else {   // TRIANGLE_STRIP, TRIANGLE_FAN
        out.reserve(nIdx >= 3 ? (nIdx - 2) * 3 : 0);
        for (size_t i = 0; i + 2 < nIdx; ++i) {
            const bool strip = mode == TINYGLTF_MODE_TRIANGLE_STRIP;
            uint32_t a = strip ? at(i) : at(i + 1), b = strip ? at(i + 1 + (i % 2)) : at(i + 2), c = strip ? at(i + 2 - (i % 2)) : at(0);
            if (a != b && b != c && a != c) out.insert(out.end(), {a, b, c});
        }
    }
}

// Vertices whose position is not finite or beyond +-1e30 are dropped together with the
// points, lines and triangles that use them (as the OBJ/OFF/PLY importers do); the unused
// slots get a harmless copy of a good position so bounds stay finite. "" or the reason
// when no vertex is usable.
std::string Converter::dropBadVertices(const std::string& id, sg::Mesh& mesh) {
    std::vector<uint8_t> bad(mesh.positions.size(), 0);
    size_t nBad = 0, good = SIZE_MAX;
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const sg::vec3& p = mesh.positions[i];
        bad[i] = !(sg::isFinite(p) && std::fabs(p.x) <= 1e30f && std::fabs(p.y) <= 1e30f && std::fabs(p.z) <= 1e30f);
        nBad += bad[i];
        if (!bad[i] && good == SIZE_MAX) good = i;
    }
    if (nBad == 0) return {};
    if (good == SIZE_MAX) return id + "all " + std::to_string(bad.size()) + " POSITION values are non-finite or beyond 1e30";
    const size_t k = mesh.mode == sg::PrimitiveMode::Triangles ? 3 : mesh.mode == sg::PrimitiveMode::Lines ? 2 : 1;
    std::vector<uint32_t> kept;
    kept.reserve(mesh.indices.size());
    for (size_t i = 0; i + k <= mesh.indices.size(); i += k) {
        bool ok = true;
        for (size_t j = 0; j < k; ++j) ok = ok && !bad[mesh.indices[i + j]];
        if (ok) kept.insert(kept.end(), mesh.indices.begin() + std::ptrdiff_t(i), mesh.indices.begin() + std::ptrdiff_t(i + k));
    }
    for (size_t i = 0; i < bad.size(); ++i)
        if (bad[i]) mesh.positions[i] = mesh.positions[good];
    warnOnce(id + "dropped " + std::to_string(nBad) + " of " + std::to_string(bad.size()) + " vertices (non-finite or |coordinate| > 1e30) and " +
             std::to_string((mesh.indices.size() - kept.size()) / k) +
             (k == 3   ? " triangles"
              : k == 2 ? " lines"
                       : " points") +
             " that use them");
    mesh.indices = std::move(kept);
    return {};
}

// Builds the sg::Mesh of one primitive; returns "" or an error; *skipped when the
// primitive has nothing to draw.
std::string Converter::buildPrimitive(size_t mi, size_t pi, sg::Mesh& mesh, bool& skipped) {
    const tinygltf::Primitive& prim = m.meshes[mi].primitives[pi];
    const std::string id = "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi) + ": ";
    const int pos = attribute(prim, "POSITION");
    skipped = pos < 0;
    if (skipped) return {};
    const size_t nv = m.accessors[size_t(pos)].count;
    const bool indexed = prim.indices >= 0;
    const size_t nIdx = indexed ? m.accessors[size_t(prim.indices)].count : nv;
    std::string e = checkBudgets(prim, id, nv, nIdx);
    if (e.empty()) e = readAttributes(prim, id, mesh);
    if (e.empty()) e = readSkinAndMorph(prim, id, m.meshes[mi].weights, mesh);
    if (!e.empty()) return e;
    std::vector<uint32_t> src;
    if (indexed) {
        if (!(e = readIndices(m, size_t(prim.indices), progress, src)).empty()) return prefixed(id, e);
        for (size_t i = 0; i < src.size(); ++i)
            if (src[i] >= nv)
                return id + "index " + std::to_string(i) + " is " + std::to_string(src[i]) + ", but there are only " + std::to_string(nv) +
                       " vertices";
    }
    assembleIndices(prim.mode, id, nIdx, indexed ? &src : nullptr, mesh);
    if (!(e = dropBadVertices(id, mesh)).empty()) return e;
    if (mesh.mode == sg::PrimitiveMode::Triangles) {
        triangles += mesh.indices.size() / 3;
        if (mesh.normals.empty()) {
            if (!indexed && prim.mode != TINYGLTF_MODE_TRIANGLES) unweld(mesh);   // flat normals for non-indexed strips/fans
            mesh.computeNormals();
            mesh.tangents.clear();   // glTF: tangents without normals are ignored
        }
        // A normal map needs tangents: generated from the UVs when the file has none.
        const bool normalMapped = prim.material >= 0 && m.materials[size_t(prim.material)].normalTexture.index >= 0;
        if (normalMapped && mesh.tangents.empty()) mesh.computeTangents((materials[size_t(prim.material)].uv1Maps & sg::Material::NormalMap) ? 1 : 0);
    } else {
        mesh.tangents.clear();
    }
    return {};
}

std::string Converter::meshPrimitives(size_t mi, const std::vector<std::pair<int, int>>*& out) {
    if (!meshDone[mi]) {
        meshDone[mi] = 1;
        const tinygltf::Mesh& gm = m.meshes[mi];
        for (size_t pi = 0; pi < gm.primitives.size(); ++pi) {
            if (progress.cancelled()) return "cancelled";
            auto mesh = std::make_shared<sg::Mesh>();
            bool skipped = false;
            std::string e = buildPrimitive(mi, pi, *mesh, skipped);
            if (!e.empty()) return e;
            if (skipped) continue;
            mesh->name = (gm.name.empty() ? "mesh " + std::to_string(mi) : gm.name) + (gm.primitives.size() > 1 ? "#" + std::to_string(pi) : "");
            if (mesh->indices.empty()) {
                warnOnce("mesh " + std::to_string(mi) + " primitive " + std::to_string(pi) + ": nothing to draw");
                continue;
            }
            scene.meshes.push_back(std::move(mesh));
            int mat = gm.primitives[pi].material >= 0 ? materials[size_t(gm.primitives[pi].material)].sgIndex : -1;
            meshPrims[mi].push_back({int(scene.meshes.size() - 1), mat});
        }
    }
    out = &meshPrims[mi];
    return {};
}

// Scene::skins from the file's skins (after buildNodes: joints not in the loaded scene
// become kNoNode, which poses as the identity). Non-finite matrices become the identity.
std::string Converter::convertSkins() {
    for (size_t i = 0; i < m.skins.size(); ++i) {
        const tinygltf::Skin& gs = m.skins[i];
        sg::Skin skin;
        skin.name = gs.name.empty() ? "skin " + std::to_string(i) : gs.name;
        for (int j : gs.joints) skin.joints.push_back(sgOf[size_t(j)]);
        skin.skeleton = gs.skeleton >= 0 ? sgOf[size_t(gs.skeleton)] : sg::kNoNode;
        skin.inverseBind.assign(gs.joints.size(), sg::mat4(1.0f));
        if (gs.inverseBindMatrices >= 0) {
            std::vector<sg::mat4>& ibm = skin.inverseBind;
            bool bad = false;
            std::string e = forEachElement(m, size_t(gs.inverseBindMatrices), progress, [&](size_t k, const unsigned char* p) {
                if (k >= ibm.size()) return;
                sg::mat4 mm;
                for (int c = 0; c < 16; ++c) mm[c / 4][c % 4] = readComponent(p + 4 * c, TINYGLTF_COMPONENT_TYPE_FLOAT, false);
                if (sg::isFinite(mm))
                    ibm[k] = mm;
                else
                    bad = true;
            });
            if (!e.empty()) return prefixed("skin " + std::to_string(i) + ": ", e);
            if (bad) warnOnce("skin " + std::to_string(i) + ": non-finite inverse bind matrices replaced by the identity");
        }
        if (std::any_of(skin.joints.begin(), skin.joints.end(), [](sg::NodeId j) { return j == sg::kNoNode; }))
            warnOnce("skin " + std::to_string(i) + ": joints outside the loaded scene stay in their bind pose");
        scene.skins.push_back(std::move(skin));
    }
    return {};
}

}   // namespace assets::detail::gltf
