#version 430
// One emitter triangle's light, once all its samples are in (direct/emitter.frag):
// Le * sum(f r V) / sum(r) added to the direct light's float sums
// (lib/direct_scratch.glsl); the triangle's sums cleared for the next one.
#include "shared/bundle_layout.h"
layout(local_size_x = 8, local_size_y = 8) in;
#include "lib/direct_scratch.glsl"
layout(binding = BINDING_EMITTER_SUMS, rg32f) uniform image2DArray sums;
uniform vec3 emitterRadiance;  // Le, radiance units
uniform int pageCount;
uniform ivec2 pageSize;

void main() {
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (t.x >= pageSize.x || t.y >= pageSize.y || t.z >= pageCount) return;
    vec2 s = imageLoad(sums, t).rg;
    if (s.y > 0.0) addDirect(t, emitterRadiance * (s.x / s.y));
    imageStore(sums, t, vec4(0.0));
}
