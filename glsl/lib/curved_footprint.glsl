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
#include "lib/triangle_2d.glsl"

// A curved texel: uvec4(x | y << 16, page, first ref, ref count | CURVED_TEXEL_FLAT | CURVED_TEXEL_EXACT).
layout(std430, binding = BINDING_CURVED_TEXELS) readonly buffer CurvedTexels { uvec4 curvedTexels[]; };

// A partial texel (engine/layout/bake_mesh.h texelOwners: its centre on no
// triangle, its square partly on a chart) that is flat: sampled as the
// raster's texels are, along its owner's plane (curvedFlatFrame).
bool curvedTexelIsFlat(uvec4 head) { return (head.w & CURVED_TEXEL_FLAT) != 0u; }
uint curvedTexelTriangles(uvec4 head) { return head.w & ~(CURVED_TEXEL_FLAT | CURVED_TEXEL_EXACT); }
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
bool curvedTriangleHolds(CurvedTriangle c, vec2 p) { return triangleHolds(c.corners01.xy, c.corners01.zw, c.corner2.xy, p); }

// A curved draw (lightmap/curved.vert) covers curved texels [curvedFirst,
// curvedFirst + curvedCount) with one rectangle, curvedRowWidth texels a row
// from the viewport's corner: llvmpipe shades 4 x 4 blocks, and a point a
// texel cost a block each (the update pass +80 % on a city whose chart
// borders' partial texels were drawn so).
uniform uint curvedFirst;
uniform uint curvedCount;
uniform uint curvedRowWidth;

#ifndef CURVED_VERTEX_SHADER
// This fragment's curved texel (its index); false past the draw's run.
bool curvedFragmentIndex(out uint index) {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint k = p.y * curvedRowWidth + p.x;
    index = curvedFirst + k;
    return k < curvedCount;
}
#endif

// A curved texel's texel in its page (`head`: its first uvec4).
ivec3 curvedTexelTexel(uvec4 head) { return ivec3(int(head.x & 0xffffu), int(head.x >> 16u), int(head.y)); }

// Whether the point `offset` texels from curved texel `index`'s square's
// centre lies off its triangles (lib/texel_footprint.glsl offChart, for a
// CURVED_TEXEL_EXACT texel).
bool exactOffChart(uint index, vec2 offset) {
    uvec4 head = curvedTexels[index];
    vec2 point = vec2(curvedTexelTexel(head).xy) + 0.5 + offset;
    for (uint k = 0u; k < curvedTexelTriangles(head); ++k)
        if (curvedTriangleHolds(curvedTriangles[curvedRefs[head.z + k]], point)) return false;
    return true;
}

// The footprint test for curved texel `index`'s flat samples: its triangles'
// where its flat test is inexact, else the flat test (offChart).
void useFootprintOf(uint index) {
    exactFootprint = (curvedTexels[index].w & CURVED_TEXEL_EXACT) != 0u ? index : NO_EXACT_FOOTPRINT;
}

// A curved texel's square's centre in page texels (`head`: its first uvec4).
vec2 curvedTexelSquareCentre(uvec4 head) { return vec2(curvedTexelTexel(head).xy) + 0.5; }

// The point of triangle c nearest page point p (p where c holds it).
vec2 nearestOnTriangle(CurvedTriangle c, vec2 p) { return nearestOnTriangle(c.corners01.xy, c.corners01.zw, c.corner2.xy, p); }

// Triangle c's position at page point p (its plane, extended past it).
vec3 curvedTrianglePosition(CurvedTriangle c, vec2 p) {
    vec2 q = p - c.corners01.xy;
    return c.position.xyz + c.positionDx.xyz * q.x + c.positionDy.xyz * q.y;
}

// Triangle c's shading normal at page point p, not normalised.
vec3 curvedTriangleNormal(CurvedTriangle c, vec2 p) {
    vec2 q = p - c.corners01.xy;
    return c.normal.xyz + c.normalDx.xyz * q.x + c.normalDy.xyz * q.y;
}

