// A point of a light map texel's footprint (issue 11: one definition of a
// texel's value for the bake and the reference, engine/reference/reference_baker.h):
// a texel holds the mean over the part of its square (page space) that lies on
// its chart, so each sample of the update and direct passes starts at a point
// spread over that part, not at the texel's centre. A fragment of the light
// map raster (its centre inside its triangle) moves by an offset in texels
// along the triangle's own plane: across an edge its chart shares the plane is
// the neighbour's too where the chart is flat (and nearly so where it is
// smooth); past a chart border (TRIANGLE_CHART_BORDER0 << k) the point is off
// the surface and is drawn again.
//
// Sample i of a texel: point i of the R2 sequence (Roberts 2018), shifted by
// the seed (FOOTPRINT_SHIFT below), the same for every texel, so that any run
// of consecutive samples is spread evenly over the square, and a texel's
// samples depend on where it lies on its surface, not on where its chart lies
// in the atlas (layouts of one density bake the same values). Candidates off
// the chart are replaced by hashed ones (uniform over the part on the chart,
// as rejection sampling is); after 8 the centre.
//
// Needs lib/rounding.glsl (pcgHash, uniform01) and shared/mesh_layout.h.

// The seed's shift of the R2 sequence (a Cranley-Patterson rotation, the same
// for every texel: Baker::Impl::footprintShiftDefine), and of the hashed candidates
#ifndef FOOTPRINT_SHIFT
#define FOOTPRINT_SHIFT uvec2(0u)
#endif

// A texel's frame along its triangle's plane, at its centre: what the light
// map raster gives a fragment (its varyings and their screen derivatives, one
// texel a step), or a flat partial texel's point (lib/curved_footprint.glsl
// curvedFlatFrame): position, shading normal, barycentrics (vertex order),
// their steps per texel along x and y, and the triangle's flags.
struct FlatFrame {
    vec3 position, normal, bary;
    vec3 positionDx, positionDy, normalDx, normalDy, baryDx, baryDy;
    uint flags;
};

// Whether the eighth-texel cell of `offset` (texels from the centre) touches
// the chart (`cells`, as offChart's).
bool cellOnChart(uvec2 cells, vec2 offset) {
    ivec2 cell = clamp(ivec2(floor((offset + 0.5) * 8.0)), ivec2(0), ivec2(7));
    uint bit = uint(cell.y * 8 + cell.x);
    uint word = bit < 32u ? cells.x : cells.y;
    return (word & (1u << (bit & 31u))) != 0u;
}

// Whether `offset` (texels from the centre) lies inside the texel's one more
// border edge (engine/layout/bake_mesh.h insideFootprintEdge, the same
// arithmetic): `code`'s low 12 bits the angle of the outward normal, its high
// 12 the distance; 0: none.
bool insideFootprintEdge(uint code, vec2 offset) {
    if (code == 0u) return true;
    float angle = float(code & 4095u) * (6.283185307 / 4096.0);
    float distance = float(code >> 12u) * (1.5 / 4095.0) - 0.75;
    return cos(angle) * offset.x + sin(angle) * offset.y <= distance;
}

// The part of the texel's square the footprint test takes as on its chart (0..1).
float footprintArea(uvec3 footprint) { return max(float(footprint.z >> 24u), 1.0) / 255.0; }

// The spread of the points a texel's samples take (xx, xy, yy; layout/
// bake_mesh.h TexelFootprint::spread, encodeFootprintSpread), from its
// footprint texel; the whole square's where none was. |xy| is kept under
// sqrt(xx yy): a strip a few hundredths of a texel wide along a diagonal has
// a determinant smaller than xy's rounding, which could flip its sign.
vec3 decodeFootprintSpread(uvec4 f) {
    if (f.w == 0u) return vec3(1.0 / 12.0, 0.0, 1.0 / 12.0);
    vec3 s = vec3(float(f.w & 0x7ffu) / 2047.0, float(f.w >> 22u) / 1022.0 * 2.0 - 1.0, float((f.w >> 11u) & 0x7ffu) / 2047.0) / 12.0;
    float bound = 0.99 * sqrt(s.x * s.z);
    return vec3(s.x, clamp(s.y, -bound, bound), s.z);
}

