// The resolution probe: how far a supersampled bake's light is off because
// the bundle pass reads the outgoing radiance a texel at a time. A ray that
// lands within a texel reads its mean (or its limited slope, or a step,
// append.frag radianceAt), not the light at that point; where light changes
// within a texel that a receiver sees from close by or at a grazing angle
// (the shared Cornell box's slot, whose panel's back within millimetres of
// its edge reads half its texel's mean; strips a few centimetres apart on the
// city's façades) the bake keeps that error whatever its directions: a bias
// the noise estimate's halves share and cannot see (noise.cpp).
//
// After the last direction, K directions (the bake's first K, their seeds and
// phases) are gathered three times from the final radiance, into sums of their
// own at the noise estimate's sampled texels (update.frag RESOLUTION_PROBE):
// reading the baked texels, the same radiance reduced to the output layout's
// texels (k times their side), and to texels twice that side, each level with
// its texels' charts, neighbours and read modes. The passes of a direction
// share every random number, so the differences D1 (output - baked) and D2
// (twice - output) are the changes that coarser reads make, with little noise
// of their own. Richardson, texel by texel (richardsonBias): for a bias
// b(h) = c h^p, D1 = b (k^p - 1), and the order p comes from D2 / D1, held to
// [1, 2]. The even and odd probe directions give two independent D; the sum of
// their products estimates the bias's mean square without the probe's own
// noise in it. The bake's maps are not touched (the same bytes with or
// without the probe).
//
// It sees only light whose detail the baked texels hold and coarser ones lose
// step by step. Where a texel's second step changes less than its first (the
// output's texels already lose the detail outright: charts about a texel wide,
// the street canyon's sills and lintels) the texel is past Richardson's range
// and left out (taken with p = 1 they put the error estimate at 2.9x the
// canyon's error and 2.3x mixed_lighting's at 4096 directions, and matched the
// shared Cornell box's slot rim only by chance: its error sits in texels whose
// steps are small). Light that changes within a baked texel's part (the
// slot's panel within millimetres of its edge) it cannot see at all: that
// needs a finer bake, not coarser reads (design notes, "The resolution
// probe").
#include <algorithm>
#include <cmath>

#include "bake/resolution_probe.h"

#include "bake/baker_impl.h"
#include "bake/supersample.h"
#include "core/log.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "gl/gl.h"
#include "gl/shader.h"
#include "glsl/shared/bundle_layout.h"
#include "glsl/shared/mesh_layout.h"

