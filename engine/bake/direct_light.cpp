// Direct light: the sun as exact shadow bundles (jittered sub-pixel), small
// emitters lit explicitly (exact polygon form factor times visibility from
// shadow cube maps), and point and spot lights (closed-form irradiance times
// visibility from a shadow cube map at the light); the bundles then carry
// only the reflected light.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "bake/baker_impl.h"
#include "bake/cube_scissor.h"
#include "bake/directions.h"
#include "bake/rounding.h"
#include "core/check.h"
#include "core/hash.h"
#include "core/memory.h"
#include "gl/gl.h"
#include "layout/bake_mesh_gl.h"
#include "glsl/shared/bundle_layout.h"
#include <glm/gtc/matrix_transform.hpp>

namespace bb {
namespace {

// A distance cube map around a point (an emitter sample, a point or spot
// light): per texel the distance to the nearest surface the texel's ray meets;
// cut-outs' cut-away parts are not drawn (direct/distance.frag). Its faces
// are turned by `cubeFromWorld` (lib/cube_visibility.glsl): each emitter
// sample's cube by its own random rotation, so that where the cube's texels
// cut a shadow's edge differs from sample to sample and the quantisation
// averages out over the samples instead of adding up (issue 11).
struct DistanceCube {
    gl::Texture cube, depth;
    gl::Framebuffer fbo;
    int size = 0;
    MeshChunks chunks;
    glm::mat3 cubeFromWorld{1.0f};

