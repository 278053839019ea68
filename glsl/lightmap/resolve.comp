#version 430
// Resolve: light map L_lm = the stored running mean (cosine-weighted mean of
// incoming radiance, = E/pi; see update.frag and DESIGN.md Units) + the direct sun
// and explicit emitter maps.
// Writes, per texel of every page:
//   radianceOut: Lo = Le + albedo * L_lm (the next bundle passes read it)
//   otherwise:   L_lm itself (output)
// Padding texels take the value of their nearest covered texel (`source`,
// computed once on the CPU), so bilinear lookups near chart edges stay right:
// the dilation costs nothing per direction. alpha = 1 where a value exists.
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rg32ui) uniform readonly uimage2DArray accum;
layout(binding = 2, rgba32f) uniform readonly image2DArray sunMap;
layout(binding = 3, rgba16f) uniform readonly image2DArray albedoMap;    // a = coverage
layout(binding = 4, rgba16f) uniform readonly image2DArray emissionMap;
layout(binding = 5, rgba32f) uniform writeonly image2DArray target;
layout(binding = 6, r32i) uniform readonly iimage2DArray source;         // x | y << 16 of the texel to copy, or -1
layout(binding = 7, rgba32f) uniform readonly image2DArray emitterMap;  // explicit direct light from emitters (L_lm)

uniform bool radianceOut;
uniform bool includeEmission;  // false when emitters are lit explicitly: bundles then carry reflected light only
uniform int pageCount;
uniform ivec2 pageSize;

float h2f(uint h) { return unpackHalf2x16(h & 0xFFFFu).x; }

void main() {
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (t.x >= pageSize.x || t.y >= pageSize.y || t.z >= pageCount) return;
    int packedSource = imageLoad(source, t).r;
    if (packedSource < 0) {
        imageStore(target, t, vec4(0.0));
        return;
    }
    ivec3 s = ivec3(packedSource & 0xFFFF, packedSource >> 16, t.z);
    uvec2 p = imageLoad(accum, s).rg;
    float w = h2f(p.y >> 16u);
    vec3 l = w > 0.0 ? vec3(h2f(p.x), h2f(p.x >> 16u), h2f(p.y)) : vec3(0.0);  // the running mean
    vec4 sun = imageLoad(sunMap, s);  // rgb: sum over valid sun samples, a: their count
    if (sun.a > 0.0) l += sun.rgb / sun.a;
    l += imageLoad(emitterMap, s).rgb;
    vec3 emission = includeEmission ? imageLoad(emissionMap, s).rgb : vec3(0.0);
    vec3 value = radianceOut ? emission + imageLoad(albedoMap, s).rgb * l : l;
    imageStore(target, t, vec4(value, 1.0));
}
