// gltf_internal.h - private to assets/src/gltf/: what the glTF importer's files share (limits,
// the parse context of tinygltf's callbacks, accessor reading, the Converter that turns a
// validated tinygltf::Model into our scene) and the importer's documentation: how glTF maps to
// our scene, the extensions honoured, and how a hostile file is kept from doing harm.
//
// glTF 2.0 (.gltf with external or embedded buffers, .glb) through Debian's tinygltf 2.7.0
// (shared library: only the header's declarations are used here). The files, in the order a
// load uses them:
//   load.cpp        detail::loadGltf: file and JSON pre-checks, tinygltf with our file access and
//                   image callbacks, then validation and conversion (convertModel)
//   extensions.cpp  the extensions honoured (extensionsRequired) and extension JSON values
//   validate.cpp    validate(): indices, byte ranges, counts, finiteness, node graph, budgets
//   accessors.cpp   accessor layout (component / element sizes, strides) and index reading
//   materials.cpp   images, textures and materials (Converter)
//   meshes.cpp      primitives -> meshes with skin and morph attributes; skins (Converter)
//   nodes.cpp       the scene's root nodes, node hierarchy, cameras, lights (Converter)
//   animation.cpp   animation clips (Converter)
//
// ---- Mapping to our scene ---------------------------------------------------------------------
// Scenes: the default scene (`scene`), else scene 0; with no scenes at all, every root node
//   (with a warning). LoadResult::sceneNames lists all scenes, loadedScene the chosen one.
// Nodes: one sg node per glTF node, same hierarchy and names ("node N" when unnamed); TRS ->
//   LocalTransform TRS (quaternion normalised), matrix -> LocalTransform Matrix.
// Meshes: one sg::Mesh per glTF primitive, shared by all nodes instancing the glTF mesh. A
//   node whose mesh has exactly one primitive (and no camera/light) carries the MeshInstance
//   itself; otherwise each primitive becomes a child node "<node>#<i>". Cameras and lights of
//   a node that already carries a payload become child nodes as well.
//   Modes: TRIANGLES; TRIANGLE_STRIP / TRIANGLE_FAN -> triangles (strip winding alternates;
//   degenerate strip/fan triangles are dropped); LINES / LINE_STRIP / LINE_LOOP -> Lines
//   (segments); POINTS -> Points. Any accessor component type (normalised or not), byteStride
//   and sparse accessors are read. Missing normals: indexed triangles get smooth area-weighted
//   normals (Mesh::computeNormals), non-indexed ones flat normals (vertices are unshared).
//   COLOR_0 (vec3/vec4; float or normalised ints) -> colors (linear); TEXCOORD_0/1 -> uv0/uv1
//   with v flipped (glTF: v = 0 at the image's top row; ours: v = 0 at the bottom, as GL/OBJ),
//   after the material's UV channels are baked in (see KHR_texture_transform below).
//   Non-finite or |x| > 1e30 positions are dropped with
//   the triangles/lines/points that use them (one warning).
// Skins and morph targets (posed on the CPU by sg::Scene::posedMesh, scenegraph/deform.h):
//   JOINTS_0/1 + WEIGHTS_0/1 -> Mesh::joints0/1 + weights0/1 (up to 8 influences; JOINTS_2+
//   ignored with a warning); skins -> Scene::skins (joints as node ids, inverseBindMatrices,
//   identity when absent); node.skin -> MeshInstance::skin of each of the node's primitives.
//   Morph targets' POSITION/NORMAL/TANGENT -> Mesh::morphTargets (other target attributes
//   ignored with a warning), mesh.weights -> Mesh::morphWeights, node.weights ->
//   MeshInstance::weights (they override the mesh's).
// Materials (glTF metallic-roughness -> our Phong material):
//   baseColor  = baseColorFactor.rgb (linear), diffuseTexture = baseColorTexture (sRGB data,
//                as our textures are), sampler wrapS/wrapT -> WrapMode; filters:
//                min NEAREST or NEAREST_MIPMAP_NEAREST+mag NEAREST -> Nearest, min LINEAR ->
//                Bilinear, mipmapped or unspecified -> Trilinear (unspecified + mag NEAREST ->
//                Nearest).
//   kd, ks, shininess, specularTinted = sg::phongFromMetallicRoughness(metallicFactor,
//                roughnessFactor) (scenegraph/material.h, docs/math.md: a Blinn-Phong exponent
//                matching a GGX lobe of width roughness^2, F0 0.04 for dielectrics, metal
//                highlights tinted, metals keep a little diffuse); ka = 0.2 (our default). The
//                factors are kept too (Material::metallic / roughness) for the texture below.
//   metallicRoughnessTexture (linear data: B metallic, G roughness) -> Material::
//                metallicRoughnessTexture: the mapping above per texel (flat and Phong shading).
//   occlusionTexture (linear, R) + strength -> on the ambient term; emissiveTexture (sRGB) x
//                emissive. A glTF texture used both as colour and as data becomes two textures.
//                normalTexture (linear) + scale -> Material::normalTexture / normalScale, with
//                TANGENT (xyz, w) or tangents generated from the UVs (Mesh::computeTangents).
//   emissive   = emissiveFactor (x KHR_materials_emissive_strength).
//   alphaMode  -> Material::alphaMode (OPAQUE, MASK with alphaCutoff, BLEND); alpha =
//                baseColorFactor.a, times texture and vertex colour alpha when drawn;
//                doubleSided -> Material::doubleSided (glTF's default false: back faces are culled
//                under RenderSettings::culling auto).
//   KHR_materials_unlit -> Material::unlit. KHR_materials_pbrSpecularGlossiness: diffuseFactor
//                / diffuseTexture -> baseColor / texture, ks = max(specularFactor),
//                specularColor = specularFactor / ks, roughness = 1 - glossiness as above.
//   texCoord and KHR_texture_transform (offset, rotation, scale, texCoord) of each texture
//                are applied to the UVs of each primitive using the material at import time
//                (uv' = T * R * S * uv as in the extension): a material's textures may sample two
//                (set, transform) channels; channel 0 (the base colour texture's, else the first
//                other one's) goes to uv0, channel 1 to uv1 with Material::uv1Maps naming the
//                maps that sample it. A third channel samples channel 0 (one warning).
//                KHR_materials_pbrSpecularGlossiness: specularGlossinessTexture (sRGB specular, linear
//                glossiness in A) -> metallicRoughnessTexture with Material::specularGlossiness.
// Cameras: perspective -> Projection Perspective (fovy = yfov, zNear, zFar; infinite zfar ->
//   max(1000 * znear, 100)); orthographic -> Orthographic (orthoHalfHeight = ymag). The glTF
//   aspectRatio is ignored (the viewport decides). The first camera met is made active.
// Lights (KHR_lights_punctual): point/spot/directional with colour; intensity is taken 1:1 in
//   our units: directional lux -> irradiance 1 lux = 1 unit; point/spot candela -> intensity
//   with inverseSquare = true, so E = I / r^2 at distance r (again lux). Spot cone angles
//   (radians from the axis) -> spotInnerDeg / spotOuterDeg. `range` is ignored.
//   Scenes with neither cameras nor lights get Scene::addDefaultCamera and a directional key.
// Animations: node translation/rotation/scale and morph "weights" channels (LINEAR, STEP,
//   CUBICSPLINE) become assets::AnimationClip (animation.h) in LoadResult::animations; a
//   weights channel becomes one channel per MeshInstance of its node (one per primitive).
//
// Extensions honoured: KHR_materials_unlit, KHR_texture_transform, KHR_lights_punctual,
// KHR_materials_pbrSpecularGlossiness, KHR_materials_emissive_strength, KHR_mesh_quantization
// (any component type is read); other extensions in extensionsRequired refuse the file.
//
// Safety: the file is read by us (size limit), its JSON (the GLB JSON chunk) is limited in
// size and nesting depth before tinygltf's recursive parser sees it; buffers and images are
// read only through ConfinedDir (model folder only, regular files only, no working-directory
// fallback); images are stored raw by our SetImageLoader callback and decoded later through
// decodeImage (PNG/JPEG magic, dimension cap) only if a used material needs them, with a
// texture byte budget. After parsing, validate() checks every index, every byte range
// (overflow-checked), counts, finiteness, the node graph (cycles, double parents) and budgets
// before anything is allocated from the file's numbers.
#pragma once

