// One direction of the bake (radiance exchange, Hermes et al. 2010 as used by
// Tokuyoshi et al. 2013): the history ramp's weight, the direction's tiles
// through the bundle tracer with the update pass (glsl/lightmap/update.frag)
// after each, and the scheduled refresh of the outgoing radiance the next
// bundles read (glsl/lightmap/meta.frag, dilate.comp); the light map itself
// (glsl/lightmap/resolve.comp) for read-backs and the viewer.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "bake/baker_impl.h"
#include "bake/rounding.h"
#include "gl/objects.h"
#include "core/check.h"
#include "core/memory.h"
#include "gl/gl.h"
#include "glsl/shared/bundle_layout.h"
#include "bake/directions.h"

namespace bb {

void Baker::Impl::beginDirection(int k) {
    // history ramp: weight min(j+1, plateau)^power relative to the stored
    // scale, j the round (the direction, baked alone): a round adds a bounce
    const double logWeight = rampLogWeight(k / shareCount());
    double sampleWeight = std::exp(logWeight - accumLogScale);
    if (sampleWeight > 16.0) {
        rescaleAccumulators(float(std::exp(accumLogScale - logWeight)), pcgHash(uint32_t(options.seed) ^ pcgHash(uint32_t(k) + 77u)));
        accumLogScale = logWeight;
        sampleWeight = 1.0;
    }
    const uint32_t seed = directionSeed(k);
    directionUpdate = [this, sampleWeight, k](const TileFrame& f, uint32_t) {
        const gl::Program& triangles = f.leafRun ? updateLeafRunProgram : updateProgram;
        const gl::Program& curved = f.leafRun ? updateCurvedLeafRunProgram : updateCurvedProgram;
        for (const gl::Program* program : {&triangles, &curved}) setUpdateUniforms(*program, sampleWeight, k);
        glBindImageTexture(BINDING_HALF_ACCUM, halfAccum.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RG32UI);
        glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RG32UI);
        glBindImageTexture(BINDING_MOMENTS, moments.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
        return BundleTracer::UpdatePrograms{triangles.id(), curvedTexelCount() ? curved.id() : 0u};
    };
    tracer->begin(directionFrame(k), tilerOptions, seed, true, options.leafRuns);
    directionActive = true;
}

uint32_t Baker::Impl::directionSeed(int k) const {
    return pcgHash(uint32_t(options.seed) * 0x9E3779B1u ^ pcgHash(uint32_t(k)));
}

BundleFrame Baker::Impl::directionFrame(int k) const {
    // the grid's phase, random per direction: where the bundle grid beats against
    // the light map's texels, the pattern moves from direction to direction and
    // averages out instead of settling into stripes (issue 11)
    const uint32_t seed = directionSeed(k);
    const glm::vec2 phase(uniform01(pcgHash(seed ^ 0x5bd1e995u)) - 0.5f, uniform01(pcgHash(seed ^ 0x1b873593u)) - 0.5f);
    return bundleFrame(directions[size_t(k)], phase, tilerOptions.uniform, pixelSize);
}

void Baker::Impl::setUpdateUniforms(const gl::Program& program, double sampleWeight, int k) const {
    const bool useEnv = bool(envTexture);
    const glm::vec3 sky = options.sky / radianceUnit;
    glUseProgram(program.id());
    glUniform1f(program.uniform("sampleWeight"), float(sampleWeight));
    // per direction, not per tile: each texel is updated once per direction, and tiles change with the budget
    glUniform1ui(program.uniform("randomSeed"), directionSeed(k));
    glUniform3fv(program.uniform("sky"), 1, &sky.x);
    glUniform1i(program.uniform("useEnv"), useEnv);
    // the noise estimate's halves: the odd directions are the second of the
    // two independently rotated sets (bake/directions.h)
    glUniform1i(program.uniform("oddDirection"), k % 2);
    glUniform1i(program.uniform("halfStride"), stats.noiseStride);
    glUniform1i(program.uniform("supersample"), options.supersample);
    glUniform1i(program.uniform("backLayerOffset"), backLayerOffset);
    glUniform1f(program.uniform("depthBias"), depthBias);
    glUniform1ui(program.uniform("footprintSample"), uint32_t(k));
    glBindTextureUnit(BINDING_FOOTPRINT, footprint.id());
    if (useEnv) glBindTextureUnit(BINDING_ENV, envTexture.id());
}

void Baker::Impl::stepTile() {
    MemoryCategory category("bundles");
    const int round = stats.directionsDone / shareCount();
    const int k = stats.directionsDone + shareIndex();
    if (k < options.directions) {  // the last round may have no direction for this baker
        if (!directionActive) beginDirection(k);
        if (!tracer->done()) tracer->next(directionUpdate);
        if (!tracer->done()) return;
        directionActive = false;
        stats.updatedTexels += stats.coveredTexels;
        combined = false;
    }
    finishRound(round);
}

void Baker::Impl::finishRound(int round) {
    stats.directionsDone = std::min(options.directions, (round + 1) * shareCount());
    // Refresh the outgoing radiance the next bundles read. After every round
    // while each one adds a bounce the estimate needs; later every j/32 rounds
    // (at most 8, and at most half the ramp's memory: refreshInterval):
    // the estimate then moves slowly and the refresh is a pass over every page.
    if (refreshesAfter(round, historyPlateau)) {
        auto tr = Clock::now();
        combineShares(round);
        stats.secondsCombine += secondsSince(tr);
        tr = Clock::now();
        refreshRadiance(uint32_t(round));
        estimateNoise();  // on the combined sums: every baker stops at the same round
        if (shareIndex() > 0) clearAccumulators();  // what this baker adds from now on, alone: baker 0 holds the sums
        glFinish();
        stats.secondsResolve += secondsSince(tr);
        combined = true;
    }
}

void Baker::Impl::combineShares(int round) {
    if (shareCount() == 1) return;
    gl::DebugGroup group("combine accumulators");
    DirectionShare& share = *options.share;
    const int res = layout.resolution;
    if (coveredTexelIndex.empty()) {  // the texels the update pass writes: the others hold nothing to combine
        std::vector<uint8_t> codes(size_t(res) * res);
        coveredTexelIndex.resize(size_t(layout.pageCount));
        halfCoveredTexelIndex.resize(size_t(layout.pageCount));
        for (int p = 0; p < layout.pageCount; ++p) {
            gl::readTexture(dilation.id(), 0, 0, p, res, res, 1, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1, codes.data());
            for (int y = 0; y < res; ++y)
                for (int x = 0; x < res; ++x) {
                    if (codes[size_t(y) * res + x] != DILATION_SELF) continue;
                    coveredTexelIndex[size_t(p)].push_back(uint32_t(y * res + x));
                    if (const int64_t half = halfTexel(x, y); half >= 0)
                        halfCoveredTexelIndex[size_t(p)].push_back(uint32_t(half));
                }
        }
    }
    // Sums relative to the round's ramp weight, which every baker knows (each
    // one's accumLogScale follows its own rescales): weights W and W x mean.
    const double logScale = rampLogWeight(round);
    const float toCommon = float(std::exp(accumLogScale - logScale));
    // the whole's accumulators (and its texels' moments, at the same
    // weights), then the noise estimate's half (a double-sided scene's back
    // sides' layers follow their page's covered texels)
    const auto combine = [&](const gl::Texture& texture, int width, int layers,
                             const std::vector<std::vector<uint32_t>>& coveredIndex, uint32_t salt,
                             const gl::Texture* withMoments) {
        const size_t pageTexels = size_t(width) * width;
        const auto rnd = [&](size_t texel, uint32_t channel) {
            return uniform01(pcgHash(uint32_t(options.seed) ^ pcgHash(uint32_t(texel) * 4u + channel) ^
                                     pcgHash(uint32_t(round) + salt)));
        };
        std::vector<glm::uvec2> raw(pageTexels);
        std::vector<glm::vec4> moments;
        std::vector<float> sums, momentSums;
        for (int p = 0; p < layers; ++p) {
            const std::vector<uint32_t>& covered = coveredIndex[size_t(p % layout.pageCount)];
            gl::readTexture(texture.id(), 0, 0, p, width, width, 1, GL_RG_INTEGER, GL_UNSIGNED_INT, 8, raw.data());
            if (withMoments) {
                moments.resize(pageTexels);
                gl::readTexture(withMoments->id(), 0, 0, p, width, width, 1, GL_RGBA, GL_FLOAT, 16, moments.data());
                momentSums.assign(covered.size() * 4, 0.0f);
            }
            sums.assign(covered.size() * 4, 0.0f);
            for (size_t i = 0; i < covered.size(); ++i) {
                const glm::vec4 state = decodeAccumulator(raw[covered[i]]);
                const float w = state.a * toCommon;
                sums[4 * i + 0] = state.r * w;
                sums[4 * i + 1] = state.g * w;
                sums[4 * i + 2] = state.b * w;
                sums[4 * i + 3] = w;
                if (withMoments)
                    for (int c = 0; c < 4; ++c) momentSums[4 * i + size_t(c)] = moments[covered[i]][c] * w;
            }
            share.sum(sums.data(), sums.size());
            stats.combineBytes += int64_t(sums.size() * sizeof(float));
            if (withMoments) {
                share.sum(momentSums.data(), momentSums.size());
                stats.combineBytes += int64_t(momentSums.size() * sizeof(float));
                for (size_t i = 0; i < covered.size(); ++i) {
                    const float w = sums[4 * i + 3];
                    for (int c = 0; c < 4; ++c) moments[covered[i]][c] = w > 0.0f ? momentSums[4 * i + size_t(c)] / w : 0.0f;
                }
                gl::writeTexture(withMoments->id(), 0, 0, p, width, width, 1, GL_RGBA, GL_FLOAT, 16, moments.data());
            }
            // every baker stores the combined means (the outgoing pass reads them);
            // the rounding's random numbers are the same on all, so are the bits
            for (size_t i = 0; i < covered.size(); ++i) {
                const float w = sums[4 * i + 3];
                const glm::vec3 mean = w > 0.0f ? glm::vec3(sums[4 * i], sums[4 * i + 1], sums[4 * i + 2]) / w : glm::vec3(0.0f);
                const size_t texel = size_t(p) * pageTexels + covered[i];
                // a sampled texel stays sampled (W > 0), as rescale.comp keeps it
                const float kept = w > 0.0f ? std::max(w, float(SAMPLED_MIN_WEIGHT)) : 0.0f;
                raw[covered[i]] = encodeAccumulator(glm::vec4(mean, kept), options.rounding,
                                                    glm::vec4(rnd(texel, 0), rnd(texel, 1), rnd(texel, 2), rnd(texel, 3)));
            }
            gl::writeTexture(texture.id(), 0, 0, p, width, width, 1, GL_RG_INTEGER, GL_UNSIGNED_INT, 8, raw.data());
        }
    };
    combine(accum, res, stateLayers(), coveredTexelIndex, 0x68e31da4u, &moments);
    combine(halfAccum, halfWidth, layout.pageCount, halfCoveredTexelIndex, 0x2545f491u, nullptr);
    accumLogScale = logScale;
    ++stats.combines;
}

void Baker::Impl::refreshRadiance(uint32_t key) {
    gl::DebugGroup group("outgoing radiance");
    glUseProgram(metaProgram.id());
    glUniform1i(metaProgram.uniform("includeEmission"), !stats.explicitEmitters);
    glUniform1ui(metaProgram.uniform("randomSeed"), pcgHash(uint32_t(options.seed) ^ pcgHash(key ^ 0x5bd1e995u)));
    glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RG32UI);
    glBindImageTexture(BINDING_DIRECT, direct.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
    glBindImageTexture(BINDING_RADIANCE_BITS, radianceBits.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32UI);
    glBindImageTexture(BINDING_MOMENTS, moments.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    glBindImageTexture(BINDING_SLOPES_IMAGE, slopes.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    glBindTextureUnit(BINDING_FOOTPRINT, footprint.id());
    glBindTextureUnit(BINDING_CHART_NEIGHBOURS, chartNeighbours.id());
    glUniform1i(metaProgram.uniform("layerOffset"), 0);
    drawSurface(metaProgram.id(), true);
    if (backLayerOffset != 0) {  // the back sides' layers
        glUniform1i(metaProgram.uniform("layerOffset"), backLayerOffset);
        drawSurface(metaProgram.id(), true);
    }
    glUseProgram(dilateProgram.id());
    glUniform1i(dilateProgram.uniform("codePages"), layout.pageCount);
    glBindImageTexture(BINDING_DILATION, dilation.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R8UI);
    glBindImageTexture(BINDING_RADIANCE_BITS, radianceBits.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
    dispatchPages(dilateProgram.id(), stateLayers());
    updateReadModes();
}

void Baker::Impl::updateReadModes() { computeReadModes(chartNeighbours, radianceBits, readModes, layout.resolution); }

void Baker::Impl::computeReadModes(const gl::Texture& neighbours, const gl::Texture& bits, const gl::Texture& modes,
                                   int res) {
    gl::DebugGroup group("radiance read modes");
    glUseProgram(readModesProgram.id());
    glUniform1i(readModesProgram.uniform("codePages"), layout.pageCount);
    glUniform1i(readModesProgram.uniform("pageCount"), stateLayers());
    glUniform2i(readModesProgram.uniform("pageSize"), res, res);
    glBindImageTexture(BINDING_CHART_NEIGHBOURS_IMAGE, neighbours.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R8UI);
    glBindImageTexture(BINDING_RADIANCE_BITS, bits.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32UI);
    glBindImageTexture(BINDING_READ_MODES_IMAGE, modes.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R8UI);
    glDispatchCompute(GLuint(res + 7) / 8, GLuint(res + 7) / 8, GLuint(stateLayers()));
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

void Baker::Impl::resolveInto(const gl::Texture& target, int y0, int rows, int page0, int pages) {
    gl::DebugGroup group("resolve");
    glUseProgram(resolveProgram.id());
    glUniform3i(resolveProgram.uniform("origin"), 0, y0, page0);
    glUniform1i(resolveProgram.uniform("pageCount"), pages);
    glUniform2i(resolveProgram.uniform("pageSize"), layout.resolution, rows);
    glUniform1f(resolveProgram.uniform("radianceUnit"), radianceUnit);
    glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RG32UI);
    glBindImageTexture(BINDING_DIRECT, direct.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
    glBindImageTexture(BINDING_DILATION, dilation.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R8UI);
    glBindImageTexture(BINDING_TARGET, target.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(GLuint(layout.resolution + 7) / 8, GLuint(rows + 7) / 8, GLuint(pages));
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

}  // namespace bb
