// scene_json.cpp - the native scene file (JSON, nlohmann-json): its format, and the base64 its
// embedded PNGs use. The reader is scene_json_read.cpp, the writer scene_json_write.cpp; what they
// share is in scene_json_internal.h.
//
// Format (version 1). Every array of numbers is plain JSON numbers; matrices are 16 numbers in
// column-major order (as GLM stores them); quaternions are [x, y, z, w]; colours linear RGB.
// Floats are written in the fewest digits that read back to the same bits (up to +-3.40282347e+38);
// a NaN or an infinity has no JSON spelling, and a scene holding one is not saved.
//   {
//     "format": "sceneviewer", "version": 1, "name": "...",
//     "activeCamera": <node index or null>,
//     "settings":  { every row of the render-settings table in scenegraph/params.h by its key:
//                    "shading": <ShadingModel>, "reflection", "attenuation", "ambientLight",
//                    "fog": {"mode": <FogMode>, "color": [..], "start", "end", "density"},
//                    "exposure": EV, "toneMapping": <ToneMapping>,
//                    "aa": <AAChoice>, "aaRate", "culling": <CullMode>, "wireframe", ... }
//                  (older files: "cullBackFaces": bool; "ambientLight" at the top level),
//     "textures":  [ {"name", "file": "relative/path.png"} | {"name", "png": "<base64 PNG>"},
//                    + "wrapS"/"wrapT": <WrapMode>, "filter": <FilterMode>,
//                    "srgb": false for data textures (metallic-roughness, occlusion) ],
//     "materials": [ {"name", the texture indices "diffuseTexture", "emissiveTexture",
//                     "occlusionTexture", "normalTexture", "metallicRoughnessTexture",
//                     "uv1Maps": the maps that sample the mesh's uv1, any of ["emissive",
//                     "occlusion", "metallicRoughness", "normal"], and every row of the
//                     material table in params.h ("baseColor", "ka", "kd", "ks", ...)} ],
//     "meshes":    [ {"name", "file": "relative/model.obj"} |
//                    {"name", "mode": "triangles|lines|points", "positions": [x,y,z,...],
//                     "normals", "uv0", "uv1", "colors" (4 per vertex), "tangents" (4 per
//                     vertex: xyz, handedness), "indices",
//                     skin: "joints0", "weights0", "joints1", "weights1" (4 per vertex),
//                     morph: "morphTargets": [ {"positions", "normals", "tangents"} (3 per
//                     vertex each) ], "morphWeights": [one per target]} ],
//     "nodes":     [ {"name", "parent": <index, absent for node 0 = root>, "visible",
//                     "transform": {"translation", "rotation", "scale"} | {"matrix": [16]},
//                     one optional payload:
//                     "mesh": {"mesh", "material", "skin", "weights"} | "camera": {...} |
//                     "light": {...} | "implicit": {...} | "csg": {"op", "material"} |
//                     "parametric": {...} | "grid": {"dims", "values", "iso", "bounds", "material"} } ],
//     "skins":     [ {"name", "joints": [node index, or null for a joint no longer in the
//                     scene], "inverseBindMatrices": [16 per joint, column-major],
//                     "skeleton": <node index or null>} ]
//   }
// Animation clips are not part of the format (convert says so); a skinned or morphed scene is
// saved in the pose it has (node transforms and MeshInstance weights as they are).
// Camera payloads hold the projection table's rows plus "frustum": [l, r, b, t] and
// "focusDistance"; light payloads the light table's rows. Every value of a table row is checked
// against the row's range, and the error names its JSON path.
// <Enum> is a name from that enum's table in scenegraph/setting_names.h (camera "type":
// <ProjectionType>, light "type": <LightType>); the writer writes the table's name, the reader
// also accepts the table's aliases.
// Nodes are a flat array with parent indices (not nested), so arbitrarily deep graphs need no
// recursion; parents may appear in any order, cycles are rejected.
#include "scene_json_internal.h"

#include <algorithm>
#include <iterator>

namespace assets::scene_json {

namespace {
const char kB64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
}   // namespace

std::string base64Encode(std::string_view in) {
    std::string out;
    out.reserve((in.size() + 2) / 3 * 4);
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        uint32_t v = uint8_t(in[i]) << 16 | uint8_t(in[i + 1]) << 8 | uint8_t(in[i + 2]);
        for (int k = 3; k >= 0; --k) out += kB64[(v >> (6 * k)) & 63];
    }
    if (i < in.size()) {
        uint32_t v = uint8_t(in[i]) << 16 | (i + 1 < in.size() ? uint8_t(in[i + 1]) << 8 : 0);
        out += kB64[(v >> 18) & 63];
        out += kB64[(v >> 12) & 63];
        out += i + 1 < in.size() ? kB64[(v >> 6) & 63] : '=';
        out += '=';
    }
    return out;
}

bool base64Decode(std::string_view in, std::string& out) {
    int8_t table[256];
    std::fill(std::begin(table), std::end(table), int8_t(-1));
    for (int i = 0; i < 64; ++i) table[uint8_t(kB64[i])] = int8_t(i);
    out.clear();
    uint32_t acc = 0;
    int bits = 0;
    for (char c : in) {
        if (c == '=') break;
        int8_t v = table[uint8_t(c)];
        if (v < 0) return false;
        acc = (acc << 6) | uint32_t(v);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out += char((acc >> bits) & 0xFF);
        }
    }
    return true;
}

}   // namespace assets::scene_json
