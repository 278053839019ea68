#version 430
// Test kernel: y[i] = a * x[i] + float(i), used to check that compute shaders
// run and write SSBOs under every headless backend.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer X { float x[]; };
layout(std430, binding = 1) writeonly buffer Y { float y[]; };
uniform float a;
uniform uint count;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < count) y[i] = a * x[i] + float(i);
}
