#version 430
// Folds the direct light's float sums (lib/direct_scratch.glsl) into the fp16
// direct map and clears them: the emitters' sums are added as they are, the
// sun's are divided by its valid sample count (the direct map's alpha, which
// is reset). Stochastic rounding (or nearest), one rounding per fold.
#include "shared/bundle_layout.h"
#include "lib/rounding.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = BINDING_SCRATCH_RG, rg32f) uniform image2DArray scratchRg;
layout(binding = BINDING_SCRATCH_B, r32f) uniform image2DArray scratchB;
layout(binding = BINDING_DIRECT, rgba16f) uniform image2DArray directMap;
uniform bool perSample;  // the sun: divide by the count
uniform uint randomSeed;
uniform int pageCount;
uniform ivec2 pageSize;

void main() {
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (t.x >= pageSize.x || t.y >= pageSize.y || t.z >= pageCount) return;
    vec3 sum = vec3(imageLoad(scratchRg, t).rg, imageLoad(scratchB, t).r);
    vec4 d = imageLoad(directMap, t);
    if (perSample) sum = d.a > 0.0 ? sum / d.a : vec3(0.0);
    vec3 v = d.rgb + sum;
    uint h = pcgHash(randomSeed ^ pcgHash(uint(t.x) | (uint(t.y) << 16u)) ^ pcgHash(uint(t.z) + 104729u));
    uint h1 = pcgHash(h), h2 = pcgHash(h1);
    // imageStore converts to fp16 by nearest: store the stochastically rounded halves exactly
    v = vec3(halfToFloat(floatToHalf(v.r, uniform01(h))), halfToFloat(floatToHalf(v.g, uniform01(h1))),
             halfToFloat(floatToHalf(v.b, uniform01(h2))));
    imageStore(directMap, t, vec4(v, 0.0));
    imageStore(scratchRg, t, vec4(0.0));
    imageStore(scratchB, t, vec4(0.0));
}
