// Points of a texel's footprint for the direct light passes (emitter.frag,
// punctual.frag): the light map fragment's, along its triangle's plane
// (lib/texel_footprint.glsl), or with CURVED_FOOTPRINT a curved texel's, on
// the triangles that hold them (lib/curved_footprint.glsl).
// Needs lib/texel_footprint.glsl, `page` and `footprint`.
#ifdef CURVED_FOOTPRINT
uint vCurved;  // this fragment's curved texel (curvedFragmentIndex)
#include "lib/curved_footprint.glsl"
#else
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
    // the light map fragment's steps per texel (flat texels)
    vec3 positionDx, positionDy, normalDx, normalDy, baryDx, baryDy;
};

// A point of the footprint: position, shading normal, its triangle's plane's normal (any length).
struct FootprintPoint {
    vec3 position, normal, plane;
};

#ifdef CURVED_FOOTPRINT
bool texelFootprint(out TexelFootprint t) {
    if (gl_HelperInvocation || !curvedFragmentIndex(vCurved)) return false;
    uvec4 head = curvedTexels[vCurved];
    t.texel = curvedTexelTexel(head);
    t.footprint = texelFetch(footprint, t.texel, 0).rgb;
    t.centre = curvedTexelCentre(vCurved);
    CurvedTriangle owner = curvedTriangles[curvedRefs[head.z]];
    t.size = max(length(owner.positionDx.xyz), length(owner.positionDy.xyz));
    return true;
}

FootprintPoint footprintPoint(TexelFootprint t, uint sampleIndex) {
    if (curvedTexelIsFlat(curvedTexels[vCurved])) {
        // a flat partial texel: along its owner's plane, as the raster's texels
        FlatFrame f = curvedFlatFrame(vCurved);
        vec2 o = footprintOffset(f.bary, f.baryDx, f.baryDy, f.flags, t.footprint, sampleIndex);
        return FootprintPoint(f.position + f.positionDx * o.x + f.positionDy * o.y,
                              normalize(f.normal + f.normalDx * o.x + f.normalDy * o.y),
                              cross(f.positionDx, f.positionDy));
    }
    vec2 point;
    CurvedTriangle tri;
    curvedFootprintPoint(vCurved, t.footprint.xy, sampleIndex, point, tri);
    vec2 q = point - tri.corners01.xy;
    return FootprintPoint(tri.position.xyz + tri.positionDx.xyz * q.x + tri.positionDy.xyz * q.y,
                          normalize(tri.normal.xyz + tri.normalDx.xyz * q.x + tri.normalDy.xyz * q.y),
                          tri.faceNormal.xyz);
}
#else
// False: a helper lane or a curved texel (its own draw's).
bool texelFootprint(out TexelFootprint t) {
    // derivatives before any return: they need the whole quad
    t.positionDx = dFdx(vPosition);
    t.positionDy = dFdy(vPosition);
    t.normalDx = dFdx(vNormal);
    t.normalDy = dFdy(vNormal);
    t.baryDx = dFdx(vBary);
    t.baryDy = dFdy(vBary);
    if (gl_HelperInvocation) return false;
    t.texel = ivec3(ivec2(gl_FragCoord.xy), page);
    if ((texelFetch(texelCharts, t.texel, 0).r & TEXEL_CURVED) != 0u) return false;
    t.footprint = texelFetch(footprint, t.texel, 0).rgb;
    t.centre = vPosition;
    t.size = max(length(t.positionDx), length(t.positionDy));
    return true;
}

FootprintPoint footprintPoint(TexelFootprint t, uint sampleIndex) {
    vec2 o = footprintOffset(vBary, t.baryDx, t.baryDy, vFlags, t.footprint, sampleIndex);
    return FootprintPoint(vPosition + t.positionDx * o.x + t.positionDy * o.y,
                          normalize(vNormal + t.normalDx * o.x + t.normalDy * o.y), cross(t.positionDx, t.positionDy));
}
#endif
