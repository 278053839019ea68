#version 430
// The noise estimate (engine/bake/noise.cpp), per sampled texel: the running
// mean splits into the odd directions' half (halfAccum, kept by the update
// pass at every halfStride-th texel) and the even directions' (the whole
// minus the odd: M_e = (M W - M_o W_o) / (W - W_o)). Writes (sum over RGB of
// (M_e - M_o)^2, sum over RGB of L_lm, 1, sum over RGB of M^2: the bounced
// light, which noise.cpp's bounceLag scales) for texels where both halves hold
// samples, zeros elsewhere; the CPU sums and scales by the halves' weights
// (noise.cpp noiseHalvesFactor). A supersampled bake's texel is its half-size
// texels' mean weighted by their parts of its footprint (bake/supersample.h
// fineTexelWeights; `weights`, halfAccum's size): M_e - M_o and L_lm are those texels'
// means at those weights, over those where both halves hold samples.
#include "shared/bundle_layout.h"
#include "lib/rounding.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = BINDING_ACCUM, rg32ui) uniform readonly uimage2DArray accum;
layout(binding = BINDING_HALF_ACCUM, rg32ui) uniform readonly uimage2DArray halfAccum;
layout(binding = BINDING_DIRECT, rgba16f) uniform readonly image2DArray directMap;
layout(binding = BINDING_TARGET, rgba32f) uniform writeonly image2DArray target;
layout(binding = BINDING_NOISE_WEIGHTS, r16f) uniform readonly image2DArray weights;
uniform int halfStride;
uniform int supersample;
uniform int pageCount;
uniform ivec2 pageSize;  // sampled texels of the output layout a side (halfAccum's / supersample)

void main() {
    ivec3 h = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (h.x >= pageSize.x || h.y >= pageSize.y || h.z >= pageCount) return;
    vec3 d = vec3(0.0), l = vec3(0.0), b = vec3(0.0);
    float n = 0.0;
    for (int j = 0; j < supersample; ++j)
        for (int i = 0; i < supersample; ++i) {
            ivec2 sub = ivec2(i, j);
            ivec3 t = ivec3(h.xy * halfStride * supersample + sub, h.z);
            vec4 whole = decodeAccumulator(imageLoad(accum, t).rg);
            vec4 odd = decodeAccumulator(imageLoad(halfAccum, ivec3(h.xy * supersample + sub, h.z)).rg);
            float evenWeight = whole.a - odd.a;
            // both halves need weight; the whole's W rounds (7 bits), so ask for a margin
            float weight = imageLoad(weights, ivec3(h.xy * supersample + sub, h.z)).r;
            if (weight <= 0.0 || odd.a <= 0.0 || evenWeight <= 0.02 * whole.a) continue;
            vec3 even = (whole.rgb * whole.a - odd.rgb * odd.a) / evenWeight;
            d += weight * (even - odd.rgb);
            l += weight * (whole.rgb + imageLoad(directMap, t).rgb);
            b += weight * whole.rgb;
            n += weight;
        }
    if (n == 0.0) {
        imageStore(target, h, vec4(0.0));
        return;
    }
    d /= n;
    l /= n;
    b /= n;
    imageStore(target, h, vec4(dot(d, d), l.r + l.g + l.b, 1.0, dot(b, b)));
}
