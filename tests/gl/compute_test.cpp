// Compute shaders run and write SSBOs, under EGL and under OSMesa, each with
// its own context in a child process-free way: one backend per test binary
// run is enforced by creating the context inside the test.
#include <gtest/gtest.h>

#include <vector>

#include "gl/objects.h"
#include "gl/shader.h"
#include "headless/platform.h"

namespace bb {
namespace {

void runSaxpy(Backend backend) {
    auto ctx = createHeadlessContext(backend);
    ASSERT_TRUE(ctx) << "no " << backendName(backend) << " context: " << ctx.error();
    EXPECT_GE(ctx.value()->caps().major * 10 + ctx.value()->caps().minor, 43);
    EXPECT_GT(ctx.value()->caps().maxShaderStorageBlockSize, 0);

    auto program = gl::buildProgram({"test/saxpy.comp"});
    ASSERT_TRUE(program) << program.error();
    const uint32_t n = 1000;
    std::vector<float> x(n);
    for (uint32_t i = 0; i < n; ++i) x[i] = 0.5f * float(i) - 7.0f;
    gl::Buffer bx = gl::Buffer::create("test x", n * 4, x.data(), 0);
    gl::Buffer by = gl::Buffer::create("test y", n * 4, nullptr, GL_MAP_READ_BIT);
    glUseProgram(program->id());
    glUniform1f(program->uniform("a"), 3.0f);
    glUniform1ui(program->uniform("count"), n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bx.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, by.id());
    glDispatchCompute((n + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> y(n);
    glGetNamedBufferSubData(by.id(), 0, n * 4, y.data());
    for (uint32_t i = 0; i < n; ++i) ASSERT_FLOAT_EQ(y[i], 3.0f * x[i] + float(i)) << "at " << i;
    EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

TEST(GlCompute, SaxpyUnderEgl) { runSaxpy(Backend::Egl); }
#ifdef BUNDLEBAKE_WITH_OSMESA
TEST(GlCompute, SaxpyUnderOsMesa) { runSaxpy(Backend::OsMesa); }
#endif

TEST(GlShader, CompileErrorNamesFileAndLine) {
    auto ctx = createHeadlessContext(Backend::Egl);
    ASSERT_TRUE(ctx) << "no EGL context: " << ctx.error();
    auto program = gl::buildProgram({"test/saxpy.comp"}, "#define x syntax error here\n");
    ASSERT_FALSE(program);
    EXPECT_NE(program.error().find("test/saxpy.comp"), std::string::npos) << program.error();
    EXPECT_EQ(program.error().find('\n'), std::string::npos);
}

}  // namespace
}  // namespace bb