#include "import_common.h"

#include "assets/animation.h"
#include "assets/scene_io.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace assets::detail::gltf {

// ---- Limits ------------------------------------------------------------------------------------
inline constexpr uint64_t kMaxFileBytes = 2ull << 30;       // .gltf/.glb itself
inline constexpr uint64_t kMaxJsonBytes = 256ull << 20;     // JSON text
inline constexpr size_t kMaxJsonDepth = 128;                // real files stay below 20
inline constexpr uint64_t kMaxResourceBytes = 2ull << 30;   // one external buffer or image file
inline constexpr uint64_t kMaxTriangles = 50'000'000;
inline constexpr uint64_t kMaxVertices = 100'000'000;   // sum over primitives (incl. lines/points)
inline constexpr uint64_t kMaxNodes = 10'000'000;
inline constexpr uint64_t kMaxMorphVectors = 50'000'000;   // morph displacements (vec3) over all primitives
inline constexpr uint64_t kMaxTextureBytes = 2ull << 30;   // decoded RGBA8
inline constexpr size_t kPollEvery = 1u << 16;

// ---- File access (load.cpp) --------------------------------------------------------------------
// What tinygltf's file-system and image callbacks (load.cpp) share with the conversion: the
// model's folder (reads confined to it), why files were refused, the images' encoded bytes.
struct Ctx {
    explicit Ctx(const std::filesystem::path& folder) : dir(folder) {}
    ConfinedDir dir;
    std::vector<std::string> refused;                       // why a file was not read
    std::map<int, std::vector<unsigned char>> imageBytes;   // image index -> raw file bytes
    std::vector<std::string> imageWarnings;
    std::string parserWarning;   // tinygltf's warnings, on one line
    tinygltf::Model* model = nullptr;
};

