// The GPU's radiance encoders (glsl/lib/rounding.glsl). RGB9E5 (the outgoing
// radiance map), written through an r32ui view and read back as GL decodes
// GL_RGB9_E5: its bits are GL's, nearest rounding stays within half a step,
// special values are safe, stochastic rounding is unbiased. RGBE (the nodes):
// the same bits as its C++ twin (engine/bake/rounding.cpp) on every input,
// special values included.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "gl/objects.h"
#include "bake/rounding.h"
#include "gl/shader.h"
#include "support/gl_fixture.h"

namespace bb {
namespace {

// Encodes values[i] with u[i] on the GPU; returns GL's decoding and the bits.
void encode(const std::vector<glm::vec4>& values, std::vector<glm::vec3>& decoded, std::vector<uint32_t>& bits) {
    auto program = gl::buildProgram({"test/rgb9e5.comp"});
    ASSERT_TRUE(program) << program.error();
    const int n = int(values.size()), width = 256, height = (n + width - 1) / width;
    gl::Texture tex = gl::Texture::create2D("rgb9e5 test", GL_RGB9_E5, width, height);
    gl::Texture view = gl::Texture::createView("rgb9e5 test bits", tex, GL_R32UI);
    gl::Buffer in = gl::Buffer::create("rgb9e5 test values", int64_t(n) * 16, values.data(), 0);
    glUseProgram(program->id());
    glUniform1i(program->uniform("count"), n);
    glUniform1i(program->uniform("width"), width);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
    glBindImageTexture(0, view.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
    glDispatchCompute(GLuint(n + 63) / 64, 1, 1);
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    std::vector<glm::vec3> all(size_t(width) * height);
    std::vector<uint32_t> allBits(all.size());
    gl::readTexture(tex.id(), 0, 0, 0, width, height, 1, GL_RGB, GL_FLOAT, 12, all.data());
    gl::readTexture(view.id(), 0, 0, 0, width, height, 1, GL_RED_INTEGER, GL_UNSIGNED_INT, 4, allBits.data());
    decoded.assign(all.begin(), all.begin() + n);
    bits.assign(allBits.begin(), allBits.begin() + n);
    EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

float step(uint32_t bits) { return std::ldexp(1.0f, int(bits >> 27) - 24); }

TEST(Rgb9e5, NearestRoundingWithinHalfAStepAndSpecialValuesSafe) {
    BB_REQUIRE_GL();
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<glm::vec3> v = {{0, 0, 0},       {1e-9f, 0, 0},     {1e-5f, 2e-5f, 3e-5f}, {0.1f, 0.2f, 0.3f},
                                {1, 1, 1},       {0.9f, 0.01f, 0.5f}, {1000, 3, 0.25f},    {65000, 1, 0},
                                {511.9f, 0, 0},  {1e6f, 1, 1},      {inf, 1, 1},          {nan, 1, 2},
                                {-1, 0.5f, 0.5f}};
    for (int i = 0; i < 200; ++i) v.push_back(glm::vec3(std::ldexp(1.37f, i / 8 - 12), 0.73f * float(i % 7), 1e-3f * float(i)));
    std::vector<glm::vec4> in;
    for (const glm::vec3& c : v) in.push_back(glm::vec4(c, 0.5f));
    std::vector<glm::vec3> out;
    std::vector<uint32_t> bits;
    encode(in, out, bits);
    ASSERT_EQ(out.size(), v.size());
    for (size_t i = 0; i < v.size(); ++i) {
        // GL's decoding of the bits is m * 2^(e - 24): the encoder writes GL's layout
        const glm::vec3 m(float(bits[i] & 511u), float((bits[i] >> 9) & 511u), float((bits[i] >> 18) & 511u));
        ASSERT_EQ(out[i], m * step(bits[i])) << "texel " << i;
        for (int c = 0; c < 3; ++c) {
            float x = v[i][c];
            float expected = std::isnan(x) ? 0.0f : std::clamp(x, 0.0f, 65408.0f);
            EXPECT_LE(std::abs(out[i][c] - expected), 0.5f * step(bits[i]) * 1.0001f)
                << "value " << i << " channel " << c << " input " << x << " got " << out[i][c];
        }
    }
    // the largest channel keeps 9 bits: relative error at most 2^-9 (one step over 256)
    for (size_t i = 0; i < v.size(); ++i) {
        float mx = std::max({out[i].r, out[i].g, out[i].b});
        if (mx > 1e-4f && mx < 65000.0f) EXPECT_GE(mx / step(bits[i]), 255.5f) << "value " << i;
    }
}

TEST(Rgb9e5, StochasticRoundingIsUnbiased) {
    BB_REQUIRE_GL();
    // one value, 4096 stratified u: the mean decodes to the value (within 1/4096 of a step)
    const glm::vec3 value(0.3f, 0.0123f, 7.7f);
    const int n = 4096;
    std::vector<glm::vec4> in;
    for (int i = 0; i < n; ++i) in.push_back(glm::vec4(value, (float(i) + 0.5f) / float(n)));
    std::vector<glm::vec3> out;
    std::vector<uint32_t> bits;
    encode(in, out, bits);
    glm::dvec3 sum(0.0);
    for (const glm::vec3& o : out) sum += glm::dvec3(o);
    const glm::dvec3 mean = sum / double(n);
    const double s = step(bits[0]);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], value[c], 2.0 * s / n + 1e-7 * value[c]) << "channel " << c;
    // and it does round both ways (0.0123 sits between two steps far apart relative to it)
    EXPECT_NE(out.front().g, out.back().g);
}

TEST(Rgbe, GpuEncoderGivesTheCppTwinsBitsOnEveryInput) {
    BB_REQUIRE_GL();
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const float big = std::numeric_limits<float>::max();
    std::vector<glm::vec4> values, us;
    const float specials[] = {0.0f, -0.0f, -1.0f, nan, inf, -inf, big, 1e38f, 3e38f, 2e-38f, 5e-39f,
                              1e-30f, 1.0f, 0.5f, 255.5f, 255.99f, 256.0f, 65504.0f, 1e6f, 0.1f, 3.0f};
    for (float a : specials)
        for (float b : {0.0f, 1.0f, a, nan, inf})
            for (float u : {0.0f, 0.5f, 0.999f}) {
                values.push_back(glm::vec4(a, b, 0.25f * a, 0.0f));
                us.push_back(glm::vec4(u, 1.0f - u, 0.5f, 0.0f));
            }
    // ordinary values, mantissas near the rounding carry, random u
    for (int i = 0; i < 2000; ++i) {
        const float x = std::ldexp(1.0f + float(i % 97) / 97.0f, i % 60 - 30);
        values.push_back(glm::vec4(x, x * 0.999f, x * float(i % 13) / 13.0f, 0.0f));
        us.push_back(glm::vec4(float(i % 101) / 101.0f, float(i % 89) / 89.0f, float(i % 83) / 83.0f, 0.0f));
    }
    auto program = gl::buildProgram({"test/rgbe.comp"});
    ASSERT_TRUE(program) << program.error();
    const int n = int(values.size());
    gl::Buffer bv = gl::Buffer::create("rgbe test values", int64_t(n) * 16, values.data(), 0);
    gl::Buffer bu = gl::Buffer::create("rgbe test u", int64_t(n) * 16, us.data(), 0);
    gl::Buffer bo = gl::Buffer::create("rgbe test out", int64_t(n) * 4, nullptr, 0);
    glUseProgram(program->id());
    glUniform1i(program->uniform("count"), n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bv.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bu.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bo.id());
    glDispatchCompute(GLuint(n + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<uint32_t> gpu(size_t(n), 0);
    glGetNamedBufferSubData(bo.id(), 0, GLsizeiptr(n) * 4, gpu.data());
    int mismatches = 0;
    for (int i = 0; i < n; ++i) {
        const uint32_t cpu = encodeRgbe(glm::vec3(values[size_t(i)]), Rounding::Stochastic, glm::vec3(us[size_t(i)]));
        if (gpu[size_t(i)] != cpu && ++mismatches <= 10)
            ADD_FAILURE() << "input (" << values[size_t(i)].x << ", " << values[size_t(i)].y << ", " << values[size_t(i)].z
                          << ") u (" << us[size_t(i)].x << ", " << us[size_t(i)].y << ", " << us[size_t(i)].z
                          << "): GPU " << std::hex << gpu[size_t(i)] << ", C++ " << cpu;
    }
    EXPECT_EQ(mismatches, 0) << "of " << n << " inputs";
}

TEST(Accumulator, GpuEncoderGivesTheCppTwinsBitsOnEveryInput) {
    BB_REQUIRE_GL();
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<glm::vec4> values, us;
    const float specials[] = {0.0f, -0.0f, -1.0f, nan, inf, -inf, 1e-30f, 3e-10f, 6.103515625e-5f, 1.0f,
                              1.0f - 0x1p-20f, 0.5f, 65535.0f, 65535.9f, 70000.0f, 64512.0f, 65504.0f, 1e6f, 0.1f};
    for (float a : specials)
        for (float b : {0.0f, 1.0f, a, nan, inf})
            for (float u : {0.0f, 0.5f, 0.999f}) {
                values.push_back(glm::vec4(a, b, 0.25f * a, b));
                us.push_back(glm::vec4(u, 1.0f - u, 0.5f, u));
            }
    // ordinary values, mantissas near the rounding carry, random u
    for (int i = 0; i < 2000; ++i) {
        const float x = std::ldexp(1.0f + float(i % 97) / 97.0f, i % 50 - 30);
        values.push_back(glm::vec4(x, x * 0.999f, x * float(i % 13) / 13.0f, std::ldexp(1.0f - float(i % 7) / 1000.0f, i % 40 - 20)));
        us.push_back(glm::vec4(float(i % 101) / 101.0f, float(i % 89) / 89.0f, float(i % 83) / 83.0f, float(i % 79) / 79.0f));
    }
    auto program = gl::buildProgram({"test/accumulator.comp"});
    ASSERT_TRUE(program) << program.error();
    const int n = int(values.size());
    gl::Buffer bv = gl::Buffer::create("accumulator test values", int64_t(n) * 16, values.data(), 0);
    gl::Buffer bu = gl::Buffer::create("accumulator test u", int64_t(n) * 16, us.data(), 0);
    gl::Buffer bo = gl::Buffer::create("accumulator test out", int64_t(n) * 8, nullptr, 0);
    gl::Buffer bd = gl::Buffer::create("accumulator test decoded", int64_t(n) * 16, nullptr, 0);
    glUseProgram(program->id());
    glUniform1i(program->uniform("count"), n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bv.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bu.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bo.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, bd.id());
    glDispatchCompute(GLuint(n + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<glm::uvec2> gpu(static_cast<size_t>(n));
    std::vector<glm::vec4> decoded(static_cast<size_t>(n));
    glGetNamedBufferSubData(bo.id(), 0, GLsizeiptr(n) * 8, gpu.data());
    glGetNamedBufferSubData(bd.id(), 0, GLsizeiptr(n) * 16, decoded.data());
    int mismatches = 0;
    for (int i = 0; i < n; ++i) {
        const glm::uvec2 cpu = encodeAccumulator(values[size_t(i)], Rounding::Stochastic, us[size_t(i)]);
        const bool same = gpu[size_t(i)] == cpu && decoded[size_t(i)] == decodeAccumulator(cpu);
        if (!same && ++mismatches <= 10)
            ADD_FAILURE() << "input (" << values[size_t(i)].x << ", " << values[size_t(i)].y << ", " << values[size_t(i)].z
                          << ", " << values[size_t(i)].w << "): GPU " << std::hex << gpu[size_t(i)].x << " "
                          << gpu[size_t(i)].y << ", C++ " << cpu.x << " " << cpu.y;
    }
    EXPECT_EQ(mismatches, 0) << "of " << n << " inputs";
}

}  // namespace
}  // namespace bb