#ifdef CURVED_FOOTPRINT
// A flat curved texel whose flat test is inexact (CURVED_TEXEL_EXACT): its
// index, set by its pass before it samples; its triangles then decide
// (lib/curved_footprint.glsl exactOffChart). NO_EXACT_FOOTPRINT: the test below.
const uint NO_EXACT_FOOTPRINT = 0xffffffffu;
uint exactFootprint = NO_EXACT_FOOTPRINT;
bool exactOffChart(uint index, vec2 offset);
#endif

// Whether the point `offset` texels from the fragment's centre lies off its
// chart: past an edge of the fragment's triangle that is a chart border
// (exact), in an eighth-texel cell of the square no part of the chart touches,
// or past the texel's one more border edge (`footprint`: the texel's
// texelFootprints record, engine/layout/bake_mesh.h: the cells, low word
// first, and the edge in z's low 24 bits: the far borders, past the triangle's
// neighbours, to an eighth of a texel, and the far side of a strip narrower
// than a texel exactly).
// bary: the fragment's barycentrics; baryDx, baryDy: their steps per texel
// (dFdx, dFdy). A CURVED_TEXEL_EXACT texel's triangles decide instead.
bool offChart(vec3 bary, vec3 baryDx, vec3 baryDy, uint flags, uvec3 footprint, vec2 offset) {
#ifdef CURVED_FOOTPRINT
    if (exactFootprint != NO_EXACT_FOOTPRINT) return exactOffChart(exactFootprint, offset);
#endif
    uint borders = (flags / TRIANGLE_CHART_BORDER0) & 7u;
    vec3 b = bary + baryDx * offset.x + baryDy * offset.y;
    return ((borders & 1u) != 0u && b.x < 0.0) || ((borders & 2u) != 0u && b.y < 0.0) ||
           ((borders & 4u) != 0u && b.z < 0.0) || !cellOnChart(footprint.xy, offset) ||
           !insideFootprintEdge(footprint.z & 0xffffffu, offset);
}

// Candidate `attempt` of sample `sampleIndex`'s point, in texels from the
// centre, each coordinate in [-0.5, 0.5): attempt 0 is point sampleIndex of
// R2, the others hashed, uniform over the cells that touch the chart
// (`cells`, cellOnChart's; all of the square if none): a texel a tenth on its
// chart (a ledge's, a partial texel's) finds its part in a few attempts, not
// in one of ten.
vec2 footprintCandidate(uint sampleIndex, int attempt, uvec2 cells) {
    if (attempt == 0) {
        // R2 in 32-bit fixed point (alpha * 2^32, wrapping: exact for any index), from 0.5
        uvec2 fixedPoint = uvec2(sampleIndex * 3242174889u, sampleIndex * 2447445413u) + 0x80000000u + FOOTPRINT_SHIFT;
        return vec2(fixedPoint >> 8u) * (1.0 / 16777216.0) - 0.5;
    }
    uint h = pcgHash((sampleIndex * 8u + uint(attempt - 1)) ^ FOOTPRINT_SHIFT.x), h1 = pcgHash(h), h2 = pcgHash(h1);
    uint low = uint(bitCount(cells.x)), count = low + uint(bitCount(cells.y));
    if (count == 0u) return vec2(uniform01(h), uniform01(h1)) - 0.5;
    // the k-th cell on the chart, k uniform
    uint k = min(uint(uniform01(h2) * float(count)), count - 1u);
    uint word = k < low ? cells.x : cells.y, cell = k < low ? 0u : 32u;
    k = k < low ? k : k - low;
    for (uint i = 0u; i < 32u; ++i) {
        if ((word & (1u << i)) == 0u) continue;
        if (k == 0u) {
            cell += i;
            break;
        }
        --k;
    }
    return (vec2(cell % 8u, cell / 8u) + vec2(uniform01(h), uniform01(h1))) * 0.125 - 0.5;
}

// Offset in texels of sample `sampleIndex`'s point, each coordinate in [-0.5, 0.5).
vec2 footprintOffset(vec3 bary, vec3 baryDx, vec3 baryDy, uint flags, uvec3 footprint, uint sampleIndex) {
    for (int attempt = 0; attempt < 8; ++attempt) {
        vec2 offset = footprintCandidate(sampleIndex, attempt, footprint.xy);
        if (!offChart(bary, baryDx, baryDy, flags, footprint, offset)) return offset;
    }
    return vec2(0.0);
}

// Barycentrics as a vertex output: vertex k of a (non-indexed) triangle is e_k.
vec3 cornerBarycentric(int vertexId) {
    int k = vertexId % 3;
    return vec3(k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0);
}
