// Bindings of the importance passes (engine/importance/importance_gl.cpp,
// glsl/importance/*), shared by C++ and GLSL. Per-triangle buffers are tight
// arrays of 4-byte values indexed like BakeMesh::triangles; the vertex buffer
// is BakeVertex (engine/layout/bake_mesh.h, 48 bytes), read by the compute
// pass as the std430 struct of shared/mesh_layout.h.
#ifndef BUNDLEBAKE_IMPORTANCE_LAYOUT_H
#define BUNDLEBAKE_IMPORTANCE_LAYOUT_H

#ifndef __cplusplus
#include "shared/mesh_layout.h"
#endif

// SSBOs (1 is lib/bake_vertex.glsl's Triangles, declared by the shared vertex shader)
#define IMPORTANCE_BINDING_VERTICES 0     // BakeVertex vertices[] (3 per triangle; compute pass)
#define IMPORTANCE_BINDING_MAX_DENSITY 2  // uint maxDensityBits[]: floatBitsToUint(I_max(t)), 0 = none
#define IMPORTANCE_BINDING_IMPORTANCE 3   // float importance[]: I(t), Eq. (4)
#define IMPORTANCE_BINDING_AREA_RATIO 4   // float areaRatio[]: A_l/A_o, Eq. (1)
// Image units
#define IMPORTANCE_IMAGE_DENSITY 0        // r32f: I(x) of Eq. (3) per texel (optional, for checks)
#define IMPORTANCE_IMAGE_POSITIONS 1      // rgba32f: the page's position buffer, xyz world, a = 1 where mapped
#define IMPORTANCE_IMAGE_TRIANGLES 2      // r32ui: its triangle index + 1, 0 = not mapped
// Attachments of the position pass
#define IMPORTANCE_OUT_POSITION 0
#define IMPORTANCE_OUT_TRIANGLE 1
// Compute work group size of the Eq. (4) pass
#define IMPORTANCE_GROUP_SIZE 64
// Eq. (1) when A_o = 0 < A_l (FLT_MAX; engine/importance/importance.h MAX_AREA_RATIO is this)
#define IMPORTANCE_MAX_AREA_RATIO 3.402823466e38
// I_max(t) where a texel centre t covers has no Eq. (3) estimate (importance.h NO_DENSITY_ESTIMATE is this)
#define IMPORTANCE_NO_DENSITY_ESTIMATE 3.402823466e38

#endif
