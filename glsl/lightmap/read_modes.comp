#version 430
// How the bundle pass reads each texel's radiance where a ray lands
// (bundle/append.frag radianceAt), decided once per refresh of the radiance
// map rather than per fragment: per axis READ_NONE (its mean), READ_SLOPE (a
// limited slope) or READ_STEP (a step inside the texel), from the texels 1
// and 2 away along its row and column on its chart (the CHART_NEIGHBOUR_*
// bits). A step: the texel's mean lies between its two neighbours' and both
// sides are flat against the jump (each side's own step at most
// STEP_FLATNESS of it), on the channels' sum. Back sides' layers (page +
// codePages) use their page's chart bits. Runs after dilate.comp.
#include "shared/bundle_layout.h"
#include "lib/rounding.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = BINDING_CHART_NEIGHBOURS_IMAGE, r8ui) uniform readonly uimage2DArray chartNeighbours;
layout(binding = BINDING_RADIANCE_BITS, r32ui) uniform readonly uimage2DArray radianceBits;
layout(binding = BINDING_READ_MODES_IMAGE, r8ui) uniform writeonly uimage2DArray readModes;
uniform int pageCount;  // layers of radianceBits and readModes
uniform int codePages;  // layers of chartNeighbours
uniform ivec2 pageSize;

// A step inside a texel is taken where the two sides are this flat against it
const float STEP_FLATNESS = 0.2;

float radianceSum(ivec3 t) { return dot(decodeRgb9e5(imageLoad(radianceBits, t).r), vec3(1.0)); }

void main() {
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (t.x >= pageSize.x || t.y >= pageSize.y || t.z >= pageCount) return;
    uint same = imageLoad(chartNeighbours, ivec3(t.xy, t.z % codePages)).r;
    float m = radianceSum(t);
    const ivec2 along[2] = ivec2[2](ivec2(1, 0), ivec2(0, 1));
    const uint beforeBit[2] = uint[2](CHART_NEIGHBOUR_LEFT, CHART_NEIGHBOUR_DOWN);
    const uint afterBit[2] = uint[2](CHART_NEIGHBOUR_RIGHT, CHART_NEIGHBOUR_UP);
    uint modes = 0u;
    for (int axis = 0; axis < 2; ++axis) {
        uint before = beforeBit[axis], after = afterBit[axis];
        if ((same & before) == 0u || (same & after) == 0u) continue;  // READ_NONE
        ivec3 s = ivec3(along[axis], 0);
        float l = radianceSum(t - s), r = radianceSum(t + s);
        float l2 = (same & (before << CHART_NEIGHBOUR_FAR)) != 0u ? radianceSum(t - 2 * s) : l;
        float r2 = (same & (after << CHART_NEIGHBOUR_FAR)) != 0u ? radianceSum(t + 2 * s) : r;
        bool step = (m - l) * (r - m) > 0.0 && max(abs(l - l2), abs(r2 - r)) <= STEP_FLATNESS * abs(r - l);
        modes |= (step ? READ_STEP : READ_SLOPE) << (2 * axis);
    }
    imageStore(readModes, t, uvec4(modes));
}
