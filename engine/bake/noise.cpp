// The noise estimate: how far the light maps are from what more directions
// would give, without a reference. The directions are two independently
// rotated stratified sets, even and odd k (bake/directions.h); the update pass
// keeps the odd directions' running means apart (at sampled texels,
// glsl/lightmap/update.frag) and the even directions' follow from the whole
// (glsl/lightmap/noise.comp). Two independent replicates' difference
// estimates each texel's variance (measured within 0.86-1.14x of the
// seed-to-seed noise; splitting one set by a coin gave 1.4-2.4x, as a random
// half of a stratified set is noisier than the set); the relative noise is
// sqrt(mean variance) / mean L_lm over the sampled texels, the measure
// `bundlebake compare` reports as rel_rmse against a reference. The direct
// light of explicit emitters and suns (drawn once, before the bundles:
// direct_light.cpp) adds its own noise, from its even and odd samples the
// same way (direct/direct_noise.comp); it was outside the estimate until
// 2026-12-05 (the Cornell box's estimate read 0.81 of the error at 1024
// directions, the shared one's 0.37, mixed_lighting's 0.45). Added to it
// (in quadrature) is the bounce lag (bounceLag below), the one bias both halves
// share that the bake's schedule predicts; other biases both share (a source
// both miss, a texel's mean read where the light bends within it) are not in it.
#include <cmath>

#include "bake/baker_impl.h"
#include "core/log.h"
#include "gl/gl.h"
#include "glsl/shared/bundle_layout.h"

