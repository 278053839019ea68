#version 450
// The surface in light map space (meta.vert: one fragment per covered texel
// centre; the draws run per page and material, `page` and the material's
// uniforms set per run).
// COVERAGE (define): marks the texel covered (DILATION_SELF), once at setup,
// unless a cut-out's mask cuts its centre away (scene/alpha_mask.h).
// Otherwise the outgoing pass: Lo = Le + albedo * L_lm, with L_lm = the
// accumulators' running mean (the indirect light, see update.frag) + the direct
// map, stochastically rounded into the RGB9E5 radiance map the bundle pass
// samples. Albedo and emission come from the material here, every pass, so no
// texel stores them. dilate.comp then fills the padding. Run again with
// layerOffset > 0 for double-sided triangles' back sides (their own running
// means; no direct light: the direct map is the front's).
#include "shared/bundle_layout.h"
#include "lib/rounding.glsl"

in vec2 vUv0;
uniform int page;

#ifdef COVERAGE
#include "shared/material_layout.h"
#include "lib/alpha_mask.glsl"
layout(binding = BINDING_DILATION, r8ui) uniform writeonly uimage2DArray dilation;
uniform int material;  // the run's (cut-outs: a texel centre on a cut-away part is not covered)

void main() {
    if (alphaCut(uint(material), vUv0)) return;
    imageStore(dilation, ivec3(ivec2(gl_FragCoord.xy), page), uvec4(DILATION_SELF));
}
#else
layout(binding = BINDING_MATERIAL_TEX) uniform sampler2D albedoTexture;
layout(binding = BINDING_MATERIAL_TEX + 1) uniform sampler2D emissionTexture;
layout(binding = BINDING_ACCUM, rg32ui) uniform readonly uimage2DArray accum;
layout(binding = BINDING_DIRECT, rgba16f) uniform readonly image2DArray directMap;
layout(binding = BINDING_RADIANCE_BITS, r32ui) uniform writeonly uimage2DArray radianceBits;
uniform vec3 albedo;
uniform vec3 emission;
uniform bool hasAlbedoTexture;
uniform bool hasEmissionTexture;
uniform bool includeEmission;  // false when emitters are lit explicitly: bundles then carry reflected light only
uniform uint randomSeed;       // per refresh
uniform int layerOffset;       // 0: the front sides; else the back sides' layers (page + layerOffset)
// The texels' slopes inside them (append.frag radianceAt): from their
// first moments (update.frag) and their footprints' spread
#include "shared/mesh_layout.h"
#include "lib/texel_footprint.glsl"
layout(binding = BINDING_MOMENTS, rgba32f) uniform readonly image2DArray moments;
layout(binding = BINDING_SLOPES_IMAGE, rgba16f) uniform writeonly image2DArray slopes;
layout(binding = BINDING_FOOTPRINT) uniform usampler2DArray footprint;
layout(binding = BINDING_CHART_NEIGHBOURS) uniform usampler2DArray chartNeighbours;

// The slope of the texel's reflected light (its channels' sum) along x and y
// inside it, per texel, and its samples' mean point, about which the slope is
// taken: the least-squares plane through its samples' L_in (the covariance of
// L_in and the point, over the footprint's spread), times the albedo. Zero for
// a curved texel (it keeps no moments: update.frag).
vec4 slopeInside(ivec3 texel, vec3 a, vec3 m) {
    // the bundle pass reads it only along an axis that lacks a neighbour on the chart (READ_NONE)
    const uint everyNeighbour = CHART_NEIGHBOUR_LEFT | CHART_NEIGHBOUR_RIGHT | CHART_NEIGHBOUR_DOWN | CHART_NEIGHBOUR_UP;
    if ((texelFetch(chartNeighbours, ivec3(texel.xy, page), 0).r & everyNeighbour) == everyNeighbour) return vec4(0.0);
    vec4 moment = imageLoad(moments, texel);
    float total = dot(m, vec3(1.0));
    if (moment == vec4(0.0) || total <= 0.0) return vec4(0.0);
    vec2 mid = moment.zw;  // the samples' mean point
    vec2 covariance = moment.xy - total * mid;
    vec3 spread = decodeFootprintSpread(texelFetch(footprint, ivec3(texel.xy, page), 0));
    vec2 slope = inverse(mat2(spread.x, spread.y, spread.y, spread.z)) * covariance;
    return vec4(slope * (dot(clamp(a, 0.0, 1.0), m) / total), mid);
}

void main() {
    // texture() before any branch: implicit derivatives need the whole quad
    vec3 a = albedo;
    if (hasAlbedoTexture) a *= texture(albedoTexture, vUv0).rgb;
    vec3 e = emission;
    if (hasEmissionTexture) e *= texture(emissionTexture, vUv0).rgb;
    ivec3 texel = ivec3(ivec2(gl_FragCoord.xy), page + layerOffset);
    vec4 state = decodeAccumulator(imageLoad(accum, texel).rg);
    vec3 l = state.a > 0.0 ? state.rgb : vec3(0.0);
    imageStore(slopes, texel, slopeInside(texel, a, l));
    if (layerOffset == 0) l += imageLoad(directMap, texel).rgb;
    vec3 lo = (includeEmission ? e : vec3(0.0)) + clamp(a, 0.0, 1.0) * l;
    uint h = pcgHash(randomSeed ^ pcgHash(uint(texel.x) | (uint(texel.y) << 16u)) ^ pcgHash(uint(texel.z) + 7919u));
    uint h1 = pcgHash(h), h2 = pcgHash(h1);
    imageStore(radianceBits, texel, uvec4(encodeRgb9e5(lo, vec3(uniform01(h), uniform01(h1), uniform01(h2)))));
}
#endif
