#version 430
// Resolve: the light map L_lm = the accumulators' running mean (cosine-weighted
// mean of incoming radiance, = E/pi; see update.frag and DESIGN.md Units) + the
// direct map (sun and explicit emitters), padding dilated (lib/dilation.glsl);
// alpha = 1 where a value exists. Writes the region of `pageSize` texels at
// `origin` (x, y, page) of the light maps to `target` at (0, 0, 0): the whole
// array (the viewer) or a band of one page (read-backs).
#include "shared/bundle_layout.h"
#include "lib/dilation.glsl"
#include "lib/rounding.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = BINDING_ACCUM, rg32ui) uniform readonly uimage2DArray accum;
layout(binding = BINDING_DIRECT, rgba16f) uniform readonly image2DArray directMap;
layout(binding = BINDING_DILATION, r8ui) uniform readonly uimage2DArray dilation;
layout(binding = BINDING_TARGET, rgba32f) uniform writeonly image2DArray target;
uniform ivec3 origin;
uniform int pageCount;   // of the region
uniform ivec2 pageSize;  // of the region
uniform float radianceUnit;  // the state holds radiance / radianceUnit (Baker::Impl::radianceUnit)

void main() {
    ivec3 g = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (g.x >= pageSize.x || g.y >= pageSize.y || g.z >= pageCount) return;
    ivec3 t = g + origin;
    ivec3 s = dilationSource(imageLoad(dilation, t).r, t);
    if (s.x < 0) {
        imageStore(target, g, vec4(0.0));
        return;
    }
    vec4 state = decodeAccumulator(imageLoad(accum, s).rg);
    vec3 l = state.a > 0.0 ? state.rgb : vec3(0.0);
    imageStore(target, g, vec4((l + imageLoad(directMap, s).rgb) * radianceUnit, 1.0));
}
