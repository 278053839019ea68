#version 430
// Test kernel: materialAlpha and alphaCut (lib/alpha_mask.glsl) of material
// materials[i] at uvs[i]; out[i] = (alpha, cut ? 1 : 0).
#include "shared/material_layout.h"
#include "lib/alpha_mask.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Uvs { vec4 uvs[]; };  // xy uv, z material
layout(std430, binding = 1) writeonly buffer Out { vec2 results[]; };
uniform int count;
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= count) return;
    uint material = uint(uvs[i].z);
    results[i] = vec2(materialAlpha(material, uvs[i].xy), alphaCut(material, uvs[i].xy) ? 1.0 : 0.0);
}
