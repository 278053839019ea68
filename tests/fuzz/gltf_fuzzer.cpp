// libFuzzer target for the glTF/glb scene loader (engine/scene/gltf_loader.cpp):
// the input's bytes are a .gltf text or, when they start with "glTF", a .glb.
// External files are not read (LoadOptions::externalFiles = false), so the
// loader sees only the input and data: URIs. Any crash, sanitizer report or
// leak is a bug to fix in the loader; an error Status is the expected answer.
// Built and run by tests/fuzz/CMakeLists.txt (clang, -fsanitize=fuzzer,address,undefined).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/log.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    bb::setLogLevel(bb::LogLevel::Quiet);  // warnings for every odd input would drown the fuzzer's output
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    bb::LoadOptions options;
    options.externalFiles = false;
    std::vector<unsigned char> bytes(data, data + size);
    auto scene = bb::loadSceneFromMemory(std::move(bytes), "fuzz.gltf", "/nonexistent-bundlebake-fuzz", options);
    if (scene) {
        // touch what the baker reads first, so lies about counts surface here
        volatile size_t triangles = scene->triangleCount();
        (void)triangles;
    }
    return 0;
}
