#version 450
// Importance pass 2: for each texel centre a triangle covers, the density of
// Eq. (3) from the four nearest neighbours in the position buffer, and
// I_max(t) = max over those texels by an atomic max. The non-negative floats
// are ordered as their bit patterns, so atomicMax on floatBitsToUint is a
// float max. Mirrors texelDensity() in engine/importance/importance.cpp.
#include "shared/importance_layout.h"

flat in uint vTriangle;

// read as images: on llvmpipe imageLoad is 1.5-2x faster here than texelFetch
layout(binding = IMPORTANCE_IMAGE_POSITIONS, rgba32f) uniform readonly image2D positions;
layout(binding = IMPORTANCE_IMAGE_TRIANGLES, r32ui) uniform readonly uimage2D triangleIds;
// bound one chunk at a time (MeshChunks, as lib/bake_vertex.glsl): triangle t is element t - meshChunkFirstTriangle
layout(std430, binding = IMPORTANCE_BINDING_MAX_DENSITY) coherent buffer MaxDensity { uint maxDensityBits[]; };
uniform uint meshChunkFirstTriangle;
layout(binding = IMPORTANCE_IMAGE_DENSITY, r32f) uniform writeonly image2D densityImage;
uniform bool writeDensity;  // also store I(x) per texel (checks and figures)
uniform int resolution;     // page side in texels

// x_0..x_3 in the supplement's cyclic order
const ivec2 NEIGHBOURS[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(-1, 0), ivec2(0, -1));
const float FLT_MAX = 3.402823466e38;

void main() {
    // llvmpipe runs helper lanes through loops with undefined loads; they have
    // nothing to contribute (no derivatives are used), so leave at once (GLSL 4.50).
    if (gl_HelperInvocation) return;
    ivec2 x = ivec2(gl_FragCoord.xy);
    vec3 p = imageLoad(positions, x).xyz;
    float count = 0.0, sum = 0.0;
    for (int i = 0; i < 4; ++i) {
        ivec2 xi = x + NEIGHBOURS[i];
        if (any(lessThan(xi, ivec2(0))) || any(greaterThanEqual(xi, ivec2(resolution)))) continue;
        if (imageLoad(triangleIds, xi).r == 0u) continue;  // w(x_i) = 0
        vec3 e = imageLoad(positions, xi).xyz - p;
        count += 1.0;
        sum += dot(e, e);
    }
    // Eq. (3); no estimate (0) where it is 0/0 or n/0 (all neighbours at p(x))
    float density = sum > 0.0 ? count / sum : 0.0;
    if (!(density <= FLT_MAX)) density = 0.0;
    // most fragments of a triangle do not raise its maximum: a plain read
    // first skips their atomics (values only grow, so skipping is safe)
    // no estimate: the triangle's own A_l / A_o (IMPORTANCE_NO_DENSITY_ESTIMATE, clamp.comp)
    uint bits = floatBitsToUint(density > 0.0 ? density : IMPORTANCE_NO_DENSITY_ESTIMATE);
    uint t = vTriangle - meshChunkFirstTriangle;
    if (bits > maxDensityBits[t]) atomicMax(maxDensityBits[t], bits);
    if (writeDensity) imageStore(densityImage, x, vec4(density));
}
