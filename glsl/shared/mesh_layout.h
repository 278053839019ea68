// Per-triangle flags of BakeTriangle (engine/layout/bake_mesh.h), shared with GLSL.
#ifndef BUNDLEBAKE_MESH_LAYOUT_H
#define BUNDLEBAKE_MESH_LAYOUT_H
#define TRIANGLE_DOUBLE_SIDED 1u
#define TRIANGLE_EMISSIVE 2u
#endif