// ---- Extensions (extensions.cpp) ---------------------------------------------------------------
const tinygltf::Value* extensionObject(const tinygltf::ExtensionMap& ext, const char* name);
// obj[key] as a finite number, else def.
double numberOr(const tinygltf::Value& obj, const char* key, double def);
// obj[key] as exactly n finite numbers into out; false (out untouched or partly set) otherwise.
bool numberArray(const tinygltf::Value& obj, const char* key, size_t n, double* out);
// The node's KHR_lights_punctual light index, -1 without one, -2 when it is not a valid index.
int nodeLight(const tinygltf::Node& n);
// Required extensions we cannot honour make the file unloadable (the spec says so). "" or why.
// Whether the viewer honours this extension (the others are drawn without; one warning).
bool honouredExtension(const std::string& ext);
std::string checkRequiredExtensions(const tinygltf::Model& model);

// ---- Validation (validate.cpp) -----------------------------------------------------------------
// Everything the conversion relies on. Returns "" or the first problem; adds warnings.
std::string validate(const tinygltf::Model& m, std::vector<std::string>& warnings);

// ---- Accessors (accessors.cpp; the per-element readers are inline here) ------------------------
int componentSize(int ct);
int componentCount(int type);
// Bytes of one element, including the column padding of small-component matrices.
size_t elementSize(const tinygltf::Accessor& a);
// Bytes the last element occupies (a padded matrix needs no padding after its last column).
size_t elementExtent(const tinygltf::Accessor& a);
size_t accessorStride(const tinygltf::Model& m, const tinygltf::Accessor& a);
std::string readIndices(const tinygltf::Model& m, size_t ai, const Progress& progress, std::vector<uint32_t>& out);
// A reading error prefixed with the object's id ("cancelled" and "" unchanged).
std::string prefixed(const std::string& id, const std::string& e);

