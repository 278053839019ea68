#version 430
// Distance from the sample point (an emitter sample, a point or spot light);
// a cut-out's cut-away part casts no shadow.
#include "shared/mesh_layout.h"
#include "shared/material_layout.h"
#include "lib/alpha_mask.glsl"
in vec3 vPosition;
in vec2 vUv0;
flat in uint vMaterial;
flat in uint vFlags;
uniform vec3 samplePoint;
layout(location = 0) out float outDistance;
void main() {
    if ((vFlags & TRIANGLE_ALPHA_MASK) != 0u && alphaCut(vMaterial, vUv0)) discard;
    outDistance = distance(vPosition, samplePoint);
}
