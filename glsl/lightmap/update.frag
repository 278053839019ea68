#version 450
// Update pass (radiance exchange, Hermes et al. 2010 as used by Tokuyoshi et
// al. 2013): each texel projects into the tile, walks its pixel's list, takes
// the nearest fragment in front of it on the side its normal faces, and
// folds L_in into a running mean with weight |cos| (times the direction's
// weight): W += w, M += (L_in - M) w / W. L_lm = M is the cosine-weighted
// mean of L_in, which equals E/pi. With uniform directions E[W] = N/2, so
// this is DESIGN.md's 2 RGB / N, but:
// - when invalid samples (below) are skipped, dividing by the weight kept
//   (not the count) keeps steep samples from being overweighted; the result
//   is still biased where the skipped grazing light differs from the rest;
// - the stored value stays near L_lm instead of growing with N, so the
//   stochastic rounding noise of each update stays small (an fp16 sum past
//   2048 samples rounds by more than a sample is worth: 1.2 % rms per texel
//   at 4096 directions in the furnace, against 0.03 % for the mean). The
//   mean is kept to 16 bits (lib/rounding.glsl, encodeAccumulator): in fp16
//   its rounding noise still grew like sqrt(N), 1.3 % after 4096 samples
//   where L_in varies as much as the mean.
//
// Double-sided triangles (BACK_SIDES): the walk also takes the
// nearest node the other way, which the texel's back side sees, into the back
// side's own accumulator (baker_impl.h).
//
// SUN_PASS (define): the same walk along the sun's direction; a texel facing
// the sun adds (nothing in front ? irradiance * cos / pi : 0) to the direct
// light's float sums (lib/direct_scratch.glsl) and 1 to its sample count (the
// direct map's alpha; direct_fold.comp divides): an exact shadow test, no noise.
#include "shared/bundle_layout.h"
#include "shared/mesh_layout.h"
#include "lib/rounding.glsl"
#include "lib/bundle_frame.glsl"
#include "lib/texel_footprint.glsl"
#include "lib/raster_frame.glsl"

#ifdef CURVED_FOOTPRINT
// a curved texel (lib/curved_footprint.glsl curvedFragmentIndex: lightmap/curved.vert draws a fragment each)
uint vCurved;
#else
in vec3 vPosition;
in vec3 vNormal;
in vec3 vBary;
flat in uint vFlags;
flat in uint vPage;
// bit TEXEL_CURVED: the curved texels' draw takes the texel's samples
layout(binding = BINDING_TEXEL_CHARTS) uniform usampler2DArray texelCharts;
#endif

layout(binding = BINDING_HEADS, r32ui) uniform readonly uimage2D heads;
layout(std430, binding = BINDING_NODES) readonly buffer Nodes { Node nodes[]; };
#ifdef SUN_PASS
#include "lib/direct_scratch.glsl"
layout(binding = BINDING_DIRECT, rgba16f) uniform coherent image2DArray directMap;
uniform vec3 sunIrradiance;
// The noise estimate's half (direct/direct_noise.comp SUN): the odd passes'
// sums and counts at every halfStride-th texel, as halfAccum's
layout(binding = BINDING_DIRECT_ODD_SUMS, rgba32f) uniform coherent image2DArray oddSums;
uniform bool oddSample;
#else
layout(binding = BINDING_ACCUM, rg32ui) uniform coherent uimage2DArray accum;
layout(binding = BINDING_ENV) uniform sampler2D envMap;
uniform bool useEnv;
uniform vec3 sky;
uniform float sampleWeight;  // this direction's weight (history ramp), relative to the stored scale
uniform uint randomSeed;
// The noise estimate's half (engine/bake/noise.cpp): the odd directions' own
// running mean (the second of the two direction sets, bake/directions.h),
// kept at every halfStride-th texel of each axis.
layout(binding = BINDING_HALF_ACCUM, rg32ui) uniform coherent uimage2DArray halfAccum;
uniform bool oddDirection;
// Each texel's first moments (a back side's at its layer): the running means of L_in's channel sum
// times the sample's point (texels from its centre) and of the point itself,
// folded at the accumulator's weights; lightmap/meta.frag makes them the slope
// of the texel's light inside it, which the bundle pass reads at chart edges.
layout(binding = BINDING_MOMENTS, rgba32f) uniform coherent image2DArray moments;
#ifdef RESOLUTION_PROBE
// The resolution probe (engine/bake/resolution_probe.cpp): this pass's
// samples, weighted, into its layers of the probe's sums at the noise
// estimate's sampled texels; the bake's own accumulators stay as they are.
layout(binding = BINDING_PROBE_SUMS, rgba32f) uniform coherent image2DArray probeSums;
uniform int probeLayer;
#endif
uniform int backLayerOffset;  // BACK_SIDES: double-sided triangles' back sides' accumulators at layer page + this
#endif
uniform int halfStride;
uniform int supersample;  // half-size texels a light map texel across (bake/supersample.h): all of a sampled one's
#include "lib/noise_half.glsl"
uniform uint nodeCount;      // nodes in this tile's lists (END_OF_LIST is larger)
uniform float depthBias;      // scene units: float precision floor
uniform uint footprintSample; // this pass's sample of each texel's footprint (the direction's, the sun jitter's index)
layout(binding = BINDING_FOOTPRINT) uniform usampler2DArray footprint;
#ifdef CURVED_FOOTPRINT
#include "lib/curved_footprint.glsl"
#endif

