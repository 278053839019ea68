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
// phases) are gathered twice from the final radiance, into sums of their own
// at the noise estimate's sampled texels (update.frag RESOLUTION_PROBE): once
// reading the baked texels, once the same radiance reduced to the output
// layout's texels (k times their side), with those texels' charts, neighbours
// and read modes. The two passes of a direction share every random number, so
// their difference D is the change that coarser reads make, with little noise
// of its own. Richardson's estimate of the fine reads' bias, for an error that
// falls linearly with the texel (light that steps within a texel: the
// reconstruction keeps each texel's mean, and the part of it a receiver sees
// wrongly scales with the texel), is D / (k - 1). The even and odd probe
// directions give two independent D; the product D_e D_o estimates the bias's
// square without the probe's own noise in it. The bake's maps are not
// touched (the same bytes with or without the probe).
#include <algorithm>
#include <cmath>

#include "bake/baker_impl.h"
#include "bake/supersample.h"
#include "core/log.h"
#include "core/memory.h"
#include "gl/gl.h"
#include "gl/shader.h"
#include "glsl/shared/bundle_layout.h"
#include "glsl/shared/mesh_layout.h"

namespace bb {

int resolutionProbeDirections(const BakeOptions& options) {
    if (options.resolutionProbe >= 0) return std::min(options.resolutionProbe, options.directions);
    // About 3 % of the bake's passes: the estimate holds within its noise from
    // 2 (the shared Cornell box at 256 directions: 0.0280 / 0.0281 / 0.0292
    // with 2 / 4 / 8; at 1024, 0.0276 / 0.0291 / 0.0268 / 0.0272 with 8 / 16 /
    // 32 / 64), and the noise of its sum of products falls as 1 / sqrt(K)
    // where there is no bias to find, as the bake's own falls with the
    // directions (the two rooms at 1024: 0 / 0.0009 / 0.0015 with 16 / 64 /
    // 128, against a bake's noise of 0.0034)
    return std::min(std::max(options.directions / 64, 2), options.directions);
}

namespace {

// The probe's four sums a sampled half-size texel: fine and coarse reads of the even, then the odd directions
enum ProbeSlot { kFineEven, kCoarseEven, kFineOdd, kCoarseOdd, kSlots };

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
    const int res = layout.resolution, coarseRes = outputLayout.resolution, pages = layout.pageCount;
    const int layers = stateLayers();

    // The coarse maps: each output texel's charts, neighbours on its chart and read
    // modes, and its radiance, the baked texels' at the reduction's weights
    // (their plain mean where none weighs: padding, dilated already).
    gl::Texture coarseRadiance = gl::Texture::create2DArray("resolution probe: coarse radiance", GL_RGB9_E5, coarseRes, coarseRes, layers);
    gl::Texture coarseBits = gl::Texture::createView("resolution probe: coarse radiance as r32ui", coarseRadiance, GL_R32UI);
    gl::Texture coarseCharts = gl::Texture::create2DArray("resolution probe: coarse texels' charts", GL_R16UI, coarseRes, coarseRes, pages);
    gl::Texture coarseNeighbours = gl::Texture::create2DArray("resolution probe: coarse same-chart neighbours", GL_R8UI, coarseRes, coarseRes, pages);
    gl::Texture coarseModes = gl::Texture::create2DArray("resolution probe: coarse read modes", GL_R8UI, coarseRes, coarseRes, layers);
    {
        const size_t fineTexels = size_t(res) * res, coarseTexels = size_t(coarseRes) * coarseRes;
        std::vector<uint8_t> fineCodes(fineTexels), codes(coarseTexels), neighbours(coarseTexels);
        std::vector<uint16_t> ownerCharts(coarseTexels);
        std::vector<glm::vec3> fine(fineTexels), coarse(coarseTexels);
        for (int p = 0; p < pages; ++p) {
            const std::vector<int32_t> owners = texelOwners(mesh, p, coarseRes);
            const std::vector<float> weights = fineTexelWeights(mesh, charts, p, coarseRes, k);
            gl::readTexture(dilation.id(), 0, 0, p, res, res, 1, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1, fineCodes.data());
            std::fill(codes.begin(), codes.end(), uint8_t(DILATION_NONE));
            for (size_t i = 0; i < fineTexels; ++i)
                if (fineCodes[i] == DILATION_SELF) codes[size_t(i / res / k) * coarseRes + (i % res) / k] = DILATION_SELF;
            chartNeighbourBits(codes, owners, charts, coarseRes, neighbours);
            for (size_t i = 0; i < coarseTexels; ++i)
                ownerCharts[i] = uint16_t(owners[i] < 0 ? TEXEL_CHART_MASK : charts[size_t(owners[i])] & TEXEL_CHART_MASK);
            gl::writeTexture(coarseCharts.id(), 0, 0, p, coarseRes, coarseRes, 1, GL_RED_INTEGER, GL_UNSIGNED_SHORT, 2, ownerCharts.data());
            gl::writeTexture(coarseNeighbours.id(), 0, 0, p, coarseRes, coarseRes, 1, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1,
                             neighbours.data());
            for (int layer = p; layer < layers; layer += std::max(1, backLayerOffset)) {  // the page, its back sides
                gl::readTexture(radiance.id(), 0, 0, layer, res, res, 1, GL_RGB, GL_FLOAT, 12, fine.data());
                for (int y = 0; y < coarseRes; ++y)
                    for (int x = 0; x < coarseRes; ++x) {
                        glm::vec3 sum(0.0f), plain(0.0f);
                        float weight = 0.0f;
                        for (int j = 0; j < k; ++j)
                            for (int i = 0; i < k; ++i) {
                                const size_t f = size_t(y * k + j) * res + size_t(x * k + i);
                                sum += weights[f] * fine[f];
                                weight += weights[f];
                                plain += fine[f];
                            }
                        coarse[size_t(y) * coarseRes + x] = weight > 0.0f ? sum / weight : plain / float(k * k);
                    }
                gl::writeTexture(coarseRadiance.id(), 0, 0, layer, coarseRes, coarseRes, 1, GL_RGB, GL_FLOAT, 12, coarse.data());
                if (backLayerOffset == 0) break;
            }
        }
        glUseProgram(readModesProgram.id());
        glUniform1i(readModesProgram.uniform("codePages"), pages);
        glUniform1i(readModesProgram.uniform("pageCount"), layers);
        glUniform2i(readModesProgram.uniform("pageSize"), coarseRes, coarseRes);
        glBindImageTexture(BINDING_CHART_NEIGHBOURS_IMAGE, coarseNeighbours.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R8UI);
        glBindImageTexture(BINDING_RADIANCE_BITS, coarseBits.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32UI);
        glBindImageTexture(BINDING_READ_MODES_IMAGE, coarseModes.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R8UI);
        glDispatchCompute(GLuint(coarseRes + 7) / 8, GLuint(coarseRes + 7) / 8, GLuint(layers));
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    }

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
    gl::Texture sums = gl::Texture::create2DArray("resolution probe: sums", GL_RGBA32F, halfWidth, halfWidth, kSlots * pages);
    const float zero[4] = {0, 0, 0, 0};
    glClearTexImage(sums.id(), 0, GL_RGBA, GL_FLOAT, zero);

