#version 450
// Direct light from an emissive triangle, one of its visibility samples:
// L_lm += Le * F(x -> triangle) * V(x, sample) / sampleCount, with F the exact
// polygon form factor (no 1/r^2 noise near the emitter) and V read from the
// sample's distance cube map. Adds to the direct light's float sums
// (lib/direct_scratch.glsl).
#include "shared/bundle_layout.h"
#include "lib/polygon_irradiance.glsl"

in vec3 vPosition;
in vec3 vNormal;

#include "lib/direct_scratch.glsl"
layout(binding = 0) uniform samplerCube distances;
uniform vec3 emitterA, emitterB, emitterC;  // world vertices
uniform vec3 emitterNormal;
uniform bool emitterDoubleSided;
uniform vec3 radianceOverSamples;         // Le / samples of this triangle
uniform vec3 samplePoint;
uniform float normalOffset;                // scene units: pushes x off its own surface
uniform float distanceBias;                // scene units
uniform float footprintPerDistance;        // half a cube texel's width per unit distance (1 / face size)
uniform int page;

void main() {
    if (gl_HelperInvocation) return;
    vec3 n = normalize(vNormal);
    vec3 x = vPosition;
    vec3 toX = x - samplePoint;
    // distance of x from the emitter's plane: behind a single-sided emitter
    // nothing arrives, and a point in the plane (the emitter's own texels, a
    // coplanar ceiling) gets nothing either: Lambert's formula would give it
    // the whole hemisphere (F = 1) from inside the polygon
    float facing = dot(emitterNormal, x - emitterA);
    float planeEpsilon = 0.01 * normalOffset;
    if (emitterDoubleSided ? abs(facing) <= planeEpsilon : facing <= planeEpsilon) return;
    if (dot(n, -toX) <= 0.0) return;                   // the sample is below x's horizon
    // visibility from a point pushed off the surface (no self-shadowing); the
    // form factor from the texel itself
    vec3 shadowX = x + n * normalOffset - samplePoint;
    float dist = length(shadowX);
    float stored = texture(distances, shadowX).r;
    if (dist > stored + distanceBias + footprintPerDistance * dist) return;  // occluded
    float f = polygonFormFactor(x, n, emitterA, emitterB, emitterC);
    ivec3 texel = ivec3(ivec2(gl_FragCoord.xy), page);
    addDirect(texel, radianceOverSamples * f);
}
