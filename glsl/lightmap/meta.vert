#version 430
// Meta pass (Unity's name for it): the surface rasterized into light map
// space, for the coverage (once) and the outgoing radiance Lo = Le + albedo *
// L_lm the bundle pass reads (each refresh; meta.frag), and the partial
// texels (layout/bake_mesh.h texelOwners), which the raster misses, as points.
#include "lib/bake_vertex.glsl"

out vec2 vUv0;

void main() {
    gl_Position = vec4(inLightmapUv * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = 1.0;  // partial texels are drawn as points (engine/bake/baker_impl.h partialRuns)
    vUv0 = inUv0;
}
