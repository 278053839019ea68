#version 450
// Direct light from a point or spot light (KHR_lights_punctual): L_lm +=
// E / pi, E = intensity x cos / d^2 x range window x cone falloff
// (lib/punctual_light.glsl), times the visibility read from the light's
// distance cube map, as the emitter samples are (direct/emitter.frag). Adds
// to the direct light's float sums (lib/direct_scratch.glsl).
#include "shared/bundle_layout.h"
#include "lib/punctual_light.glsl"

in vec3 vPosition;
in vec3 vNormal;

#include "lib/direct_scratch.glsl"
layout(binding = 0) uniform samplerCube distances;
uniform float normalOffset;                // scene units: pushes x off its own surface
uniform float distanceBias;                // scene units
uniform float footprintPerDistance;        // half a cube texel's width per unit distance (1 / face size)
uniform int page;

const float PI = 3.14159265358979;

void main() {
    if (gl_HelperInvocation) return;
    vec3 n = normalize(vNormal);
    vec3 x = vPosition;
    vec3 e = punctualIrradiance(x, n);
    if (e == vec3(0.0)) return;  // below the horizon, outside the cone or the range
    // visibility from a point pushed off the surface (no self-shadowing); the
    // irradiance at the texel itself
    vec3 shadowX = x + n * normalOffset - lightPosition;
    float dist = length(shadowX);
    float stored = texture(distances, shadowX).r;
    if (dist > stored + distanceBias + footprintPerDistance * dist) return;  // occluded
    addDirect(ivec3(ivec2(gl_FragCoord.xy), page), e / PI);
}
