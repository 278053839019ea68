// The BakeVertex attributes (engine/layout/bake_mesh.h) and per-triangle data.
layout(location = 0) in vec4 inPosition;    // world, w = 1
layout(location = 1) in vec4 inNormal;      // world unit normal, w = 0
layout(location = 2) in vec2 inUv0;         // material texture coordinates
layout(location = 3) in vec2 inLightmapUv;  // page-space light map coordinates

#include "shared/mesh_layout.h"

// Per-triangle SSBOs are bound one chunk at a time (MeshChunks in
// engine/layout/bake_mesh_gl.h: each range fits GL_MAX_SHADER_STORAGE_BLOCK_SIZE):
// mesh triangle t is element t - meshChunkFirstTriangle of a bound range.
// gl_VertexID is the mesh's (draws are split at chunk boundaries, not rebased).
uniform uint meshChunkFirstTriangle;

// uvec4(material, page, instance, flags) per triangle; triangle = gl_VertexID / 3.
layout(std430, binding = MESH_BINDING_TRIANGLES) readonly buffer Triangles { uvec4 triangles[]; };

// BakeTriangle of mesh triangle t (in the bound chunk).
uvec4 bakeTriangle(uint t) { return triangles[t - meshChunkFirstTriangle]; }