const float PI = 3.14159265358979;

#ifdef LEAF_TABLE
// One update over a run of whole leaves (engine/bake/bundle_tracer.h):
// each leaf's lists at its place in one head image, the leaves in a table.
layout(std430, binding = BINDING_LEAF_TABLE) readonly buffer Leaves { LeafRecord leafTable[]; };
uniform int leafCount;

// The leaf whose square holds q (root units) becomes the frame's
// (bundle_frame.glsl): the same float bounds as a tile's uniforms, so the same
// leaf takes the point either way. False: no leaf with receivers does.
bool takeLeaf(vec2 q) {
    for (int i = 0; i < leafCount; ++i) {
        LeafRecord l = leafTable[i];
        vec2 lo = vec2(l.minX, l.minY);
        if (inSquare(q, lo, l.extent)) {
            leafMin = lo;
            leafExtent = l.extent;
            leafPixels = l.pixels;
            pixelSize = l.pixelSize;
            ivec2 origin = ivec2(l.originX, l.originY);
            tileOffset = -origin;
            ownedPixels = drawnPixels = ivec4(origin, origin + ivec2(l.pixels));
            return true;
        }
    }
    return false;
}
#else
// The tile's leaf holds q (root units): the tile's frame is the uniforms'.
bool takeLeaf(vec2 q) { return leafOwns(q); }
#endif

vec3 environment(vec3 dir) {
#ifndef SUN_PASS
    if (useEnv) {
        // equirectangular, +Y up, u = 0 at -X going through +Z (glTF-style)
        float phi = atan(dir.z, dir.x);
        float theta = acos(clamp(dir.y, -1.0, 1.0));
        return textureLod(envMap, vec2(0.5 + phi / (2.0 * PI), theta / PI), 0.0).rgb;
    }
    return sky;
#else
    return vec3(0.0);
#endif
}

// Of two nodes at the same depth, whether node i is preferred to node j:
// seen from the looking side, then the brighter (so any order of the list
// picks the same node). A double-sided surface's two nodes share a depth, and
// so do two faces where a ray passes their shared edge (append.frag
// planePoint): a box's near and far sides along its outline, where the ray
// touches the box from outside. The far side's back is black, and taken (the
// first in the list, at equal radiance) it was 1.7e-6 of the rho 0.99
// furnace's samples (each 1e-6 of black reads costs it 0.01 %).
bool preferred(uint i, uint j, uint seen) {
    bool visible = (nodes[i].depth & seen) != 0u, otherVisible = (nodes[j].depth & seen) != 0u;
    if (visible != otherVisible) return visible;
    return nodes[i].radiance > nodes[j].radiance;
}

// The nearest node of `pixel`'s list past depth `start` along +d (forward)
// or -d; at equal depth the one seen from side `seen`, then the brighter (a
// double-sided surface's two nodes share a depth; any order of the list picks
// the same node). END_OF_LIST: none.
uint nearestNode(ivec2 pixel, float start, bool forward, uint seen) {
    float best = forward ? 3.0e38 : -3.0e38;
    uint bestNode = END_OF_LIST;
    for (uint i = imageLoad(heads, pixel).r; i < nodeCount; i = nodes[i].next) {
        float z = uintBitsToFloat(nodes[i].depth & ~NODE_FLAG_MASK);  // the depth without its side flags
        // (ties are rare: the loads of `preferred` only run for them)
        if (forward ? (z > start && z <= best) : (z < start && z >= best)) {
            if (z != best || preferred(i, bestNode, seen)) bestNode = i;
            best = z;
        }
    }
    return bestNode;
}

#ifndef SUN_PASS
// L_in from node i seen from side `seen` (a back face is black), or the
// environment looking along `look` where nothing is there.
vec3 incomingRadiance(uint i, uint seen, vec3 look) {
    if (i == END_OF_LIST) return environment(look);
    return (nodes[i].depth & seen) != 0u ? decodeRgbe(nodes[i].radiance) : vec3(0.0);
}

// `stored` (running mean M, weight W; lib/rounding.glsl's accumulator) with
// L_in folded in at weight w: W += w, M += (L_in - M) w / W, rounded with the
// random numbers of h.
uvec2 foldSample(vec4 state, vec3 incoming, float w, uint h) {
    float total = state.a + w;
    vec4 sum = vec4(state.rgb + (incoming - state.rgb) * (w / total), total);
    uint h1 = pcgHash(h), h2 = pcgHash(h1), h3 = pcgHash(h2);
    return encodeAccumulator(sum, vec4(uniform01(h), uniform01(h1), uniform01(h2), uniform01(h3)));
}

uvec2 foldSample(uvec2 stored, vec3 incoming, float w, uint h) {
    return foldSample(decodeAccumulator(stored), incoming, w, h);
}

