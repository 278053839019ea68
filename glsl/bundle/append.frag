#version 430
// Bundle pass: append one node per fragment to its pixel's linked list.
// Outgoing radiance comes from the previous iteration: Lo = Le + albedo * L_lm,
// written per texel into the RGB9E5 `radiance` (lightmap/meta.frag), read
// where the fragment lands (radianceAt).
#include "shared/bundle_layout.h"
#include "shared/mesh_layout.h"
#include "lib/rounding.glsl"
#include "lib/bundle_frame.glsl"
#include "shared/material_layout.h"
#include "lib/alpha_mask.glsl"
#include "lib/triangle_2d.glsl"

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
flat in vec3 vCorners[3];

layout(binding = BINDING_NODE_COUNTER, offset = 0) uniform atomic_uint nodeCounter;
// the nodes of the tile's own pixels (the rest are its apron's, another tile's own)
layout(binding = BINDING_NODE_COUNTER, offset = 4) uniform atomic_uint ownedCounter;
layout(binding = BINDING_HEADS, r32ui) uniform coherent uimage2D heads;
layout(std430, binding = BINDING_NODES) buffer Nodes { Node nodes[]; };
layout(binding = BINDING_RADIANCE) uniform sampler2DArray radiance;
layout(binding = BINDING_READ_MODES) uniform usampler2DArray readModes;
layout(binding = BINDING_TEXEL_CHARTS) uniform usampler2DArray texelCharts;
layout(binding = BINDING_SLOPES) uniform sampler2DArray slopes;
uniform bool slopesInside;  // the slopes are the radiance map's (not while the resolution probe reads coarser maps)

uniform uint nodeCapacity;
uniform uint randomSeed;  // per direction and leaf (not per tile: tiles change with the budget, the bytes must not)
uniform int backLayerOffset;  // BACK_SIDES: double-sided triangles' back sides' radiance at layer page + backLayerOffset

// The monotonized-central limiter (van Leer), per channel, from the
// differences a and b to the two neighbours along an axis: the central
// difference, at most twice either one-sided one, 0 at an extremum
vec3 limitedSlope(vec3 a, vec3 b) {
    return mix(vec3(0.0), sign(a) * min(abs(a + b) * 0.5, 2.0 * min(abs(a), abs(b))), greaterThan(a * b, vec3(0.0)));
}

// The offset from the texel's mean m at position x in [-1/2, 1/2] along one
// axis, from its neighbours l before and r after on the same chart, as
// lightmap/read_modes.comp decided: READ_STEP where a shadow's edge, a
// contact or a slot's rim crosses the texel: the r side's share f = (m - l)
// / (r - l) of it reads r, the rest l (Harten's subcell resolution, for cell
// means); READ_SLOPE the limited slope; READ_NONE the mean. Each keeps the
// texel's mean.
vec3 axisOffset(uint mode, vec3 l, vec3 m, vec3 r, float x) {
    vec3 a = m - l, b = r - m;
    bvec3 inside = greaterThan(a * b, vec3(0.0));
    vec3 share = clamp(a / mix(vec3(1.0), r - l, inside), 0.0, 1.0);
    vec3 stepped = mix(l, r, vec3(greaterThan(vec3(x), 0.5 - share))) - m;
    vec3 offset = mode == READ_STEP ? mix(vec3(0.0), stepped, inside) : limitedSlope(a, b) * x;
    return mode == READ_NONE ? vec3(0.0) : offset;
}

// The texel whose radiance a fragment of chart `chart` reads at texel position
// t (page texels minus 1/2): the nearest, c, unless another chart owns it
// (charts closer than a texel: its light is the other chart's surface's, a
// wall's seen on the sill beside it), then of the eight around c that the
// fragment's own chart owns the one whose square lies nearest t; c where none
// is. Only the three toward t were searched before: past the middle of a
// texel another chart owns, away from its own (a wall's last fifth of a texel
// under a soffit, the texels above a strip's), none is, and the fragment read
// the other chart's light (the city's own atlas: soffits twice too bright).
ivec2 ownTexel(vec2 t, ivec2 c, ivec2 size, int page, uint chart) {
    if ((texelFetch(texelCharts, ivec3(c, page), 0).r & TEXEL_CHART_MASK) == chart) return c;
    ivec2 best = c;
    float bestDistance = 3.0e38;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 n = clamp(c + ivec2(dx, dy), ivec2(0), size - 1);
            if (n == c || (texelFetch(texelCharts, ivec3(n, page), 0).r & TEXEL_CHART_MASK) != chart) continue;
            vec2 e = clamp(t, vec2(n) - 0.5, vec2(n) + 0.5) - t;  // from t to n's square
            float d = dot(e, e);
            if (d < bestDistance) bestDistance = d, best = n;
        }
    return best;
}

