// The bake's error from two independent reference estimates: see error_check.h.
#include "reference/error_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bake/seam_stitch.h"
#include "bake/supersample.h"
#include "core/hash.h"
#include "core/timer.h"

namespace bb {

nlohmann::json ErrorCheck::toJson() const {
    return {{"rel_rmse", relRmse},     {"upper_bound", upperBound}, {"mean_square", meanSquare}, {"mean_square_error", meanSquareError},
            {"texels", texels}, {"covered_texels", coveredTexels}, {"spp", spp}, {"paths", paths},                  {"seconds", seconds},
            {"conclusive", conclusive()}};
}

std::string ErrorCheck::summary() const {
    char line[256];
    std::snprintf(line, sizeof line, "path-traced check: rel_rmse %.4g, at most %.4g (%s; %lld texels, %lld paths, %.1f s)",
                  relRmse, upperBound, conclusive() ? "conclusive" : "inconclusive: more paths would tell",
                  (long long)texels, (long long)paths, seconds);
    return line;
}

namespace {
constexpr double kNominalRays = 6.0;  // rays a path of the bench's scenes takes at most (1.7-5.7, shadow rays included)

// One estimate of the checked texels ids (spp[i] paths of texel i under `seed`) as
// light maps: dilated into the padding and its seams stitched as the bake's
// were (both linear: the truth's image under them is what the bake's maps
// estimate). Covered texels not checked (a large map's subset; the few the
// reference does not cover) hold the bake's values, so that a seam through them is stitched
// against what the bake has there. Kept at the checked texels only, in ids'
// order (a large map's pages are made one at a time).
std::vector<glm::dvec3> stitchedEstimate(ReferenceBaker& r, const Layout& layout, const LightmapPages& maps,
                                         const std::vector<TexelId>& ids,
                                         const std::vector<uint32_t>& spp, uint64_t seed, bool stitch) {
    const std::vector<glm::dvec4> sums = r.sampleTexels(seed, spp);
    const size_t perPage = size_t(layout.resolution) * layout.resolution;
    LightmapPages pages;
    pages.resolution = layout.resolution;
    pages.covered = maps.covered;
    for (size_t p = 0; p < size_t(layout.pageCount); ++p) {
        std::vector<glm::vec4> page(perPage, glm::vec4(0.0f));
        for (size_t t = 0; p < maps.pages.size() && t < perPage; ++t)
            if (maps.covered[p][t]) page[t] = glm::vec4(maps.pages[p].pixels[t], 1.0f);
        for (size_t i = 0; i < ids.size(); ++i)
            if (ids[i].page == p)
                page[ids[i].index] = glm::vec4(glm::vec3(glm::dvec3(sums[i]) / double(spp[i])), 1.0f);
        pages.pages.push_back(dilatedImage(std::move(page), layout.resolution, layout.padding + 1));
    }
    if (stitch) stitchSeams(pages, findSeams(r.mesh(), layout.resolution));
    std::vector<glm::dvec3> out;
    for (size_t i = 0; i < ids.size(); ++i)
        out.push_back(glm::dvec3(pages.pages[ids[i].page].pixels[ids[i].index]));
    return out;
}

// The paths each texel of the reference gets: a pilot of options.pilotSpp
// paths (stream `pilotSeed`) measures each texel's second moment m; a quarter
// of the budget is shared evenly (a pilot can miss a texel's rare bright
// paths), the rest as m^(2/3); the budget is in rays (paths longer than
// kNominalRays, a high albedo's, get proportionally fewer). Where the pilot
// says the budget could not resolve the expected error, more paths, up to
// options.maxSpp, if those would resolve twice it; else the fallback's,
// where not even twice it could be. The counts follow from the pilot (a third
// stream) and the bake's own figures alone: stopping when A and B agreed
// would bias the estimate.
struct Budget {
    std::vector<uint32_t> spp;  // per texel, in coveredTexels() order
    int meanSpp = 0;
};
Budget shareBudget(ReferenceBaker& r, const ErrorCheckOptions& options, uint64_t pilotSeed) {
    const size_t count = r.coveredTexels().size();
    Budget b{std::vector<uint32_t>(count, uint32_t(options.pilotSpp)), 0};
    const std::vector<glm::dvec4> pilot = r.sampleTexels(pilotSeed, b.spp);
    const double n0 = options.pilotSpp;
    std::vector<double> weight(count);
    double weightSum = 0.0;
    for (size_t i = 0; i < count; ++i) {
        weight[i] = std::pow(pilot[i].w / n0, 2.0 / 3.0);
        weightSum += weight[i];
    }
    const auto allocate = [&](int meanSpp) {
        b.meanSpp = meanSpp;
        const double floorSpp = std::max(2.0, 0.25 * meanSpp);
        const double share = weightSum > 0.0 ? (double(meanSpp) - floorSpp) * double(count) / weightSum : 0.0;
        for (size_t i = 0; i < count; ++i)
            b.spp[i] = uint32_t(std::min(floorSpp + std::floor(share * weight[i]), double(1 << 24)));
    };
    const ReferenceStats& traced = r.stats();  // the pilot's paths alone
    const double raysPerPath = traced.paths > 0 ? double(traced.rays + traced.shadowRays) / double(traced.paths) : 1.0;
    const double rayShare = std::min(1.0, kNominalRays / std::max(raysPerPath, 1.0));
    const auto scaled = [&](int paths) { return std::max(2, int(std::lround(paths * rayShare))); };
    allocate(scaled(options.spp));
    if (options.expectedError > 0.0 && (options.fallbackSpp > 0 || options.maxSpp > options.spp)) {
        // the standard error of the mean product at this budget, from the pilot's sample variances (the
        // reference's noise alone); it falls as 1 / the paths
        double squares = 0.0, sum = 0.0;
        for (size_t i = 0; i < count; ++i) {
            const double texelMean = (pilot[i].x + pilot[i].y + pilot[i].z) / (3.0 * n0);
            const double s = std::max(0.0, (pilot[i].w - n0 * texelMean * texelMean) / (n0 - 1.0)) / double(b.spp[i]);
            squares += s * s;
            sum += texelMean;
        }
        const double mapMean = sum / double(count);
        const double predicted = mapMean > 0.0 ? std::sqrt(squares) / double(count) / (mapMean * mapMean) : 0.0;
        // the standard error at which an error the size of the expected one (or twice it) would be conclusive
        const double resolves = options.expectedError * options.expectedError / 3.0, twice = 4.0 * resolves;
        if (predicted <= resolves) return b;
        const int most = scaled(std::max(options.maxSpp, options.spp));
        if (most > b.meanSpp && predicted * b.meanSpp / most <= twice)  // more paths, up to the most, would tell
            allocate(std::min(most, int(std::ceil(double(b.meanSpp) * predicted / resolves))));
        else if (options.fallbackSpp > 0 && predicted > twice)  // not even twice the expected error
            allocate(scaled(std::min(options.fallbackSpp, options.spp)));
    }
    return b;
}
}  // namespace

void setAutoBudget(ErrorCheckOptions& options, int directions, double bakeEstimate) {
    options.spp = std::clamp(directions / 4, 16, 1024);
    options.maxSpp = std::clamp(directions / 2, 16, 2048);
    options.fallbackSpp = std::clamp(directions / 16, 16, 256);
    options.expectedError = bakeEstimate;
}

Expected<ErrorCheck> checkError(const Scene& scene, const Layout& layout, const LightmapPages& maps,
                                const ErrorCheckOptions& options) {
    if (options.spp < 1 || options.pilotSpp < 2) return Status::error("the error check needs spp >= 1 and a pilot >= 2");
    const auto t0 = Clock::now();
    ReferenceOptions ro = options.reference;
    ro.spp = 1;
    // the bake's covered texels; of a large map a uniform random subset, by a hash of each texel (the
    // same for any run), which the reference alone sets up (its footprints cost memory per texel)
    int64_t covered = 0;
    for (const auto& page : maps.covered)
        for (uint8_t c : page) covered += c != 0;
    const double keep = options.maxTexels > 0 && covered > options.maxTexels ? double(options.maxTexels) / double(covered) : 1.0;
    ro.texelFilter = [&maps, keep, seed = ro.seed](uint32_t page, uint32_t index) {
        if (page >= maps.covered.size() || !maps.covered[page][index]) return false;
        return keep >= 1.0 || double(hash(seed, 0x5B5E7ull, uint64_t(page) << 32 | index) >> 11) * 0x1p-53 < keep;
    };
    auto reference = ReferenceBaker::create(scene, layout, ro);
    if (!reference) return reference.status();
    ReferenceBaker& r = **reference;
    // the texels checked: covered in both (and picked)
    const std::vector<TexelId> ids = r.coveredTexels();
    const int64_t count = int64_t(ids.size());
    if (count == 0) return Status::error("error check: no texel is covered in both the bake and the reference");

    const uint64_t seed = hash(ro.seed, 0xE220C4EC4ull);
    const Budget budget = shareBudget(r, options, hash(seed, 0));
    const std::vector<uint32_t>& spp = budget.spp;
    const std::array<std::vector<glm::dvec3>, 2> estimates = {
        stitchedEstimate(r, layout, maps, ids, spp, hash(seed, 1), options.stitchSeams),
        stitchedEstimate(r, layout, maps, ids, spp, hash(seed, 2), options.stitchSeams)};
    std::vector<double> products;
    products.reserve(size_t(count));
    double referenceSum = 0.0;
    for (size_t i = 0; i < ids.size(); ++i) {
        const glm::dvec3 baked(maps.pages[ids[i].page].pixels[ids[i].index]);
        const glm::dvec3 a = estimates[0][i], b = estimates[1][i];
        const glm::dvec3 ea = baked - a, eb = baked - b;
        products.push_back((ea.x * eb.x + ea.y * eb.y + ea.z * eb.z) / 3.0);
        referenceSum += (a.x + a.y + a.z + b.x + b.y + b.z) / 6.0;
    }
    const double n = double(count);
    const double mean = referenceSum / n;
    double sum = 0.0;
    for (double p : products) sum += p;
    const double productMean = sum / n;
    double spread = 0.0;
    for (double p : products) spread += (p - productMean) * (p - productMean);
    const double productError = std::sqrt(spread / std::max(n - 1.0, 1.0) / n);

    ErrorCheck out;
    const double scale = mean != 0.0 ? 1.0 / (mean * mean) : 0.0;
    out.meanSquare = productMean * scale;
    out.meanSquareError = productError * scale;
    out.relRmse = std::sqrt(std::max(0.0, out.meanSquare));
    out.upperBound = std::sqrt(std::max(0.0, out.meanSquare + 2.0 * out.meanSquareError));
    out.texels = count;
    out.coveredTexels = covered;
    out.spp = budget.meanSpp;
    for (uint32_t n : spp) out.paths += options.pilotSpp + 2 * int64_t(n);
    out.seconds = secondsSince(t0);
    return out;
}

}  // namespace bb