// Texel `texel`'s accumulator with L_in folded in (foldSample) and, for a
// flat texel's sample at `point`, its moments at the same weights.
void foldTexel(ivec3 texel, vec3 incoming, float w, uint h, bool flat_, vec2 point) {
    vec4 state = decodeAccumulator(imageLoad(accum, texel).rg);
    if (flat_) {
        vec4 moment = imageLoad(moments, texel);
        float share = w / (state.a + w);
        imageStore(moments, texel, moment + (vec4(dot(incoming, vec3(1.0)) * point, point) - moment) * share);
    }
    imageStore(accum, texel, uvec4(foldSample(state, incoming, w, h), 0u, 0u));
}
#endif

// The texel's own surface at this sample (main): the sample's point, its
// depth along d, the triangle's plane (normal ng, ng . d = cg), the texel's
// size, the surface's curvature, the node flag of the side it looks to,
// where the plane is exact (the fragment's point; the curved texels' sample's)
// and the triangle's chart borders (TexelSample's).
struct OwnSurface {
    vec3 position;
    vec3 anchor;
    float depth;
    vec3 ng;
    float cg;
    float texelSize;
    float curvature;
    uint side;
    uint borders;
    vec3 bary;
    mat3 baryGradient;
};

const float NO_CROSSING = 3.0e38;

// The depth at which the ray of `pixel`, which passes `offset` (scene units,
// the point minus the pixel's centre) beside the sample's point, crosses the
// texel's own surface: a fragment facing the texel's side at the depth where
// the ray meets the triangle's plane. NO_CROSSING: none. The crossing must lie
// within one texel (at least two pixels) of the point in 3D: at grazing angles
// the ray meets the plane far away, past a wall's edge, where a fragment of
// another surface facing the same way (the floor of the room behind a thin
// wall) would pass for it. The depth tolerance is tight: a surface facing the
// same way a millimetre off (a light under a ceiling) must not pass for it.
float ownCrossing(OwnSurface own, ivec2 pixel, vec2 offset) {
    float planeDepth = own.depth + dot(vec2(dot(own.ng, bundleU), dot(own.ng, bundleV)), offset) / own.cg;
    vec3 crossing = own.position - bundleU * offset.x - bundleV * offset.y + bundleDir * (planeDepth - own.depth);
    // At or past a chart border of the triangle the surface ends, and the
    // ray passes beside it, outside whatever it closes. A node there at the
    // plane's depth is its triangle's all the same: the bundle pass covers a
    // pixel where the triangle snapped to the raster's subpixel grid does and
    // keeps the true plane for depth, so a wall nearly edge-on to d has nodes
    // millimetres past its edge; and a ray through the edge itself meets the
    // wall on it at the crossing's own depth. A closed box's texels there saw
    // the sky and the sun from inside (tests/golden/closed_box_bake_test.cpp:
    // 9 of 2400 texels lit at 1024 directions, up to 0.55 % of the sun's E / pi).
    // So no crossing within four depth margins of a border edge or past it,
    // beside the edge (not past its ends, where the chart may go on round a
    // corner the edge's line cuts: ExactFootprintBake's L-shaped ledge).
    vec3 b = own.bary + (crossing - own.position) * own.baryGradient;
    for (int k = 0; k < 3; ++k)
        if ((own.borders & (1u << k)) != 0u && b[k] < 4.0 * depthBias * length(own.baryGradient[k]) &&
            b[(k + 1) % 3] >= 0.0 && b[(k + 2) % 3] >= 0.0)
            return NO_CROSSING;
    // one texel: two bundle pixels where the pixel is half a texel (the
    // uniform grid's rule), this texel's own size where the leaf's pixel is
    // finer (adaptive leaves take their pixel from their densest texel)
    if (distance(crossing, own.position) > max(2.0 * pixelSize, own.texelSize)) return NO_CROSSING;
    // On a curved surface the crossing lies on this triangle's plane, which the
    // neighbouring facets leave by about curvature x r^2 / 2 at r from it (the
    // triangles of a finely tessellated chair are smaller than a bundle pixel:
    // their own fragments are mostly another facet's); the curvature from the
    // shading normals' change across the texel (0 on flat charts, where the
    // tolerance stays tight).
    float r = distance(crossing, own.anchor);
    float tolerance = 0.05 * pixelSize + depthBias + 1e-5 * abs(planeDepth) +
                      min(0.5 * own.curvature * r * r / abs(own.cg), 0.5 * own.texelSize);
    float self = NO_CROSSING, selfDistance = 3.0e38;
    // `i < nodeCount` rather than `!= END_OF_LIST`: ends on any stray index too
    for (uint i = imageLoad(heads, pixel).r; i < nodeCount; i = nodes[i].next) {
        float z = uintBitsToFloat(nodes[i].depth & ~NODE_FLAG_MASK);  // the depth without its side flags
        float dz = abs(z - planeDepth);
        if (dz <= tolerance && (nodes[i].depth & own.side) != 0u && dz < selfDistance) {
            selfDistance = dz;
            self = z;
        }
    }
    return self;
}

