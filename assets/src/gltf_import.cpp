// gltf_import.cpp - glTF 2.0 (.gltf with external or embedded buffers, .glb) through Debian's
// tinygltf 2.7.0 (shared library: only the header's declarations are used here).
//
// Sections: 1. mapping to our scene (documentation)  2. limits  3. file access + image
// callbacks, JSON pre-checks  4. validation  5. accessor reading  6. textures + materials
// 7. meshes  8. nodes, cameras, lights  9. animations  10. loadGltf
//
// ---- 1. Mapping ----------------------------------------------------------------------------
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
#include "import_common.h"
#include "importers.h"

#include "assets/files.h"
#include "assets/image_io.h"

#include <tiny_gltf.h>

#if defined(__GLIBC__)
#include <malloc.h>   // malloc_trim
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <unordered_map>

namespace fs = std::filesystem;

namespace assets::detail {

namespace {

// ---- 2. Limits ---------------------------------------------------------------------------
constexpr uint64_t kMaxFileBytes = 2ull << 30;       // .gltf/.glb itself
constexpr uint64_t kMaxJsonBytes = 256ull << 20;     // JSON text
constexpr size_t kMaxJsonDepth = 128;                // real files stay below 20
constexpr uint64_t kMaxResourceBytes = 2ull << 30;   // one external buffer or image file
constexpr uint64_t kMaxTriangles = 50'000'000;
constexpr uint64_t kMaxVertices = 100'000'000;   // sum over primitives (incl. lines/points)
constexpr uint64_t kMaxNodes = 10'000'000;
constexpr uint64_t kMaxMorphVectors = 50'000'000;   // morph displacements (vec3) over all primitives
constexpr uint64_t kMaxTextureBytes = 2ull << 30;   // decoded RGBA8
constexpr size_t kPollEvery = 1u << 16;

// Gives the heap's free pages back to the system. tinygltf's JSON tree is millions of small
// blocks; freed, they stay in the heap (resident) while the scene's big arrays come from new
// pages: at 1M nodes the load's peak was tinygltf's parse peak plus the whole scene.
void releaseFreedMemory() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

// ---- 3. File access and image callbacks --------------------------------------------------
struct Ctx {
    explicit Ctx(const fs::path& folder) : dir(folder) {}
    ConfinedDir dir;
    std::vector<std::string> refused;                       // why a file was not read
    std::map<int, std::vector<unsigned char>> imageBytes;   // image index -> raw file bytes
    std::vector<std::string> imageWarnings;
    std::string parserWarning;   // tinygltf's warnings, on one line
    tinygltf::Model* model = nullptr;
};

void addRefusal(Ctx& c, const std::string& why) {
    if (std::find(c.refused.begin(), c.refused.end(), why) == c.refused.end()) c.refused.push_back(why);
}

bool fsFileExists(const std::string& path, void* ud) {
    Ctx& c = *static_cast<Ctx*>(ud);
    std::string rel;
    // tinygltf also tries "./name" (the working directory): refused silently, the model-folder
    // attempt already recorded why the name was not found.
    if (!c.dir.relativeOf(path, rel, nullptr)) return false;
    std::string why = c.dir.probe(rel);
    if (!why.empty()) addRefusal(c, why);
    return why.empty();
}
std::string fsExpand(const std::string& path, void*) { return path; }   // no ~ or $VAR expansion
bool fsRead(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* ud) {
    Ctx& c = *static_cast<Ctx*>(ud);
    std::string why = c.dir.readAbsolute(path, kMaxResourceBytes, *out);
    if (!why.empty()) {
        addRefusal(c, why);
        if (err) *err = why;
        return false;
    }
    return true;
}
bool fsWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err = "writing is disabled";
    return false;
}

// Keeps the encoded bytes; decoding happens after validation, for used images only.
bool storeImage(tinygltf::Image* image, const int idx, std::string*, std::string*, int, int, const unsigned char* bytes, int size, void* ud) {
    Ctx& c = *static_cast<Ctx*>(ud);
    size_t n = size > 0 ? size_t(size) : 0;
    if (image->bufferView >= 0) {
        // tinygltf checked the view and buffer indices but not the byte range.
        const tinygltf::Model& m = *c.model;
        const auto& bv = m.bufferViews[size_t(image->bufferView)];
        const auto& buf = m.buffers[size_t(bv.buffer)];
        if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset) {
            c.imageWarnings.push_back("image " + std::to_string(idx) + ": bufferView " + std::to_string(image->bufferView) +
                                      " exceeds its buffer; texture skipped");
            return true;
        }
        bytes = buf.data.data() + bv.byteOffset;
        n = bv.byteLength;
    }
    if (!bytes || n == 0) {
        c.imageWarnings.push_back("image " + std::to_string(idx) + ": no data; texture skipped");
        return true;
    }
    c.imageBytes[idx].assign(bytes, bytes + n);
    return true;
}

// Maximum nesting of {} / [] outside strings; stops counting past `limit`.
size_t jsonDepth(const char* s, size_t n, size_t limit) {
    size_t depth = 0, maxDepth = 0;
    bool inString = false;
    for (size_t i = 0; i < n; ++i) {
        char ch = s[i];
        if (inString) {
            if (ch == '\\')
                ++i;
            else if (ch == '"')
                inString = false;
        } else if (ch == '"') {
            inString = true;
        } else if (ch == '{' || ch == '[') {
            if (++depth > maxDepth) {
                maxDepth = depth;
                if (maxDepth > limit) return maxDepth;
            }
        } else if (ch == '}' || ch == ']') {
            if (depth > 0) --depth;
        }
    }
    return maxDepth;
}

std::string oneLine(std::string s) {
    for (char& ch : s)
        if (ch == '\n' || ch == '\r') ch = ' ';
    while (!s.empty() && s.back() == ' ') s.pop_back();
    size_t p;
    while ((p = s.find("  ")) != std::string::npos) s.replace(p, 2, "; ");
    if (s.size() > 400) s = s.substr(0, 400) + "...";
    return s;
}

