#version 430
// Multiplies every accumulator (RGB and W) by `factor`, with the same
// rounding as the update pass. Keeps fp16 sums in range when the direction
// weights of the history ramp grow; L_lm = 2 RGB / W is unchanged.
#include "lib/rounding.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rg32ui) uniform uimage2DArray accum;
uniform float factor;
uniform uint randomSeed;
uniform int pageCount;
uniform ivec2 pageSize;

void main() {
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (t.x >= pageSize.x || t.y >= pageSize.y || t.z >= pageCount) return;
    uvec2 p = imageLoad(accum, t).rg;
    if (p == uvec2(0u)) return;
    vec4 v = factor * vec4(halfToFloat(p.x), halfToFloat(p.x >> 16u), halfToFloat(p.y), halfToFloat(p.y >> 16u));
    uint h = pcgHash(randomSeed ^ pcgHash(uint(t.x) | (uint(t.y) << 16u)) ^ pcgHash(uint(t.z) + 104729u));
    uint h1 = pcgHash(h), h2 = pcgHash(h1), h3 = pcgHash(h2);
    imageStore(accum, t, uvec4(floatToHalf(v.r, uniform01(h)) | (floatToHalf(v.g, uniform01(h1)) << 16u),
                               floatToHalf(v.b, uniform01(h2)) | (floatToHalf(v.a, uniform01(h3)) << 16u), 0u, 0u));
}
