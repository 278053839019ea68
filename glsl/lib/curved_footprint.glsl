// Curved texels (issue 11: a texel holds the mean over the part of its square
// on its chart). Where the chart folds or curves within a texel's square (a
// chair's piping: 96 sliver triangles wrap a 7 mm tube into one texel row),
// the owner triangle's plane extended over the square (lib/texel_footprint.glsl)
// leaves the surface, and every sample read the light of one facet's
// orientation (the piping's texels 15 against the reference's 120). Such
// texels (engine/layout/bake_mesh.h curvedTexels) are drawn as points, one per
// texel (lightmap/curved.vert), by the update, sun, emitter and point light
// passes, and each sample finds its footprint point on the triangle that
// holds it: its position, shading normal and plane are that triangle's.
//
// Needs shared/bundle_layout.h, lib/rounding.glsl and lib/texel_footprint.glsl.

// A curved texel: uvec4(x | y << 16, page, first ref, ref count).
layout(std430, binding = BINDING_CURVED_TEXELS) readonly buffer CurvedTexels { uvec4 curvedTexels[]; };
// Per curved texel, its triangles (indices into curvedTriangles), owner first.
layout(std430, binding = BINDING_CURVED_REFS) readonly buffer CurvedRefs { uint curvedRefs[]; };
// engine/bake/curved_footprints.h CurvedTriangle: the triangle in page texels
// and its position and shading normal as affine functions of them.
struct CurvedTriangle {
    vec4 corners01;   // corners 0 and 1, page texels
    vec4 corner2;     // corner 2; z: flags (uint bits), w: curvature (1 / scene units)
    vec4 position;    // at corner 0
    vec4 positionDx;  // per texel along x
    vec4 positionDy;  // per texel along y
    vec4 normal;      // shading normal at corner 0 (unnormalised), and its steps
    vec4 normalDx;
    vec4 normalDy;
    vec4 faceNormal;  // unit; the side the bundle pass gives its fragments (TRIANGLE_DERIVATIVE_NORMAL_FLIPPED applied)
};
layout(std430, binding = BINDING_CURVED_TRIANGLES) readonly buffer CurvedTriangles { CurvedTriangle curvedTriangles[]; };

// Whether page point p lies on triangle c (its edges count).
bool curvedTriangleHolds(CurvedTriangle c, vec2 p) {
    vec2 a = c.corners01.xy, b = c.corners01.zw, d = c.corner2.xy;
    float area = (b.x - a.x) * (d.y - a.y) - (b.y - a.y) * (d.x - a.x);
    vec3 w = vec3((d.x - b.x) * (p.y - b.y) - (d.y - b.y) * (p.x - b.x),
                  (a.x - d.x) * (p.y - d.y) - (a.y - d.y) * (p.x - d.x),
                  (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x));
    return all(greaterThanEqual(w * sign(area), vec3(0.0)));
}

// A curved texel's square's centre in page texels (`head`: its first uvec4).
vec2 curvedTexelSquareCentre(uvec4 head) { return vec2(head.x & 0xffffu, head.x >> 16u) + 0.5; }

// Curved texel `index`'s centre on its owner triangle (the first of its
// triangles, which holds the centre): where the leaf that takes its samples is.
vec3 curvedTexelCentre(uint index) {
    uvec4 head = curvedTexels[index];
    CurvedTriangle owner = curvedTriangles[curvedRefs[head.z]];
    vec2 q = curvedTexelSquareCentre(head) - owner.corners01.xy;
    return owner.position.xyz + owner.positionDx.xyz * q.x + owner.positionDy.xyz * q.y;
}

// Sample `sampleIndex`'s point of curved texel `index` (its square's part on
// the chart, uniform: candidates as footprintOffset draws them, each kept if
// one of the texel's triangles holds it): page point `point`, triangle `tri`.
// After 8 candidates the centre, which the owner holds.
void curvedFootprintPoint(uint index, uvec2 cells, uint sampleIndex, out vec2 point, out CurvedTriangle tri) {
    uvec4 head = curvedTexels[index];
    vec2 centre = curvedTexelSquareCentre(head);
    for (int attempt = 0; attempt < 8; ++attempt) {
        vec2 offset = footprintCandidate(sampleIndex, attempt);
        if (!cellOnChart(cells, offset)) continue;
        point = centre + offset;
        for (uint k = 0u; k < head.w; ++k) {
            tri = curvedTriangles[curvedRefs[head.z + k]];
            if (curvedTriangleHolds(tri, point)) return;
        }
    }
    point = centre;
    tri = curvedTriangles[curvedRefs[head.z]];
}
