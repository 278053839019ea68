// The BakeVertex attribute layout for GL (glsl/lib/bake_vertex.glsl), defined
// once for every pass that draws a BakeMesh: location 0 position, 1 normal,
// 2 uv0, 3 lightmapUv, all from binding 0. Requires a current context.
#pragma once

#include <string>

#include "gl/objects.h"

namespace bb {

gl::VertexArray createBakeVertexArray(const std::string& label, const gl::Buffer& vertices);

}  // namespace bb
