#version 430
// One emitter triangle's light, once all its samples are in (direct/emitter.frag):
// Le * (sum F / N) * sum(w V) / sum(w) added to the direct light's float sums
// (lib/direct_scratch.glsl); the triangle's sums cleared for the next one.
#include "shared/bundle_layout.h"
layout(local_size_x = 8, local_size_y = 8) in;
#include "lib/direct_scratch.glsl"
layout(binding = BINDING_EMITTER_SUMS, rgba32f) uniform image2DArray sums;
uniform vec3 emitterRadiance;  // Le, radiance units
uniform float sampleCount;     // N, the triangle's samples
uniform int pageCount;
uniform ivec2 pageSize;

void main() {
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (t.x >= pageSize.x || t.y >= pageSize.y || t.z >= pageCount) return;
    vec3 s = imageLoad(sums, t).rgb;
    if (s.z > 0.0) addDirect(t, emitterRadiance * (s.x / sampleCount * (s.y / s.z)));
    imageStore(sums, t, vec4(0.0));
}
