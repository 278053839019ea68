// Importance analysis on the GPU (supplement §1): position buffer, I_max by
// atomic max, Eq. (4) in a compute pass.
//
// Based on: Tokuyoshi, Sekine, da Silva, Kanai, "Adaptive Ray-bundle Tracing
// with Memory Usage Prediction", CGF 32(7) 2013, supplement §1.
#include "layout/bake_mesh_gl.h"
#include "importance/importance_gl.h"
#include "core/timer.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstddef>
#include <string>

#include "core/check.h"
#include "gl/gl.h"
#include "gl/shader.h"
#include "glsl/shared/importance_layout.h"

namespace bb {
namespace {


// The compute pass reads BakeVertex as the std430 struct of glsl/shared/mesh_layout.h.
static_assert(sizeof(BakeVertex) == 48);
static_assert(offsetof(BakeVertex, position) == 0);
static_assert(offsetof(BakeVertex, lightmapUv) == 40);

}  // namespace

Expected<std::unique_ptr<ImportanceAnalyzer>> ImportanceAnalyzer::create() {
    std::unique_ptr<ImportanceAnalyzer> a(new ImportanceAnalyzer());
    struct Spec {
        gl::Program* target;
        std::vector<std::string> files;
    } specs[] = {
        {&a->positionProgram_, {"importance/lightmap.vert", "importance/position.frag"}},
        {&a->maxDensityProgram_, {"importance/lightmap.vert", "importance/imax.frag"}},
        {&a->clampProgram_, {"importance/clamp.comp"}},
    };
    for (auto& s : specs) {
        auto p = gl::buildProgram(s.files);
        if (!p) return p.status();
        *s.target = std::move(p.value());
    }
    GLint bits = 0;
    glGetIntegerv(GL_SUBPIXEL_BITS, &bits);
    if (bits > 0) a->rules_.subpixelBits = bits;
    return a;
}

Expected<ImportanceGlResult> ImportanceAnalyzer::analyze(const BakeMesh& mesh, int resolution,
                                                        const ImportanceCapture& capture) {
    CHECK(!mesh.pageFirstTriangle.empty());
    CHECK_EQ(mesh.vertices.size(), mesh.triangles.size() * 3);
    const int pageCount = int(mesh.pageFirstTriangle.size()) - 1;
    const size_t n = mesh.triangles.size();
    ImportanceGlResult result;

    // limits (read, not assumed)
    GLint maxTex = 0, vp[2] = {0, 0}, maxFbW = 0, maxFbH = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxTex);
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, vp);
    glGetIntegerv(GL_MAX_FRAMEBUFFER_WIDTH, &maxFbW);
    glGetIntegerv(GL_MAX_FRAMEBUFFER_HEIGHT, &maxFbH);
    const int maxSide = std::min({maxTex, vp[0], vp[1], maxFbW, maxFbH});
    if (resolution < 1 || resolution > maxSide)
        return Status::error("light map resolution " + std::to_string(resolution) +
                             " exceeds this GL's texture/viewport/framebuffer limit " + std::to_string(maxSide));
    if (Status drawable = checkMeshDrawable(int64_t(n)); !drawable) return drawable;
    if (n == 0) return result;

    gl::DebugGroup group("importance analysis");
    auto tu = Clock::now();
    // upload: the bake vertices (vertex attributes for passes 1-2, an SSBO for pass 3)
    gl::Buffer vertices = gl::Buffer::create("importance vertices", int64_t(mesh.vertices.size() * sizeof(BakeVertex)),
                                             mesh.vertices.data(), 0);
    gl::VertexArray vao = createBakeVertexArray("importance vertex array", vertices);
    const int64_t perTriangleBytes = int64_t(n) * 4;
    gl::Buffer maxDensity = gl::Buffer::create("importance I_max(t) bits", perTriangleBytes, nullptr, 0);
    const uint32_t zero = 0;
    glClearNamedBufferData(maxDensity.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);  // I_max = 0.0f
    importance_ = gl::Buffer::create("importance I(t)", perTriangleBytes, nullptr, 0);
    gl::Buffer ratio = gl::Buffer::create("importance A_l/A_o", perTriangleBytes, nullptr, 0);
    // the SSBOs each pass reads, bound per chunk of GL_MAX_SHADER_STORAGE_BLOCK_SIZE
    const MeshChunks positionChunks = MeshChunks::create(int64_t(n), {});  // reads none
    const MeshChunks maxDensityChunks =
        MeshChunks::create(int64_t(n), {{IMPORTANCE_BINDING_MAX_DENSITY, maxDensity.id(), 4}});

    gl::Texture positions = gl::Texture::create2D("importance position buffer", GL_RGBA32F, resolution, resolution);
    gl::Texture triangles = gl::Texture::create2D("importance triangle buffer", GL_R32UI, resolution, resolution);
    gl::Texture density;
    if (capture.texelDensity) density = gl::Texture::create2D("importance texel density", GL_R32F, resolution, resolution);
    gl::Framebuffer positionFbo = gl::Framebuffer::create("importance position framebuffer");
    glNamedFramebufferTexture(positionFbo.id(), GL_COLOR_ATTACHMENT0 + IMPORTANCE_OUT_POSITION, positions.id(), 0);
    glNamedFramebufferTexture(positionFbo.id(), GL_COLOR_ATTACHMENT0 + IMPORTANCE_OUT_TRIANGLE, triangles.id(), 0);
    const GLenum drawBuffers[] = {GL_COLOR_ATTACHMENT0 + IMPORTANCE_OUT_POSITION,
                                  GL_COLOR_ATTACHMENT0 + IMPORTANCE_OUT_TRIANGLE};
    glNamedFramebufferDrawBuffers(positionFbo.id(), 2, drawBuffers);
    CHECK_EQ(glCheckNamedFramebufferStatus(positionFbo.id(), GL_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
    // pass 2 reads the position buffer, so it draws into a framebuffer without attachments
    gl::Framebuffer emptyFbo = gl::Framebuffer::create("importance I_max framebuffer (no attachments)");
    glNamedFramebufferParameteri(emptyFbo.id(), GL_FRAMEBUFFER_DEFAULT_WIDTH, resolution);
    glNamedFramebufferParameteri(emptyFbo.id(), GL_FRAMEBUFFER_DEFAULT_HEIGHT, resolution);
    CHECK_EQ(glCheckNamedFramebufferStatus(emptyFbo.id(), GL_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
    glFinish();
    result.seconds.upload = secondsSince(tu);

    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);  // both windings: UV charts may be mirrored
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    glViewport(0, 0, resolution, resolution);
    glBindVertexArray(vao.id());
    const size_t texels = size_t(resolution) * resolution;
    for (int page = 0; page < pageCount; ++page) {
        const uint32_t first = mesh.pageFirstTriangle[size_t(page)], last = mesh.pageFirstTriangle[size_t(page) + 1];
        if (first == last && !capture.texelTriangles && !capture.positionBuffers && !capture.texelDensity) continue;
        auto t1 = Clock::now();
        {
            gl::DebugGroup pass("importance position pass");
            glBindFramebuffer(GL_FRAMEBUFFER, positionFbo.id());
            const float zeroF[4] = {0, 0, 0, 0};
            const GLuint zeroU[4] = {0, 0, 0, 0};
            glClearBufferfv(GL_COLOR, IMPORTANCE_OUT_POSITION, zeroF);
            glClearBufferuiv(GL_COLOR, IMPORTANCE_OUT_TRIANGLE, zeroU);
            glUseProgram(positionProgram_.id());
            positionChunks.drawArrays(positionProgram_.id(), first, int64_t(last) - first);
            glFinish();
        }
        result.seconds.positionPass += secondsSince(t1);
        auto t2 = Clock::now();
        {
            gl::DebugGroup pass("importance I_max pass");
            glBindFramebuffer(GL_FRAMEBUFFER, emptyFbo.id());
            glUseProgram(maxDensityProgram_.id());
            glUniform1i(maxDensityProgram_.uniform("resolution"), resolution);
            glUniform1i(maxDensityProgram_.uniform("writeDensity"), capture.texelDensity ? 1 : 0);
            glBindImageTexture(IMPORTANCE_IMAGE_POSITIONS, positions.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
            glBindImageTexture(IMPORTANCE_IMAGE_TRIANGLES, triangles.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
            if (capture.texelDensity) {
                const float zeroF = 0.0f;
                glClearTexImage(density.id(), 0, GL_RED, GL_FLOAT, &zeroF);
                glBindImageTexture(IMPORTANCE_IMAGE_DENSITY, density.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
            }
            maxDensityChunks.drawArrays(maxDensityProgram_.id(), first, int64_t(last) - first);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT |
                            GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
            glFinish();
        }
        result.seconds.maxDensityPass += secondsSince(t2);
        auto tr = Clock::now();
        if (capture.texelTriangles || capture.positionBuffers) {
            std::vector<uint32_t> ids(texels);
            gl::readTexture(triangles.id(), 0, 0, 0, resolution, resolution, 1, GL_RED_INTEGER, GL_UNSIGNED_INT, 4, ids.data());
            if (capture.positionBuffers) {
                std::vector<glm::vec4> p(texels);
                gl::readTexture(positions.id(), 0, 0, 0, resolution, resolution, 1, GL_RGBA, GL_FLOAT, 16, p.data());
                PositionBuffer buffer;
                buffer.resolution = resolution;
                buffer.texels.resize(texels);
                for (size_t i = 0; i < texels; ++i) buffer.texels[i] = PositionTexel{glm::vec3(p[i]), ids[i]};
                result.positionBuffers.push_back(std::move(buffer));
            }
            if (capture.texelTriangles) result.texelTriangles.push_back(std::move(ids));
        }
        if (capture.texelDensity) {
            std::vector<float> d(texels);
            gl::readTexture(density.id(), 0, 0, 0, resolution, resolution, 1, GL_RED, GL_FLOAT, 4, d.data());
            result.texelDensity.push_back(std::move(d));
        }
        result.seconds.readback += secondsSince(tr);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    // pass 3: Eq. (4), in chunks so that every bound range fits the SSBO size
    // limit and the dispatch limit (clamp.comp indexes from its chunk's first triangle)
    auto t3 = Clock::now();
    {
        gl::DebugGroup pass("importance clamp pass");
        GLint maxGroups = 0;
        glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &maxGroups);
        const MeshChunks chunks =
            MeshChunks::create(int64_t(n),
                               {{IMPORTANCE_BINDING_VERTICES, vertices.id(), 3 * int64_t(sizeof(BakeVertex))},
                                {IMPORTANCE_BINDING_MAX_DENSITY, maxDensity.id(), 4},
                                {IMPORTANCE_BINDING_IMPORTANCE, importance_.id(), 4},
                                {IMPORTANCE_BINDING_AREA_RATIO, ratio.id(), 4}},
                               int64_t(maxGroups) * IMPORTANCE_GROUP_SIZE);
        glUseProgram(clampProgram_.id());
        glUniform1f(clampProgram_.uniform("resolution"), float(resolution));
        for (int c = 0; c < chunks.chunkCount(); ++c) {
            const int64_t count = chunks.chunkEnd(c) - chunks.chunkFirst(c);
            chunks.bind(c, clampProgram_.id());
            glUniform1ui(clampProgram_.uniform("triangleCount"), GLuint(count));
            glDispatchCompute(GLuint((count + IMPORTANCE_GROUP_SIZE - 1) / IMPORTANCE_GROUP_SIZE), 1, 1);
        }
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        glFinish();
    }
    result.seconds.computePass = secondsSince(t3);

    auto tr = Clock::now();
    Importance& out = result.importance;
    out.importance.resize(n);
    out.areaRatio.resize(n);
    out.maxDensity.resize(n);
    glGetNamedBufferSubData(importance_.id(), 0, perTriangleBytes, out.importance.data());
    glGetNamedBufferSubData(ratio.id(), 0, perTriangleBytes, out.areaRatio.data());
    glGetNamedBufferSubData(maxDensity.id(), 0, perTriangleBytes, out.maxDensity.data());  // float bits
    result.seconds.readback += secondsSince(tr);
    glBindVertexArray(0);
    glUseProgram(0);
    return result;
}

}  // namespace bb