// Columns: pixels of side `pixel` per texel of offset along the light map's x and y.
mat2 pixelsFromOffset(vec3 positionDx, vec3 positionDy, float pixel) {
    return mat2(vec2(dot(positionDx, bundleU), dot(positionDx, bundleV)),
                vec2(dot(positionDy, bundleU), dot(positionDy, bundleV))) / pixel;
}

// Whether a pixel centre's crossing `o` texels from the texel's centre lies
// off its footprint: outside its square, or off its chart (offChart).
bool offFootprint(vec2 o, vec3 bary, vec3 baryDx, vec3 baryDy, uint flags, uvec3 onChart) {
    return any(greaterThan(abs(o), vec2(0.5))) || offChart(bary, baryDx, baryDy, flags, onChart, o);
}

// Which pixel's ray a texel's sample takes (issue 11). A sample at a point x of
// the footprint, read along the ray of the pixel x lies in, sees from where
// that ray crosses the surface, up to half a pixel from x: the footprint is
// read blurred by a pixel, and where the light changes within a pixel of a
// contact (a light under a ceiling, a block's foot, a partition wall) the blur
// carries light under the contact and takes it from beside it. So the sample
// takes the ray of a pixel whose centre crosses the footprint itself. With the
// grid's random phase per direction those crossings are spread uniformly over
// the footprint, one per pixel cell; one of them is taken at random (the one
// whose pixel hashes highest: the same pixels give the same choice whatever
// the layout). Where the footprint projects to a pixel or more, the sample's
// weight stays the direction's (`weight` 1): weighing it by how many
// crossings the footprint holds (n / (area |det G|), exact in expectation)
// made the weights noisy. Where it projects to less (a grazing direction), a
// pixel centre crosses it only now and then, and the footprint's own point,
// which stood in for it, read along a ray up to half a pixel beside it, 1 / cos
// of that along the surface: a bias that did not fall with the directions (the
// Cornell box's mean rose from +0.07 % at 1024 directions to +0.38 % at 4096).
// There the sample weighs n / (area |det G|) (Horvitz-Thompson: n crossings
// found, area |det G| expected), 0 when none is: false with `weight` 0, skip
// it. `area` is the part of the square on the chart (texelFootprints): a
// texel only partly on its chart (a 35 cm ledge in a 4 m texel of the city)
// projects to less than a pixel in many more directions than its square
// does, and taken at the square's |det G| those directions weighed a tenth of
// the steep ones (the city's setback ledges and sills, sky light alone, 1024
// directions: its upward texels on chart borders read +2.1 % of the scene's
// mean too bright, +0.5 % with the area and texelFootprints' edge).
// Where more than 6 x 6 centres might cross (a leaf much finer than the
// texel, where the blur is small), or none does of a footprint a pixel or
// more across (off its chart), false with `weight` 1: the footprint's own
// point instead.
bool footprintPixel(vec2 centre, vec3 positionDx, vec3 positionDy, vec3 bary, vec3 baryDx, vec3 baryDy, uint flags,
                    uvec3 onChart, uint seed, out vec2 offset, out float weight) {
    weight = 1.0;
    mat2 G = pixelsFromOffset(positionDx, positionDy, pixelSize);
    vec2 halfExtent = 0.5 * (abs(G[0]) + abs(G[1]));
    ivec2 lo = ivec2(ceil(centre - halfExtent - 0.5)), hi = ivec2(floor(centre + halfExtent - 0.5));
    ivec2 span = max(hi - lo + 1, ivec2(0));
    if (span.x * span.y > 36 || abs(determinant(G)) < 1e-6) return false;
    mat2 offsetFromPixel = inverse(G);
    uint best = 0u, crossings = 0u;
    bool found = false;
    offset = vec2(0.0);
    for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
            vec2 o = offsetFromPixel * (vec2(x, y) + 0.5 - centre);
            if (offFootprint(o, bary, baryDx, baryDy, flags, onChart)) continue;
            uint h = pcgHash(seed ^ (uint(x) * 0x9e3779b1u) ^ (uint(y) * 0x85ebca77u));
            ++crossings;
            if (!found || h > best) {
                best = h;
                offset = o;
                found = true;
            }
        }
    float expected = abs(determinant(G)) * footprintArea(onChart);
    if (expected < 1.0) weight = float(crossings) / expected;
    return found;
}

