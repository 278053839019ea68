// The BakeMesh on the GL side, defined once for every pass that draws it.
//
// createBakeVertexArray: the BakeVertex attribute layout (glsl/lib/bake_vertex.glsl):
// location 0 position, 1 normal, 2 uv0, 3 lightmapUv, all from binding 0.
//
// MeshChunks: per-triangle SSBOs (BakeTriangle 16 B, BakeVertex 3 x 48 B,
// one float or uint per triangle...) bound in chunks that fit
// GL_MAX_SHADER_STORAGE_BLOCK_SIZE (128 MiB on llvmpipe: 932 k triangles of
// vertices, 8.4 M of BakeTriangle). Chunk c covers the mesh's triangles
// [c * chunkTriangles, (c + 1) * chunkTriangles); every stream is bound with
// glBindBufferRange at that chunk's first triangle (offsets multiples of
// GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT), and the program's uniform
// MESH_CHUNK_UNIFORM ("meshChunkFirstTriangle", uint) holds the first
// triangle, which the shader subtracts (glsl/lib/bake_vertex.glsl
// bakeTriangle(t)). gl_VertexID stays the mesh's: draws are split at chunk
// boundaries, never rebased. The draw helpers keep the order of the
// triangles they are given (a run that crosses a boundary becomes two draws
// of the same triangles in the same order), so chunking changes no pixel.
// One chunk (every mesh under the limit) costs one glBindBufferRange per
// stream and one glUniform per draw call, as the whole-buffer binds did.
//
// Draw firsts are GLint vertices (3 per triangle): a mesh above
// MAX_DRAWABLE_TRIANGLES (715 827 882) cannot be drawn with glDrawArrays /
// glDrawElements offsets in 32 bits. checkMeshDrawable() reports it as an
// error at create time; the draw helpers CHECK it.
//
// Requires a current context for everything but checkMeshDrawable.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"
#include "gl/gl.h"
#include "gl/objects.h"

namespace bb {

gl::VertexArray createBakeVertexArray(const std::string& label, const gl::Buffer& vertices);

inline constexpr int64_t MAX_DRAWABLE_TRIANGLES = int64_t(INT32_MAX) / 3;  // 715 827 882
inline constexpr const char* MESH_CHUNK_UNIFORM = "meshChunkFirstTriangle";

// Error (one line) if a mesh of `triangleCount` triangles has a vertex index
// beyond GLint (the first of a draw call).
Status checkMeshDrawable(int64_t triangleCount);

// GLint first vertex of a draw starting at `triangle` (CHECKs the range).
GLint drawFirstVertex(int64_t triangle);

// One per-triangle array a program reads as an SSBO.
struct MeshStream {
    GLuint binding = 0;             // SSBO binding point (glsl/shared/*.h)
    GLuint buffer = 0;              // triangle t at byte t * bytesPerTriangle; 0: counts for the chunk size, not bound
    int64_t bytesPerTriangle = 0;   // 16 (BakeTriangle), 144 (3 BakeVertex), 4 (a float per triangle)
};

// Test-only: caps the bytes of one bound range below
// GL_MAX_SHADER_STORAGE_BLOCK_SIZE (0 = GL's limit), for MeshChunks created
// afterwards, so a small scene spans many chunks. Process-wide.
void setMeshChunkBytesForTesting(int64_t bytes);

class MeshChunks {
public:
    MeshChunks() = default;
    // Reads GL_MAX_SHADER_STORAGE_BLOCK_SIZE and the offset alignment.
    // maxTrianglesPerChunk: a further cap (e.g. a compute dispatch limit), 0 = none.
    // The chunk size is the largest multiple of the alignment granularity
    // (lcm over streams of align / gcd(align, bytesPerTriangle)) whose every
    // range fits the limit. No streams: one chunk.
    static MeshChunks create(int64_t triangleCount, std::initializer_list<MeshStream> streams,
                             int64_t maxTrianglesPerChunk = 0);

    int64_t triangleCount() const { return triangles_; }
    int64_t chunkTriangles() const { return chunk_; }
    int chunkCount() const { return int((triangles_ + chunk_ - 1) / chunk_); }
    int chunkOf(int64_t triangle) const { return int(triangle / chunk_); }
    int64_t chunkFirst(int chunk) const { return int64_t(chunk) * chunk_; }
    int64_t chunkEnd(int chunk) const;  // one past its last triangle
    // Replaces stream `index`'s buffer (0: not bound).
    void setBuffer(size_t index, GLuint buffer) { streams_.at(index).buffer = buffer; }

    // Binds chunk `chunk` of every stream with a buffer and sets
    // MESH_CHUNK_UNIFORM of `program` (which must be bound; absent is fine).
    void bind(int chunk, GLuint program) const;

    // GL_TRIANGLES glDrawArrays of triangles [first, first + count), one
    // draw per chunk it crosses. `program` bound, vertex array bound.
    void drawArrays(GLuint program, int64_t firstTriangle, int64_t count) const;
    // glMultiDrawArrays of vertex ranges (firsts and counts multiples of 3,
    // e.g. clusterRanges), in their order: ranges are cut at chunk
    // boundaries and consecutive pieces of one chunk go in one multi-draw.
    void multiDrawArrays(GLuint program, std::span<const GLint> firstVertex, std::span<const GLint> vertexCount) const;
    // The pieces of a run of triangle ids in ascending order (an index buffer
    // built from a stable sort, as the renderer's and the meta pass's):
    // fn(chunk, begin, end) for each [begin, end) of `triangles` within one chunk, in order.
    template <class Fn>
    void forEachPiece(std::span<const uint32_t> ascendingTriangles, Fn&& fn) const;
    // glDrawElements (GL_UNSIGNED_INT, 3 indices t*3+k per triangle) of a run
    // of ascending triangle ids whose indices start at index `firstIndex` of
    // the bound element buffer, one draw per chunk it crosses.
    void drawElements(GLuint program, std::span<const uint32_t> ascendingTriangles, int64_t firstIndex) const;

private:
    std::vector<MeshStream> streams_;
    int64_t triangles_ = 0;
    int64_t chunk_ = 1;
    mutable std::vector<GLint> first_, count_;  // scratch for multiDrawArrays
};

template <class Fn>
void MeshChunks::forEachPiece(std::span<const uint32_t> t, Fn&& fn) const {
    size_t begin = 0;
    while (begin < t.size()) {
        const int c = chunkOf(t[begin]);
        size_t end = begin + 1;
        if (end < t.size() && chunkOf(t.back()) != c) {
            // first id at or past the next chunk (ascending ids)
            const uint32_t next = uint32_t(chunkEnd(c));
            size_t lo = end, hi = t.size();
            while (lo < hi) {
                const size_t mid = lo + (hi - lo) / 2;
                if (t[mid] < next) lo = mid + 1; else hi = mid;
            }
            end = lo;
        } else {
            end = t.size();
        }
        fn(c, begin, end);
        begin = end;
    }
}

}  // namespace bb