namespace bb {

int resolutionProbeDirections(const BakeOptions& options) {
    if (options.resolutionProbe >= 0) return std::min(options.resolutionProbe, options.directions);
    // About 5 % of the bake's passes from 512 directions on (three gathers a
    // probe direction), 9 % at 256, none below, where the noise is most of the
    // error. Not fewer than 8: its sums are shrunk by their noise, which at 4
    // hid the shared Cornell box's slot rim (0 at 256 directions, 2.7 % with 8
    // and at 1024 with 16). Not capped: where there is no bias to find, the sum
    // is noise that falls as 1 / sqrt(K) and must stay under the bake's own
    // noise as that falls with the directions (a cap of 32 read the two rooms
    // 0.18 % at 4096 directions, their error less the reference's noise 0.17 %).
    if (options.directions < 256) return 0;
    return std::min(std::max(options.directions / 64, 8), options.directions);
}

namespace {

// One level of the probe's coarser maps: the output layout's texels (level 1)
// or twice their side (level 2), each texel's owner's chart, its neighbours on
// that chart, its radiance (the level below's at the reduction's weights,
// their plain mean where none weighs: padding, dilated already) and read
// modes; and on the CPU what the next level reduces from.
struct CoarseLevel {
    int res = 0;
    gl::Texture radiance, bits, charts, neighbours, modes;
    std::vector<std::vector<glm::vec3>> values;  // per layer
    std::vector<std::vector<uint8_t>> codes;     // per page: DILATION_SELF where covered
    std::vector<std::vector<int32_t>> owners;    // per page
};

}  // namespace

void Baker::Impl::probeResolution() {
    probed = true;
    const int directionsToProbe = resolutionProbeDirections(options);
    const int k = options.supersample;
    // whole texels read whole texels: there is no coarser map than the output's to compare with
    if (directionsToProbe < 2 || k < 2 || shareCount() > 1 || stats.noiseRelative < 0 || noiseMean <= 0) return;
    gl::DebugGroup group("resolution probe");
    MemoryCategory category("noise estimate");
    const auto t0 = Clock::now();
    const double tilingBefore = stats.secondsTiling;
    const int res = layout.resolution, pages = layout.pageCount, layers = stateLayers();

    // The baked level, as the coarser ones reduce from it
    CoarseLevel baked;
    baked.res = res;
    baked.values.assign(size_t(layers), std::vector<glm::vec3>(size_t(res) * res));
    for (int layer = 0; layer < layers; ++layer)
        gl::readTexture(radiance.id(), 0, 0, layer, res, res, 1, GL_RGB, GL_FLOAT, 12, baked.values[size_t(layer)].data());
    baked.codes.assign(size_t(pages), std::vector<uint8_t>(size_t(res) * res));
    for (int p = 0; p < pages; ++p)
        gl::readTexture(dilation.id(), 0, 0, p, res, res, 1, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1, baked.codes[size_t(p)].data());
    // each baked texel's weight in its output texel (the reduction's), or each
    // output texel's in its level-2 texel (its baked texels' sum, where the two
    // share a chart)
    std::vector<std::vector<float>> weights(static_cast<size_t>(pages));
    parallelFor(size_t(pages), [&](size_t p) { weights[p] = fineTexelWeights(mesh, charts, int(p), outputLayout.resolution, k); });

    const auto reduce = [&](const CoarseLevel& from, int factor, CoarseLevel& to) {
        const int r = to.res;
        const std::string label = "resolution probe, texels of " + std::to_string(res / r) + " baked ones: ";
        to.radiance = gl::Texture::create2DArray(label + "radiance", GL_RGB9_E5, r, r, layers);
        to.bits = gl::Texture::createView(label + "radiance as r32ui", to.radiance, GL_R32UI);
        to.charts = gl::Texture::create2DArray(label + "charts", GL_R16UI, r, r, pages);
        to.neighbours = gl::Texture::create2DArray(label + "same-chart neighbours", GL_R8UI, r, r, pages);
        to.modes = gl::Texture::create2DArray(label + "read modes", GL_R8UI, r, r, layers);
        to.owners.resize(size_t(pages));
        to.codes.assign(size_t(pages), std::vector<uint8_t>(size_t(r) * r, uint8_t(DILATION_NONE)));
        to.values.assign(size_t(layers), std::vector<glm::vec3>(size_t(r) * r));
        parallelFor(size_t(pages), [&](size_t p) { to.owners[p] = texelOwners(mesh, int(p), r); });
        std::vector<uint8_t> neighbours(size_t(r) * r);
        std::vector<uint16_t> ownerCharts;
        for (int p = 0; p < pages; ++p) {
            const std::vector<int32_t>& owners = to.owners[size_t(p)];
            std::vector<uint8_t>& codes = to.codes[size_t(p)];
            for (int y = 0; y < from.res; ++y)
                for (int x = 0; x < from.res; ++x)
                    if (from.codes[size_t(p)][size_t(y) * from.res + x] == DILATION_SELF)
                        codes[size_t(y / factor) * r + size_t(x / factor)] = DILATION_SELF;
            chartNeighbourBits(codes, owners, charts, r, neighbours);
            ownerChartCodes(owners, charts, ownerCharts);
            gl::writeTexture(to.charts.id(), 0, 0, p, r, r, 1, GL_RED_INTEGER, GL_UNSIGNED_SHORT, 2, ownerCharts.data());
            gl::writeTexture(to.neighbours.id(), 0, 0, p, r, r, 1, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1, neighbours.data());
            // the weights of `from`'s texels in `to`'s: the reduction's from the baked
            // level; an output texel's its baked texels' sum where it shares its chart
            std::vector<float> summed;
            const std::vector<float>& w = &from == &baked ? weights[size_t(p)] : summed;
            if (&from != &baked) {
                summed.assign(size_t(from.res) * from.res, 0.0f);
                const std::vector<float>& fine = weights[size_t(p)];
                for (int y = 0; y < from.res; ++y)
                    for (int x = 0; x < from.res; ++x) {
                        const int32_t own = from.owners[size_t(p)][size_t(y) * from.res + x];
                        const int32_t parent = owners[size_t(y / factor) * r + size_t(x / factor)];
                        if (own < 0 || parent < 0 || charts[size_t(own)] != charts[size_t(parent)]) continue;
                        float sum = 0.0f;
                        for (int j = 0; j < k; ++j)
                            for (int i = 0; i < k; ++i) sum += fine[size_t(y * k + j) * res + size_t(x * k + i)];
                        summed[size_t(y) * from.res + x] = sum;
                    }
            }
            for (int side = 0; side < (backLayerOffset ? 2 : 1); ++side) {  // the page, its back sides' layer
                const int layer = p + side * backLayerOffset;
                const std::vector<glm::vec3>& below = from.values[size_t(layer)];
                std::vector<glm::vec3>& out = to.values[size_t(layer)];
                for (int y = 0; y < r; ++y)
                    for (int x = 0; x < r; ++x) {
                        glm::vec3 sum(0.0f), plain(0.0f);
                        float weight = 0.0f, count = 0.0f;
                        for (int j = 0; j < factor; ++j)
                            for (int i = 0; i < factor; ++i) {
                                const int fx = x * factor + i, fy = y * factor + j;
                                if (fx >= from.res || fy >= from.res) continue;
                                const size_t f = size_t(fy) * from.res + size_t(fx);
                                sum += w[f] * below[f];
                                weight += w[f];
                                plain += below[f];
                                count += 1.0f;
                            }
                        out[size_t(y) * r + x] = weight > 0.0f ? sum / weight : plain / count;
                    }
                gl::writeTexture(to.radiance.id(), 0, 0, layer, r, r, 1, GL_RGB, GL_FLOAT, 12, out.data());
            }
        }
        computeReadModes(to.neighbours, to.bits, to.modes, r);
    };
    CoarseLevel output, twice;
    output.res = outputLayout.resolution;
    twice.res = (output.res + 1) / 2;
    reduce(baked, k, output);
    reduce(output, 2, twice);

    // The update programs that fold into the probe's sums
    const std::string defines = roundingDefine() + footprintShiftDefine() + backSidesDefine() + "#define RESOLUTION_PROBE 1\n";
    gl::Program programs[4];  // triangles, curved; over one tile, over a leaf run
    const char* vertexShaders[2] = {"lightmap/update.vert", "lightmap/curved.vert"};
    for (int i = 0; i < 4; ++i) {
        auto built = gl::buildProgram({vertexShaders[i % 2], "lightmap/update.frag"},
                                      defines + (i % 2 ? "#define CURVED_FOOTPRINT 1\n" : "") +
                                          (i / 2 ? "#define LEAF_TABLE 1\n" : ""));
        if (!built) {
            logWarning("resolution probe skipped: " + built.status().message());
            return;
        }
        programs[i] = std::move(built.value());
    }
    // per level (baked, output, twice the output's) and half (even, odd directions) its sums
    constexpr int kLevels = 3, kSlots = 2 * kLevels;
    gl::Texture sums = gl::Texture::create2DArray("resolution probe: sums", GL_RGBA32F, halfWidth, halfWidth, kSlots * pages);
    const float zero[4] = {0, 0, 0, 0};
    glClearTexImage(sums.id(), 0, GL_RGBA, GL_FLOAT, zero);
    for (int d = 0; d < directionsToProbe; ++d)
        for (int level = 0; level < kLevels; ++level) {
            const CoarseLevel* coarse = level == 1 ? &output : level == 2 ? &twice : nullptr;
            if (coarse)
                tracer->setRadianceSource(coarse->radiance.id(), coarse->modes.id(), coarse->charts.id(), 0);
            else
                tracer->setRadianceSource(radiance.id(), readModes.id(), texelCharts.id(), slopes.id());
            const int slot = 2 * level + d % 2;
            tracer->run(directionFrame(d), tilerOptions, directionSeed(d), false,
                        [&](const TileFrame& f, uint32_t) {
                            const gl::Program& triangles = programs[f.leafRun ? 2 : 0];
                            const gl::Program& curved = programs[f.leafRun ? 3 : 1];
                            for (const gl::Program* program : {&triangles, &curved}) {
                                setUpdateUniforms(*program, 1.0, d);
                                glUniform1i(program->uniform("probeLayer"), slot * pages);
                            }
                            glBindImageTexture(BINDING_PROBE_SUMS, sums.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
                            return BundleTracer::UpdatePrograms{triangles.id(), curvedTexelCount() ? curved.id() : 0u};
                        },
                        options.leafRuns);
        }
    tracer->setRadianceSource(radiance.id(), readModes.id(), texelCharts.id(), slopes.id());
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);

    // Each sampled texel's six values (its half-size texels' means at the
    // reduction's weights, as noise.comp forms the halves'), and their steps
    // from level to level.
    const size_t slotTexels = size_t(halfWidth) * halfWidth * pages;
    std::vector<glm::vec4> values(slotTexels * kSlots);
    gl::readTexture(sums.id(), 0, 0, 0, halfWidth, halfWidth, kSlots * pages, GL_RGBA, GL_FLOAT, 16, values.data());
    std::vector<float> texelWeights(slotTexels);
    gl::readTexture(noiseWeights.id(), 0, 0, 0, halfWidth, halfWidth, pages, GL_RED, GL_FLOAT, 4, texelWeights.data());
    const int width = halfWidth / k;
    std::vector<ProbeSteps> steps;
    for (int p = 0; p < pages; ++p)
        for (int y = 0; y < width; ++y)
            for (int x = 0; x < width; ++x) {
                glm::dvec3 mean[kSlots];
                bool complete = true;
                for (int s = 0; s < kSlots && complete; ++s) {
                    glm::dvec3 sum(0.0);
                    double weight = 0;
                    for (int j = 0; j < k; ++j)
                        for (int i = 0; i < k; ++i) {
                            const size_t h = (size_t(p) * halfWidth + size_t(y * k + j)) * halfWidth + size_t(x * k + i);
                            const glm::vec4& v = values[size_t(s) * slotTexels + h];
                            if (v.a <= 0.0f || texelWeights[h] <= 0.0f) continue;
                            sum += double(texelWeights[h]) * glm::dvec3(v) / double(v.a);
                            weight += texelWeights[h];
                        }
                    complete = weight > 0;
                    mean[s] = complete ? sum / weight : glm::dvec3(0.0);
                }
                if (complete)
                    steps.push_back({mean[2] - mean[0], mean[3] - mean[1], mean[4] - mean[2], mean[5] - mean[3]});
            }
    if (steps.empty()) return;
    const ResolutionBias bias = richardsonBias(steps, k);
    stats.noiseResolution = std::sqrt(bias.meanSquare) / noiseMean;
    stats.resolutionOrder = bias.order;
    stats.resolutionPastRange = bias.pastRange;
    stats.resolutionProbeDirections = directionsToProbe;
    glFinish();
    stats.secondsTiling = tilingBefore;
    stats.secondsProbe = secondsSince(t0);
}

ResolutionBias richardsonBias(std::span<const ProbeSteps> texels, int k) {
    // Per texel and half: in range, and the factor 1 / (k^p - 1) its first step's
    // product takes to the baked reads' bias. The second step's growth over the
    // first, D2 / D1 = k^p (2^p - 1) / (k^p - 1), = 2^p at k = 2 (at k = 4, x^2 /
    // (x + 1) with x = 2^p), p held to [1, 2]: a light that steps within a texel
    // (a shadow's edge) errs as h, smooth light as h^2.
    const auto extrapolation = [k](const glm::dvec3& first, const glm::dvec3& second, double& p) {
        const double a = glm::dot(first, first), b = glm::dot(second, second);
        if (a <= 0.0 || b < a) return 0.0;  // past the range (or no step): none
        const double growth = std::sqrt(b / a);
        const double x = std::clamp(k == 2 ? growth : (growth + std::sqrt(growth * growth + 4.0 * growth)) / 2.0, 2.0, 4.0);
        p = std::log2(x);
        return 1.0 / ((k == 2 ? x : x * x) - 1.0);
    };
    double sum = 0, variance = 0, orderSum = 0, orderWeight = 0, changed = 0, past = 0;
    for (const ProbeSteps& t : texels) {
        const double product = glm::dot(t.firstEven, t.firstOdd);
        // the product's variance where no bias is, from the halves' difference (free of
        // the bias, which both share: a product's own square is not); per channel alike
        const glm::dvec3 apart = t.firstEven - t.firstOdd;
        const double spread = glm::dot(apart, apart) / 2.0, productVariance = spread * spread / 3.0;
        // the texel's factor: its halves' mean, each half's 0 past the range
        double weight = 0, order = 0;
        for (const auto& [first, second] : {std::pair{t.firstEven, t.secondEven}, std::pair{t.firstOdd, t.secondOdd}}) {
            double p = 0;
            const double f = extrapolation(first, second, p);
            weight += 0.5 * f * f;
            order += 0.5 * f * f * p;
            if (f == 0.0) past += 0.5 * std::max(product, 0.0);
        }
        sum += product * weight;
        variance += productVariance * weight * weight;
        changed += std::max(product, 0.0);
        if (product > 0.0) {
            orderSum += product * order;
            orderWeight += product * weight;
        }
    }
    ResolutionBias bias;
    // Where there is little bias to find the sum is mostly the probe's noise, and
    // its root (clipped at 0) would read that noise as a bias (mixed_lighting at
    // 256 directions, K = 4: 1.1 % with a bake's noise of 1.2 % and an error of
    // 0.9 %). So it is shrunk by its own variance, S (1 - V / S^2): S where it
    // stands far above its noise, 0 where it stands within it.
    const double shrunk = sum > 0 ? std::max(0.0, sum - variance / sum) : 0.0;
    bias.meanSquare = texels.empty() ? 0.0 : shrunk / (3.0 * double(texels.size()));
    bias.order = orderWeight > 0 ? orderSum / orderWeight : 0.0;
    bias.pastRange = changed > 0 ? past / changed : 0.0;
    return bias;
}

}  // namespace bb
