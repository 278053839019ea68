#version 430
// Bundle pass: append one node per fragment to its pixel's linked list.
// Outgoing radiance comes from the previous iteration: Lo = Le + albedo * L_lm,
// written per texel into the RGB9E5 `radiance` (lightmap/meta.frag), read
// at the fragment's texel (GL_NEAREST: its footprint's mean, engine/bake/baker.cpp).
#include "shared/bundle_layout.h"
#include "shared/mesh_layout.h"
#include "lib/rounding.glsl"
#include "lib/bundle_frame.glsl"
#include "shared/material_layout.h"
#include "lib/alpha_mask.glsl"

flat in vec3 vDepthPlane;
flat in vec3 vUPlane;
flat in vec3 vVPlane;
flat in uint vPage;
flat in uint vFlags;
flat in vec3 vFaceNormal;
flat in uint vTriangle;
flat in vec3 vUv0XPlane;
flat in vec3 vUv0YPlane;
flat in uint vMaterial;

layout(binding = BINDING_NODE_COUNTER, offset = 0) uniform atomic_uint nodeCounter;
// the nodes of the tile's own pixels (the rest are its apron's, another tile's own)
layout(binding = BINDING_NODE_COUNTER, offset = 4) uniform atomic_uint ownedCounter;
layout(binding = BINDING_HEADS, r32ui) uniform coherent uimage2D heads;
layout(std430, binding = BINDING_NODES) buffer Nodes { Node nodes[]; };
layout(binding = BINDING_RADIANCE) uniform sampler2DArray radiance;

uniform uint nodeCapacity;
uniform uint randomSeed;  // per direction and leaf (not per tile: tiles change with the budget, the bytes must not)
uniform int backLayerOffset;  // BACK_SIDES: double-sided triangles' back sides' radiance at layer page + backLayerOffset

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);  // in the drawn window (the head image)
    bool owned = ownedPixel(pixel);
    ivec2 leafPixel = pixel + tileOffset;
    vec2 centre = vec2(leafPixel) + 0.5;
    // a cut-out's cut-away part is not there: no node, light goes through
    if ((vFlags & TRIANGLE_ALPHA_MASK) != 0u &&
        alphaCut(vMaterial, vec2(dot(vUv0XPlane.xy, centre) + vUv0XPlane.z, dot(vUv0YPlane.xy, centre) + vUv0YPlane.z)))
        return;
    float depth = dot(vDepthPlane.xy, centre) + vDepthPlane.z;
    vec2 lightmapUv = vec2(dot(vUPlane.xy, centre) + vUPlane.z, dot(vVPlane.xy, centre) + vVPlane.z);
    uint h = pcgHash(randomSeed ^ pcgHash(uint(leafPixel.x) + 65536u * uint(leafPixel.y)) ^ pcgHash(vTriangle + 0x9E3779B9u));
    vec3 u = vec3(uniform01(h), uniform01(pcgHash(h)), uniform01(pcgHash(h + 1u)));
    // the side the triangle's front faces (its texels' side, update.frag)
    uint front = dot(vFaceNormal, bundleDir) < 0.0 ? NODE_VISIBLE_FROM_BEHIND : NODE_VISIBLE_FROM_AHEAD;
    uint radianceFront = encodeRgbe(textureLod(radiance, vec3(lightmapUv, float(vPage)), 0.0).rgb, u);
    // A double-sided surface is seen from both sides: one node for both where
    // they look the same, else a second node at the same depth for its back
    // side's own radiance (update.frag tells the two apart by their sides),
    // unless that is black.
    bool twoSides = (vFlags & TRIANGLE_DOUBLE_SIDED) != 0u;
    uint radianceBack = radianceFront;
#ifdef BACK_SIDES
    // (only built for scenes with back sides: llvmpipe runs the fetch of a
    // branch no lane takes, 25 % of the pass)
    if (twoSides) {
        vec3 lo = textureLod(radiance, vec3(lightmapUv, float(int(vPage) + backLayerOffset)), 0.0).rgb;
        radianceBack = encodeRgbe(lo, u);
    }
#endif
    uint depthBits = floatBitsToUint(depth) & ~NODE_FLAG_MASK;
    uint frontFlags = twoSides ? NODE_FLAG_MASK : front;
    uint nodeCount = 1u;
    if (radianceBack != radianceFront) {
        // a black back side needs no node of its own: a side no node is seen
        // from reads black (the walls of a closed room, seen from outside:
        // one node each, not two; the texel's own search uses the front's)
        frontFlags = front;
        nodeCount = radianceBack == 0u ? 1u : 2u;
    }
    // the front's node, then the back's where there is one
    for (uint k = 0u; k < nodeCount; ++k) {
        uint index = atomicCounterIncrement(nodeCounter);
        if (index >= nodeCapacity) return;  // overflow: the host sees counter > capacity and redraws split
        if (owned) atomicCounterIncrement(ownedCounter);
        nodes[index].radiance = k == 0u ? radianceFront : radianceBack;
        nodes[index].depth = depthBits | (k == 0u ? frontFlags : NODE_FLAG_MASK & ~front);
        nodes[index].next = imageAtomicExchange(heads, pixel, index);
    }
}
