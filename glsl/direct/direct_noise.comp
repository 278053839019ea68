#version 430
// The noise of one light's direct light, for the noise estimate
// (engine/bake/noise.cpp), once all its samples are in and before the fold
// clears its sums: per sampled texel of the output layout, its light from the
// even and from the odd samples and their difference, over the texel's
// half-size texels at their weights in it (noise.comp's). The variance of the
// whole's light is then n_e n_o / n^2 x (D_e - D_o)^2 (independent halves of
// n_e and n_o samples); each light's adds (their samples are independent),
// summed over RGB as noise.comp's terms. The odd sums are cleared for the
// next light.
// - An emitter triangle's (direct/emitter.frag): its samples by their index
//   in the triangle's R2 sequence (each half is itself a stratified set, as
//   the even and odd directions are), each half Le * (sum F / n) * sum(w V) /
//   sum(w) over its own samples.
// - SUN (define): a sun's (lightmap/update.frag SUN_PASS), its jittered
//   passes of even and odd index (engine/bake/direct_light.cpp bakeSun), each
//   half its sum over its count; the whole's in the direct light's scratch
//   and the direct map's alpha.
#include "shared/bundle_layout.h"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = BINDING_DIRECT_ODD_SUMS, rgba32f) uniform image2DArray oddSums;
layout(binding = BINDING_DIRECT_VARIANCE, r32f) uniform image2DArray variance;
layout(binding = BINDING_DIRECT_WEIGHTS, r16f) uniform readonly image2DArray weights;
#ifdef SUN
#include "lib/direct_scratch.glsl"
layout(binding = BINDING_DIRECT, rgba16f) uniform readonly image2DArray directMap;
#else
layout(binding = BINDING_EMITTER_SUMS, rgba32f) uniform readonly image2DArray sums;
uniform vec3 emitterRadiance;  // Le, radiance units
uniform float evenCount;       // n_e: the triangle's samples of even index
uniform float oddCount;        // n_o
#endif
uniform int halfStride;
uniform int supersample;
uniform int pageCount;
uniform ivec2 pageSize;  // sampled texels of the output layout a side

#ifdef SUN
// (sum, count) of texel t's samples
vec4 whole(ivec3 t) { return vec4(imageLoad(scratchRg, t).rg, imageLoad(scratchB, t).r, imageLoad(directMap, t).a); }
vec3 light(vec4 s) { return s.a > 0.0 ? s.rgb / s.a : vec3(0.0); }
#else
vec3 light(vec4 s, float n) { return s.z > 0.0 ? emitterRadiance * (s.x / n * (s.y / s.z)) : vec3(0.0); }
#endif

void main() {
    ivec3 h = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (h.x >= pageSize.x || h.y >= pageSize.y || h.z >= pageCount) return;
    vec3 d = vec3(0.0);
    float n = 0.0;
#ifdef SUN
    float evenCount = 0.0, oddCount = 0.0;
#endif
    for (int j = 0; j < supersample; ++j)
        for (int i = 0; i < supersample; ++i) {
            ivec2 sub = ivec2(i, j);
            ivec3 t = ivec3(h.xy * halfStride * supersample + sub, h.z), half_ = ivec3(h.xy * supersample + sub, h.z);
            vec4 odd = imageLoad(oddSums, half_);
            imageStore(oddSums, half_, vec4(0.0));
            float weight = imageLoad(weights, half_).r;
            if (weight <= 0.0) continue;
#ifdef SUN
            vec4 even = whole(t) - odd;
            if (even.a <= 0.0 || odd.a <= 0.0) continue;  // a half without samples tells nothing
            d += weight * (light(even) - light(odd));
            evenCount += even.a;
            oddCount += odd.a;
#else
            d += weight * (light(imageLoad(sums, t) - odd, evenCount) - light(odd, oddCount));
#endif
            n += weight;
        }
    if (n == 0.0) return;
    d /= n;
    float total = evenCount + oddCount;
    imageStore(variance, h, imageLoad(variance, h) + vec4(evenCount * oddCount / (total * total) * dot(d, d)));
}
