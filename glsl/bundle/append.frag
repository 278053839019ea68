#version 430
// Bundle pass: append one node per fragment to its pixel's linked list.
// Outgoing radiance comes from the previous iteration: Lo = Le + albedo * L_lm,
// written per texel into the RGB9E5 `radiance` (lightmap/meta.frag).
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

layout(binding = BINDING_NODE_COUNTER) uniform atomic_uint nodeCounter;
layout(binding = BINDING_HEADS, r32ui) uniform coherent uimage2D heads;
layout(std430, binding = BINDING_NODES) buffer Nodes { Node nodes[]; };
layout(binding = BINDING_RADIANCE) uniform sampler2DArray radiance;

uniform uint nodeCapacity;
uniform uint randomSeed;  // per direction and leaf (not per tile: tiles change with the budget, the bytes must not)
uniform int backLayerOffset;  // > 0: double-sided triangles' back sides' radiance at layer page + backLayerOffset

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);  // in the tile (the head image)
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
    uint back = NODE_FLAG_MASK & ~front;
    bool twoSides = (vFlags & TRIANGLE_DOUBLE_SIDED) != 0u;
    // a double-sided surface: its back side's own radiance, in a second node at
    // the same depth where it differs (the same depth bits: update.frag tells
    // them apart by their sides)
    uint radianceBack = radianceFront;
    if (twoSides && backLayerOffset > 0)
        radianceBack = encodeRgbe(textureLod(radiance, vec3(lightmapUv, float(int(vPage) + backLayerOffset)), 0.0).rgb, u);
    uint depthBits = floatBitsToUint(depth) & ~NODE_FLAG_MASK;
    if (!twoSides || radianceBack == radianceFront) {
        uint index = atomicCounterIncrement(nodeCounter);
        if (index >= nodeCapacity) return;  // overflow: the host sees counter > capacity and redraws split
        nodes[index].radiance = radianceFront;
        nodes[index].depth = depthBits | (twoSides ? NODE_FLAG_MASK : front);
        nodes[index].next = imageAtomicExchange(heads, pixel, index);
        return;
    }
    uint index = atomicCounterIncrement(nodeCounter);
    uint indexBack = atomicCounterIncrement(nodeCounter);
    if (max(index, indexBack) >= nodeCapacity) return;
    nodes[index].radiance = radianceFront;
    nodes[index].depth = depthBits | front;
    nodes[indexBack].radiance = radianceBack;
    nodes[indexBack].depth = depthBits | back;
    nodes[index].next = imageAtomicExchange(heads, pixel, index);
    nodes[indexBack].next = imageAtomicExchange(heads, pixel, indexBack);
}