// One component as a float (normalised integers mapped to 0..1 or -1..1) and one index; inline,
// as they run for every element read.
inline float readComponent(const unsigned char* p, int ct, bool normalized) {
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p, 4);
        return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(p[0]) / 255.0f : float(p[0]);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        float v = float(int8_t(p[0]));
        return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? float(v) / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? float(double(v) / 4294967295.0) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_INT: {
        int32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? std::max(float(double(v) / 2147483647.0), -1.0f) : float(v);
    }
    default: return 0.0f;
    }
}
inline uint32_t readIndex(const unsigned char* p, int ct) {
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
    }
    default: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
    }
    }
}

// Calls f(i, bytes) for every element (zeros when there is no bufferView), then again for the
// sparse substitutions. Ranges were validated; sparse indices are checked here.
template <class F>
std::string forEachElement(const tinygltf::Model& m, size_t ai, const Progress& progress, F&& f) {
    const tinygltf::Accessor& a = m.accessors[ai];
    static const unsigned char zeros[64] = {};
    if (a.bufferView >= 0) {
        const auto& bv = m.bufferViews[size_t(a.bufferView)];
        const unsigned char* base = m.buffers[size_t(bv.buffer)].data.data() + bv.byteOffset + a.byteOffset;
        size_t stride = accessorStride(m, a);
        for (size_t i = 0; i < a.count; ++i) {
            if ((i & (kPollEvery - 1)) == kPollEvery - 1 && progress.cancelled()) return "cancelled";
            f(i, base + i * stride);
        }
    } else {
        for (size_t i = 0; i < a.count; ++i) f(i, zeros);
    }
    if (a.sparse.isSparse) {
        const auto& s = a.sparse;
        const auto& iv = m.bufferViews[size_t(s.indices.bufferView)];
        const auto& vv = m.bufferViews[size_t(s.values.bufferView)];
        const unsigned char* ip = m.buffers[size_t(iv.buffer)].data.data() + iv.byteOffset + size_t(s.indices.byteOffset);
        const unsigned char* vp = m.buffers[size_t(vv.buffer)].data.data() + vv.byteOffset + size_t(s.values.byteOffset);
        size_t ics = size_t(componentSize(s.indices.componentType)), es = elementSize(a);
        for (size_t j = 0; j < size_t(s.count); ++j) {
            uint32_t target = readIndex(ip + j * ics, s.indices.componentType);
            if (target >= a.count)
                return "accessor " + std::to_string(ai) + ": sparse index " + std::to_string(target) + " >= count " + std::to_string(a.count);
            f(target, vp + j * es);
        }
    }
    return {};
}

// Reads an accessor as floats, `n` components per element (the accessor's own count of
// components must be >= n... exactly n for vectors; extra components are ignored).
template <class Vec>
std::string readVectors(const tinygltf::Model& m, size_t ai, int n, const Progress& progress, std::vector<Vec>& out, float fill = 0.0f) {
    const tinygltf::Accessor& a = m.accessors[ai];
    int have = componentCount(a.type);
    int cs = componentSize(a.componentType);
    out.assign(a.count, Vec(fill));
    Vec* dst = out.data();
    const int ct = a.componentType;
    const bool norm = a.normalized;
    const int use = std::min(have, n);
    return forEachElement(m, ai, progress, [&](size_t i, const unsigned char* p) {
        Vec v(fill);
        for (int c = 0; c < use; ++c) v[c] = readComponent(p + size_t(c * cs), ct, norm);
        dst[i] = v;
    });
}

// ---- Conversion (materials.cpp, meshes.cpp, nodes.cpp, animation.cpp) --------------------------
// One UV channel of a material: a TEXCOORD set with a KHR_texture_transform (glTF uv space).
struct UvChannel {
    int texCoord = 0;
    sg::mat3 transform{1.0f};
    bool operator==(const UvChannel&) const = default;
};
struct MaterialInfo {
    int sgIndex = -1;
    // The channels its textures sample, at most two: channel 0 (the base colour texture's, else
    // the first other texture's) becomes the primitives' uv0, channel 1 their uv1.
    UvChannel channel[2];
    int channels = 0;
    uint8_t uv1Maps = 0;   // sg::Material::uv1Maps
};

// One texture reference of a material: which glTF texture, which UV set, its
// KHR_texture_transform (null: none).
struct TexRef {
    int index = -1;
    int texCoord = 0;
    const tinygltf::Value* transform = nullptr;
};

