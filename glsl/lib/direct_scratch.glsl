// The direct light's float sums while it is baked, before the bundles need the
// accumulators and the radiance map: r, g in the accumulators (viewed rg32f),
// b in the radiance map (viewed r32f). direct_fold.comp folds them into the
// fp16 direct map. No texel memory of its own.
layout(binding = BINDING_SCRATCH_RG, rg32f) uniform coherent image2DArray scratchRg;
layout(binding = BINDING_SCRATCH_B, r32f) uniform coherent image2DArray scratchB;

void addDirect(ivec3 texel, vec3 value) {
    imageStore(scratchRg, texel, vec4(imageLoad(scratchRg, texel).rg + value.rg, 0.0, 0.0));
    imageStore(scratchB, texel, vec4(imageLoad(scratchB, texel).r + value.b));
}
