// materials.cpp - glTF materials, textures and images -> our materials and textures (the mapping
// is documented in gltf_internal.h): images decoded on first use within a byte budget, textures
// with their samplers (an sRGB colour or a linear data copy each), metallic-roughness and
// specular-glossiness -> Phong, and the UV channels (TEXCOORD set + KHR_texture_transform) a
// material's textures sample.
#include "gltf_internal.h"

#include "assets/image_io.h"

#include <cmath>

namespace assets::detail::gltf {

namespace {

// The TexRef of a core textureInfo, of the occlusion / normal texture infos (their own types in
// tinygltf) and of a textureInfo inside an extension object.
TexRef texRef(const tinygltf::TextureInfo& t) { return {t.index, t.texCoord, extensionObject(t.extensions, "KHR_texture_transform")}; }
TexRef texRef(int index, int texCoord, const tinygltf::ExtensionMap& ext) { return {index, texCoord, extensionObject(ext, "KHR_texture_transform")}; }
TexRef texRef(const tinygltf::Value& v) {   // a textureInfo inside an extension object
    TexRef r{int(numberOr(v, "index", -1)), int(numberOr(v, "texCoord", 0)), nullptr};
    if (v.Has("extensions") && v.Get("extensions").IsObject() && v.Get("extensions").Has("KHR_texture_transform"))
        r.transform = &v.Get("extensions").Get("KHR_texture_transform");
    return r;
}

// KHR_texture_transform as a matrix in glTF's uv space: T * R * S (column-major), with
// R = [cos sin; -sin cos] as in the extension. Its texCoord override goes to texCoord.
sg::mat3 uvTransformOf(const tinygltf::Value& tt, int& texCoord) {
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

}   // namespace

sg::TexturePtr Converter::image(int ii) {
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
int Converter::texture(int ti, bool srgb) {
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

// Our meshes carry two UV sets, uv0 and uv1, with the texture transforms baked in
// (readAttributes): a material's textures may sample two different (TEXCOORD set,
// KHR_texture_transform) channels. refs: base colour, metallic-roughness, occlusion,
// emissive, normal. A texture asking for a third channel samples channel 0 (one warning);
// TEXCOORD_2 and above are read as TEXCOORD_0 (one warning).
void Converter::chooseUvChannels(size_t i, const std::vector<TexRef>& refs, MaterialInfo& info) {
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
void Converter::convertPbr(const tinygltf::Material& gm, sg::Material& mat, sg::vec4& base, std::vector<TexRef>& refs) {
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

void Converter::convertMaterial(size_t i) {
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
    if (const tinygltf::Value* ior = extensionObject(gm.extensions, "KHR_materials_ior")) {
        const double v = numberOr(*ior, "ior", 1.5);
        mat.ior = v >= 1.0 && v <= 5.0 ? float(v) : 1.5f;   // 0 (an infinite ior) and beyond the table's range: the default
    }
    if (const tinygltf::Value* sp = extensionObject(gm.extensions, "KHR_materials_specular")) {
        mat.specularFactor = float(std::clamp(numberOr(*sp, "specularFactor", 1.0), 0.0, 1.0));
        double c[3] = {1, 1, 1};
        numberArray(*sp, "specularColorFactor", 3, c);
        mat.specularColorFactor = glm::clamp(sg::vec3(float(c[0]), float(c[1]), float(c[2])), sg::vec3(0.0f), sg::vec3(1e4f));
        if (sp->Has("specularTexture") || sp->Has("specularColorTexture"))
            warnOnce("material " + std::to_string(i) + ": KHR_materials_specular's textures are not honoured (its factors are)");
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

void Converter::convertMaterials() {
    materials.resize(m.materials.size());
    for (size_t i = 0; i < m.materials.size(); ++i) convertMaterial(i);
}

}   // namespace assets::detail::gltf
