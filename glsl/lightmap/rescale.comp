#version 430
// Multiplies every accumulator's weight W by `factor`, with the same
// rounding as the update pass. Keeps fp16 weights in range when the direction
// weights of the history ramp grow; the stored mean (rgb) is unchanged.
#include "shared/bundle_layout.h"
#include "lib/rounding.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = BINDING_ACCUM, rg32ui) uniform uimage2DArray accum;
uniform float factor;
uniform uint randomSeed;
uniform int pageCount;
uniform ivec2 pageSize;

void main() {
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (t.x >= pageSize.x || t.y >= pageSize.y || t.z >= pageCount) return;
    uvec2 p = imageLoad(accum, t).rg;
    if (p == uvec2(0u)) return;
    // a texel that was sampled stays sampled: its weight never rounds to 0
    // (meta.frag and resolve.comp read a texel whose W is 0 as never sampled,
    // black). The early rounds of a steep ramp scale by e^-97 and less: W
    // underflowed, and a texel that then missed a round (no own surface in
    // its pixel) lost its light for a bounce, which held the rho 0.99 furnace
    // at 46 instead of 73 after 256 directions.
    float w = max(factor * decodeAccumulatorWeight(p.y >> 21u), SAMPLED_MIN_WEIGHT);
    uint h = pcgHash(randomSeed ^ pcgHash(uint(t.x) | (uint(t.y) << 16u)) ^ pcgHash(uint(t.z) + 104729u));
    imageStore(accum, t, uvec4(p.x, (p.y & 0x1FFFFFu) | (encodeAccumulatorWeight(w, uniform01(h)) << 21u), 0u, 0u));
}
