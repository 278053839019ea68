// The BakeVertex attributes (engine/layout/bake_mesh.h) and per-triangle data.
layout(location = 0) in vec4 inPosition;    // world, w = 1
layout(location = 1) in vec4 inNormal;      // world unit normal, w = 0
layout(location = 2) in vec2 inUv0;         // material texture coordinates
layout(location = 3) in vec2 inLightmapUv;  // page-space light map coordinates

// uvec4(material, page, instance, flags) per triangle; triangle = gl_VertexID / 3.
layout(std430, binding = 1) readonly buffer Triangles { uvec4 triangles[]; };

#include "shared/mesh_layout.h"
