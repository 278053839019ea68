// A light map fragment's frame (lib/texel_footprint.glsl FlatFrame) from its
// varyings, for fragment shaders (update.frag, direct/footprint_point.glsl).
// Call it before any return: screen derivatives need the whole quad.
// Needs lib/texel_footprint.glsl.
FlatFrame rasterFrame(vec3 position, vec3 normal, vec3 bary, uint flags) {
    return FlatFrame(position, normal, bary, dFdx(position), dFdy(position), dFdx(normal), dFdy(normal), dFdx(bary),
                     dFdy(bary), flags);
}
