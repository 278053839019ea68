// Points of a texel's footprint for the direct light passes (emitter.frag,
// punctual.frag): the light map fragment's, along its triangle's plane
// (lib/texel_footprint.glsl), or with CURVED_FOOTPRINT a curved texel's, on
// the triangles that hold them (lib/curved_footprint.glsl).
// Needs lib/texel_footprint.glsl, `page` and `footprint`.
#ifdef CURVED_FOOTPRINT
uint vCurved;  // this fragment's curved texel (curvedFragmentIndex)
#include "lib/curved_footprint.glsl"
#else
#include "lib/raster_frame.glsl"
in vec3 vPosition;
in vec3 vNormal;
in vec3 vBary;
flat in uint vFlags;
// bit TEXEL_CURVED: the curved texels' draw takes the texel
layout(binding = BINDING_TEXEL_CHARTS) uniform usampler2DArray texelCharts;
#endif

struct TexelFootprint {
    ivec3 texel;
    uvec3 footprint;
    vec3 centre;  // the texel's centre on its surface
    float size;   // its size on the surface (the longer of its steps along x and y)
    bool onPlane; // along its triangle's plane (the raster's texels, flat partial ones): `frame`
    FlatFrame frame;
};

// A point of the footprint: position, shading normal, its triangle's plane's normal (any length).
struct FootprintPoint {
    vec3 position, normal, plane;
};

// Sample `sampleIndex`'s point of a texel along its triangle's plane (frame f).
FootprintPoint planeFootprintPoint(FlatFrame f, uvec3 footprint, uint sampleIndex) {
    vec2 o = footprintOffset(f.bary, f.baryDx, f.baryDy, f.flags, footprint, sampleIndex);
    return FootprintPoint(f.position + f.positionDx * o.x + f.positionDy * o.y,
                          normalize(f.normal + f.normalDx * o.x + f.normalDy * o.y), cross(f.positionDx, f.positionDy));
}

#ifdef CURVED_FOOTPRINT
bool texelFootprint(out TexelFootprint t) {
    if (gl_HelperInvocation || !curvedFragmentIndex(vCurved)) return false;
    uvec4 head = curvedTexels[vCurved];
    t.texel = curvedTexelTexel(head);
    t.footprint = texelFetch(footprint, t.texel, 0).rgb;
    t.centre = curvedTexelCentre(vCurved);
    t.onPlane = curvedTexelIsFlat(head);
    if (t.onPlane) t.frame = curvedFlatFrame(vCurved);
    useFootprintOf(vCurved);
    CurvedTriangle owner = curvedTriangles[curvedRefs[head.z]];
    t.size = max(length(owner.positionDx.xyz), length(owner.positionDy.xyz));
    return true;
}

FootprintPoint footprintPoint(TexelFootprint t, uint sampleIndex) {
    if (t.onPlane) return planeFootprintPoint(t.frame, t.footprint, sampleIndex);  // a flat partial texel
    vec2 point;
    CurvedTriangle tri;
    curvedFootprintPoint(vCurved, t.footprint.xy, sampleIndex, point, tri);
    return FootprintPoint(curvedTrianglePosition(tri, point), normalize(curvedTriangleNormal(tri, point)),
                          tri.faceNormal.xyz);
}
#else
// False: a helper lane or a curved texel (its own draw's).
bool texelFootprint(out TexelFootprint t) {
    t.frame = rasterFrame(vPosition, vNormal, vBary, vFlags);  // derivatives before any return
    if (gl_HelperInvocation) return false;
    t.texel = ivec3(ivec2(gl_FragCoord.xy), page);
    if ((texelFetch(texelCharts, t.texel, 0).r & TEXEL_CURVED) != 0u) return false;
    t.footprint = texelFetch(footprint, t.texel, 0).rgb;
    t.centre = vPosition;
    t.size = max(length(t.frame.positionDx), length(t.frame.positionDy));
    t.onPlane = true;
    return true;
}

FootprintPoint footprintPoint(TexelFootprint t, uint sampleIndex) { return planeFootprintPoint(t.frame, t.footprint, sampleIndex); }
#endif
