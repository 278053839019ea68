// Buffer layouts and binding points shared by C++ and GLSL (std430 only, no
// vec3 members). Included by engine/bake/*.cpp and by the shaders.
#ifndef BUNDLEBAKE_BUNDLE_LAYOUT_H
#define BUNDLEBAKE_BUNDLE_LAYOUT_H

#ifdef __cplusplus
#include <cstdint>
namespace bb::shared {
using uint = uint32_t;
#endif

// One fragment of a ray bundle: 12 bytes.
struct Node {
    uint radiance;  // outgoing radiance Lo, RGBE (see glsl/lib/rounding.glsl)
    uint depth;     // floatBitsToUint(depth along d); its 2 low mantissa bits are NODE_VISIBLE_* flags
    uint next;      // index of the next node in this pixel's list, or END_OF_LIST
};

// One leaf of a run updated at once (BINDING_LEAF_TABLE; lightmap/update.frag
// takeLeaf, engine/bake/bundle_tracer.h): 32 bytes.
struct LeafRecord {
    float minX, minY;  // the leaf's lower-left corner, root units
    float extent;      // its side, root units
    int pixels;        // pixels across
    float pixelSize;   // scene units
    int originX, originY;  // its pixel (0, 0) in the head image
    int pad;
};

#define END_OF_LIST 0xFFFFFFFFu
// Which side of the surface the radiance leaves from (front faces, or both for double-sided):
#define NODE_VISIBLE_FROM_BEHIND 1u   // seen by texels looking along +d (surface front faces -d)
#define NODE_VISIBLE_FROM_AHEAD 2u    // seen by texels looking along -d (surface front faces +d)
#define NODE_FLAG_MASK 3u

// The least weight W an accumulator that has been sampled keeps (the smallest
// normal fp16, 2^-14): W = 0 means "never sampled", which the outgoing pass
// and the resolve read as black (lightmap/rescale.comp, the MPI combine).
#define SAMPLED_MIN_WEIGHT 6.103515625e-5

// Bindings
#define BINDING_NODES 0          // SSBO: Node nodes[]
#define BINDING_NODE_COUNTER 0   // atomic counter: nodes appended
#define BINDING_VERTICES 2       // SSBO: the bake vertices (BakeVertex, 48 bytes), read by the bundle pass
#define BINDING_CURVED_TEXELS 3  // SSBO: curved texels (lib/curved_footprint.glsl), update and sun passes
#define BINDING_CURVED_REFS 4    // SSBO: their triangles' indices
#define BINDING_CURVED_TRIANGLES 7  // SSBO: CurvedTriangle curvedTriangles[]
#define BINDING_LEAF_TABLE 8     // SSBO: a run's leaves for one update over all of them (LeafRecord, update.frag)
#define BINDING_HEADS 0          // image unit: r32ui head pointers of the tile
#define BINDING_ACCUM 1          // image unit: rg32ui accumulators (packed fp16 RGB + W), array of pages
#define BINDING_DIRECT 2         // image unit: rgba16f direct light L_lm (sun + emitters); a: the sun's sample count while it is baked
#define BINDING_SCRATCH_RG 3     // image unit: rg32f view of the accumulators: direct light sums (r, g) while it is baked
#define BINDING_SCRATCH_B 4      // image unit: r32f view of the radiance map: direct light sums (b) while it is baked
#define BINDING_RADIANCE_BITS 5  // image unit: r32ui view of the radiance map (RGB9E5 bits), written by the outgoing pass
#define BINDING_EMITTER_SUMS 5   // image unit: rgba32f an emitter triangle's sums while it is baked (direct/emitter.frag)
#define BINDING_DILATION 6       // image unit: r8ui per texel: DILATION_SELF, the covered texel it copies, or DILATION_NONE
#define BINDING_TARGET 7         // image unit: rgba32f light map L_lm (the resolve's output)
#define BINDING_HALF_ACCUM 3     // image unit: rg32ui odd directions' accumulators at every halfStride-th texel
#define BINDING_NOISE_WEIGHTS 5  // image unit, noise pass only: r16f each sampled texel's half-size texels' weights
                                 // (the noise estimate; unit 3 is the direct-light scratch only while that is baked)
#define BINDING_DIRECT_ODD_SUMS 6  // image unit, direct light passes only: rgba32f an emitter triangle's or a sun's
                                   // odd samples' sums at the noise estimate's sampled texels (halfAccum's size)
#define BINDING_DIRECT_VARIANCE 7  // image unit, direct light passes only: r32f its light's variance per sampled texel
#define BINDING_MOMENTS 4        // image unit, update and outgoing passes: rg32f each front texel's first moments (update.frag)
#define BINDING_SLOPES_IMAGE 6   // image unit, outgoing pass only: rgba16f the slopes inside each front texel (meta.frag)
#define BINDING_PROBE_SUMS 7      // image unit, resolution probe's update pass only: rgba32f sums (bake/resolution_probe.cpp)
#define BINDING_DIRECT_WEIGHTS 1   // image unit, direct noise pass only: the noise weights (BINDING_NOISE_WEIGHTS')
#define BINDING_RADIANCE 0       // texture unit: RGB9_E5 outgoing radiance Lo per texel, array of pages
#define BINDING_ENV 1            // texture unit: environment map (equirectangular)
#define BINDING_MATERIAL_TEX 2   // texture unit: a material's albedo texture (emission: + 1)
#define BINDING_READ_MODES 4     // texture unit: r8ui per texel: READ_* per axis (lightmap/read_modes.comp)
#define BINDING_FOOTPRINT 5       // texture unit: rgb32ui per texel: its square's part on its chart (texelFootprints)
#define BINDING_CHART_NEIGHBOURS 4  // texture unit, outgoing pass only: chartNeighbours (r8ui, CHART_NEIGHBOUR_*)
#define BINDING_SLOPES 7         // texture unit: rgba16f per front texel: the slope of its light inside it (meta.frag)
#define BINDING_TEXEL_CHARTS 6   // texture unit: r16ui per texel: its owner's chart, low 15 bits, and TEXEL_CURVED (mesh_layout.h)
#define BINDING_CHART_NEIGHBOURS_IMAGE 6  // image unit, read-modes pass only (the dilation's unit elsewhere)
#define BINDING_READ_MODES_IMAGE 7        // image unit, read-modes pass only (the resolve target's unit elsewhere)

// How the bundle pass reads a texel's radiance along an axis (2 bits an
// axis, x in bits 0-1, y in 2-3): its mean, a limited slope, or a step
#define READ_NONE 0u
#define READ_SLOPE 1u
#define READ_STEP 2u

// Which texels along a covered texel's row and column, 1 and 2 away, are
// covered by the same chart (r8ui bits; 2 away only where 1 away is too)
#define CHART_NEIGHBOUR_LEFT 1u   // x - 1
#define CHART_NEIGHBOUR_RIGHT 2u  // x + 1
#define CHART_NEIGHBOUR_DOWN 4u   // y - 1
#define CHART_NEIGHBOUR_UP 8u     // y + 1
#define CHART_NEIGHBOUR_FAR 4u    // shift: the same bits for x - 2, x + 2, y - 2, y + 2

// Dilation codes (r8ui): the covered texel whose value an uncovered one shows,
// at offset (code & 15, code >> 4) - DILATION_RADIUS; a covered texel shows itself.
#define DILATION_RADIUS 7
#define DILATION_SELF 119u        // offset (0, 0)
#define DILATION_NONE 255u        // no covered texel within the radius

#ifdef __cplusplus
}  // namespace bb::shared
static_assert(sizeof(bb::shared::Node) == 12, "a node is 12 bytes");
static_assert(sizeof(bb::shared::LeafRecord) == 32, "a leaf record is 32 bytes");
#endif

#endif