namespace bb {

// The factor that turns a texel's (M_e - M_o)^2 into the variance of its
// mean M. The directions' weights w (the history ramp, rampLogWeight: the
// same for every texel but for its cosines) make M = sum w x / W with
// W = sum w, S = sum w^2 over the directions done, so Var(M) = s^2 S / W^2,
// and E[(M_e - M_o)^2] = s^2 (S_e / W_e^2 + S_o / W_o^2): the factor is the
// ratio, W_e W_o / W^2 (a quarter at equal halves) where each half's weights
// are equal. Until 2026-12-03 that was the factor everywhere: early in a bake
// under a steep ramp the halves are each ruled by their latest direction, and
// the estimate read the last direction's weight share instead of the one or two
// directions that M is (mixed_lighting, ramp power 1024: 0.27 % after 17
// directions against 13.8 % true error, and `--target-noise 0.01` stopped there).
double Baker::Impl::noiseHalvesFactor() const {
    if (stats.directionsDone < 2) return 0.0;
    // the ramp never falls: the latest direction's weight is the largest
    const double top = rampLogWeight((stats.directionsDone - 1) / shareCount());
    double w[2] = {0, 0}, s[2] = {0, 0};  // even, odd directions
    for (int k = 0; k < stats.directionsDone; ++k) {
        const double v = std::exp(rampLogWeight(k / shareCount()) - top);
        w[k % 2] += v;
        s[k % 2] += v * v;
    }
    if (w[0] <= 0.0 || w[1] <= 0.0) return 0.0;
    const double whole = w[0] + w[1];
    return (s[0] + s[1]) / (whole * whole) / (s[0] / (w[0] * w[0]) + s[1] / (w[1] * w[1]));
}

// The bounces still to come, as a share of the bounced light the maps hold
// now. Each direction reads the outgoing radiance of the last refresh, so the
// light of many bounces comes in over many directions, and the history ramp
// weighs each direction's samples as they came: a bias both halves share,
// which their difference leaves out (the rho 0.99 furnace at 256 directions
// reads 34 % low while the halves agree to 0.14 %). A model of one bounce
// mode, run over the bake's own schedule (ramp weights, refresh rounds) up to
// the rounds done: a round's sample x = 1 + lambda M_r, M_r the mean at the
// refresh before it, lambda the scene's transport albedo (its dominant
// eigenvalue, the slowest mode); the fixed point is 1 / (1 - lambda) and the
// lag 1 - M (1 - lambda). Under a steep ramp the bake falls behind that
// (rho 0.9 furnace, power 57, 8 directions: 0.389 of its light against 0.424),
// as if a share f of the texels kept its mean each round, a bounce behind.
// That share is the update pass's grazing samples of weight 0 (update.frag
// footprintPixel: where a texel's footprint projects to less than a pixel,
// no pixel centre crosses it with probability 1 - r^2 |cos|, r the pixels a
// texel side spans, and the sample weighs 0, else crossings / expected): a
// mean weighted by such random weights lags where the latest directions
// weigh most (the ramp), as a miss keeps the mean of the directions before.
// Over |cos| uniform (directions uniform on the sphere) the share is
// 1 / (2 r^2) for r >= 1 (1 - r^2 / 2 below): 1/8 at the default 2, 0.004 at
// 11 (--bundle-res 2048, where the bake keeps up). Counted in the furnace
// at the default: 14.5 % of its samples weighed 0 (its partial texels
// project smaller), other skips 1e-4; with the grazing samples taken at
// weight 1 instead, the bake read 0.252 / 0.416 / 0.625 at 4 / 8 / 16
// directions against the model's 0.256 / 0.424 / 0.642 without f. With f
// the model reads 0.242 / 0.396 / 0.603 (baked 0.246 / 0.389 / 0.609);
// power 0: 0.293 at 16 (baked 0.293).
double Baker::Impl::lagMissedShare() const {
    const double r = tilerOptions.fixedPixelSize > 0.0 ? texelSize / tilerOptions.fixedPixelSize
                                                         : tilerOptions.pixelsPerTexel;
    return r >= 1.0 ? 0.5 / (r * r) : 1.0 - 0.5 * r * r;
}

void Baker::Impl::LagModel::advance(double weightStep, bool refresh, double lambda, double missed) {
    weight *= weightStep;
    const double hit = (mean * weight + 1.0 + lambda * read) / (weight + 1.0);
    mean = rounds == 0 ? hit : (1.0 - missed) * hit + missed * mean;
    weight += rounds == 0 ? 1.0 : 1.0 - missed;
    if (refresh) read = mean;
    ++rounds;
}

void Baker::Impl::runLagModel(LagModel& m, int rounds, int plateau, double lambda) const {
    const double missed = lagMissedShare();
    for (int j = m.rounds; j < rounds; ++j)
        m.advance(j > 0 ? std::exp(rampLogWeight(j - 1, plateau) - rampLogWeight(j, plateau)) : 1.0,
                  refreshesAfter(j, plateau), lambda, missed);
}

// The model advances from the rounds it has run (a resumed bake runs it from 0).
double Baker::Impl::bounceLag() {
    const double lambda = stats.transportAlbedo;
    const int done = stats.directionsDone / shareCount();
    if (!(lambda > 0.0) || done < 1) return 0.0;
    runLagModel(lagModel, done, historyPlateau, lambda);
    return lagModel.lag(lambda);
}

// Where the history ramp ends: the earliest round (a power of two from 16,
// at most half the rounds) after which the model above, run over the whole
// schedule for the scene's slowest mode (transport_albedo.h `slowest`: a
// pocket that keeps its light), leaves at most 0.02 / sqrt(directions) of
// its bounced light to come: a fiftieth of a texel's noise if one
// direction's sample of it varied by its whole value (the bake's is smaller,
// but not by that much: the Cornell box's 0.16 / sqrt(N)). The ramp fades
// the early rounds, which read light maps with few bounces in them and are
// then read again (the radiance is the running mean: a lag the rounds after
// inherit); from the plateau on every round weighs the same. Until
// 2026-12-05 the ramp ran over the first half of the rounds, which the lag
// needs only where light is kept long (the rho 0.99 furnace keeps it;
// mixed_lighting's slowest, 0.93, and the city's, 0.58, too): the Cornell
// box (power 3) counted its rounds as 0.68 of as many equal ones and read
// 0.83 % against the converged reference at 1024 directions (two seeds);
// ending at round 64 (0.96) 0.66 %, at 128 0.71 %, at 32 0.68 %, with no
// lag to see in the mean (0.998-0.999 of the reference's either way). With
// the scene's lambda (5 bounces) instead of its slowest mode the shared
// Cornell box ended at 32 and its brightest texels, in the gap over its
// light panel, read 0.9 % low (0.5 % with the ramp over half).
int Baker::Impl::chooseHistoryPlateau() const {
    const int half = std::max(1, rounds() / 2);
    if (options.historyPlateau > 0) return std::min(options.historyPlateau, half);
    const double lambda = stats.transportAlbedoSlowest;
    if (!(lambda > 0.0)) return std::min(16, half);
    const double bound = 0.02 / std::sqrt(double(std::max(1, options.directions)));
    for (int plateau = 16; plateau < half; plateau *= 2) {
        LagModel m;
        runLagModel(m, rounds(), plateau, lambda);
        if (m.lag(lambda) <= bound) return plateau;
    }
    return half;
}

void Baker::Impl::estimateNoise() {
    gl::DebugGroup group("noise estimate");
    glUseProgram(noiseProgram.id());
    const int width = halfWidth / options.supersample;  // sampled texels of the output layout a side
    glUniform1i(noiseProgram.uniform("halfStride"), stats.noiseStride);
    glUniform1i(noiseProgram.uniform("supersample"), options.supersample);
    glUniform1i(noiseProgram.uniform("pageCount"), layout.pageCount);
    glUniform2i(noiseProgram.uniform("pageSize"), width, width);
    glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RG32UI);
    glBindImageTexture(BINDING_HALF_ACCUM, halfAccum.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RG32UI);
    glBindImageTexture(BINDING_DIRECT, direct.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
    glBindImageTexture(BINDING_TARGET, noiseTerms.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glBindImageTexture(BINDING_NOISE_WEIGHTS, noiseWeights.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R16F);
    glDispatchCompute(GLuint(width + 7) / 8, GLuint(width + 7) / 8, GLuint(layout.pageCount));
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    std::vector<glm::vec4> values(size_t(width) * width * size_t(layout.pageCount));
    gl::readTexture(noiseTerms.id(), 0, 0, 0, width, width, layout.pageCount, GL_RGBA, GL_FLOAT, 16, values.data());
    double variance = 0, direct = 0, sum = 0, bouncedSquares = 0;
    int64_t texels = 0;
    for (size_t i = 0; i < values.size(); ++i) {
        const glm::vec4& v = values[i];
        variance += v.x;
        sum += v.y;
        texels += v.z > 0.0f;
        bouncedSquares += v.w;
        if (v.z > 0.0f && i < directVariance.size()) direct += directVariance[i];
    }
    stats.noiseTexels = texels;
    // too few texels with both halves (the first directions): no estimate yet
    if (texels < 16 || sum <= 0.0) return;
    // the bundles' and the direct light's (drawn apart: their noises add)
    variance = variance * noiseHalvesFactor() + direct;
    const double mean = sum / (3.0 * double(texels));
    noiseMean = mean;
    stats.noiseHalves = std::sqrt(variance / (3.0 * double(texels))) / mean;
    stats.noiseDirect = std::sqrt(direct / (3.0 * double(texels))) / mean;
    // the lag l scales the bounced light (the bundles' means, RMS b), not the direct light beside it: the
    // bounced light to come is b l / (1 - l), over the mean the maps will have (the furnace: l)
    const double lag = bounceLag(), toCome = std::sqrt(bouncedSquares / (3.0 * double(texels))) * lag / (1.0 - lag);
    stats.noiseLag = toCome / (mean + toCome);
    stats.noiseRelative = std::hypot(stats.noiseHalves, stats.noiseLag);
    stats.noiseHistory.emplace_back(stats.directionsDone, stats.noiseRelative);
    if (options.targetNoise > 0 && stats.directionsDone >= 16 && stats.directionsDone < options.directions &&
        stats.noiseRelative <= options.targetNoise) {
        stats.stoppedAtTargetNoise = true;
        logInfo("noise " + std::to_string(stats.noiseRelative) + " <= --target-noise " +
                std::to_string(options.targetNoise) + " after " + std::to_string(stats.directionsDone) + " directions");
    }
}

}  // namespace bb
