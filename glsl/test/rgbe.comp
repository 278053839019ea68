#version 430
// Test kernel: encodeRgbe (lib/rounding.glsl) of values[i].rgb with u = us[i].rgb.
#include "lib/rounding.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Values { vec4 values[]; };
layout(std430, binding = 1) readonly buffer Us { vec4 us[]; };
layout(std430, binding = 2) writeonly buffer Out { uint encoded[]; };
uniform int count;
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i < count) encoded[i] = encodeRgbe(values[i].rgb, us[i].rgb);
}
