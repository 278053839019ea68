#version 450
// Importance compute pass: Eq. (4) per triangle,
//   I(t) = min(A_l(t) / A_o(t), I_max(t)),
// or A_l / A_o (0 if not finite) where a centre t covers had no estimate
// (I_max = IMPORTANCE_NO_DENSITY_ESTIMATE: triangleImportance() in importance.h),
// A_o in world units^2, A_l in texels^2. Conventions (as areaRatio() in
// engine/importance/importance.cpp): A_l = 0 -> ratio 0; A_o = 0 < A_l ->
// IMPORTANCE_MAX_AREA_RATIO, so I(t) = I_max(t). One invocation per triangle
// of a chunk: the buffers are bound as ranges starting at the chunk's first
// triangle.
#include "shared/importance_layout.h"

layout(local_size_x = IMPORTANCE_GROUP_SIZE) in;

layout(std430, binding = IMPORTANCE_BINDING_VERTICES) readonly buffer Vertices { BakeVertex vertices[]; };
layout(std430, binding = IMPORTANCE_BINDING_MAX_DENSITY) readonly buffer MaxDensity { uint maxDensityBits[]; };
layout(std430, binding = IMPORTANCE_BINDING_IMPORTANCE) writeonly buffer Importance { float importance[]; };
layout(std430, binding = IMPORTANCE_BINDING_AREA_RATIO) writeonly buffer AreaRatio { float areaRatio[]; };
uniform uint triangleCount;  // in this chunk
uniform float resolution;    // page side in texels

void main() {
    uint t = gl_GlobalInvocationID.x;
    if (t >= triangleCount) return;
    vec3 p0 = vertices[3u * t].position.xyz;
    vec3 p1 = vertices[3u * t + 1u].position.xyz;
    vec3 p2 = vertices[3u * t + 2u].position.xyz;
    vec2 a = (vertices[3u * t + 1u].lightmapUv - vertices[3u * t].lightmapUv) * resolution;
    vec2 b = (vertices[3u * t + 2u].lightmapUv - vertices[3u * t].lightmapUv) * resolution;
    precise float worldArea = 0.5 * length(cross(p1 - p0, p2 - p0));
    precise float texelArea = 0.5 * abs(a.x * b.y - a.y * b.x);
    float ratio = 0.0;
    if (texelArea > 0.0) {
        ratio = worldArea > 0.0 ? texelArea / worldArea : float(IMPORTANCE_MAX_AREA_RATIO);
        if (!(ratio <= float(IMPORTANCE_MAX_AREA_RATIO))) ratio = float(IMPORTANCE_MAX_AREA_RATIO);
    }
    float maxDensity = uintBitsToFloat(maxDensityBits[t]);
    areaRatio[t] = ratio;
    if (maxDensity == IMPORTANCE_NO_DENSITY_ESTIMATE)
        importance[t] = ratio < float(IMPORTANCE_MAX_AREA_RATIO) ? ratio : 0.0;
    else
        importance[t] = min(ratio, maxDensity);
}
