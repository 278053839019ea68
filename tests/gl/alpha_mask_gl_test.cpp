// lib/alpha_mask.glsl against its C++ twin (scene/alpha_mask.h): the same
// alpha (to float rounding) and the same cut decision away from the cutoff.
#include <gtest/gtest.h>

#include <cmath>

#include "gl/gl.h"
#include "gl/objects.h"
#include "gl/shader.h"
#include "scene/alpha_mask.h"
#include "support/gl_fixture.h"

namespace bb {
namespace {

TEST(AlphaMaskGl, GpuMatchesCpp) {
    BB_REQUIRE_GL();
    // a 5 x 3 ramp of alphas (odd sizes: the repeat and row order show), a 2 x 2, none
    std::vector<Texture> textures(2);
    textures[0].width = 5;
    textures[0].height = 3;
    for (int i = 0; i < 15; ++i) textures[0].texels.push_back(glm::vec4(1.0f, 1.0f, 1.0f, float((i * 7) % 15) / 14.0f));
    textures[1].width = textures[1].height = 2;
    textures[1].texels = {glm::vec4(0.0f), glm::vec4(1.0f), glm::vec4(0.2f), glm::vec4(0.9f)};
    std::vector<Material> materials(4);
    materials[1].alphaMask = true;
    materials[1].albedoTexture = 0;
    materials[1].alphaCutoff = 0.45f;
    materials[2].alphaMask = true;
    materials[2].albedoTexture = 1;
    materials[2].alpha = 0.7f;
    materials[3].alphaMask = true;
    materials[3].alpha = 0.3f;
    const AlphaMaskTables tables = packAlphaMasks(materials, textures);
    std::vector<glm::vec4> uvs;
    for (int i = 0; i < 4000; ++i) {
        const float u = -2.0f + 5.0f * std::fmod(0.7548776662f * float(i + 1), 1.0f);
        const float v = -2.0f + 5.0f * std::fmod(0.5698402910f * float(i + 1), 1.0f);
        uvs.push_back(glm::vec4(u, v, float(i % 4), 0.0f));
    }
    auto program = gl::buildProgram({"test/alpha_mask.comp"});
    ASSERT_TRUE(program) << program.error();
    const int n = int(uvs.size());
    gl::Buffer bm = gl::Buffer::create("alpha test materials", int64_t(tables.materials.size() * 16), tables.materials.data(), 0);
    gl::Buffer bt = gl::Buffer::create("alpha test texels", int64_t(tables.texels.size() * 4), tables.texels.data(), 0);
    gl::Buffer bu = gl::Buffer::create("alpha test uvs", int64_t(n) * 16, uvs.data(), 0);
    gl::Buffer bo = gl::Buffer::create("alpha test out", int64_t(n) * 8, nullptr, 0);
    glUseProgram(program->id());
    glUniform1i(program->uniform("count"), n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_MATERIAL_ALPHA, bm.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_ALPHA_TEXELS, bt.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bu.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bo.id());
    glDispatchCompute(GLuint(n + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<glm::vec2> gpu(static_cast<size_t>(n));
    glGetNamedBufferSubData(bo.id(), 0, GLsizeiptr(n) * 8, gpu.data());
    int mismatches = 0, cuts = 0;
    for (int i = 0; i < n; ++i) {
        const Material& m = materials[size_t(i % 4)];
        const glm::vec2 uv(uvs[size_t(i)]);
        const float alpha = m.alphaMask ? materialAlpha(m, textures, uv) : 1.0f;
        const bool cut = alphaCut(m, textures, uv);
        cuts += cut;
        const bool nearCutoff = std::fabs(alpha - m.alphaCutoff) < 1e-4f;
        if ((std::fabs(gpu[size_t(i)].x - alpha) > 1e-5f || (!nearCutoff && (gpu[size_t(i)].y != 0.0f) != cut)) &&
            ++mismatches <= 10)
            ADD_FAILURE() << "material " << i % 4 << " uv (" << uv.x << ", " << uv.y << "): GPU alpha " << gpu[size_t(i)].x
                          << " cut " << gpu[size_t(i)].y << ", C++ " << alpha << " cut " << cut;
    }
    EXPECT_EQ(mismatches, 0) << "of " << n;
    EXPECT_GT(cuts, n / 8);  // the inputs do cut
}

}  // namespace
}  // namespace bb