#ifdef SUN_PASS
// The sun's sample of a flat texel: a pixel centre's crossing inside the
// footprint, its ray through the sample itself (nothing blurs a shadow's edge
// into or out of the texel). The leaf that holds the pass's footprint point
// takes the sample (any leaf the footprint reaches: a texel's parts in each
// leaf by their area). In its grid, a point x uniform over the footprint's
// square widened by a pixel's cell each way lies in the cell of any one
// centre inside the square with the same chance (the whole cell lies in the
// widened square), so the centre of x's cell, taken where it lies on the
// chart and in the leaf, is uniform over the centres there; up to 8 points
// (R2's, then hashed). Until 2026-12-06 the sample was the footprint's own
// point, read along its pixel's ray and spread over the texel less half a
// pixel each way (or, where the footprint spans up to 6 x 6 pixels, one of
// the centres in it), taken by the leaf of the texel's centre alone: a band a
// pixel wide along the texel's edges weighed half and a texel's parts in
// another leaf nothing, a bias the passes did not lower and the noise
// estimate could not see (mixed_lighting's floor: shadow edges up to 5 %
// off, 0.27 % rms over its interior texels with 16 x 16 passes; 0.09-0.12 %
// now, two seeds). 1: taken (offset: the crossing, texels from the centre),
// 0: another leaf's, -1: none found (the sun along the surface, a footprint
// far off its square: footprintOffset's point instead).
int sunCrossing(FlatFrame f, uvec3 onChart, out vec2 offset) {
    vec2 first = footprintCandidate(footprintSample, 0, uvec2(0u));
    offset = vec2(0.0);
    if (!takeLeaf(rootFromBundle(bundleFromWorld(f.position + f.positionDx * first.x + f.positionDy * first.y).xy)))
        return 0;
    mat2 G = pixelsFromOffset(f.positionDx, f.positionDy, pixelSize);
    if (abs(determinant(G)) < 1e-6) return -1;
    mat2 offsetFromPixel = inverse(G);
    vec2 widened = 1.0 + abs(offsetFromPixel[0]) + abs(offsetFromPixel[1]);
    vec2 centre = gridFromRoot(rootFromBundle(bundleFromWorld(f.position).xy));
    for (int attempt = 0; attempt < 8; ++attempt) {
        vec2 x = attempt == 0 ? first : footprintCandidate(footprintSample, attempt, uvec2(0u));
        vec2 pixel = floor(centre + G * (x * widened)) + 0.5;
        vec2 o = offsetFromPixel * (pixel - centre);
        if (any(lessThan(pixel, vec2(0.0))) || any(greaterThan(pixel, vec2(leafPixels))) ||
            offFootprint(o, f.bary, f.baryDx, f.baryDy, f.flags, onChart))
            continue;
        offset = o;
        return 1;
    }
    return -1;
}
#endif

// One sample of a texel for this pass: its footprint point, the shading
// normal there, its triangle's plane (ng: the side the bundle pass gives the
// triangle's fragments, lib/triangle_side.glsl), the texel's size on the
// surface, the surface's curvature, the triangle's flags and the sample's
// footprint weight (footprintPixel).
struct TexelSample {
    ivec3 texel;
    vec3 position;
    vec3 anchor;  // where ng's plane is exact (OwnSurface)
    vec3 n;
    vec3 ng;
    float texelSize;
    float curvature;
    uint flags;
    float weight;
    vec2 point;  // the point, texels from the texel's centre along the page's axes
    bool flat_;  // point holds it (a curved texel's samples keep no moments)
    bool concave;  // a curved texel's surface bends toward ng's side (curvedTriangleConcave)
    // the triangle's barycentrics at `position` and their gradients along its
    // plane (columns, per scene unit): where a ray crosses the plane relative
    // to the triangle's chart borders (ownCrossing); borders 0 on curved texels
    vec3 bary;
    mat3 baryGradient;
};

