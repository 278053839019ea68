#version 450
// Direct light from a point or spot light (KHR_lights_punctual): L_lm +=
// E / pi, E = intensity x cos / d^2 x range window x cone falloff
// (lib/punctual_light.glsl), times the visibility read from the light's
// distance cube map, as the emitter samples are (direct/emitter.frag). Adds
// to the direct light's float sums (lib/direct_scratch.glsl).
#include "shared/bundle_layout.h"
#include "lib/punctual_light.glsl"
#include "lib/cube_visibility.glsl"

in vec3 vPosition;
in vec3 vNormal;

#include "lib/direct_scratch.glsl"
uniform int page;

const float PI = 3.14159265358979;

void main() {
    vec3 facet = cross(dFdx(vPosition), dFdy(vPosition));
    if (gl_HelperInvocation) return;
    vec3 n = normalize(vNormal);
    vec3 x = vPosition;
    vec3 e = punctualIrradiance(x, n);
    if (e == vec3(0.0)) return;  // below the horizon, outside the cone or the range
    if (occludedFromLight(x, facet, lightPosition)) return;
    addDirect(ivec3(ivec2(gl_FragCoord.xy), page), e / PI);
}