// ---- 4. Validation -----------------------------------------------------------------------
int componentSize(int ct) {
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
    }
}
int componentCount(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}
// Bytes of one element, including the column padding of small-component matrices.
size_t elementSize(const tinygltf::Accessor& a) {
    size_t cs = size_t(componentSize(a.componentType));
    auto col = [&](size_t rows) { return (rows * cs + 3) / 4 * 4; };
    switch (a.type) {
    case TINYGLTF_TYPE_MAT2: return cs < 4 ? 2 * col(2) : 4 * cs;
    case TINYGLTF_TYPE_MAT3: return cs < 4 ? 3 * col(3) : 9 * cs;
    case TINYGLTF_TYPE_MAT4: return 16 * cs;
    default: return size_t(componentCount(a.type)) * cs;
    }
}
// Bytes the last element occupies (a padded matrix needs no padding after its last column).
size_t elementExtent(const tinygltf::Accessor& a) {
    size_t cs = size_t(componentSize(a.componentType));
    if (cs < 4 && (a.type == TINYGLTF_TYPE_MAT2 || a.type == TINYGLTF_TYPE_MAT3)) {
        size_t rows = a.type == TINYGLTF_TYPE_MAT2 ? 2 : 3;
        return (rows - 1) * ((rows * cs + 3) / 4 * 4) + rows * cs;
    }
    return elementSize(a);
}
size_t accessorStride(const tinygltf::Model& m, const tinygltf::Accessor& a) {
    if (a.bufferView < 0) return elementSize(a);
    size_t s = m.bufferViews[size_t(a.bufferView)].byteStride;
    return s ? s : elementSize(a);
}

bool addOv(uint64_t a, uint64_t b, uint64_t& r) { return __builtin_add_overflow(a, b, &r); }
bool mulOv(uint64_t a, uint64_t b, uint64_t& r) { return __builtin_mul_overflow(a, b, &r); }

bool finiteAll(const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double d) { return std::isfinite(d) && std::abs(d) < 1e30; });
}

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