// One sample of a texel along its triangle's plane (frame f at the texel's
// centre: a light map fragment's, or a flat partial texel's; `leafPoint`: a
// point of the texel on its triangle, whose leaf takes the sample): a point of
// the texel's footprint (lib/texel_footprint.glsl), at a pixel centre's
// crossing where one is found (footprintPixel). False: no sample (another
// leaf's, a grazing direction with no crossing).
bool planeSample(FlatFrame f, ivec3 texel, vec3 leafPoint, out TexelSample s) {
    vec3 faceNormal = cross(f.positionDx, f.positionDy);
    // this texel's size on the surface (one step of the light map raster)
    s.texelSize = max(length(f.positionDx), length(f.positionDy));
    s.texel = texel;
    s.weight = 1.0;
    vec2 jitter;
    uvec3 onChart = texelFetch(footprint, s.texel, 0).rgb;
#ifdef SUN_PASS
    int taken = sunCrossing(f, onChart, jitter);
    if (taken == 0) return false;
    if (taken < 0) {
        // none found: the footprint's point, read along its pixel's ray up to
        // half a pixel beside it, spread over the texel less that so that the
        // two stay in it (a pixel wider than the texel: the pixel's jitter
        // alone spreads the samples). Not where that leaves the chart: a
        // partial texel's centre lies off it, and a point drawn toward it
        // past the chart's edge read the sun from outside what the edge
        // closes (a closed box's ceiling, 7 mm past its wall: 0.06 % of the
        // sun's light in its corner texels).
        jitter = footprintOffset(f.bary, f.baryDx, f.baryDy, f.flags, onChart, footprintSample);
        float facing = length(faceNormal) > 0.0 ? abs(dot(normalize(faceNormal), bundleDir)) : 1.0;
        vec2 drawn = jitter * clamp(1.0 - pixelSize / (max(facing, 1e-3) * max(s.texelSize, 1e-30)), 0.0, 1.0);
        if (!offFootprint(drawn, f.bary, f.baryDx, f.baryDy, f.flags, onChart)) jitter = drawn;
    }
#else
    // the leaf of the texel's centre takes its sample (a sample whose point
    // lies in another leaf is lost, at random: leaves move with d)
    if (!takeLeaf(rootFromBundle(bundleFromWorld(leafPoint).xy))) return false;
    vec2 centreRoot = rootFromBundle(bundleFromWorld(f.position).xy);
    if (!footprintPixel(gridFromRoot(centreRoot), f.positionDx, f.positionDy, f.bary, f.baryDx, f.baryDy, f.flags,
                        onChart, pcgHash(randomSeed), jitter, s.weight)) {
        if (s.weight == 0.0) return false;  // a grazing direction no pixel centre crossed the footprint in
        jitter = footprintOffset(f.bary, f.baryDx, f.baryDy, f.flags, onChart, footprintSample);
    }
#endif
    s.position = f.position + f.positionDx * jitter.x + f.positionDy * jitter.y;
    s.point = jitter;
    s.flat_ = true;
    s.concave = false;
    s.anchor = leafPoint;
    // the shading normal where the point leaves the triangle, not extrapolated
    // past it: a triangle far smaller than a texel (300 to a texel on the
    // chair of mixed_lighting) would swing it by tens of degrees
    vec3 baryStep = f.baryDx * jitter.x + f.baryDy * jitter.y;
    float inside = 1.0;
    for (int k = 0; k < 3; ++k)
        if (baryStep[k] < 0.0) inside = min(inside, max(f.bary[k], 0.0) / -baryStep[k]);
    s.n = normalize(f.normal + (f.normalDx * jitter.x + f.normalDy * jitter.y) * inside);
    s.bary = f.bary + baryStep;
    // texel steps from a step v along the plane: (ax . v, ay . v) = (J^T J)^-1 J^T v, J = (positionDx, positionDy)
    mat2 metric = inverse(mat2(dot(f.positionDx, f.positionDx), dot(f.positionDx, f.positionDy),
                               dot(f.positionDx, f.positionDy), dot(f.positionDy, f.positionDy)));
    vec3 ax = metric[0][0] * f.positionDx + metric[1][0] * f.positionDy;
    vec3 ay = metric[0][1] * f.positionDx + metric[1][1] * f.positionDy;
    for (int k = 0; k < 3; ++k) s.baryGradient[k] = f.baryDx[k] * ax + f.baryDy[k] * ay;
    // the triangle's plane, on the side the bundle pass gives its fragments
    // (lib/triangle_side.glsl; the flag is computed with the mesh)
    s.ng = s.n;
    if (length(faceNormal) > 0.0) {
        s.ng = normalize(faceNormal);
        if ((f.flags & TRIANGLE_DERIVATIVE_NORMAL_FLIPPED) != 0u) s.ng = -s.ng;
    }
    s.curvature = max(length(f.normalDx) / max(length(f.positionDx), 1e-30),
                      length(f.normalDy) / max(length(f.positionDy), 1e-30));
    s.flags = f.flags;
    return true;
}

#ifdef CURVED_FOOTPRINT
// A curved texel's sample: its point on the triangle that holds it
// (curvedFootprintPoint), read along the ray of the pixel it lies in: the
// pixel-centre crossings of footprintPixel assume one plane over the square.
// A flat partial texel's (curvedTexelIsFlat): planeSample's, from its frame.
// False: another leaf's.
bool curvedSample(out TexelSample s) {
    if (gl_HelperInvocation || !curvedFragmentIndex(vCurved)) return false;
    uvec4 head = curvedTexels[vCurved];
    ivec3 texel = curvedTexelTexel(head);
    if (curvedTexelIsFlat(head)) {
        useFootprintOf(vCurved);
        return planeSample(curvedFlatFrame(vCurved), texel, curvedTexelCentre(vCurved), s);
    }
    s.texel = texel;
#ifndef SUN_PASS
    // the leaf of the texel's centre takes its sample, as on flat texels
    if (!takeLeaf(rootFromBundle(bundleFromWorld(curvedTexelCentre(vCurved)).xy))) return false;
#endif
    vec2 point;
    CurvedTriangle tri;
    curvedFootprintPoint(vCurved, texelFetch(footprint, s.texel, 0).xy, footprintSample, point, tri);
    s.position = curvedTrianglePosition(tri, point);
#ifdef SUN_PASS
    // the leaf the point lies in (the sun's leaves stay put from pass to pass:
    // the centre's would drop the texel's parts in another leaf every time, as
    // sunCrossing says of flat texels)
    if (!takeLeaf(rootFromBundle(bundleFromWorld(s.position).xy))) return false;
#endif
    s.anchor = s.position;
    s.n = normalize(curvedTriangleNormal(tri, point));
    s.ng = tri.faceNormal.xyz;
    s.texelSize = max(length(tri.positionDx.xyz), length(tri.positionDy.xyz));
    s.curvature = tri.corner2.w;
    s.flags = floatBitsToUint(tri.corner2.z);
    s.weight = 1.0;
    s.point = vec2(0.0);
    s.flat_ = false;
    s.concave = curvedTriangleConcave(tri, point);
    s.bary = vec3(0.0);
    s.baryGradient = mat3(0.0);
    return true;
}
#else
// A light map fragment's sample (planeSample). False: no sample (a helper
// lane, a curved texel, another leaf's, a grazing direction with no crossing).
bool triangleSample(out TexelSample s) {
    // the triangle's own plane, from screen derivatives (before any return:
    // derivatives need the whole quad)
    FlatFrame f = rasterFrame(vPosition, vNormal, vBary, vFlags);
    // llvmpipe runs helper lanes through the walk with undefined loads, where they
    // spin; they have no side effects to make, so leave at once (GLSL 4.50).
    if (gl_HelperInvocation) return false;
    // this sample's point of the texel's footprint (lib/texel_footprint.glsl):
    // a texel half under a building reads half its outside value, as the
    // reference's does (the city under a sky: 6.6 % -> 5.3 % against it)
    ivec3 texel = ivec3(ivec2(gl_FragCoord.xy), int(vPage));
    if ((texelFetch(texelCharts, texel, 0).r & TEXEL_CURVED) != 0u) return false;
    return planeSample(f, texel, vPosition, s);
}
#endif

