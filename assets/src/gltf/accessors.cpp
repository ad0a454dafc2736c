// accessors.cpp - glTF accessors: component and element sizes (with the column padding of small
// matrices), strides and index reading. The readers that run per element (readComponent,
// readIndex, forEachElement, readVectors) are inline in gltf_internal.h.
#include "gltf_internal.h"

namespace assets::detail::gltf {

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

std::string readIndices(const tinygltf::Model& m, size_t ai, const Progress& progress, std::vector<uint32_t>& out) {
    const tinygltf::Accessor& a = m.accessors[ai];
    out.assign(a.count, 0);
    const int ct = a.componentType;
    uint32_t* dst = out.data();
    return forEachElement(m, ai, progress, [&](size_t i, const unsigned char* p) { dst[i] = readIndex(p, ct); });
}

std::string prefixed(const std::string& id, const std::string& e) { return e.empty() || e == "cancelled" ? e : id + e; }

}   // namespace assets::detail::gltf