// The validated model -> our scene. load.cpp's convertModel runs the phases in this order:
// convertMaterials, buildNodes (which builds each glTF mesh when a node first uses it),
// convertSkins, animations. The member functions are defined across the files named below.
struct Converter {
    Converter(const tinygltf::Model& model, Ctx& c, const Progress& p) : m(model), ctx(c), progress(p) {}
    const tinygltf::Model& m;
    Ctx& ctx;
    const Progress& progress;
    std::string file;
    sg::Scene scene;
    std::vector<std::string> warnings;
    std::vector<std::array<int, 2>> textureOf;   // glTF texture -> scene texture as [sRGB colour, linear data] (-2 = not yet)
    std::vector<sg::TexturePtr> decodedImage;    // glTF image -> decoded (null: failed/unused)
    std::vector<int8_t> imageTried;
    uint64_t textureBytes = 0;
    std::vector<MaterialInfo> materials;                       // glTF material -> ours
    std::vector<std::vector<std::pair<int, int>>> meshPrims;   // glTF mesh -> (sg mesh, material) per primitive
    std::vector<int8_t> meshDone;
    uint64_t triangles = 0, vertices = 0;
    std::vector<sg::NodeId> sgOf;                       // glTF node -> sg node
    std::vector<std::vector<sg::NodeId>> instancesOf;   // glTF node -> the sg nodes carrying its MeshInstances

    std::string warnOnce(const std::string& w) {
        if (std::find(warnings.begin(), warnings.end(), w) == warnings.end()) warnings.push_back(w);
        return w;
    }

    // materials.cpp: images and textures (decoded on first use), materials.
    sg::TexturePtr image(int ii);
    int texture(int ti, bool srgb = true);
    void chooseUvChannels(size_t i, const std::vector<TexRef>& refs, MaterialInfo& info);
    void convertPbr(const tinygltf::Material& gm, sg::Material& mat, sg::vec4& base, std::vector<TexRef>& refs);
    void convertMaterial(size_t i);
    void convertMaterials();

    // meshes.cpp: primitives -> meshes (built when a node first uses their glTF mesh), skins.
    std::string checkBudgets(const tinygltf::Primitive& prim, const std::string& id, size_t nv, size_t nIdx);
    std::string readAttributes(const tinygltf::Primitive& prim, const std::string& id, sg::Mesh& mesh);
    void bakeUvChannels(const std::string& id, const MaterialInfo& info, sg::Mesh& mesh);
    std::string readSkinAndMorph(const tinygltf::Primitive& prim, const std::string& id, const std::vector<double>& meshWeights, sg::Mesh& mesh);
    void assembleIndices(int mode, const std::string& id, size_t nIdx, const std::vector<uint32_t>* src, sg::Mesh& mesh);
    std::string dropBadVertices(const std::string& id, sg::Mesh& mesh);
    std::string buildPrimitive(size_t mi, size_t pi, sg::Mesh& mesh, bool& skipped);
    std::string meshPrimitives(size_t mi, const std::vector<std::pair<int, int>>*& out);
    std::string convertSkins();

    // nodes.cpp: the node hierarchy with its meshes, cameras and lights.
    sg::Camera camera(int ci) const;
    sg::Light light(int li) const;
    void setSkinAndWeights(const tinygltf::Node& n, sg::MeshInstance& inst);
    std::string buildNodes(const std::vector<int>& roots);

    // animation.cpp: animation clips.
    size_t targetCount(int node) const;
    std::string channelTarget(const tinygltf::Animation& ga, size_t ci, AnimationChannel& out) const;
    std::string readKeys(const tinygltf::AnimationSampler& s, AnimationChannel& out);
    std::vector<AnimationClip> animations();
};

// nodes.cpp: the root nodes to load (the default scene's, or the first, else every node without
// a parent); fills result.sceneNames / loadedScene and warns about the scenes left out.
std::vector<int> chooseRoots(const tinygltf::Model& model, const std::string& file, LoadResult& result);

}   // namespace assets::detail::gltf