void main() {
    TexelSample s;
#ifdef CURVED_FOOTPRINT
    if (!curvedSample(s)) return;
    bool curved = !curvedTexelIsFlat(curvedTexels[vCurved]);  // not a flat partial texel
#else
    if (!triangleSample(s)) return;
    const bool curved = false;
#endif
    ivec3 texel = s.texel;
    vec3 b = bundleFromWorld(s.position);
    vec2 q = rootFromBundle(b.xy);
    if (!leafOwns(q)) return;  // another leaf's
    vec2 g = gridFromRoot(q);
    ivec2 pixel = min(ivec2(floor(g)), ivec2(leafPixels - 1)) - tileOffset;
    if (!ownedPixel(pixel)) return;  // another tile's

    // The side the texel looks to is its triangle's (ng, the side the bundle
    // pass gives the triangle's own fragments); its shading normal n weighs the
    // sample (cosine), and a direction below n's horizon adds nothing.
    bool ahead = dot(s.ng, bundleDir) > 0.0;  // the texel looks along +d
    float c = dot(s.n, bundleDir);
    float cosine = ahead ? c : -c;
#ifdef SUN_PASS
    // the sun pass's d is the light's travel direction: a texel facing the sun
    // looks along -d. A flat texel facing away takes no sample (its count stays
    // 0: no light); a curved texel's point facing away is one of its samples,
    // dark, once its ray is found below like the lit ones'.
    bool lit = !ahead && cosine > 0.0;
    if (!lit && !curved) return;
#else
    if (cosine <= 0.0) return;
#endif
    uint ownSide = ahead ? NODE_VISIBLE_FROM_AHEAD : NODE_VISIBLE_FROM_BEHIND;
    uint seenSide = ahead ? NODE_VISIBLE_FROM_BEHIND : NODE_VISIBLE_FROM_AHEAD;
    // The ray through the pixel centre passes beside the sample's point; find
    // where it crosses the texel's own surface (ownCrossing), so that it starts
    // exactly on the surface. Near an edge of the surface (a block's side
    // meeting the floor) the crossing can fall past it, off the surface: the
    // ray would run beside the surface and see what the texel cannot. The
    // sample then takes a neighbouring pixel whose ray does cross the surface
    // (within one pixel of the point; the tile draws a one-pixel apron, so
    // the neighbours are there whatever the tiling): skipping it instead (as
    // Unity's backface validity does) drops the directions toward the edge and
    // so weighs the rest too much (rel_rmse against the reference, 1024
    // directions: two rooms 1.09 -> 1.04 %, Cornell box 2.38 -> 2.26 %; the
    // update pass 5-15 % slower on the city). No crossing in any: skipped.
    float cg = dot(s.ng, bundleDir);
    if (abs(cg) < 1e-4) return;
    vec2 offset = (g - floor(g) - 0.5) * pixelSize;  // texel minus pixel centre, scene units
    uint borders = s.flat_ ? (s.flags / TRIANGLE_CHART_BORDER0) & 7u : 0u;
    OwnSurface own = OwnSurface(s.position, s.anchor, b.z, s.ng, cg, s.texelSize, s.curvature, ownSide, borders,
                                s.bary, s.baryGradient);
    float self = ownCrossing(own, pixel, offset);
    if (self == NO_CROSSING) {
        // the three on the point's side of the pixel's centre (toward sign(offset)): their rays pass nearer it
        const ivec2 order[3] = ivec2[3](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1));
        ivec2 toward = ivec2(offset.x < 0.0 ? -1 : 1, offset.y < 0.0 ? -1 : 1);
        for (int k = 0; k < 3 && self == NO_CROSSING; ++k) {
            ivec2 step = order[k] * toward, neighbour = pixel + step;
            if (!drawnPixel(neighbour)) continue;
            self = ownCrossing(own, neighbour, offset - vec2(step) * pixelSize);
            if (self != NO_CROSSING) pixel = neighbour;
        }
#ifdef SUN_PASS
        // A curved texel's sun sample counts whatever its light: skipped, the
        // facets the sun grazes (those between a tube's lit and dark halves)
        // went missing from the mean, and a tube read 5 % bright. It reads
        // along its own pixel's ray from its own depth instead (geometry finer
        // than a pixel, or a grazing facet: a small cosine either way). The
        // update pass's samples weigh by their cosine, and are skipped: a
        // ray beside the point from its own depth starts inside a convex
        // surface and sees its back (a sphere in the furnace 1.3 % dark).
        // Where the surface bends toward the sun (a tube's inside), that ray
        // starts behind the surface as it rises beside the point, or passes
        // outside it altogether where the sun grazes it: a closed cylinder's
        // inside read the sun along its silhouette (123 of 1366 texels lit
        // at 256 directions, up to 2 % of the sun's E / pi). There the surface
        // itself shades the point: a dark sample.
        if (self == NO_CROSSING && curved) {
            self = b.z;
            lit = lit && !s.concave;
        }
#endif
        if (self == NO_CROSSING) return;
    }
    // The walk starts a little past the own crossing: nodes nearer are taken
    // for the surface itself (float rounding). That margin is a precision
    // floor scaled to the scene (depthBias: 4e-6 of its extent and distance
    // from the origin), and what lies within it is missed: a tube 0.04 across
    // on a floor 200 wide (0.56 mm) had the floor under its underside's
    // points skipped, and their rays into the floor saw the sky (+9.9 % on
    // the tube; CurvedFootprintBake.ThinTubeOnAWideFloorReadsItsTurnsMean).
    // A tenth of it (about 3 float ulps of the scene's extent) is enough for
    // every radiance test. The sun pass keeps all of it: with a tenth a
    // floating cube's face read one sun sample shadowed at its bottom edge
    // (0.57 % of its light in one texel, SunBake.BoxCastsShadowWhereGeometrySays),
    // a node seen from the looking side within the margin: likely the bottom
    // face's at the shared edge, its depth rounded to in front of the side's
    // (a depth plane's rounding grows with its slope over the leaf, not only
    // with the scene's extent; not confirmed).
