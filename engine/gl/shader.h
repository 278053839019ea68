// Programs from the shaders embedded at build time (glsl/ -> shader_sources).
// The stage comes from the file extension: .vert .geom .frag .comp.
// Every compile and link is checked; the error carries the driver's log with
// source-string numbers mapped back to glsl/ file names.
#pragma once

#include <string>
#include <vector>

#include "core/status.h"
#include "gl/objects.h"

namespace bb::gl {

// files: paths under glsl/, e.g. {"bundle/append.vert", "bundle/append.frag"}.
// defines: extra lines inserted after #version (e.g. "#define ROUNDING 1\n").
Expected<Program> buildProgram(const std::vector<std::string>& files, const std::string& defines = {});

// The embedded text of one file (with #include resolved); nullptr if absent.
const char* shaderSource(const std::string& file);

}  // namespace bb::gl