    for (int d = 0; d < directionsToProbe; ++d)
        for (const bool coarse : {false, true}) {
            if (coarse)
                tracer->setRadianceSource(coarseRadiance.id(), coarseModes.id(), coarseCharts.id());
            else
                tracer->setRadianceSource(radiance.id(), readModes.id(), texelCharts.id());
            const int slot = (d % 2 ? kFineOdd : kFineEven) + int(coarse);
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
    tracer->setRadianceSource(radiance.id(), readModes.id(), texelCharts.id());
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);

    // Each sampled texel's four values (its half-size texels' means at the
    // reduction's weights, as noise.comp forms the halves'), then the bias.
    const size_t slotTexels = size_t(halfWidth) * halfWidth * pages;
    std::vector<glm::vec4> values(slotTexels * kSlots);
    gl::readTexture(sums.id(), 0, 0, 0, halfWidth, halfWidth, kSlots * pages, GL_RGBA, GL_FLOAT, 16, values.data());
    std::vector<float> weights(slotTexels);
    gl::readTexture(noiseWeights.id(), 0, 0, 0, halfWidth, halfWidth, pages, GL_RED, GL_FLOAT, 4, weights.data());
    const int width = halfWidth / k;
    double squares = 0;
    int64_t texels = 0;
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
                            const glm::vec4& v = values[size_t(s) * size_t(pages) * halfWidth * halfWidth + h];
                            if (v.a <= 0.0f || weights[h] <= 0.0f) continue;
                            sum += double(weights[h]) * glm::dvec3(v) / double(v.a);
                            weight += weights[h];
                        }
                    complete = weight > 0;
                    mean[s] = complete ? sum / weight : glm::dvec3(0.0);
                }
                if (!complete) continue;
                const glm::dvec3 even = mean[kCoarseEven] - mean[kFineEven], odd = mean[kCoarseOdd] - mean[kFineOdd];
                squares += glm::dot(even, odd);
                ++texels;
            }
    // the bias's mean square a channel, the radiance unit's as noiseMean's
    const double bias = texels > 0 ? std::sqrt(std::max(0.0, squares / (3.0 * double(texels)))) / double(k - 1) : 0.0;
    stats.noiseResolution = bias / noiseMean;
    stats.resolutionProbeDirections = directionsToProbe;
    glFinish();
    stats.secondsTiling = tilingBefore;
    stats.secondsProbe = secondsSince(t0);
}

}  // namespace bb
