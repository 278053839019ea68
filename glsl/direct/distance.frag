#version 430
// Distance from the sample point (an emitter sample, a point or spot light);
// a cut-out's cut-away part casts no shadow, nor does the emitter triangle
// the sample lies on: its plane passes through the sample point (a hair's
// breadth off it), and the rays that leave the point within a degree or so
// of that plane read it as the nearest surface. A double-sided emitter's
// back lights a ceiling just above it along such rays (the shared Cornell
// box's light, 0.9 mm under its ceiling).
#include "shared/mesh_layout.h"
#include "shared/material_layout.h"
#include "lib/alpha_mask.glsl"
in vec3 vPosition;
in vec2 vUv0;
flat in uint vMaterial;
flat in uint vFlags;
flat in uint vTriangle;
uniform vec3 samplePoint;
uniform uint ownTriangle;  // the emitter sample's triangle (none: 0xffffffff)
// the distance's bits and the surface's plane normal (either way), octahedral
// as two snorm16 (lib/cube_visibility.glsl)
layout(location = 0) out uvec2 outDistance;

vec2 octahedralEncode(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return n.xy;
}

void main() {
    vec3 facet = cross(dFdx(vPosition), dFdy(vPosition));
    if (vTriangle == ownTriangle) discard;
    if ((vFlags & TRIANGLE_ALPHA_MASK) != 0u && alphaCut(vMaterial, vUv0)) discard;
    // a degenerate facet: a plane facing the light point, as good as the receiver's test alone
    vec3 n = length(facet) > 0.0 ? facet : vPosition - samplePoint;
    outDistance = uvec2(floatBitsToUint(distance(vPosition, samplePoint)), packSnorm2x16(octahedralEncode(n)));
}
