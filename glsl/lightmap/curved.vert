#version 430
// Curved texels (lib/curved_footprint.glsl): one point a texel, at its
// centre on its page; the update and sun passes draw them in runs of the
// tile's clusters (engine/bake/curved_footprints.h), the direct light passes
// all at once.
#include "shared/bundle_layout.h"
#include "shared/mesh_layout.h"
#include "lib/rounding.glsl"
#include "lib/texel_footprint.glsl"
#include "lib/curved_footprint.glsl"

uniform int pageResolution;
flat out uint vCurved;

void main() {
    vec2 centre = curvedTexelSquareCentre(curvedTexels[gl_VertexID]);
    gl_Position = vec4(centre / float(pageResolution) * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = 1.0;
    vCurved = uint(gl_VertexID);
}
