#version 430
// Test kernel: encodeAccumulator (lib/rounding.glsl) of values[i] with u = us[i],
// and decodeAccumulator of those bits.
#include "lib/rounding.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Values { vec4 values[]; };
layout(std430, binding = 1) readonly buffer Us { vec4 us[]; };
layout(std430, binding = 2) writeonly buffer Out { uvec2 encoded[]; };
layout(std430, binding = 3) writeonly buffer Decoded { vec4 decoded[]; };
uniform int count;
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= count) return;
    uvec2 bits = encodeAccumulator(values[i], us[i]);
    encoded[i] = bits;
    decoded[i] = decodeAccumulator(bits);
}
