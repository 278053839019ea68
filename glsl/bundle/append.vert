#version 430
// Bundle pass: orthographic projection of the scene along d into the tile.
#include "shared/bundle_layout.h"
#include "lib/bake_vertex.glsl"
#include "lib/bundle_frame.glsl"

uniform int viewportPixels;   // the viewport's side: a power of two >= leafPixels
uniform float subpixelSteps;  // 2^GL_SUBPIXEL_BITS

// The whole triangle, for the plane equations below, and its side.
#include "lib/triangle_side.glsl"

// Depth and light map uv as planes over the leaf's pixel grid: value =
// dot(plane.xy, pixel centre) + plane.z. Every vertex of a triangle computes
// the same planes from the same three vertices, and a fragment evaluates them
// at its leaf pixel centre, so a node's depth and radiance do not depend on
// which tile drew it (the rasterizer's own interpolation is set up relative
// to the viewport, and differs in the last bits from tile to tile).
flat out vec3 vDepthPlane;
flat out vec3 vUPlane;
flat out vec3 vVPlane;
flat out uint vPage;
flat out uint vFlags;
flat out vec3 vFaceNormal;
flat out uint vTriangle;
// cut-outs: TEXCOORD_0 as planes too (the mask's edge must not move with the tile)
flat out vec3 vUv0XPlane;
flat out vec3 vUv0YPlane;
flat out uint vMaterial;
// the true triangle: each corner's leaf grid x, y and depth (append.frag planePoint)
flat out vec3 vCorners[3];

vec3 plane(vec2 p0, vec2 p1, vec2 p2, float a0, float a1, float a2, float det) {
    vec2 e1 = p1 - p0, e2 = p2 - p0;
    float da1 = a1 - a0, da2 = a2 - a0;
    vec2 grad = vec2(da1 * e2.y - da2 * e1.y, e1.x * da2 - e2.x * da1) / det;
    return vec3(grad, a0 - dot(grad, p0));
}

void main() {
    uint t = uint(gl_VertexID) / 3u;
    uint v0 = 3u * (t - meshChunkFirstTriangle);  // the triangle's first vertex in the bound chunk
    vec3 b = bundleFromWorld(inPosition.xyz);
    // Clip space of the leaf's grid: the viewport (-tileOffset) and a scissor
    // to the tile select the tile. Vertices are snapped to the rasterizer's
    // subpixel grid, in a viewport of a power-of-two side: every step to
    // window coordinates is then exact in float, so shifting the viewport by
    // a tile's integer offset moves the snapped vertices by exactly that much,
    // and each pixel's coverage is the same whichever tile draws it.
    vec2 g = round(gridFromRoot(rootFromBundle(b.xy)) * subpixelSteps) / subpixelSteps;
    vec2 ndc = g * (2.0 / float(viewportPixels)) - 1.0;
    gl_Position = vec4(ndc, 0.0, 1.0);  // no depth clipping: every fragment along the line counts

    vec3 c[3];
    vec2 p[3];
    for (int k = 0; k < 3; ++k) {
        c[k] = bundleFromWorld(vertices[v0 + uint(k)].position.xyz);
        p[k] = gridFromRoot(rootFromBundle(c[k].xy));  // the true plane, not the snapped one: exact depths
        vCorners[k] = vec3(p[k], c[k].z);
    }
    float det = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
    if (det != 0.0) {
        vDepthPlane = plane(p[0], p[1], p[2], c[0].z, c[1].z, c[2].z, det);
        vec2 uv0 = vertices[v0].lightmapUv, uv1 = vertices[v0 + 1u].lightmapUv, uv2 = vertices[v0 + 2u].lightmapUv;
        vUPlane = plane(p[0], p[1], p[2], uv0.x, uv1.x, uv2.x, det);
        vVPlane = plane(p[0], p[1], p[2], uv0.y, uv1.y, uv2.y, det);
        vec2 t0 = vertices[v0].uv0, t1 = vertices[v0 + 1u].uv0, t2 = vertices[v0 + 2u].uv0;
        vUv0XPlane = plane(p[0], p[1], p[2], t0.x, t1.x, t2.x, det);
        vUv0YPlane = plane(p[0], p[1], p[2], t0.y, t1.y, t2.y, det);
    } else {
        // no area on the grid: no fragment either (kept finite all the same)
        vDepthPlane = vec3(0.0, 0.0, c[0].z);
        vUPlane = vec3(0.0, 0.0, inLightmapUv.x);
        vVPlane = vec3(0.0, 0.0, inLightmapUv.y);
        vUv0XPlane = vec3(0.0, 0.0, inUv0.x);
        vUv0YPlane = vec3(0.0, 0.0, inUv0.y);
    }
    uvec4 tri = bakeTriangle(t);
    vPage = tri.y;
    vMaterial = tri.x;
    vFlags = tri.w;
    vFaceNormal = triangleSide(t);
    vTriangle = t;  // gl_PrimitiveID restarts with each draw of a multi-draw
}
