#version 450
// Importance pass 1: the position buffer (supplement §1) of one page: the
// world position at each texel centre and which triangle is there.
#include "shared/importance_layout.h"

in vec3 vWorld;
flat in uint vTriangle;

layout(location = IMPORTANCE_OUT_POSITION) out vec4 outPosition;  // xyz world, w = 1 (mapped)
layout(location = IMPORTANCE_OUT_TRIANGLE) out uint outTriangle;  // triangle index + 1

void main() {
    outPosition = vec4(vWorld, 1.0);
    outTriangle = vTriangle + 1u;
}
