#version 430
// The noise estimate (engine/bake/noise.cpp), per sampled texel: the running
// mean splits into the odd directions' half (halfAccum, kept by the update
// pass at every halfStride-th texel) and the even directions' (the whole
// minus the odd: M_e = (M W - M_o W_o) / (W - W_o)). Writes (sum over RGB of
// (M_e - M_o)^2, sum over RGB of L_lm, 1) for texels where both halves hold
// samples, zeros elsewhere; the CPU sums and scales by the halves' weights
// (noise.cpp noiseHalvesFactor).
#include "shared/bundle_layout.h"
#include "lib/rounding.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = BINDING_ACCUM, rg32ui) uniform readonly uimage2DArray accum;
layout(binding = BINDING_HALF_ACCUM, rg32ui) uniform readonly uimage2DArray halfAccum;
layout(binding = BINDING_DIRECT, rgba16f) uniform readonly image2DArray directMap;
layout(binding = BINDING_TARGET, rgba32f) uniform writeonly image2DArray target;
uniform int halfStride;
uniform int pageCount;
uniform ivec2 pageSize;  // of halfAccum

void main() {
    ivec3 h = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (h.x >= pageSize.x || h.y >= pageSize.y || h.z >= pageCount) return;
    vec4 whole = decodeAccumulator(imageLoad(accum, ivec3(h.xy * halfStride, h.z)).rg);
    vec4 odd = decodeAccumulator(imageLoad(halfAccum, h).rg);
    float evenWeight = whole.a - odd.a;
    // both halves need weight; the whole's W rounds (7 bits), so ask for a margin
    if (odd.a <= 0.0 || evenWeight <= 0.02 * whole.a) {
        imageStore(target, h, vec4(0.0));
        return;
    }
    vec3 even = (whole.rgb * whole.a - odd.rgb * odd.a) / evenWeight;
    vec3 d = even - odd.rgb;
    vec3 l = whole.rgb + imageLoad(directMap, ivec3(h.xy * halfStride, h.z)).rgb;
    imageStore(target, h, vec4(dot(d, d), l.r + l.g + l.b, 1.0, 0.0));
}
