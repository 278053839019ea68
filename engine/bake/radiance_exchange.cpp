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
#include "core/check.h"
#include "core/memory.h"
#include "gl/gl.h"
#include "glsl/shared/bundle_layout.h"
#include "bake/directions.h"

namespace bb {

void Baker::Impl::beginDirection(int k) {
    const glm::vec3 d = directions[size_t(k)];
    // history ramp: weight min(k+1, K)^power relative to the stored scale
    double rampEnd = std::max(1, options.directions / 2);
    double weight = std::pow(std::min(double(k + 1), rampEnd), historyPower);
    double sampleWeight = weight / accumScale;
    if (sampleWeight > 16.0) {
        gl::DebugGroup group("rescale accumulators");
        glUseProgram(rescaleProgram.id());
        glUniform1f(rescaleProgram.uniform("factor"), float(accumScale / weight));
        glUniform1ui(rescaleProgram.uniform("randomSeed"), pcgHash(uint32_t(options.seed) ^ pcgHash(uint32_t(k) + 77u)));
        glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RG32UI);
        dispatchPages(rescaleProgram.id());
        accumScale = weight;
        sampleWeight = 1.0;
    }
    const uint32_t seed = pcgHash(uint32_t(options.seed) * 0x9E3779B1u ^ pcgHash(uint32_t(k)));
    directionUpdate = [this, sampleWeight, seed](const TileFrame&, uint32_t) -> GLuint {
        const bool useEnv = bool(envTexture);
        glUseProgram(updateProgram.id());
        glUniform1f(updateProgram.uniform("sampleWeight"), float(sampleWeight));
        // per direction, not per tile: each texel is updated once per direction, and tiles change with the budget
        glUniform1ui(updateProgram.uniform("randomSeed"), seed);
        const glm::vec3 sky = options.sky / radianceUnit;
        glUniform3fv(updateProgram.uniform("sky"), 1, &sky.x);
        glUniform1i(updateProgram.uniform("useEnv"), useEnv);
        glUniform1f(updateProgram.uniform("depthBias"), depthBias);
        if (useEnv) glBindTextureUnit(BINDING_ENV, envTexture.id());
        glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RG32UI);
        return updateProgram.id();
    };
    tracer->begin(bundleFrame(d, glm::vec2(0.0f), tilerOptions.uniform, pixelSize), tilerOptions, seed, true);
    directionActive = true;
}

void Baker::Impl::stepTile() {
    MemoryCategory category("bundles");
    const int k = stats.directionsDone;
    if (!directionActive) beginDirection(k);
    if (!tracer->done()) tracer->next(directionUpdate);
    if (tracer->done()) finishDirection(k);
}

void Baker::Impl::finishDirection(int k) {
    directionActive = false;
    stats.updatedTexels += stats.coveredTexels;
    // Refresh the outgoing radiance the next bundles read. Every direction at
    // first, when each one adds a bounce; later every k/32 directions (at most
    // 8): the estimate then moves slowly and the resolve is a pass over every page.
    const int interval = std::clamp(k / 32, 1, 8);
    if ((k + 1) % interval == 0 || k + 1 == options.directions) {
        auto tr = Clock::now();
        refreshRadiance(uint32_t(k));
        glFinish();
        stats.secondsResolve += secondsSince(tr);
    }
    ++stats.directionsDone;
}

void Baker::Impl::refreshRadiance(uint32_t key) {
    gl::DebugGroup group("outgoing radiance");
    glUseProgram(metaProgram.id());
    glUniform1i(metaProgram.uniform("includeEmission"), !stats.explicitEmitters);
    glUniform1ui(metaProgram.uniform("randomSeed"), pcgHash(uint32_t(options.seed) ^ pcgHash(key ^ 0x5bd1e995u)));
    glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RG32UI);
    glBindImageTexture(BINDING_DIRECT, direct.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
    glBindImageTexture(BINDING_RADIANCE_BITS, radianceBits.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32UI);
    drawSurface(metaProgram.id(), true);
    glUseProgram(dilateProgram.id());
    glBindImageTexture(BINDING_DILATION, dilation.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R8UI);
    glBindImageTexture(BINDING_RADIANCE_BITS, radianceBits.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
    dispatchPages(dilateProgram.id());
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
