// Limits and quirks of the current GL, queried once at start-up. Nothing in
// the engine hard-codes a limit: read it from here.
#pragma once

#include <cstdint>
#include <string>

namespace bb::gl {

struct Caps {
    std::string vendor, renderer, version, glslVersion;
    int major = 0, minor = 0;
    int64_t maxShaderStorageBlockSize = 0;   // bytes; 128 MiB on llvmpipe: caps one node buffer binding
    int maxTextureSize = 0;                  // texels per side of a 2D texture (head image, light map pages)
    int maxViewportWidth = 0, maxViewportHeight = 0;
    int maxFramebufferWidth = 0, maxFramebufferHeight = 0;
    int maxComputeWorkGroupInvocations = 0;
    int maxAtomicCounterBufferBindings = 0;
    bool khrDebug = false;
    // Driver quirks, one named flag each with why:
    // llvmpipe rasterizes on the CPU; a single global atomic counter serializes
    // appends (~20-30 M fragments/s on 2 cores). Informational, used by bench.
    bool isLlvmpipe = false;

    std::string describe() const;  // one line: renderer, version, key limits
};

}  // namespace bb::gl
