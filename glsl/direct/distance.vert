#version 430
// Emitter sample visibility: distance from the sample point, one cube face.
#include "lib/bake_vertex.glsl"
uniform mat4 clipFromWorld;
out vec3 vPosition;
void main() {
    vPosition = inPosition.xyz;
    gl_Position = clipFromWorld * vec4(inPosition.xyz, 1.0);
}