#ifdef SUN_PASS
    float skip = depthBias;
#else
    float skip = 0.1 * depthBias;
#endif
    float start = self + (ahead ? skip : -skip);

    uint bestNode = nearestNode(pixel, start, ahead, seenSide);

#ifdef SUN_PASS
    // a valid sample: sums += lit irradiance * cos / pi, count += 1 (exact in fp16 to 2048)
    vec3 sunLight = lit && bestNode == END_OF_LIST ? sunIrradiance * cosine / PI : vec3(0.0);
    addDirect(texel, sunLight);
    vec4 d = imageLoad(directMap, texel);
    imageStore(directMap, texel, vec4(d.rgb, d.a + 1.0));
    ivec3 half_;
    if (oddSample && noiseHalfTexel(texel, half_)) {
        imageStore(oddSums, half_, imageLoad(oddSums, half_) + vec4(sunLight, 1.0));
    }
#else
    vec3 incoming = incomingRadiance(bestNode, seenSide, ahead ? bundleDir : -bundleDir);
    // the running cosine-weighted mean of L_in (rgb) and its weight W (a)
    float w = sampleWeight * cosine * s.weight;
#ifdef RESOLUTION_PROBE
    ivec3 probed;
    if (noiseHalfTexel(texel, probed)) {
        probed.z += probeLayer;
        imageStore(probeSums, probed, imageLoad(probeSums, probed) + vec4(incoming * w, w));
    }
    return;
#endif
    uint h = pcgHash(randomSeed ^ pcgHash(uint(texel.x) | (uint(texel.y) << 16u)) ^ pcgHash(uint(texel.z) + 7919u));
    foldTexel(texel, incoming, w, h, s.flat_, s.point);
#ifdef BACK_SIDES
    // A double-sided triangle's back side: the nearest node the other way,
    // which it sees along the same line at the same cosine, into its own
    // accumulator (only built for scenes with back sides: llvmpipe runs the
    // loads of a branch no lane takes).
    if ((s.flags & TRIANGLE_DOUBLE_SIDED) != 0u) {
        uint bestBackNode = nearestNode(pixel, self + (ahead ? -skip : skip), !ahead, ownSide);
        ivec3 back = ivec3(texel.xy, texel.z + backLayerOffset);
        vec3 incomingBack = incomingRadiance(bestBackNode, ownSide, ahead ? -bundleDir : bundleDir);
        foldTexel(back, incomingBack, w, pcgHash(h ^ 0x85ebca6bu), s.flat_, s.point);
    }
#endif
    ivec3 half_;
    if (oddDirection && noiseHalfTexel(texel, half_)) {
        imageStore(halfAccum, half_, uvec4(foldSample(imageLoad(halfAccum, half_).rg, incoming, w, pcgHash(h ^ 0x9e3779b9u)), 0u, 0u));
    }
#endif
}
