#include "layout/bake_mesh_gl.h"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <numeric>

#include "core/check.h"
#include "layout/bake_mesh.h"

namespace bb {
namespace {

std::atomic<int64_t> chunkBytesForTesting{0};

}  // namespace

gl::VertexArray createBakeVertexArray(const std::string& label, const gl::Buffer& vertices) {
    gl::VertexArray vao = gl::VertexArray::create(label);
    glVertexArrayVertexBuffer(vao.id(), 0, vertices.id(), 0, sizeof(BakeVertex));
    const GLint sizes[] = {4, 4, 2, 2};
    const GLuint offsets[] = {offsetof(BakeVertex, position), offsetof(BakeVertex, normal), offsetof(BakeVertex, uv0),
                              offsetof(BakeVertex, lightmapUv)};
    for (GLuint a = 0; a < 4; ++a) {
        glEnableVertexArrayAttrib(vao.id(), a);
        glVertexArrayAttribFormat(vao.id(), a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a]);
        glVertexArrayAttribBinding(vao.id(), a, 0);
    }
    return vao;
}

Status checkMeshDrawable(int64_t triangleCount) {
    if (triangleCount <= MAX_DRAWABLE_TRIANGLES) return Status::ok();
    return Status::error(std::to_string(triangleCount) + " triangles: GL draw calls address vertices (3 per triangle) "
                         "with a GLint first, so at most " + std::to_string(MAX_DRAWABLE_TRIANGLES) +
                         " triangles can be drawn");
}

GLint drawFirstVertex(int64_t triangle) {
    CHECK_GE(triangle, 0);
    CHECK_LE(triangle, MAX_DRAWABLE_TRIANGLES);
    return GLint(3 * triangle);
}

void setMeshChunkBytesForTesting(int64_t bytes) { chunkBytesForTesting = std::max<int64_t>(bytes, 0); }

MeshChunks MeshChunks::create(int64_t triangleCount, std::initializer_list<MeshStream> streams,
                              int64_t maxTrianglesPerChunk) {
    CHECK_GE(triangleCount, 0);
    MeshChunks m;
    m.streams_.assign(streams.begin(), streams.end());
    m.triangles_ = triangleCount;
    m.chunk_ = std::max<int64_t>(triangleCount, 1);
    if (m.streams_.empty()) return m;

    GLint64 glLimit = 0;
    GLint align = 1;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &glLimit);
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &align);
    CHECK_GT(glLimit, 0);
    align = std::max(align, 1);
    int64_t limit = glLimit;
    if (int64_t testing = chunkBytesForTesting; testing > 0) limit = std::min(limit, testing);
    // a chunk's first triangle times every stream's stride must be a multiple of the alignment
    int64_t granularity = 1, widest = 1;
    for (const MeshStream& s : m.streams_) {
        CHECK_GT(s.bytesPerTriangle, 0);
        granularity = std::lcm(granularity, int64_t(align) / std::gcd(int64_t(align), s.bytesPerTriangle));
        widest = std::max(widest, s.bytesPerTriangle);
    }
    CHECK_LE(granularity * widest, int64_t(glLimit));
    int64_t chunk = limit / widest;
    if (maxTrianglesPerChunk > 0) chunk = std::min(chunk, maxTrianglesPerChunk);
    chunk = std::max(granularity, chunk / granularity * granularity);
    m.chunk_ = std::min(chunk, m.chunk_);  // one chunk holds a small mesh whole
    return m;
}

int64_t MeshChunks::chunkEnd(int chunk) const { return std::min(triangles_, (int64_t(chunk) + 1) * chunk_); }

void MeshChunks::bind(int chunk, GLuint program) const {
    CHECK_GE(chunk, 0);
    const int chunks = std::max(chunkCount(), 1);  // (CHECK_LT binds references: no temporaries in it)
    CHECK_LT(chunk, chunks);
    const int64_t first = chunkFirst(chunk), count = std::max<int64_t>(chunkEnd(chunk) - first, 1);
    for (const MeshStream& s : streams_)
        if (s.buffer)
            glBindBufferRange(GL_SHADER_STORAGE_BUFFER, s.binding, s.buffer, GLintptr(first * s.bytesPerTriangle),
                              GLsizeiptr(count * s.bytesPerTriangle));
    const GLint location = glGetUniformLocation(program, MESH_CHUNK_UNIFORM);
    if (location >= 0) glUniform1ui(location, GLuint(first));
}

void MeshChunks::drawArrays(GLuint program, int64_t firstTriangle, int64_t count) const {
    CHECK_GE(count, 0);
    CHECK_LE(firstTriangle + count, triangles_);
    for (int64_t t = firstTriangle, end = firstTriangle + count; t < end;) {
        const int c = chunkOf(t);
        const int64_t pieceEnd = std::min(end, chunkEnd(c));
        bind(c, program);
        glDrawArrays(GL_TRIANGLES, drawFirstVertex(t), GLsizei(3 * (pieceEnd - t)));
        t = pieceEnd;
    }
}

void MeshChunks::multiDrawArrays(GLuint program, std::span<const GLint> firstVertex,
                                 std::span<const GLint> vertexCount) const {
    CHECK_EQ(firstVertex.size(), vertexCount.size());
    first_.clear();
    count_.clear();
    int current = -1;
    auto flush = [&] {
        if (first_.empty()) return;
        bind(current, program);
        glMultiDrawArrays(GL_TRIANGLES, first_.data(), count_.data(), GLsizei(first_.size()));
        first_.clear();
        count_.clear();
    };
    for (size_t i = 0; i < firstVertex.size(); ++i) {
        DCHECK(firstVertex[i] % 3 == 0 && vertexCount[i] % 3 == 0);
        int64_t t = firstVertex[i] / 3;
        const int64_t end = t + vertexCount[i] / 3;
        CHECK_LE(end, triangles_);
        while (t < end) {
            const int c = chunkOf(t);
            const int64_t pieceEnd = std::min(end, chunkEnd(c));
            if (c != current) {
                flush();
                current = c;
            }
            first_.push_back(drawFirstVertex(t));
            count_.push_back(GLint(3 * (pieceEnd - t)));
            t = pieceEnd;
        }
    }
    flush();
}

void MeshChunks::drawElements(GLuint program, std::span<const uint32_t> ascendingTriangles, int64_t firstIndex) const {
    CHECK_GE(firstIndex, 0);
    forEachPiece(ascendingTriangles, [&](int chunk, size_t begin, size_t end) {
        CHECK_LE(int64_t(ascendingTriangles[end - 1]), MAX_DRAWABLE_TRIANGLES);
        bind(chunk, program);
        const int64_t byteOffset = (firstIndex + 3 * int64_t(begin)) * int64_t(sizeof(uint32_t));
        glDrawElements(GL_TRIANGLES, GLsizei(3 * (end - begin)), GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>(uintptr_t(byteOffset)));
    });
}

}  // namespace bb