// Whether the surface at p bends toward the side its face normal looks to (a
// tube's inside, a bowl's): the shading normal's turn along each texel axis
// against that axis's step, summed (the shape operator's trace, up to scale),
// is negative where the normals converge ahead of the surface.
bool curvedTriangleConcave(CurvedTriangle c, vec2 p) {
    float bend = dot(c.normalDx.xyz, c.positionDx.xyz) / max(dot(c.positionDx.xyz, c.positionDx.xyz), 1e-30) +
                 dot(c.normalDy.xyz, c.positionDy.xyz) / max(dot(c.positionDy.xyz, c.positionDy.xyz), 1e-30);
    return bend * dot(curvedTriangleNormal(c, p), c.faceNormal.xyz) < 0.0;
}

// Curved texel `index`'s centre on its owner triangle (the first of its
// triangles, which holds the centre, or of a partial texel the point nearest
// it): where the leaf that takes its samples is.
vec3 curvedTexelCentre(uint index) {
    uvec4 head = curvedTexels[index];
    CurvedTriangle owner = curvedTriangles[curvedRefs[head.z]];
    return curvedTrianglePosition(owner, nearestOnTriangle(owner, curvedTexelSquareCentre(head)));
}

// A flat partial texel's frame (curvedTexelIsFlat, lib/texel_footprint.glsl
// FlatFrame): its owner's at the square's centre, on the owner's plane extended.
FlatFrame curvedFlatFrame(uint index) {
    uvec4 head = curvedTexels[index];
    CurvedTriangle c = curvedTriangles[curvedRefs[head.z]];
    vec2 a = c.corners01.xy, e1 = c.corners01.zw - a, e2 = c.corner2.xy - a;
    vec2 centre = curvedTexelSquareCentre(head), q = centre - a;
    float det = e1.x * e2.y - e1.y * e2.x;
    // barycentrics 1 and 2 solve e1 b1 + e2 b2 = q; their steps per texel are the inverse's rows
    vec2 dB1 = vec2(e2.y, -e2.x) / det, dB2 = vec2(-e1.y, e1.x) / det;
    float b1 = dot(dB1, q), b2 = dot(dB2, q);
    FlatFrame f;
    f.position = curvedTrianglePosition(c, centre);
    f.normal = curvedTriangleNormal(c, centre);
    f.bary = vec3(1.0 - b1 - b2, b1, b2);
    f.baryDx = vec3(-dB1.x - dB2.x, dB1.x, dB2.x);
    f.baryDy = vec3(-dB1.y - dB2.y, dB1.y, dB2.y);
    f.positionDx = c.positionDx.xyz;
    f.positionDy = c.positionDy.xyz;
    f.normalDx = c.normalDx.xyz;
    f.normalDy = c.normalDy.xyz;
    f.flags = floatBitsToUint(c.corner2.z);
    return f;
}

// Sample `sampleIndex`'s point of curved texel `index` (its square's part on
// the chart, uniform: candidates as footprintOffset draws them, each kept if
// one of the texel's triangles holds it): page point `point`, triangle `tri`.
// After 8 candidates the owner's point nearest the centre.
void curvedFootprintPoint(uint index, uvec2 cells, uint sampleIndex, out vec2 point, out CurvedTriangle tri) {
    uvec4 head = curvedTexels[index];
    vec2 centre = curvedTexelSquareCentre(head);
    uint count = curvedTexelTriangles(head);
    for (int attempt = 0; attempt < 8; ++attempt) {
        vec2 offset = footprintCandidate(sampleIndex, attempt, cells);
        if (!cellOnChart(cells, offset)) continue;
        point = centre + offset;
        for (uint k = 0u; k < count; ++k) {
            tri = curvedTriangles[curvedRefs[head.z + k]];
            if (curvedTriangleHolds(tri, point)) return;
        }
    }
    tri = curvedTriangles[curvedRefs[head.z]];
    point = nearestOnTriangle(tri, centre);
}