// Outgoing radiance where a fragment of chart `chart` lands, light-map
// position uv on page `page`, layer `layer` (the page or its back sides'
// layer): its texel's (ownTexel) mean plus an offset along each axis from the
// texels next to it on the same chart (none from another chart or padding, so
// no light crosses), kept within their range. A ray that meets the dark side
// of a texel a shadow, a contact or a slot's rim crosses reads the dark side's
// light, not the texel's mean (design notes, "Radiance reads"). Six fetches a
// fragment and one to four for its texel's chart: what could be decided once
// per texel is (read_modes.comp), as llvmpipe runs every fetch.
vec3 radianceAt(vec2 uv, int page, int layer, uint chart) {
    ivec2 size = textureSize(radiance, 0).xy;
    vec2 t = uv * vec2(size) - 0.5;
    ivec2 c = ownTexel(t, clamp(ivec2(floor(t + 0.5)), ivec2(0), size - 1), size, page, chart);
    vec2 f = clamp(t - vec2(c), vec2(-0.5), vec2(0.5));
    uint modes = texelFetch(readModes, ivec3(c, layer), 0).r;
    vec3 m = texelFetch(radiance, ivec3(c, layer), 0).rgb;
    vec3 l = texelFetch(radiance, ivec3(max(c.x - 1, 0), c.y, layer), 0).rgb;
    vec3 r = texelFetch(radiance, ivec3(min(c.x + 1, size.x - 1), c.y, layer), 0).rgb;
    vec3 d = texelFetch(radiance, ivec3(c.x, max(c.y - 1, 0), layer), 0).rgb;
    vec3 u = texelFetch(radiance, ivec3(c.x, min(c.y + 1, size.y - 1), layer), 0).rgb;
    uint modeX = modes & 3u, modeY = (modes >> 2u) & 3u;
    vec3 lo = m, hi = m;
    if (modeX != READ_NONE) lo = min(lo, min(l, r)), hi = max(hi, max(l, r));
    if (modeY != READ_NONE) lo = min(lo, min(d, u)), hi = max(hi, max(d, u));
    vec3 read = clamp(m + axisOffset(modeX, l, m, r, f.x) + axisOffset(modeY, d, m, u, f.y), lo, hi);
    // Along an axis with no neighbour on the chart to take a slope from (a
    // chart's edge, a strip a texel wide), the slope measured inside the texel
    // from its own samples (meta.frag slopeInside), about their mean point, in
    // the texel's colour, within the mean either way
    float total = dot(m, vec3(1.0));
    if (slopesInside && (modeX == READ_NONE || modeY == READ_NONE) && total > 0.0) {
        vec4 inside = texelFetch(slopes, ivec3(c, layer), 0);
        vec2 along = vec2(modeX == READ_NONE ? 1.0 : 0.0, modeY == READ_NONE ? 1.0 : 0.0);
        float offset = dot(inside.xy * along, f - inside.zw);
        read += m * clamp(offset / total, -1.0, 1.0);
    }
    return max(read, vec3(0.0));
}

// Where a fragment reads its triangle's planes: its pixel's centre c, or,
// where c lies off the true triangle, the triangle's point nearest c and the
// depth there (`depth`, along the edge; the planes are exact at the corners).
// The raster covers the triangle snapped to its subpixel grid, up to half a
// step (1/512 of a pixel) past the true one. Where two faces meet at a box's
// outline (one toward d, one away), their planes cross at the edge, and read
// past it their order along the ray flips: a ray just outside the outline met
// the far side's back before the near side, and read black (the rho 0.99
// furnace's inner box: 4.3e-6 of its samples, most of its -0.086 % at 4096
// directions). Read on the edge, the two share a depth, and the ray takes the
// side it sees (update.frag preferred). Where the triangle's neighbour in
// the same plane goes on, its plane read past the edge was exact, and the
// edge's point is off by the same step times the plane's slope. The depth
// is interpolated along the edge, not read from the plane there: a steep
// plane's terms cancel, the two faces of an edge parted by their rounding,
// and that settled the tie (the furnace at 4096 directions: -0.020 % so,
// -0.002 % along the edge).
vec2 planePoint(vec2 c, out float depth) {
    vec2 a = vCorners[0].xy, b = vCorners[1].xy, d = vCorners[2].xy;
    depth = dot(vDepthPlane.xy, c) + vDepthPlane.z;
    if (doubleArea(a, b, d) != 0.0 && triangleHolds(a, b, d, c)) return c;
    vec2 nearest = c;
    float best = 3.0e38;
    for (int k = 0; k < 3; ++k) {
        vec3 from = vCorners[k], to = vCorners[(k + 1) % 3];
        vec2 e = to.xy - from.xy;
        float t = segmentParameter(from.xy, to.xy, c);
        vec2 q = from.xy + t * e;
        float d2 = dot(c - q, c - q);
        if (d2 < best) best = d2, nearest = q, depth = mix(from.z, to.z, t);
    }
    return nearest;
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);  // in the drawn window (the head image)
    bool owned = ownedPixel(pixel);
    ivec2 leafPixel = pixel + tileOffset;
    float depth;
    vec2 centre = planePoint(vec2(leafPixel) + 0.5, depth);
    // a cut-out's cut-away part is not there: no node, light goes through
    if ((vFlags & TRIANGLE_ALPHA_MASK) != 0u &&
        alphaCut(vMaterial, vec2(dot(vUv0XPlane.xy, centre) + vUv0XPlane.z, dot(vUv0YPlane.xy, centre) + vUv0YPlane.z)))
        return;
    vec2 lightmapUv = vec2(dot(vUPlane.xy, centre) + vUPlane.z, dot(vVPlane.xy, centre) + vVPlane.z);
    uint h = pcgHash(randomSeed ^ pcgHash(uint(leafPixel.x) + 65536u * uint(leafPixel.y)) ^ pcgHash(vTriangle + 0x9E3779B9u));
    vec3 u = vec3(uniform01(h), uniform01(pcgHash(h)), uniform01(pcgHash(h + 1u)));
    // the side the triangle's front faces (its texels' side, update.frag)
    uint front = dot(vFaceNormal, bundleDir) < 0.0 ? NODE_VISIBLE_FROM_BEHIND : NODE_VISIBLE_FROM_AHEAD;
    uint chart = vFlags >> TRIANGLE_CHART_SHIFT;
    uint radianceFront = encodeRgbe(radianceAt(lightmapUv, int(vPage), int(vPage), chart), u);
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
        vec3 lo = radianceAt(lightmapUv, int(vPage), int(vPage) + backLayerOffset, chart);
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
