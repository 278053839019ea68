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

void main() {
    // texture() before any branch: implicit derivatives need the whole quad
    vec3 a = albedo;
    if (hasAlbedoTexture) a *= texture(albedoTexture, vUv0).rgb;
    vec3 e = emission;
    if (hasEmissionTexture) e *= texture(emissionTexture, vUv0).rgb;
    ivec3 texel = ivec3(ivec2(gl_FragCoord.xy), page + layerOffset);
    vec4 state = decodeAccumulator(imageLoad(accum, texel).rg);
    vec3 l = state.a > 0.0 ? state.rgb : vec3(0.0);
    if (layerOffset == 0) l += imageLoad(directMap, texel).rgb;
    vec3 lo = (includeEmission ? e : vec3(0.0)) + clamp(a, 0.0, 1.0) * l;
    uint h = pcgHash(randomSeed ^ pcgHash(uint(texel.x) | (uint(texel.y) << 16u)) ^ pcgHash(uint(texel.z) + 7919u));
    uint h1 = pcgHash(h), h2 = pcgHash(h1);
    imageStore(radianceBits, texel, uvec4(encodeRgb9e5(lo, vec3(uniform01(h), uniform01(h1), uniform01(h2)))));
}
#endif
