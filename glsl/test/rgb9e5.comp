#version 430
// Test kernel: encodeRgb9e5 (lib/rounding.glsl) of values[i].rgb with u =
// values[i].a on every channel, stored into texel i of an RGB9_E5 texture
// through its r32ui view, as the outgoing radiance pass does.
#include "lib/rounding.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Values { vec4 values[]; };
layout(binding = 0, r32ui) uniform writeonly uimage2D bits;
uniform int count;
uniform int width;
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= count) return;
    imageStore(bits, ivec2(i % width, i / width), uvec4(encodeRgb9e5(values[i].rgb, vec3(values[i].a))));
}
