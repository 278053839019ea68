// Seam stitching: make the light map agree on both sides of every UV seam
// (layout/seams.h), so bilinear lookups on either side of a seam return the
// same value and a render shows no line along it. CPU, after read-back
// (Baker::readLightmaps), before the light maps are written.
//
// Based on: M. Iwanicki, "Lighting Technology of The Last of Us", SIGGRAPH
// 2013 Advances course, as ands' seamoptimizer (github.com/ands/seamoptimizer)
// implements it: a sparse least-squares over the texels the bilinear lookups
// at the seams' sample pairs touch,
//     minimize  sum_pairs |bilinear_A(x) - bilinear_B(x)|^2 + keepWeight sum_texels |x - x_baked|^2,
// one sparse SPD system (J^T J + keepWeight I) x = keepWeight x_baked, factored
// once (Eigen SimplicialLDLT, AMD ordering: deterministic) and solved per
// channel in double. Texels no lookup touches keep their bytes; those it
// touches are the covered texels along the seams and the padding texels next
// to them (their dilated values become part of the stitch).
//
// Cost: a few us per sample pair, seam search included (the test sphere at
// 128 texels: 830 pairs, 5 ms; living_room at 512: 765 pairs, 7 ms).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "bake/baker.h"
#include "layout/seams.h"

namespace bb {

struct SeamStitchOptions {
    // Weight of a texel's change from its baked value against the seam pairs'
    // squared differences (typ. 0.02..1: smaller stitches tighter and moves
    // texels further from what the bake measured). Measured on the golden
    // test's sphere (seam RMS 0.0112 unstitched, texel noise 0.0029): 0.02 ->
    // 0.00033, 0.05 -> 0.00050, 0.1 -> 0.0007, 0.2 -> 0.0010, 0.5 -> 0.0017,
    // 1 -> 0.0027. 0.1 leaves every seam below the noise.
    double keepWeight = 0.1;
    // ... times this for covered texels (the bake's measured values, its
    // footprints' means), so that the padding texels the seams' bilinear
    // lookups tap take more of the stitch. The city under a sky (bench
    // city_sky, 1024 directions) against the converged reference: 3.9 %
    // unstitched; stitched 5.3 % with 1, 4.6 % with 3 (seam RMS 0.154 -> 0.021,
    // 0.016 with 1), 4.1 % with 10 (0.029; the golden sphere's seams then stay
    // above its noise). Times the part of the texel's square on its chart
    // (Seams::texelArea, from the mesh: the same for a bake and the reference).
    double coveredKeepFactor = 3.0;
};

// How well the two sides of the seams agree: over the sample pairs, the RMS
// of bilinear(A) - bilinear(B) per channel, and the mean of the lookups.
// A pair one of whose taps has no baked value (neither covered nor next to a
// covered texel: a sliver chart that covers no texel centre) is skipped, here
// and in the stitch.
struct SeamDifference {
    double rms = 0.0;
    double mean = 0.0;
    size_t pairs = 0;     // pairs measured
    size_t skipped = 0;   // pairs with a tap without a baked value
};
SeamDifference seamDifference(const LightmapPages& maps, const Seams& seams);
// Per sample pair (Seams::samples order): |bilinear(A) - bilinear(B)| / sqrt(3)
// (the pair's RMS over the channels), or -1 for a skipped pair.
std::vector<double> seamPairDifferences(const LightmapPages& maps, const Seams& seams);

struct SeamStitchStats {
    size_t seamEdges = 0;
    size_t hardEdges = 0;      // edges across charts with split normals: not stitched
    size_t narrowPairs = 0;    // sample pairs where a side's chart owns no texel of its lookup: left out
    size_t samplePairs = 0;    // pairs stitched
    size_t skippedPairs = 0;   // pairs with a tap without a baked value: left alone
    size_t texelsAdjusted = 0; // texels in the solve (changed in general)
    double rmsBefore = 0.0, rmsAfter = 0.0;  // SeamDifference::rms before and after
    double meanValue = 0.0;    // SeamDifference::mean before
    double seconds = 0.0;
    bool solved = true;        // false: the factorisation failed, the maps are unchanged
    nlohmann::json toJson() const;
};

// Stitches `maps` in place along `seams` (found for maps.resolution).
// Same maps and seams give the same bytes. No seams: nothing changes.
SeamStitchStats stitchSeams(LightmapPages& maps, const Seams& seams, const SeamStitchOptions& options = {});

}  // namespace bb
