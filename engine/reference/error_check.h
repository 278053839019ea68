// The bake's error against the truth, without a converged reference: the
// reference path tracer (reference_baker.h) traces two independent unbiased
// estimates A and B of every covered texel, and for a baked value b
//   E[(b - A)(b - B)] = (b - L)^2
// exactly (L the texel's true value; A's and B's errors are independent and
// of mean 0), so the mean of (b - A)(b - B) over the texels is an unbiased
// estimate of the bake's mean squared error, bias and noise alike, however
// noisy A and B are. Its own standard error falls with the texels and the
// samples and is reported with it.
//
// The reference's noise is far from even: a texel seen by a small bright
// emitter (the shared Cornell box's slot beside its panel light, 130x the
// map's mean) can hold most of it. A pilot of a few samples per texel (a
// third stream, so that the counts it sets do not bias A or B) measures each
// texel's samples' second moment m (their variance plus their mean squared:
// 16 samples of a texel lit through a 0.9 mm gap can all miss its rare bright
// paths, but not its brightness), and the budget is shared out as m^(2/3),
// which minimises the variance of the sum of the products where the
// reference's noise v dominates them (Var (b - A)(b - B) ~ (v / n)^2 per
// texel), v bounded by m.
//
// It estimates the error against the reference baker's definition of a
// texel (the mean over its footprint, reference_baker.h): where that
// definition and another baker's differ, it cannot see it. Units: the
// estimate is relative, RMSE over the mean of the reference, as
// `bundlebake compare` reports rel_rmse. A bake whose seams were stitched is
// checked against the truth stitched the same way (the stitch is a linear map
// of the texels, so the two estimates' stitched images are unbiased estimates
// of the truth's; stitching alone moves mixed_lighting's texels by 2.3 % of
// its mean).
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "bake/baker.h"  // LightmapPages
#include "core/status.h"
#include "layout/layout.h"
#include "reference/reference_baker.h"
#include "scene/scene.h"

namespace bb {

struct ErrorCheckOptions {
    ReferenceOptions reference;  // sky, environment, threads, seed (spp, passSpp unused)
    // Mean paths per texel per estimate (two estimates, plus the pilot) where a path takes 6 rays or
    // fewer (segments and shadow rays; 1.7-5.7 on the bench's scenes); where the pilot's paths take
    // more (a high albedo: the rho 0.99 furnace's run ~100 bounces), proportionally fewer.
    int spp = 256;
    // Where the pilot's variances say that spp would not resolve expectedError (> 0: the error the
    // bake expects, e.g. its noise estimate), more paths up to maxSpp where those would resolve twice
    // it (the bake's estimate may miss a bias, the check's reason to be); where not even twice it
    // could be resolved at spp, fallbackSpp (> 0) instead: small maps spread the reference's noise
    // over few texels, and there the check can only bound the error cheaply.
    int maxSpp = 0;
    int fallbackSpp = 0;
    double expectedError = 0;
    int pilotSpp = 16;           // paths per texel of the pilot
    // At most this many texels (0: all), a uniform random subset of them: the estimate stays unbiased
    // and its standard error follows the texels checked (a subset's seams are stitched against the
    // bake's values at the texels left out).
    int64_t maxTexels = 1 << 16;
    bool stitchSeams = true;     // the bake's seams were stitched (bake/seam_stitch.h): stitch the estimates'
};

struct ErrorCheck {
    double relRmse = 0;          // sqrt(max(0, meanSquare))
    double meanSquare = 0;       // the estimated mean squared error over the reference's mean squared (may be < 0)
    double meanSquareError = 0;  // its standard error (from the spread of the texels' products)
    double upperBound = 0;       // sqrt(meanSquare + 2 meanSquareError): relRmse's upper bound at about 98 %
    int64_t texels = 0;         // checked (covered in both the maps and the reference; a subset of them)
    int64_t coveredTexels = 0;  // covered in the bake
    int spp = 0;               // mean paths per texel per estimate, as traced
    int64_t paths = 0;         // traced, pilot included
    double seconds = 0;        // BVH, coverage and tracing
    // relRmse is an estimate worth reporting: meanSquare at least 3 standard errors
    // above 0 (relRmse then within about +-17 %, one standard error)
    bool conclusive() const { return meanSquare > 0 && meanSquare >= 3.0 * meanSquareError; }
    nlohmann::json toJson() const;
    std::string summary() const;  // one line: the estimate, its bound, the work (no "error": it is no failure)
};

// The budget `bake --error-check auto` and `check --spp auto` take after a
// bake of `directions` whose own estimate (noise and resolution probe) was
// `bakeEstimate`: directions / 4 paths per texel and estimate (16 to 1024);
// up to directions / 2 (2048) where that would not resolve the estimate but
// those would resolve twice it; directions / 16 (16 to 256) where not even twice it
// could be resolved.
void setAutoBudget(ErrorCheckOptions& options, int directions, double bakeEstimate);

// Checks `maps` (the bake of `scene` laid out as `layout`) texel by texel.
// Errors: the reference's (bad options, a scene without triangles), no texel
// covered in both.
Expected<ErrorCheck> checkError(const Scene& scene, const Layout& layout, const LightmapPages& maps,
                                const ErrorCheckOptions& options);

}  // namespace bb
