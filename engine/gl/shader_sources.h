// The shader table embedded at build time from glsl/ (scripts/embed_shaders.py).
// SHADER_SOURCES[i].name is the path under glsl/; i is also the `#line` source
// string number used in that file's markers.
#pragma once

namespace bb::gl {
struct ShaderSource {
    const char* name;
    const char* text;
};
extern const ShaderSource SHADER_SOURCES[];
extern const int SHADER_SOURCE_COUNT;
}  // namespace bb::gl
