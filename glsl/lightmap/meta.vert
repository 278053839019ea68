#version 430
// Meta pass (Unity's name for it): surface albedo and emission rasterized
// once into light map space, so the bundle pass reads Lo = Le + albedo * L_lm
// per texel from one texture.
#include "lib/bake_vertex.glsl"

out vec2 vUv0;

void main() {
    gl_Position = vec4(inLightmapUv * 2.0 - 1.0, 0.0, 1.0);
    vUv0 = inUv0;
}
