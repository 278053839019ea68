// The noise estimate's sampled texels (engine/bake/noise.cpp): every
// halfStride-th texel of the output layout with all its half-size texels,
// kept in the odd half's images (halfAccum's size) at `half_`. True where
// `texel` (a baked texel: page or layer in z) is one. Needs the uniforms
// halfStride and supersample.
bool noiseHalfTexel(ivec3 texel, out ivec3 half_) {
    ivec2 outputTexel = texel.xy / supersample;
    half_ = ivec3(outputTexel / halfStride * supersample + texel.xy % supersample, texel.z);
    return outputTexel.x % halfStride == 0 && outputTexel.y % halfStride == 0;
}
