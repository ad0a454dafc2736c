// fuzz_loader.cpp - one libFuzzer entry point compiled once per format (FUZZ_TARGET_*).
// Loaders read files (they confine references to the model's folder), so each input is
// written to a private temporary folder with the right extension and loaded from there; a
// successful load is flattened as a renderer would see it.
#include "assets/image_io.h"
#include "assets/scene_io.h"
#include "scenegraph/frame.h"

#include <unistd.h>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace {

[[maybe_unused]] const char* extension() {
#if defined(FUZZ_TARGET_SCENE_JSON)
    return ".json";
#elif defined(FUZZ_TARGET_GLTF)
    return ".gltf";
#elif defined(FUZZ_TARGET_GLB)
    return ".glb";
#elif defined(FUZZ_TARGET_OBJ)
    return ".obj";
#elif defined(FUZZ_TARGET_PLY)
    return ".ply";
#elif defined(FUZZ_TARGET_OFF)
    return ".off";
#elif defined(FUZZ_TARGET_STL)
    return ".stl";
#else
    return ".png";
#endif
}

[[maybe_unused]] const fs::path& workDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("viewer-fuzz-" FUZZ_NAME "-" + std::to_string(getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

}   // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
#if defined(FUZZ_TARGET_IMAGE)
    assets::ImageLoad img = assets::decodeImage(data, size, "fuzz.png");
    if (img.texture && (img.texture->rgba.size() != size_t(img.texture->width) * img.texture->height * 4)) __builtin_trap();
    return 0;
#else
    fs::path file = workDir() / (std::string("input") + extension());
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    }
    assets::LoadResult r = assets::loadScene(file);
    if (r.scene) {
        sg::FrameInput f = sg::flatten(*r.scene, 1.5f);
        size_t tris = 0;
        for (const auto& m : f.meshes) {
            std::string why = m.mesh->validate();
            if (!why.empty()) {   // loaders must hand out valid meshes
                std::fprintf(stderr, "invalid mesh from the loader: %s\n", why.c_str());
                __builtin_trap();
            }
            tris += m.mesh->triangleCount();
        }
        (void)tris;
    } else if (r.error.empty()) {
        __builtin_trap();   // a failed load must say why
    }
    return 0;
#endif
}
