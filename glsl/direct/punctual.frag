#version 450
// Direct light from a point or spot light (KHR_lights_punctual): L_lm +=
// E / pi, E = intensity x cos / d^2 x range window x cone falloff
// (lib/punctual_light.glsl), times the visibility read from the light's
// distance cube map, as the emitter samples are (direct/emitter.frag). Adds
// to the direct light's float sums (lib/direct_scratch.glsl). A flat texel
// takes it at its centre; a curved one (CURVED_FOOTPRINT), whose surface
// turns within it, as the mean over CURVED_POINTS points of its footprint.
#include "shared/bundle_layout.h"
#include "shared/mesh_layout.h"
#include "lib/rounding.glsl"
#include "lib/texel_footprint.glsl"
#include "lib/punctual_light.glsl"
#include "lib/cube_visibility.glsl"
#include "lib/direct_scratch.glsl"
uniform int page;
layout(binding = BINDING_FOOTPRINT) uniform usampler2DArray footprint;
#include "direct/footprint_point.glsl"

const float PI = 3.14159265358979;
const uint CURVED_POINTS = 256u;

// E / pi at x, 0 where it is shadowed
vec3 lightAt(FootprintPoint x) {
    vec3 e = punctualIrradiance(x.position, x.normal);
    if (e == vec3(0.0)) return e;  // below the horizon, outside the cone or the range
    return occludedFromLight(x.position, x.plane, lightPosition) ? vec3(0.0) : e / PI;
}

void main() {
    TexelFootprint texel;
    if (!texelFootprint(texel)) return;
#ifdef CURVED_FOOTPRINT
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < CURVED_POINTS; ++k) sum += lightAt(footprintPoint(texel, k));
    vec3 light = sum / float(CURVED_POINTS);
#else
    FlatFrame f = texel.frame;
    vec3 light = lightAt(FootprintPoint(vPosition, normalize(vNormal), cross(f.positionDx, f.positionDy)));
#endif
    if (light != vec3(0.0)) addDirect(texel.texel, light);
}