    DistanceCube(int faceSize, GLuint triangleBuffer, int64_t triangles) : size(faceSize) {
        cube = gl::Texture::createCube("shadow cube distances and planes", GL_RG32UI, size);
        glTextureParameteri(cube.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(cube.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        depth = gl::Texture::create2D("shadow cube depth", GL_DEPTH_COMPONENT32F, size, size);
        fbo = gl::Framebuffer::create("shadow cube face");
        glNamedFramebufferTexture(fbo.id(), GL_DEPTH_ATTACHMENT, depth.id(), 0);
        // the per-triangle material and flags (cut-outs), bound in chunks
        chunks = MeshChunks::create(triangles, {{MESH_BINDING_TRIANGLES, triangleBuffer, int64_t(sizeof(BakeTriangle))}});
    }

    // Draws the whole mesh but triangle `own` (an emitter sample's) into the
    // six faces around `point`, turned by `orientation` (cube from world),
    // distances up to farPlane. `front` (a single-sided emitter's normal):
    // only the directions in front of the emitter are looked up (behind it
    // nothing is lit, direct/emitter.frag), so each face draws only the part
    // of it that sees them (faceScissor) and a face wholly behind draws
    // nothing; every face is cleared whole all the same.
    void render(GLuint vertexArray, const gl::Program& program, const glm::vec3& point, const glm::mat3& orientation,
                float nearPlane, float farPlane, uint32_t own = 0xffffffffu, const glm::vec3* front = nullptr) {
        cubeFromWorld = orientation;
        const glm::mat4 cubeFromPoint = glm::mat4(orientation) * glm::translate(glm::mat4(1.0f), -point);
        static const glm::vec3 faceDir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        static const glm::vec3 faceUp[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
        const glm::mat4 projection = glm::perspective(glm::radians(90.0f), 1.0f, nearPlane, farPlane);
        const float far = 1e30f;
        GLuint farValue[4] = {0u, 0u, 0u, 0u};  // (1e30's bits, a normal along +z)
        std::memcpy(&farValue[0], &far, 4);
        glBindVertexArray(vertexArray);
        glUseProgram(program.id());
        glUniform3fv(program.uniform("samplePoint"), 1, &point.x);
        glUniform1ui(program.uniform("ownTriangle"), own);
        glEnable(GL_DEPTH_TEST);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
        glViewport(0, 0, size, size);
        for (int f = 0; f < 6; ++f) {
            glNamedFramebufferTextureLayer(fbo.id(), GL_COLOR_ATTACHMENT0, cube.id(), 0, f);
            glm::mat4 clipFromWorld = projection * glm::lookAt(glm::vec3(0.0f), faceDir[f], faceUp[f]) * cubeFromPoint;
            glUniformMatrix4fv(program.uniform("clipFromWorld"), 1, GL_FALSE, &clipFromWorld[0][0]);
            glClearNamedFramebufferuiv(fbo.id(), GL_COLOR, 0, farValue);
            glClearNamedFramebufferfi(fbo.id(), GL_DEPTH_STENCIL, 0, 1.0f, 0);
            if (front) {
                const glm::mat3 viewFromWorld = glm::mat3(glm::lookAt(glm::vec3(0.0f), faceDir[f], faceUp[f])) * orientation;
                const glm::ivec4 rect = faceScissor(viewFromWorld * *front, size);
                if (rect.z <= 0 || rect.w <= 0) continue;
                glEnable(GL_SCISSOR_TEST);
                glScissor(rect.x, rect.y, rect.z, rect.w);
            }
            chunks.drawArrays(program.id(), 0, chunks.triangleCount());
            glDisable(GL_SCISSOR_TEST);
        }
        glDisable(GL_DEPTH_TEST);
    }
};

// The direct light's float sums (lib/direct_scratch.glsl): views of the
// accumulators and the radiance map, unused while the direct light is baked.
void bindDirectSums(const Baker::Impl& m) {
    glBindImageTexture(BINDING_SCRATCH_RG, m.accumAsFloat.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RG32F);
    glBindImageTexture(BINDING_SCRATCH_B, m.radianceAsFloat.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32F);
}

// The noise estimate's share of a direct light pass (direct/direct_noise.comp):
// each light's odd samples' sums at the sampled texels (halfAccum's), and the
// variance of the pass's light there, added to Baker::Impl::directVariance
// when the pass ends.
struct DirectHalves {
    gl::Texture oddSums, variance;
    int width = 0;  // sampled texels of the output layout a side

    explicit DirectHalves(const Baker::Impl& m) : width(m.halfWidth / m.options.supersample) {
        const int pages = m.layout.pageCount;
        oddSums = gl::Texture::create2DArray("direct light's odd samples' sums", GL_RGBA32F, m.halfWidth, m.halfWidth, pages);
        variance = gl::Texture::create2DArray("direct light's variance", GL_R32F, width, width, pages);
        const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        glClearTexImage(oddSums.id(), 0, GL_RGBA, GL_FLOAT, zero);
        glClearTexImage(variance.id(), 0, GL_RED, GL_FLOAT, zero);
        glBindImageTexture(BINDING_DIRECT_ODD_SUMS, oddSums.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
    }

    // the sampled texels, for the passes that draw the light (their halfStride and supersample)
    static void setSampling(const Baker::Impl& m, std::initializer_list<const gl::Program*> programs) {
        for (const gl::Program* p : programs) {
            glUseProgram(p->id());
            glUniform1i(p->uniform("halfStride"), m.stats.noiseStride);
            glUniform1i(p->uniform("supersample"), m.options.supersample);
        }
    }

    // One light's variance, its samples all in (`program` in use, its light's uniforms set), its odd sums cleared
    void addLight(const Baker::Impl& m, const gl::Program& program) const {
        setSampling(m, {&program});
        glUniform1i(program.uniform("pageCount"), m.layout.pageCount);
        glUniform2i(program.uniform("pageSize"), width, width);
        glBindImageTexture(BINDING_DIRECT_ODD_SUMS, oddSums.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindImageTexture(BINDING_DIRECT_VARIANCE, variance.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32F);
        glBindImageTexture(BINDING_DIRECT_WEIGHTS, m.noiseWeights.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R16F);
        glDispatchCompute(GLuint(width + 7) / 8, GLuint(width + 7) / 8, GLuint(m.layout.pageCount));
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    }

    void finish(Baker::Impl& m) const {
        std::vector<float> v(size_t(width) * width * size_t(m.layout.pageCount));
        gl::readTexture(variance.id(), 0, 0, 0, width, width, m.layout.pageCount, GL_RED, GL_FLOAT, 4, v.data());
        if (m.directVariance.empty()) m.directVariance.assign(v.size(), 0.0f);
        for (size_t i = 0; i < v.size(); ++i) m.directVariance[i] += v[i];
    }
};

}  // namespace

int sunJitterFor(const BakeOptions& options) {
    if (options.sunJitter > 0) return options.sunJitter;
    return std::clamp(int(std::ceil(std::sqrt(options.directions / 16.0))), 2, 16);
}

void Baker::Impl::bakeSun() {
    MemoryCategory category("bundles");
    const int j = sunJitterFor(options);
    // Adaptive: the sun at the scene's finest pixel, jittered by it (a fraction
    // of the mean texel's pixel in leaves of finer pixels bunched the samples:
    // on mixed_lighting, 256 directions: 8.0 % against the reference, now 5.5 %)
    TilerOptions sunOptions = tilerOptions;
    if (sunPixelSize > 0) sunOptions.fixedPixelSize = sunPixelSize;
    const double jitterUnit = sunPixelSize > 0 ? sunPixelSize : pixelSize;
    if (lights.empty()) return;
    stats.sunJitter = j;
    const DirectHalves halves(*this);  // each sun's odd jitters apart
    DirectHalves::setSampling(*this, {&sunProgram, &sunCurvedProgram, &sunLeafRunProgram, &sunCurvedLeafRunProgram});
    for (size_t li = 0; li < lights.size(); ++li) {
        const glm::vec3 irradiance = lights[li].irradiance / radianceUnit;
        uint32_t footprintSample = 0;  // the jitter's index: each one samples another point of every texel's footprint
        bool oddSample = false;        // the pass's half for the noise estimate (below)
        const BundleTracer::UpdateFn update = [&](const TileFrame& f, uint32_t) {
            const gl::Program& triangles = f.leafRun ? sunLeafRunProgram : sunProgram;
            const gl::Program& curved = f.leafRun ? sunCurvedLeafRunProgram : sunCurvedProgram;
            for (const gl::Program* program : {&triangles, &curved}) {
                glUseProgram(program->id());
                glUniform3fv(program->uniform("sunIrradiance"), 1, &irradiance.x);
                glUniform1f(program->uniform("depthBias"), depthBias);
                glUniform1ui(program->uniform("footprintSample"), footprintSample);
                glUniform1i(program->uniform("oddSample"), oddSample);
            }
            glBindImageTexture(BINDING_DIRECT_ODD_SUMS, halves.oddSums.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
            glBindTextureUnit(BINDING_FOOTPRINT, footprint.id());
            bindDirectSums(*this);
            glBindImageTexture(BINDING_DIRECT, direct.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA16F);
            return BundleTracer::UpdatePrograms{triangles.id(), curvedTexelCount() ? curved.id() : 0u};
        };
        // The noise estimate's halves are the passes of even and odd index
        // (every other column where j is even: each half a stratified grid,
        // its footprint points every other point of the R2 sequence). The
        // grid is the same for every seed: shifted by a seeded random offset,
        // pixel centres came within the raster's precision of a blocker's
        // outline that lies on a texel's edge, and a few texels under it
        // read 1/4 to 1/2 lit (CutoutBake.SunShadowOfTheMaskIsHalfDark, one
        // seed in 8).
        for (int jy = 0; jy < j; ++jy)
            for (int jx = 0; jx < j; ++jx) {
                const glm::vec2 jitter((jx + 0.5f) / j - 0.5f, (jy + 0.5f) / j - 0.5f);
                footprintSample = uint32_t(jy * j + jx);
                oddSample = footprintSample % 2 == 1;
                // each sun's seeds apart from the next's (--sun-jitter is at most 45: 2025 passes)
                tracer->run(bundleFrame(glm::normalize(lights[li].direction), jitter, sunOptions.uniform, jitterUnit),
                            sunOptions, uint32_t(li * 4096 + jy * j + jx), false, update, options.leafRuns);
            }
        glUseProgram(sunNoiseProgram.id());
        bindDirectSums(*this);
        glBindImageTexture(BINDING_DIRECT, direct.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
        halves.addLight(*this, sunNoiseProgram);
        foldDirect(true);  // this sun's mean over its valid samples, added to the direct map
    }
    halves.finish(*this);
}

// A face's pixels in front of the plane: the lookups near the plane step up
// to a texel's angle past the direction they test and read the texel they
// fall in, so a margin of 4 texels' angle keeps them well inside.
glm::ivec4 faceScissor(const glm::vec3& m, int size) {
    // m . (x, y, -1) >= -slack, with slack = sin(4 texels' angle) |m| sqrt(3)
    // (|(x, y, -1)| <= sqrt(3) on the face): the texels' angle is at most 2 / size
    const float slack = std::sin(8.0f / float(size)) * glm::length(m) * std::sqrt(3.0f);
    const auto inside = [&](glm::vec2 p) { return m.x * p.x + m.y * p.y - m.z + slack; };
    // the square [-1, 1]^2 clipped to the half-plane inside >= 0 (Sutherland-Hodgman, one plane)
    const glm::vec2 square[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    glm::vec2 lo(2.0f), hi(-2.0f);
    for (int k = 0; k < 4; ++k) {
        const glm::vec2 a = square[k], b = square[(k + 1) % 4];
        const float da = inside(a), db = inside(b);
        if (da >= 0.0f) lo = glm::min(lo, a), hi = glm::max(hi, a);
        if ((da >= 0.0f) != (db >= 0.0f)) {
            const glm::vec2 c = a + (b - a) * (da / (da - db));
            lo = glm::min(lo, c), hi = glm::max(hi, c);
        }
    }
    if (lo.x > hi.x) return glm::ivec4(0);
    // to pixels, a pixel wider each way for the rounding
    const glm::ivec2 p0 = glm::clamp(glm::ivec2(glm::floor((lo + 1.0f) * 0.5f * float(size))) - 1, 0, size);
    const glm::ivec2 p1 = glm::clamp(glm::ivec2(glm::ceil((hi + 1.0f) * 0.5f * float(size))) + 1, 0, size);
    return glm::ivec4(p0, p1 - p0);
}

bool Baker::Impl::useExplicitEmitters() const {
    using D = BakeOptions::DirectLight;
    if (options.directLight != D::Auto) return options.directLight == D::Explicit;
    size_t emitters = 0;
    double emitterArea = 0, area = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        area += projectedArea[t];
        if (mesh.triangles[t].flags & TRIANGLE_EMISSIVE) {
            ++emitters;
            emitterArea += projectedArea[t];
        }
    }
    return emitters > 0 && emitters <= 1024 && emitterArea <= 0.25 * area;
}

int Baker::Impl::emitterSamples() const {
    return options.emitterSamples > 0 ? options.emitterSamples : std::max(128, options.directions / 4);
}

// auto: 4 cube texels per bundle pixel across (gridSize pixels span the
// scene's diameter), 64..512. Measured on the Cornell box at 64^2 texels:
// 64^2 faces raise the error from 4.3 % to 5.0 %, 256^2 and 512^2 give 4.3 %
// and 256^2 costs 0.3 s instead of 0.5 s. (Until 2026-12-02 the size was
// rounded up to a power of two: 512 for the Cornell box's 67 pixels, 2.5x
// the cost of a sample at 268.) A supersampled bake's pixels are half the
// size, and so would its cubes be, at 3.6x the cost (the Cornell box's
// emitters took 2.4 s of a 2.8 s bake at 16 directions): they stay at the
// layout's texels' size, where they measured as good as the finer ones.
namespace {
constexpr int kMaxShadowCubeSize = 512;

// a cube's GL memory: two 32-bit words a texel of its six faces and a 32-bit depth face
constexpr int64_t distanceCubeBytes(int faceSize) { return int64_t(faceSize) * faceSize * (6 * 8 + 4); }

int shadowCubeSize(const Baker::Impl& m) {
    const int size = m.options.emitterShadowSize;
    return size > 0 ? size : std::clamp(4 * m.gridSize / m.options.supersample, 64, kMaxShadowCubeSize);
}
}  // namespace

// What the emitters' and the point and spot lights' passes hold at their
// peak, beyond the light maps: a distance cube, the emitters' float sums, and the
// noise estimate's share (DirectHalves). The budget's check holds it to what
// the budget leaves (Baker::Impl::init): the direct light runs before the
// bundle pass's buffers are made.
int64_t Baker::Impl::directLightPeakBytes() const {
    if (!useExplicitEmitters() && punctualLights.empty()) return 0;
    const int64_t pages = layout.pageCount, res = layout.resolution;
    const int64_t sampled = halfWidth / options.supersample;
    const int64_t halves = int64_t(halfWidth) * halfWidth * pages * 16 + sampled * sampled * pages * 4;
    const int64_t sums = useExplicitEmitters() ? res * res * pages * 16 : 0;
    return distanceCubeBytes(shadowCubeSize(*this)) + sums + halves;
}

int64_t largestDistanceCubeBytes(const Scene& scene, const BakeMesh& mesh, const BakeOptions& options) {
    const bool emitters = options.directLight != BakeOptions::DirectLight::Bundles && mesh.anyTriangle(TRIANGLE_EMISSIVE);
    if (!emitters && scene.punctualLights.empty()) return 0;
    return distanceCubeBytes(options.emitterShadowSize > 0 ? options.emitterShadowSize : kMaxShadowCubeSize);
}

namespace {

// One light's (an emitter sample's, a point or spot light's) irradiance times
// the visibility `cube` holds, into the direct light's float sums: `program`
// (its light uniforms set) over every page.
void addVisibleLight(Baker::Impl& m, const gl::Program& program, const gl::Program& curvedProgram,
                     const DistanceCube& cube) {
    for (const gl::Program* p : {&program, &curvedProgram}) {
        glUseProgram(p->id());
        // the visibility test's tolerance along the ray (lib/cube_visibility.glsl):
        // half a bundle pixel, well under a texel so walls one texel thick still cast shadows
        glUniform1f(p->uniform("rayOffset"), 0.5f * m.pixelSize);
        glUniform1i(p->uniform("cubeSize"), cube.size);
        glUniformMatrix3fv(p->uniform("cubeFromWorld"), 1, GL_FALSE, &cube.cubeFromWorld[0][0]);
    }
    glBindTextureUnit(0, cube.cube.id());
    glBindTextureUnit(BINDING_TEXEL_CHARTS, m.texelCharts.id());
    glBindTextureUnit(BINDING_FOOTPRINT, m.footprint.id());
    bindDirectSums(m);
    glBindFramebuffer(GL_FRAMEBUFFER, m.pageFbo.id());
    glViewport(0, 0, m.layout.resolution, m.layout.resolution);
    glUseProgram(program.id());
    glBindVertexArray(m.vao.id());
    const std::vector<uint32_t>& first = m.mesh.pageFirstTriangle;
    for (int page = 0; page < m.layout.pageCount; ++page) {
        glUniform1i(program.uniform("page"), page);
        const int64_t count = int64_t(first[page + 1]) - first[page];
        if (count) glDrawArrays(GL_TRIANGLES, drawFirstVertex(first[page]), GLsizei(count * 3));
    }
    // the curved texels, every page's (the draw above leaves them to this one)
    if (m.curvedTexelCount()) {
        glUseProgram(curvedProgram.id());
        m.bindCurvedTexels(curvedProgram.id());
        drawCurvedTexelRuns(curvedProgram.id(), m.layout.resolution, {0}, {int32_t(m.curvedTexelCount())});
        glBindVertexArray(m.vao.id());
    }
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}
}  // namespace

void Baker::Impl::bakeEmitters() {
    gl::DebugGroup group("explicit emitters");
    MemoryCategory category("direct light");
    // emitters and their sample counts, proportional to area x luminance (>= 1 each)
    struct Emitter {
        size_t triangle;
        glm::vec3 radiance;
        double power;
        int samples = 1;
    };
    std::vector<Emitter> emitters;
    double totalPower = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (!(mesh.triangles[t].flags & TRIANGLE_EMISSIVE)) continue;
        const Material& m = materials[mesh.triangles[t].material];
        glm::vec3 le = m.emission * (m.emissionTexture >= 0 ? textureMeans[size_t(m.emissionTexture)] : glm::vec3(1.0f));
        double power = projectedArea[t] * (0.2126 * le.r + 0.7152 * le.g + 0.0722 * le.b);
        emitters.push_back({t, le, power});
        totalPower += power;
    }
    if (emitters.empty()) return;
    bindAlphaMasks();
    for (auto& e : emitters)
        e.samples = std::max(1, int(std::lround(emitterSamples() * (totalPower > 0 ? e.power / totalPower : 0.0))));

    DistanceCube cube(shadowCubeSize(*this), triangleBuffer.id(), int64_t(mesh.triangles.size()));
    const float nearPlane = 1e-4f * sphereRadius, farPlane = 4.0f * sphereRadius;
    // one triangle's sums at a time (direct/emitter.frag), for this pass
    // only: 16 bytes a texel while the bundle pass's buffers are still small,
    // within the budget's share for them
    const int res = layout.resolution;
    gl::Texture sums = gl::Texture::create2DArray("emitter sums", GL_RGBA32F, res, res, layout.pageCount);
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    glClearTexImage(sums.id(), 0, GL_RGBA, GL_FLOAT, zero);
    glBindImageTexture(BINDING_EMITTER_SUMS, sums.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
    const DirectHalves halves(*this);  // each triangle's samples of odd index apart
    DirectHalves::setSampling(*this, {&emitterProgram, &emitterCurvedProgram});

    for (const Emitter& e : emitters) {
        const BakeVertex* v = &mesh.vertices[e.triangle * 3];
        glm::vec3 a(v[0].position), b(v[1].position), c(v[2].position);
        glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
        bool doubleSided = mesh.triangles[e.triangle].flags & TRIANGLE_DOUBLE_SIDED;
        // Sample i takes point i of every texel's footprint and a point of the
        // triangle: the first e.samples points of the R2 sequence (Roberts
        // 2018), stratified over the triangle, in a seeded random order.
        // Taken in sequence order, point i of the footprint and point i of
        // the triangle lie on one lattice (both R2), so their offsets are
        // tied, and a penumbra that crosses the footprint is read at one
        // pairing only: the Cornell box's direct light (every albedo 0) held
        // at 1.1 % against the reference from 512 samples on. The sequence is
        // shifted by a seeded random offset (a Cranley-Patterson rotation):
        // fixed at 0.5 until 2026-12-05, every seed drew the same points of
        // the triangle, and two seeds' bakes differed by less than either's
        // error (the noise estimate's tests measure the noise so).
        std::vector<std::pair<uint64_t, int>> order(size_t(e.samples));
        for (int i = 0; i < e.samples; ++i) order[size_t(i)] = {hash(options.seed, e.triangle, uint64_t(i)), i};
        std::sort(order.begin(), order.end());
        const double shiftU = unitFromHash(hash(options.seed, e.triangle, 0x5368696674ull)),
                     shiftV = unitFromHash(hash(options.seed, e.triangle, 0x5368696675ull));
        for (int i = 0; i < e.samples; ++i) {
            const int k = order[size_t(i)].second + 1;
            double su = std::fmod(shiftU + 0.7548776662466927 * k, 1.0);
            double sv = std::fmod(shiftV + 0.5698402909980532 * k, 1.0);
            if (su + sv > 1.0) {
                su = 1.0 - su;
                sv = 1.0 - sv;
            }
            glm::vec3 point = a + float(su) * (b - a) + float(sv) * (c - a) + n * (1e-4f * pixelSize);
            // distance cube map
            const glm::mat3 orientation(randomRotation(hash(options.seed, e.triangle, uint64_t(i) + (1ull << 32))));
            cube.render(vao.id(), distanceProgram, point, orientation, nearPlane, farPlane, uint32_t(e.triangle),
                        doubleSided ? nullptr : &n);
            // accumulate this sample's share into the direct map, page by page
            for (const gl::Program* p : {&emitterProgram, &emitterCurvedProgram}) {
                glUseProgram(p->id());
                glUniform3fv(p->uniform("emitterA"), 1, &a.x);
                glUniform3fv(p->uniform("emitterB"), 1, &b.x);
                glUniform3fv(p->uniform("emitterC"), 1, &c.x);
                glUniform3fv(p->uniform("emitterNormal"), 1, &n.x);
                glUniform1i(p->uniform("emitterDoubleSided"), doubleSided);
                glUniform3fv(p->uniform("samplePoint"), 1, &point.x);
                glUniform1ui(p->uniform("footprintSample"), uint32_t(stats.emitterSampleCount));
                glUniform1i(p->uniform("oddSample"), k % 2);  // k: the point's index in the R2 sequence
            }
            addVisibleLight(*this, emitterProgram, emitterCurvedProgram, cube);
            ++stats.emitterSampleCount;
        }
        const glm::vec3 radiance = e.radiance / radianceUnit;
        glUseProgram(emitterNoiseProgram.id());
        glUniform3fv(emitterNoiseProgram.uniform("emitterRadiance"), 1, &radiance.x);
        glUniform1f(emitterNoiseProgram.uniform("evenCount"), float(e.samples / 2));  // indices 1..n
        glUniform1f(emitterNoiseProgram.uniform("oddCount"), float((e.samples + 1) / 2));
        halves.addLight(*this, emitterNoiseProgram);
        glUseProgram(emitterFoldProgram.id());
        glUniform3fv(emitterFoldProgram.uniform("emitterRadiance"), 1, &radiance.x);
        glUniform1f(emitterFoldProgram.uniform("sampleCount"), float(e.samples));
        bindDirectSums(*this);
        dispatchPages(emitterFoldProgram.id());
    }
    halves.finish(*this);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

// Point and spot lights: each a distance cube map at its position (as an
// emitter sample's) and the closed-form irradiance (scene/punctual_light.h)
// times that visibility, per texel, into the direct light's float sums.
// A spot light draws the whole cube too (the cone is tested per texel).
void Baker::Impl::bakePunctualLights() {
    gl::DebugGroup group("point and spot lights");
    MemoryCategory category("direct light");
    DistanceCube cube(shadowCubeSize(*this), triangleBuffer.id(), int64_t(mesh.triangles.size()));
    bindAlphaMasks();
    for (size_t li = 0; li < punctualLights.size(); ++li) {
        const PunctualLight& light = punctualLights[li];
        const glm::vec3 position(light.position - mesh.origin);  // local space, as the mesh
        // every surface lies within |position - centre| + radius of the light
        const float reach = glm::length(position - sphereCenter) + sphereRadius;
        const float nearPlane = 1e-4f * sphereRadius, farPlane = 1.01f * reach + sphereRadius;
        // turned at random, as the emitter samples' cubes: with the faces along
        // the axes, a floor texel seen exactly along a face's diagonal (the light
        // at a whole number of texels from it) read another face's distance
        const glm::mat3 orientation(randomRotation(hash(options.seed, li, 0x70756e6374ull)));
        cube.render(vao.id(), distanceProgram, position, orientation, nearPlane, farPlane);

        const glm::vec3 intensity = light.intensity / radianceUnit;
        const float cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
        for (const gl::Program* p : {&punctualProgram, &punctualCurvedProgram}) {
            glUseProgram(p->id());
            glUniform3fv(p->uniform("lightPosition"), 1, &position.x);
            glUniform3fv(p->uniform("lightIntensity"), 1, &intensity.x);
            glUniform1f(p->uniform("lightRange"), light.range);
            glUniform1i(p->uniform("lightIsSpot"), light.type == PunctualLight::Type::Spot);
            glUniform3fv(p->uniform("spotDirection"), 1, &light.direction.x);
            glUniform1f(p->uniform("spotCosOuter"), cosOuter);
            glUniform1f(p->uniform("spotScale"), 1.0f / std::max(0.001f, cosInner - cosOuter));
        }
        addVisibleLight(*this, punctualProgram, punctualCurvedProgram, cube);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void Baker::Impl::foldDirect(bool perSample) {
    gl::DebugGroup group("fold direct light");
    glUseProgram(directFoldProgram.id());
    glUniform1i(directFoldProgram.uniform("perSample"), perSample);
    glUniform1ui(directFoldProgram.uniform("randomSeed"), pcgHash(uint32_t(options.seed) ^ (perSample ? 0x51u : 0xE4u)));
    bindDirectSums(*this);
    glBindImageTexture(BINDING_DIRECT, direct.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA16F);
    dispatchPages(directFoldProgram.id());
}

}  // namespace bb
