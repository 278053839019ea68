#version 430
// Padding texels of the radiance map take the bits of their nearest covered
// texel (lib/dilation.glsl), after the outgoing pass (meta.frag) wrote the
// covered ones: reads covered texels only, writes uncovered ones only. Back
// sides' layers (page + codePages) follow their page's codes.
#include "shared/bundle_layout.h"
#include "lib/dilation.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = BINDING_DILATION, r8ui) uniform readonly uimage2DArray dilation;
layout(binding = BINDING_RADIANCE_BITS, r32ui) uniform uimage2DArray radianceBits;
uniform int pageCount;  // layers of radianceBits
uniform int codePages;  // layers of dilation
uniform ivec2 pageSize;

void main() {
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (t.x >= pageSize.x || t.y >= pageSize.y || t.z >= pageCount) return;
    uint code = imageLoad(dilation, ivec3(t.xy, t.z % codePages)).r;
    if (code == DILATION_SELF) return;
    ivec3 s = dilationSource(code, t);
    imageStore(radianceBits, t, uvec4(s.x < 0 ? 0u : imageLoad(radianceBits, s).r));
}
