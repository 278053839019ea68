#version 430
// Curved texels (lib/curved_footprint.glsl): a rectangle a run of them, one
// fragment a texel (curvedFragmentIndex); the update and sun passes draw them
// in runs of the tile's clusters (engine/bake/curved_footprints.h), the direct
// light passes all at once.
#include "shared/bundle_layout.h"
#include "shared/mesh_layout.h"
#include "lib/rounding.glsl"
#include "lib/texel_footprint.glsl"
#define CURVED_VERTEX_SHADER  // no fragment's index here
#include "lib/curved_footprint.glsl"

uniform int pageResolution;

void main() {
    // the run's rectangle: rows of curvedRowWidth fragments, one a curved texel
    uint rows = (curvedCount + curvedRowWidth - 1u) / curvedRowWidth;
    const vec2 corners[6] = vec2[6](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 0), vec2(1, 1), vec2(0, 1));
    vec2 pixels = corners[gl_VertexID % 6] * vec2(float(curvedRowWidth), float(rows));
    gl_Position = vec4(pixels / float(pageResolution) * 2.0 - 1.0, 0.0, 1.0);
}
