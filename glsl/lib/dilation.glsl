// The covered texel an uncovered one shows (see DILATION_* in bundle_layout.h),
// so bilinear lookups near chart edges stay right: t itself if covered, its
// nearest covered neighbour (computed once on the CPU), or ivec3(-1) if none.
ivec3 dilationSource(uint code, ivec3 t) {
    if (code == DILATION_NONE) return ivec3(-1);
    return ivec3(t.xy + ivec2(int(code & 15u), int(code >> 4u)) - DILATION_RADIUS, t.z);
}
