#version 450
// Direct light from an emissive triangle, one of its visibility samples, at
// the sample's point x of the texel's footprint (lib/texel_footprint.glsl:
// over the samples, the texel's mean). Over the triangle's N samples the
// texel's light is
//   Le * (sum F(x) / N) * sum(w V) / sum(w),   w = cos_x cos_e / d^2
// (direct/emitter_fold.comp divides once they are all in): the footprint's
// mean of the exact polygon form factor F (no 1/d^2 noise near the emitter)
// times the visible share of the light, each sample weighted by what it
// brings, V its visibility from its distance cube map. The share is a ratio
// estimate, exact where the triangle is wholly seen and where it is wholly
// hidden (a sealed room stays 0). F times the fraction of samples seen
// weighs every point of the emitter alike, but the part a blocker hides is
// mostly the farther, more grazing one: penumbrae read 20-50 % dark on the
// Cornell box (issue 11). Keeping the mean of F apart from the share matters
// where F changes across the footprint: sum(F r V) / sum(r), r = w / mean(w)
// at each sample's own x, leaned toward the points with the largest r, those
// that see the light most obliquely, and read the ceiling texels along a
// panel light's outline 50-80 % dark (the shared Cornell box).
// CURVED_FOOTPRINT (define): curved texels (lib/curved_footprint.glsl), one
// point each (lightmap/curved.vert), their points on the triangles that hold them.
#include "shared/bundle_layout.h"
#include "shared/mesh_layout.h"
#include "lib/rounding.glsl"
#include "lib/texel_footprint.glsl"
#include "lib/polygon_irradiance.glsl"
#include "lib/cube_visibility.glsl"

layout(binding = BINDING_EMITTER_SUMS, rgba32f) uniform coherent image2DArray sums;  // (sum F, sum w V, sum w, -)
uniform vec3 emitterA, emitterB, emitterC;  // world vertices
uniform vec3 emitterNormal;
uniform bool emitterDoubleSided;
uniform vec3 samplePoint;
uniform int page;
uniform uint footprintSample;              // this emitter sample's index over all emitters
// The noise estimate (direct_noise.comp): the triangle's odd samples' sums
// apart, at the texels it samples (update.frag's halfAccum, the same places)
layout(binding = BINDING_DIRECT_ODD_SUMS, rgba32f) uniform coherent image2DArray oddSums;
uniform bool oddSample;
uniform int halfStride;
uniform int supersample;
#include "lib/noise_half.glsl"
layout(binding = BINDING_FOOTPRINT) uniform usampler2DArray footprint;
const uint NEAR_FIELD_POINTS = 16u;  // F's points a sample within a texel of the emitter's plane
#include "direct/footprint_point.glsl"

// F from point p with normal n. Behind a single-sided emitter nothing
// arrives, and a point in its plane (the emitter's own texels, a coplanar
// ceiling) gets nothing either: Lambert's formula would give it the whole
// hemisphere (F = 1) from inside the polygon.
float formFactorAt(vec3 p, vec3 n) {
    float facing = dot(emitterNormal, p - emitterA), planeEpsilon = 0.01 * rayOffset;
    if (emitterDoubleSided ? abs(facing) <= planeEpsilon : facing <= planeEpsilon) return 0.0;
    return polygonFormFactor(p, n, emitterA, emitterB, emitterC);
}

void main() {
    TexelFootprint texel;
    if (!texelFootprint(texel)) return;
    FootprintPoint x = footprintPoint(texel, footprintSample);
    float f = formFactorAt(x.position, x.normal);
    // F's mean over the footprint. Within a texel of the emitter's plane F
    // steps from 0 to 1 across the footprint along the emitter's outline (the
    // shared Cornell box's ceiling, 0.9 mm over its light, 20 mm texels), and
    // one point a sample read the step's share 3 % off at 128 samples a
    // triangle. There each sample takes NEAR_FIELD_POINTS points of their own
    // run of R2 (with the sample's index, one R2 sequence of samples x
    // NEAR_FIELD_POINTS points): within 0.1 % there, 1.2 % on texels a
    // thirtieth over the outline.
    float fMean = f;
    if (abs(dot(emitterNormal, texel.centre - emitterA)) < texel.size) {
        fMean = 0.0;
        for (uint k = 0u; k < NEAR_FIELD_POINTS; ++k) {
            FootprintPoint p = footprintPoint(texel, footprintSample * NEAR_FIELD_POINTS + k);
            fMean += formFactorAt(p.position, p.normal);
        }
        fMean /= float(NEAR_FIELD_POINTS);
    }
    // the sample's weight and visibility; below x's horizon it counts in F's mean only
    vec3 toX = x.position - samplePoint;
    float r2 = dot(toX, toX);
    float cosX = -dot(x.normal, toX), cosE = abs(dot(emitterNormal, toX));
    float w = 0.0, seen = 0.0;
    if (f > 0.0 && cosX > 0.0) {
        w = cosX * cosE / (r2 * r2);
        seen = occludedFromLight(x.position, x.plane, samplePoint) ? 0.0 : 1.0;
    }
    if (fMean > 0.0 || w > 0.0) {
        vec4 add = vec4(fMean, w * seen, w, 0.0);
        imageStore(sums, texel.texel, imageLoad(sums, texel.texel) + add);
        ivec3 half_;
        if (oddSample && noiseHalfTexel(texel.texel, half_)) {
            imageStore(oddSums, half_, imageLoad(oddSums, half_) + add);
        }
    }
}
