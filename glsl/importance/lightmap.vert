#version 450
// Importance passes 1 and 2: every triangle in light map space, with the same
// projection as the light maps (page uv * 2 - 1, as lightmap/meta.vert). Both
// passes link this one shader and gl_Position is invariant, so pass 2 covers
// exactly the texels pass 1 wrote.
#include "lib/bake_vertex.glsl"

invariant gl_Position;
out vec3 vWorld;
flat out uint vTriangle;  // BakeMesh triangle index (glDrawArrays: gl_VertexID counts from `first`)

void main() {
    gl_Position = vec4(inLightmapUv * 2.0 - 1.0, 0.0, 1.0);
    vWorld = inPosition.xyz;
    vTriangle = uint(gl_VertexID) / 3u;
}