// ---- 5. Accessor reading -----------------------------------------------------------------
float readComponent(const unsigned char* p, int ct, bool normalized) {
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
uint32_t readIndex(const unsigned char* p, int ct) {
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

std::string readIndices(const tinygltf::Model& m, size_t ai, const Progress& progress, std::vector<uint32_t>& out) {
    const tinygltf::Accessor& a = m.accessors[ai];
    out.assign(a.count, 0);
    const int ct = a.componentType;
    uint32_t* dst = out.data();
    return forEachElement(m, ai, progress, [&](size_t i, const unsigned char* p) { dst[i] = readIndex(p, ct); });
}

// ---- 6. Textures and materials -----------------------------------------------------------
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

    sg::TexturePtr image(int ii) {
        if (imageTried[size_t(ii)]) return decodedImage[size_t(ii)];
        imageTried[size_t(ii)] = 1;
        const tinygltf::Image& img = m.images[size_t(ii)];
        std::string name = "image " + std::to_string(ii) + (img.uri.empty() || img.uri.rfind("data:", 0) == 0 ? "" : " ('" + img.uri + "')");
        auto it = ctx.imageBytes.find(ii);
        if (it == ctx.imageBytes.end()) {
            warnOnce(name + " could not be read; material uses no texture");
            return nullptr;
        }
        int w = 0, h = 0;
        if (imageSize(it->second.data(), it->second.size(), w, h) && w <= kMaxImageDimension && h <= kMaxImageDimension) {
            uint64_t bytes = uint64_t(std::max(w, 0)) * uint64_t(std::max(h, 0)) * 4;
            if (textureBytes + bytes > kMaxTextureBytes) {
                warnOnce(name + ": texture budget of " + std::to_string(kMaxTextureBytes >> 20) + " MB exceeded; texture skipped");
                return nullptr;
            }
        }
        ImageLoad r = decodeImage(it->second.data(), it->second.size(), name);
        std::vector<unsigned char>().swap(it->second);
        if (!r.texture) {
            warnOnce(r.error + "; material uses no texture");
            return nullptr;
        }
        textureBytes += r.texture->rgba.size();
        if (!img.uri.empty() && img.uri.rfind("data:", 0) != 0) r.texture->sourcePath = (ctx.dir.root() / percentDecode(img.uri)).string();
        decodedImage[size_t(ii)] = r.texture;
        return r.texture;
    }

    // Scene texture for glTF texture ti, holding colour (sRGB) or data (linear); -1 if unusable.
    int texture(int ti, bool srgb = true) {
        if (ti < 0 || size_t(ti) >= m.textures.size()) return -1;
        int& slot = textureOf[size_t(ti)][srgb ? 0 : 1];
        if (slot != -2) return slot;
        slot = -1;
        const tinygltf::Texture& t = m.textures[size_t(ti)];
        if (t.source < 0) {
            warnOnce("texture " + std::to_string(ti) + " has no PNG/JPEG source (other image formats are not supported)");
            return -1;
        }
        sg::TexturePtr src = image(t.source);
        if (!src) return -1;
        auto tex = std::make_shared<sg::Texture>(*src);
        tex->id = sg::newResourceId();
        tex->srgb = srgb;
        if (!t.name.empty()) tex->name = t.name;
        if (t.sampler >= 0) {
            const tinygltf::Sampler& s = m.samplers[size_t(t.sampler)];
            auto wrap = [](int w) {
                return w == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? sg::WrapMode::ClampToEdge
                       : w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? sg::WrapMode::MirroredRepeat
                                                                    : sg::WrapMode::Repeat;
            };
            tex->wrapS = wrap(s.wrapS);
            tex->wrapT = wrap(s.wrapT);
            int mn = s.minFilter, mg = s.magFilter;
            if (mn == TINYGLTF_TEXTURE_FILTER_NEAREST ||
                (mn == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST && mg == TINYGLTF_TEXTURE_FILTER_NEAREST) ||
                (mn == -1 && mg == TINYGLTF_TEXTURE_FILTER_NEAREST))
                tex->filter = sg::FilterMode::Nearest;
            else if (mn == TINYGLTF_TEXTURE_FILTER_LINEAR)
                tex->filter = sg::FilterMode::Bilinear;
            else
                tex->filter = sg::FilterMode::Trilinear;
        }
        scene.textures.push_back(std::move(tex));
        slot = int(scene.textures.size() - 1);
        return slot;
    }

    // One texture reference of a material: which glTF texture, which UV set, its
    // KHR_texture_transform (null: none).
    struct TexRef {
        int index = -1;
        int texCoord = 0;
        const tinygltf::Value* transform = nullptr;
    };
    static TexRef texRef(const tinygltf::TextureInfo& t) { return {t.index, t.texCoord, extensionObject(t.extensions, "KHR_texture_transform")}; }
    static TexRef texRef(int index, int texCoord, const tinygltf::ExtensionMap& ext) {
        return {index, texCoord, extensionObject(ext, "KHR_texture_transform")};
    }
    static TexRef texRef(const tinygltf::Value& v) {   // a textureInfo inside an extension object
        TexRef r{int(numberOr(v, "index", -1)), int(numberOr(v, "texCoord", 0)), nullptr};
        if (v.Has("extensions") && v.Get("extensions").IsObject() && v.Get("extensions").Has("KHR_texture_transform"))
            r.transform = &v.Get("extensions").Get("KHR_texture_transform");
        return r;
    }

    // KHR_texture_transform as a matrix in glTF's uv space: T * R * S (column-major), with
    // R = [cos sin; -sin cos] as in the extension. Its texCoord override goes to texCoord.
    static sg::mat3 uvTransformOf(const tinygltf::Value& tt, int& texCoord) {
        double off[2] = {0, 0}, sc[2] = {1, 1};
        numberArray(tt, "offset", 2, off);
        numberArray(tt, "scale", 2, sc);
        float rot = float(numberOr(tt, "rotation", 0.0));
        if (tt.Has("texCoord")) texCoord = int(numberOr(tt, "texCoord", 0));
        sg::mat3 T(1.0f), R(1.0f), S(1.0f);
        T[2] = sg::vec3(float(off[0]), float(off[1]), 1.0f);
        float c = std::cos(rot), s = std::sin(rot);
        R[0] = sg::vec3(c, -s, 0.0f);
        R[1] = sg::vec3(s, c, 0.0f);
        S[0][0] = float(sc[0]);
        S[1][1] = float(sc[1]);
        return T * R * S;
    }

    // Our meshes carry two UV sets, uv0 and uv1, with the texture transforms baked in
    // (readAttributes): a material's textures may sample two different (TEXCOORD set,
    // KHR_texture_transform) channels. refs: base colour, metallic-roughness, occlusion,
    // emissive, normal. A texture asking for a third channel samples channel 0 (one warning);
    // TEXCOORD_2 and above are read as TEXCOORD_0 (one warning).
    void chooseUvChannels(size_t i, const std::vector<TexRef>& refs, MaterialInfo& info) {
        static const uint8_t bit[5] = {0, sg::Material::MetallicRoughnessMap, sg::Material::OcclusionMap, sg::Material::EmissiveMap,
                                       sg::Material::NormalMap};
        for (size_t k = 0; k < refs.size() && k < 5; ++k) {
            const TexRef& r = refs[k];
            if (r.index < 0) continue;
            UvChannel c;
            c.texCoord = r.texCoord;
            if (r.transform) c.transform = uvTransformOf(*r.transform, c.texCoord);
            if (c.texCoord < 0 || c.texCoord > 1) {
                warnOnce("material " + std::to_string(i) + ": texCoord " + std::to_string(c.texCoord) + " is not supported (using TEXCOORD_0)");
                c.texCoord = 0;
            }
            int found = -1;
            for (int ch = 0; ch < info.channels; ++ch)
                if (info.channel[ch] == c) found = ch;
            if (found < 0 && info.channels < 2) {
                found = info.channels++;
                info.channel[found] = c;
            }
            if (found < 0)
                warnOnce("material " + std::to_string(i) +
                         ": its textures use more than two UV set / texture transform combinations; the others sample the base colour "
                         "texture's");
            if (found == 1) info.uv1Maps |= bit[k];
        }
    }

    // metallic-roughness (or specular-glossiness) parameters -> Phong factors and textures.
    void convertPbr(const tinygltf::Material& gm, sg::Material& mat, sg::vec4& base, std::vector<TexRef>& refs) {
        const auto& pbr = gm.pbrMetallicRoughness;
        base = glm::clamp(
            sg::vec4(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]), float(pbr.baseColorFactor[2]), float(pbr.baseColorFactor[3])),
            sg::vec4(0.0f), sg::vec4(1.0f));
        mat.metallic = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
        mat.roughness = std::clamp(float(pbr.roughnessFactor), 0.0f, 1.0f);
        const sg::PhongFromPbr ph = sg::phongFromMetallicRoughness(mat.metallic, mat.roughness);
        mat.kd = ph.kd;
        mat.ks = ph.ks;
        mat.shininess = ph.shininess;
        mat.specularTinted = ph.tinted;
        mat.specularColor = sg::vec3(1.0f);
        mat.ka = 0.2f;
        refs[0] = texRef(pbr.baseColorTexture);
        refs[1] = texRef(pbr.metallicRoughnessTexture);
        const tinygltf::Value* sgx = extensionObject(gm.extensions, "KHR_materials_pbrSpecularGlossiness");
        if (!sgx) return;
        double d[4] = {1, 1, 1, 1}, s[3] = {1, 1, 1};
        numberArray(*sgx, "diffuseFactor", 4, d);
        numberArray(*sgx, "specularFactor", 3, s);
        float gloss = std::clamp(float(numberOr(*sgx, "glossinessFactor", 1.0)), 0.0f, 1.0f);
        base = glm::clamp(sg::vec4(float(d[0]), float(d[1]), float(d[2]), float(d[3])), sg::vec4(0.0f), sg::vec4(1.0f));
        sg::vec3 spec = glm::clamp(sg::vec3(float(s[0]), float(s[1]), float(s[2])), sg::vec3(0.0f), sg::vec3(1.0f));
        float ks = std::max({spec.x, spec.y, spec.z});
        mat.kd = 1.0f;
        mat.ks = ks;
        mat.specularColor = ks > 0 ? spec / ks : sg::vec3(1.0f);
        mat.specularTinted = false;
        mat.shininess = sg::phongFromMetallicRoughness(0.0f, 1.0f - gloss).shininess;
        refs[0] = sgx->Has("diffuseTexture") && sgx->Get("diffuseTexture").IsObject() ? texRef(sgx->Get("diffuseTexture")) : TexRef{};
        mat.specularGlossiness = true;
        mat.glossiness = gloss;
        refs[1] = sgx->Has("specularGlossinessTexture") && sgx->Get("specularGlossinessTexture").IsObject()
                      ? texRef(sgx->Get("specularGlossinessTexture"))
                      : TexRef{};
    }

    void convertMaterial(size_t i) {
        const tinygltf::Material& gm = m.materials[i];
        sg::Material mat;
        mat.name = gm.name.empty() ? "material " + std::to_string(i) : gm.name;
        sg::vec4 base(1.0f);
        std::vector<TexRef> refs(5);   // base colour, metallic-roughness, occlusion, emissive, normal
        convertPbr(gm, mat, base, refs);
        refs[2] = texRef(gm.occlusionTexture.index, gm.occlusionTexture.texCoord, gm.occlusionTexture.extensions);
        refs[3] = texRef(gm.emissiveTexture);
        refs[4] = texRef(gm.normalTexture.index, gm.normalTexture.texCoord, gm.normalTexture.extensions);
        mat.baseColor = sg::vec3(base);
        if (!gm.emissiveFactor.empty()) {
            mat.emissive = sg::vec3(float(gm.emissiveFactor[0]), float(gm.emissiveFactor[1]), float(gm.emissiveFactor[2]));
            if (const tinygltf::Value* es = extensionObject(gm.extensions, "KHR_materials_emissive_strength"))
                mat.emissive *= float(std::clamp(numberOr(*es, "emissiveStrength", 1.0), 0.0, 1e6));
        }
        mat.alpha = base.a;   // baseColorFactor.a (diffuseFactor.a); texture and vertex alpha multiply it when drawn
        mat.alphaMode = gm.alphaMode == "BLEND" ? sg::AlphaMode::Blend : gm.alphaMode == "MASK" ? sg::AlphaMode::Mask : sg::AlphaMode::Opaque;
        if (gm.alphaMode != "OPAQUE" && gm.alphaMode != "BLEND" && gm.alphaMode != "MASK")
            warnOnce("material " + std::to_string(i) + ": alphaMode \"" + gm.alphaMode + "\" is not one of OPAQUE, MASK, BLEND (drawn opaque)");
        mat.alphaCutoff = std::isfinite(gm.alphaCutoff) && gm.alphaCutoff >= 0 ? float(gm.alphaCutoff) : 0.5f;
        mat.doubleSided = gm.doubleSided;
        mat.unlit = extensionObject(gm.extensions, "KHR_materials_unlit") != nullptr || gm.extensions.count("KHR_materials_unlit");
        mat.diffuseTexture = texture(refs[0].index, true);
        mat.metallicRoughnessTexture = texture(refs[1].index, mat.specularGlossiness);   // specular-glossiness: sRGB colour
        mat.occlusionTexture = texture(refs[2].index, false);
        mat.occlusionStrength = std::isfinite(gm.occlusionTexture.strength) ? std::clamp(float(gm.occlusionTexture.strength), 0.0f, 1.0f) : 1.0f;
        mat.emissiveTexture = texture(refs[3].index, true);
        mat.normalTexture = texture(gm.normalTexture.index, false);
        mat.normalScale = std::isfinite(gm.normalTexture.scale) ? float(gm.normalTexture.scale) : 1.0f;
        MaterialInfo info;
        chooseUvChannels(i, refs, info);
        mat.uv1Maps = info.uv1Maps;
        scene.materials.push_back(std::move(mat));
        info.sgIndex = int(scene.materials.size() - 1);
        materials[i] = info;
    }

    void convertMaterials() {
        materials.resize(m.materials.size());
        for (size_t i = 0; i < m.materials.size(); ++i) convertMaterial(i);
    }

    // ---- 7. Meshes -----------------------------------------------------------------------
    static int attribute(const tinygltf::Primitive& prim, const char* name) {
        auto it = prim.attributes.find(name);
        return it == prim.attributes.end() ? -1 : it->second;
    }
    static std::string prefixed(const std::string& id, const std::string& e) { return e.empty() || e == "cancelled" ? e : id + e; }

    // Counts what the primitive will add against the vertex and triangle budgets before anything
    // large is read; "" or the reason.
    std::string checkBudgets(const tinygltf::Primitive& prim, const std::string& id, size_t nv, size_t nIdx) {
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
    std::string readAttributes(const tinygltf::Primitive& prim, const std::string& id, sg::Mesh& mesh) {
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
    void bakeUvChannels(const std::string& id, const MaterialInfo& info, sg::Mesh& mesh) {
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
    std::string readSkinAndMorph(const tinygltf::Primitive& prim, const std::string& id, const std::vector<double>& meshWeights, sg::Mesh& mesh) {
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
    void assembleIndices(int mode, const std::string& id, size_t nIdx, const std::vector<uint32_t>* src, sg::Mesh& mesh) {
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
    std::string dropBadVertices(const std::string& id, sg::Mesh& mesh) {
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
    std::string buildPrimitive(size_t mi, size_t pi, sg::Mesh& mesh, bool& skipped) {
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
            if (normalMapped && mesh.tangents.empty())
                mesh.computeTangents((materials[size_t(prim.material)].uv1Maps & sg::Material::NormalMap) ? 1 : 0);
        } else {
            mesh.tangents.clear();
        }
        return {};
    }

    // Gives every triangle corner its own vertex (so computeNormals yields flat normals).
    static void unweld(sg::Mesh& mesh) {
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
    // unweld() for the per-vertex skin and morph data (`copy` gathers by the old indices).
    // (Base tangents need none: unweld runs only for a primitive without normals, whose
    // tangents are then dropped.)
    template <class Copy>
    static void unweldDeformation(sg::Mesh& mesh, Copy& copy) {
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

    std::string meshPrimitives(size_t mi, const std::vector<std::pair<int, int>>*& out) {
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

    // ---- 8. Nodes, cameras, lights --------------------------------------------------------
    sg::Camera camera(int ci) const {
        const tinygltf::Camera& c = m.cameras[size_t(ci)];
        sg::Camera cam;
        if (c.type == "perspective") {
            cam.projection.type = sg::ProjectionType::Perspective;
            cam.projection.fovyDeg = std::clamp(sg::degrees(float(c.perspective.yfov)), 0.01f, 179.0f);
            cam.projection.zNear = float(c.perspective.znear);
            cam.projection.zFar = c.perspective.zfar > 0 ? float(c.perspective.zfar) : std::max(1000.0f * cam.projection.zNear, 100.0f);
        } else {
            cam.projection.type = sg::ProjectionType::Orthographic;
            cam.projection.orthoHalfHeight = std::abs(float(c.orthographic.ymag));
            cam.projection.zNear = float(c.orthographic.znear);
            cam.projection.zFar = float(c.orthographic.zfar);
        }
        return cam;
    }
    sg::Light light(int li) const {
        const tinygltf::Light& l = m.lights[size_t(li)];
        sg::Light o;
        o.type = l.type == "directional" ? sg::LightType::Directional : l.type == "spot" ? sg::LightType::Spot : sg::LightType::Point;
        if (l.color.size() == 3) o.color = glm::max(sg::vec3(float(l.color[0]), float(l.color[1]), float(l.color[2])), sg::vec3(0.0f));
        o.intensity = float(std::min(l.intensity, 1e6));
        o.inverseSquare = o.type != sg::LightType::Directional;
        if (o.type == sg::LightType::Spot) {
            o.spotOuterDeg = sg::degrees(float(l.spot.outerConeAngle));
            o.spotInnerDeg = std::min(sg::degrees(float(l.spot.innerConeAngle)), o.spotOuterDeg);
        }
        return o;
    }

    static sg::LocalTransform localOf(const tinygltf::Node& n) {
        if (n.matrix.size() == 16) {
            sg::mat4 mm;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) mm[c][r] = float(n.matrix[size_t(c * 4 + r)]);
            return sg::LocalTransform::fromMatrix(mm);
        }
        sg::vec3 t(0.0f), s(1.0f);
        sg::quat q(1, 0, 0, 0);
        if (n.translation.size() == 3) t = sg::vec3(float(n.translation[0]), float(n.translation[1]), float(n.translation[2]));
        if (n.scale.size() == 3) s = sg::vec3(float(n.scale[0]), float(n.scale[1]), float(n.scale[2]));
        if (n.rotation.size() == 4) {
            q = sg::quat(float(n.rotation[3]), float(n.rotation[0]), float(n.rotation[1]), float(n.rotation[2]));
            float len = glm::length(q);
            q = len > 1e-12f ? q / len : sg::quat(1, 0, 0, 0);
        }
        return sg::LocalTransform::fromTRS(t, q, s);
    }

    // A node's skin (the index is the same in our Scene::skins) and its own morph weights.
    void setSkinAndWeights(const tinygltf::Node& n, sg::MeshInstance& inst) {
        const sg::Mesh& mesh = *scene.meshes[size_t(inst.mesh)];
        if (n.skin >= 0 && mesh.skinned()) {
            inst.skin = n.skin;
            const size_t joints = m.skins[size_t(n.skin)].joints.size();
            uint16_t most = 0;
            for (const auto* set : {&mesh.joints0, &mesh.joints1})
                for (const sg::u16vec4& j : *set) most = std::max({most, j.x, j.y, j.z, j.w});
            if (most >= joints)
                warnOnce("mesh '" + mesh.name + "' names joint " + std::to_string(most) + " of skin " + std::to_string(n.skin) + ", which has " +
                         std::to_string(joints) + " joints; those influences are ignored");
        }
        for (double w : n.weights) inst.weights.push_back(std::isfinite(w) ? float(w) : 0.0f);
    }

    // Scene::skins from the file's skins (after buildNodes: joints not in the loaded scene
    // become kNoNode, which poses as the identity). Non-finite matrices become the identity.
    std::string convertSkins() {
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

    std::string buildNodes(const std::vector<int>& roots) {
        sgOf.assign(m.nodes.size(), sg::kNoNode);
        instancesOf.assign(m.nodes.size(), {});
        scene.reserveNodes(std::min<size_t>(m.nodes.size(), kMaxNodes) + 8);   // one node each at least, and the default camera and light
        std::vector<std::pair<int, sg::NodeId>> stack;
        for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, scene.root()});
        size_t done = 0, created = 0;
        while (!stack.empty()) {
            auto [gi, parent] = stack.back();
            stack.pop_back();
            if ((++done & 4095) == 0) {
                if (progress.cancelled()) return "cancelled";
                progress.set(0.5f + 0.4f * float(done) / float(std::max<size_t>(m.nodes.size(), 1)));
            }
            const tinygltf::Node& n = m.nodes[size_t(gi)];
            std::string name = n.name.empty() ? "node " + std::to_string(gi) : n.name;
            const std::vector<std::pair<int, int>>* prims = nullptr;
            if (n.mesh >= 0) {
                std::string e = meshPrimitives(size_t(n.mesh), prims);
                if (!e.empty()) return e;
            }
            int li = nodeLight(n);
            size_t payloads = (prims ? prims->size() : 0) + (n.camera >= 0) + (li >= 0);
            if (++created + payloads > kMaxNodes) return "node budget of " + std::to_string(kMaxNodes) + " exceeded";
            sg::NodeId id = scene.addNode(name, parent);
            scene.setLocal(id, localOf(n));
            sgOf[size_t(gi)] = id;
            bool onNode = payloads == 1;
            if (prims) {
                for (size_t k = 0; k < prims->size(); ++k) {
                    sg::MeshInstance inst{(*prims)[k].first, (*prims)[k].second};
                    setSkinAndWeights(n, inst);
                    if (onNode)
                        scene.setPayload(id, inst);
                    else
                        scene.addNode(name + "#" + std::to_string(k), id, inst), ++created;
                    instancesOf[size_t(gi)].push_back(onNode ? id : scene.node(id).children.back());
                }
            }
            if (n.camera >= 0) {
                sg::NodeId cid = onNode ? id : scene.addNode(name + " camera", id);
                scene.setPayload(cid, camera(n.camera));
                if (!scene.valid(scene.activeCamera)) scene.activeCamera = cid;
            }
            if (li >= 0) {
                sg::NodeId lid = onNode ? id : scene.addNode(name + " light", id);
                scene.setPayload(lid, light(li));
            }
            for (auto it = n.children.rbegin(); it != n.children.rend(); ++it) stack.push_back({*it, id});
        }
        return {};
    }

    // ---- 9. Animations ---------------------------------------------------------------------
    // The morph target count of a node's mesh (its first primitive; glTF requires all
    // primitives of a mesh to have the same number), 0 without a mesh.
    size_t targetCount(int node) const {
        int mi = m.nodes[size_t(node)].mesh;
        if (mi < 0 || m.meshes[size_t(mi)].primitives.empty()) return 0;
        return m.meshes[size_t(mi)].primitives[0].targets.size();
    }

    // Path, target node and interpolation of channel `ci` into `out`; "" or why it is skipped.
    std::string channelTarget(const tinygltf::Animation& ga, size_t ci, AnimationChannel& out) const {
        const auto& ch = ga.channels[ci];
        if (ch.target_path == "translation")
            out.path = AnimationPath::Translation;
        else if (ch.target_path == "rotation")
            out.path = AnimationPath::Rotation;
        else if (ch.target_path == "scale")
            out.path = AnimationPath::Scale;
        else if (ch.target_path == "weights")
            out.path = AnimationPath::Weights;
        else
            return "'" + ch.target_path + "' animation is not supported";
        if (ch.sampler < 0 || size_t(ch.sampler) >= ga.samplers.size()) return "sampler does not exist";
        if (ch.target_node < 0 || size_t(ch.target_node) >= m.nodes.size()) return "target node does not exist";
        const auto& s = ga.samplers[size_t(ch.sampler)];
        if (s.interpolation == "STEP")
            out.interpolation = AnimationInterpolation::Step;
        else if (s.interpolation == "CUBICSPLINE")
            out.interpolation = AnimationInterpolation::CubicSpline;
        else if (s.interpolation == "LINEAR" || s.interpolation.empty())
            out.interpolation = AnimationInterpolation::Linear;
        else
            return "unknown interpolation '" + s.interpolation + "'";
        if (out.path == AnimationPath::Weights && (out.width = targetCount(ch.target_node)) == 0) return "weights of a node without morph targets";
        return {};
    }

    // Key times and values of the channel's sampler (types and counts checked, times finite and
    // increasing, values finite); "" or why the channel is skipped.
    std::string readKeys(const tinygltf::AnimationSampler& s, AnimationChannel& out) {
        if (s.input < 0 || size_t(s.input) >= m.accessors.size() || s.output < 0 || size_t(s.output) >= m.accessors.size())
            return "sampler accessors do not exist";
        const auto& in = m.accessors[size_t(s.input)];
        const auto& op = m.accessors[size_t(s.output)];
        const bool weights = out.path == AnimationPath::Weights;
        int want = weights ? TINYGLTF_TYPE_SCALAR : out.path == AnimationPath::Rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3;
        uint64_t perKey = (out.interpolation == AnimationInterpolation::CubicSpline ? 3 : 1) * (weights ? out.width : 1);
        if (in.type != TINYGLTF_TYPE_SCALAR || in.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || op.type != want || in.count == 0 ||
            op.count != in.count * perKey)
            return "sampler input/output accessors have the wrong type or count";
        std::vector<sg::vec4> t4, v4;
        if (!readVectors(m, size_t(s.input), 1, progress, t4).empty() || !readVectors(m, size_t(s.output), weights ? 1 : 4, progress, v4).empty())
            return "cannot read keyframes";
        out.times.resize(t4.size());
        bool ok = true;
        for (size_t k = 0; k < t4.size(); ++k) {
            out.times[k] = t4[k].x;
            if (!std::isfinite(out.times[k]) || (k > 0 && out.times[k] <= out.times[k - 1])) ok = false;
        }
        for (const auto& v : v4)
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z) || !std::isfinite(v.w)) ok = false;
        if (!ok) return "key times must be finite and increasing, values finite";
        if (weights)
            for (const auto& v : v4) out.weights.push_back(v.x);
        else
            out.values = std::move(v4);
        return {};
    }

    std::vector<AnimationClip> animations() {
        std::vector<AnimationClip> clips;
        for (size_t ai = 0; ai < m.animations.size(); ++ai) {
            const tinygltf::Animation& ga = m.animations[ai];
            AnimationClip clip;
            clip.name = ga.name.empty() ? "animation " + std::to_string(ai) : ga.name;
            float tmin = std::numeric_limits<float>::infinity(), tmax = 0.0f;
            for (size_t ci = 0; ci < ga.channels.size(); ++ci) {
                std::string id = "animation " + std::to_string(ai) + " channel " + std::to_string(ci) + ": ";
                AnimationChannel out;
                std::string why = channelTarget(ga, ci, out);
                if (why.empty()) {
                    out.node = sgOf[size_t(ga.channels[ci].target_node)];
                    if (out.node == sg::kNoNode) continue;   // node not in the loaded scene
                    why = readKeys(ga.samplers[size_t(ga.channels[ci].sampler)], out);
                }
                if (!why.empty()) {
                    warnOnce(id + why + "; channel skipped");
                    continue;
                }
                tmin = std::min(tmin, out.times.front());
                tmax = std::max(tmax, out.times.back());
                if (out.path != AnimationPath::Weights) {
                    clip.channels.push_back(std::move(out));
                    continue;
                }
                // Morph weights go to every MeshInstance of the node (one per primitive).
                for (sg::NodeId inst : instancesOf[size_t(ga.channels[ci].target_node)]) {
                    clip.channels.push_back(out);
                    clip.channels.back().node = inst;
                }
            }
            if (clip.channels.empty()) continue;
            clip.start = std::isfinite(tmin) ? tmin : 0.0f;
            clip.duration = tmax;
            clips.push_back(std::move(clip));
        }
        return clips;
    }
};

}   // namespace

// ---- 10. loadGltf ----------------------------------------------------------------------------
namespace {

// Checks the size limits and, for GLB, the header; sets `json` to the JSON text. "" or the reason.
std::string locateJson(const std::string& bytes, const fs::path& path, bool& binary, std::string_view& json) {
    binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    json = bytes;
    if (binary) {
        if (bytes.size() < 20) return "GLB file is truncated (" + std::to_string(bytes.size()) + " bytes)";
        uint32_t chunkLen = 0, chunkType = 0, total = 0;
        std::memcpy(&total, bytes.data() + 8, 4);
        std::memcpy(&chunkLen, bytes.data() + 12, 4);
        std::memcpy(&chunkType, bytes.data() + 16, 4);
        if (chunkType != 0x4E4F534Au) return "GLB: first chunk is not JSON";
        if (uint64_t(chunkLen) + 20 > bytes.size())
            return "GLB: JSON chunk length " + std::to_string(chunkLen) + " exceeds the file size " + std::to_string(bytes.size());
        if (total > bytes.size())
            return "GLB: header length " + std::to_string(total) + " exceeds the file size " + std::to_string(bytes.size()) + " (truncated file?)";
        json = std::string_view(bytes.data() + 20, chunkLen);
    } else if (path.extension() == ".glb" || path.extension() == ".GLB") {
        return "not a GLB file (no 'glTF' magic)";
    }
    if (json.size() > kMaxJsonBytes) return "JSON is " + std::to_string(json.size()) + " bytes, limit " + std::to_string(kMaxJsonBytes);
    if (jsonDepth(json.data(), json.size(), kMaxJsonDepth) > kMaxJsonDepth)
        return "JSON nesting deeper than " + std::to_string(kMaxJsonDepth) + " levels";
    if (bytes.size() > UINT32_MAX) return "file larger than 4 GB";
    return {};
}

// tinygltf parses `bytes` with our file-system and image callbacks (which confine reads to the
// file's folder and keep images undecoded). "" or the reason.
std::string parseModel(const std::string& bytes, bool binary, Ctx& ctx, tinygltf::Model& model) {
    ctx.model = &model;
    tinygltf::TinyGLTF loader;
    tinygltf::FsCallbacks cb{};
    cb.FileExists = &fsFileExists;
    cb.ExpandFilePath = &fsExpand;
    cb.ReadWholeFile = &fsRead;
    cb.WriteWholeFile = &fsWrite;
    cb.user_data = &ctx;
    loader.SetFsCallbacks(cb);
    loader.SetImageLoader(&storeImage, &ctx);
    std::string terr, twarn;
    bool ok = false;
    const std::string base = ctx.dir.root().string();
    try {
        if (binary)
            ok = loader.LoadBinaryFromMemory(&model, &terr, &twarn, reinterpret_cast<const unsigned char*>(bytes.data()), unsigned(bytes.size()),
                                             base, 0);
        else
            ok = loader.LoadASCIIFromString(&model, &terr, &twarn, bytes.data(), unsigned(bytes.size()), base, 0);
    } catch (const std::bad_alloc&) { return "out of memory while parsing"; } catch (const std::exception& e) {
        return std::string("parse error: ") + e.what();
    }
    ctx.parserWarning = oneLine(twarn);
    if (ok) return {};
    std::string why = oneLine(terr.empty() ? "tinygltf could not parse the file" : terr);
    if (!ctx.refused.empty() && why.find("File not found") != std::string::npos) return ctx.refused.front() + " (" + why + ")";
    if (!ctx.refused.empty() && why.find("read error") != std::string::npos) return ctx.refused.front();
    return why;
}

// Required extensions we cannot honour make the file unloadable (the spec says so). "" or why.
std::string checkRequiredExtensions(const tinygltf::Model& model) {
    static const char* kSupported[] = {"KHR_materials_unlit",
                                       "KHR_texture_transform",
                                       "KHR_lights_punctual",
                                       "KHR_materials_pbrSpecularGlossiness",
                                       "KHR_materials_emissive_strength",
                                       "KHR_mesh_quantization"};   // quantized attributes: any component type is read
    for (const std::string& ext : model.extensionsRequired)
        if (std::none_of(std::begin(kSupported), std::end(kSupported), [&](const char* s) { return ext == s; }))
            return "requires the unsupported extension " + ext;
    if (model.asset.version.rfind("2.", 0) != 0) return "glTF version '" + model.asset.version + "' is not 2.x";
    return {};
}

// The root nodes to load: the default scene's (or the first), else every node without a parent.
// Fills result.sceneNames / loadedScene and says which scenes were left out.
std::vector<int> chooseRoots(const tinygltf::Model& model, const std::string& file, LoadResult& result) {
    for (size_t i = 0; i < model.scenes.size(); ++i)
        result.sceneNames.push_back(model.scenes[i].name.empty() ? "scene " + std::to_string(i) : model.scenes[i].name);
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        result.loadedScene = model.defaultScene >= 0 ? model.defaultScene : 0;
        roots = model.scenes[size_t(result.loadedScene)].nodes;
        if (model.scenes.size() > 1) {
            std::string others;
            for (size_t i = 0; i < model.scenes.size(); ++i)
                if (int(i) != result.loadedScene) others += (others.empty() ? "'" : ", '") + result.sceneNames[i] + "'";
            result.warnings.push_back(file + ": loaded scene '" + result.sceneNames[size_t(result.loadedScene)] + "'; other scenes: " + others);
        }
        return roots;
    }
    std::vector<uint8_t> isChild(model.nodes.size(), 0);
    for (const auto& n : model.nodes)
        for (int c : n.children) isChild[size_t(c)] = 1;
    for (size_t i = 0; i < model.nodes.size(); ++i)
        if (!isChild[i]) roots.push_back(int(i));
    result.warnings.push_back(
        file + (roots.empty() ? ": the file contains no nodes" : ": no scenes; loading all " + std::to_string(roots.size()) + " root nodes"));
    return roots;
}

// The validated model -> result.scene (+ animations, warnings). "" or the reason.
std::string convertModel(tinygltf::Model& model, Ctx& ctx, const Progress& progress, const fs::path& path, LoadResult& result) {
    const std::string file = fileNameOf(path);
    Converter conv(model, ctx, progress);
    conv.file = file;
    conv.scene.name = path.stem().string();
    conv.textureOf.assign(model.textures.size(), {-2, -2});
    conv.decodedImage.assign(model.images.size(), nullptr);
    conv.imageTried.assign(model.images.size(), 0);
    conv.meshPrims.resize(model.meshes.size());
    conv.meshDone.assign(model.meshes.size(), 0);
    try {
        conv.convertMaterials();
        progress.set(0.4f);
        std::string e = conv.buildNodes(chooseRoots(model, file, result));
        if (!e.empty()) return e;
        if (!(e = conv.convertSkins()).empty()) return e;
        result.animations = conv.animations();
    } catch (const std::bad_alloc&) { return "out of memory while building the scene"; }
    progress.set(0.95f);
    // The file's nodes (~480 bytes each in tinygltf) and the per-node tables are done with: free
    // them before the scene builds its caches (traversal order, world matrices), so that a file
    // of 1M nodes peaks at tinygltf's own parse peak instead of ~330 MB above it (bench_import).
    std::vector<tinygltf::Node>().swap(model.nodes);
    std::vector<std::vector<sg::NodeId>>().swap(conv.instancesOf);
    std::vector<sg::NodeId>().swap(conv.sgOf);
    releaseFreedMemory();
    addDefaultCameraAndLight(conv.scene);
    for (auto& w : conv.warnings) result.warnings.push_back(file + ": " + w);
    result.scene = std::move(conv.scene);
    return {};
}

}   // namespace

LoadResult loadGltf(const fs::path& path, const LoadOptions& options) {
    LoadResult result;
    const std::string file = fileNameOf(path);
    Progress progress{options};
    auto fail = [&](const std::string& why) {
        result.scene.reset();
        result.error = file + ": " + why;
        return std::move(result);
    };
    std::string bytes;
    if (std::string err = readFileLimited(path, kMaxFileBytes, bytes); !err.empty()) {
        result.error = err;
        return result;
    }
    if (bytes.empty()) return fail("empty file");
    progress.set(0.02f);
    bool binary = false;
    std::string_view json;
    if (std::string e = locateJson(bytes, path, binary, json); !e.empty()) return fail(e);

    Ctx ctx(path.parent_path().empty() ? fs::path(".") : path.parent_path());
    if (!ctx.dir.ok()) return fail(ctx.dir.error());
    tinygltf::Model model;
    std::string e = parseModel(bytes, binary, ctx, model);
    std::string().swap(bytes);
    if (!e.empty()) return fail(e);
    releaseFreedMemory();   // tinygltf's JSON tree is gone: give its pages back before the scene is built
    progress.set(0.3f);
    // Files we refused or could not read (images: the load goes on without them).
    for (const std::string& why : ctx.refused) result.warnings.push_back(file + ": file not read: " + why);
    if (!ctx.parserWarning.empty() && ctx.refused.empty()) result.warnings.push_back(file + ": " + ctx.parserWarning);
    for (const auto& w : ctx.imageWarnings) result.warnings.push_back(file + ": " + w);
    if (!(e = checkRequiredExtensions(model)).empty()) return fail(e);

    std::vector<std::string> vwarn;
    if (!(e = validate(model, vwarn)).empty()) return fail(e);
    for (auto& w : vwarn) result.warnings.push_back(file + ": " + w);
    if (progress.cancelled() || !(e = convertModel(model, ctx, progress, path, result)).empty()) return fail(e.empty() ? "cancelled" : e);
    progress.set(1.0f);
    return result;
}

}   // namespace assets::detail
