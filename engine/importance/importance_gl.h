// Importance analysis on the GPU: the supplement §1 preprocessing as two
// raster passes in light map space and one compute pass.
//
//   pass 1  position buffer: every triangle of a page drawn in light map space
//           (page uv * 2 - 1, as the light maps), writing local position
//           (rgba32f) and triangle index + 1 (r32ui) per texel;
//   pass 2  the same triangles again: per covered texel, Eq. (3) from the four
//           neighbours in the position buffer, I_max(t) by atomicMax;
//           (passes 1-2 run page by page over one page-sized position buffer)
//   pass 3  compute, per triangle: I(t) = min(A_l/A_o, I_max(t)), Eq. (4).
//
// Units and conventions are those of importance.h (texels per world area,
// local positions: world - BakeMesh::origin, finite results). The CPU reference in importance.h is
// checked against this class in tests/gl/importance_test.cpp.
//
// Requires a current GL 4.3+ context for create(), analyze() and the
// lifetime of the object. GPU memory during analyze(): 48 B per vertex
// (3 per triangle) + 12 B per triangle + 20 B per texel of one page (+4 B per
// texel with capture.texelDensity).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/status.h"
#include "gl/objects.h"
#include "importance/importance.h"
#include "layout/bake_mesh.h"

namespace bb {

// What analyze() also reads back to the CPU, per page (row-major,
// resolution^2, row 0 at v = 0). Off by default: the result per triangle is
// all the tiler needs.
struct ImportanceCapture {
    bool texelTriangles = false;   // triangle index + 1 per texel, 0 = unmapped (per-texel importance maps)
    bool positionBuffers = false;  // the position buffer of pass 1 (checks)
    bool texelDensity = false;     // Eq. (3) per texel as pass 2 computed it, 0 where unmapped (checks, figures)
};

// Wall-clock seconds per phase, each measured up to a glFinish.
struct ImportanceTimings {
    double upload = 0;          // vertex buffer, per-triangle buffers, textures
    double positionPass = 0;    // pass 1, all pages
    double maxDensityPass = 0;  // pass 2, all pages
    double computePass = 0;     // pass 3
    double readback = 0;        // per-triangle results (and captures) to the CPU
    double total() const { return upload + positionPass + maxDensityPass + computePass + readback; }
};

struct ImportanceGlResult {
    Importance importance;                              // per triangle, BakeMesh order
    std::vector<std::vector<uint32_t>> texelTriangles;  // per page, if captured
    std::vector<PositionBuffer> positionBuffers;        // per page, if captured
    std::vector<std::vector<float>> texelDensity;       // per page, if captured
    ImportanceTimings seconds;
};

class ImportanceAnalyzer {
public:
    // Builds the three programs. Error: a shader failed to build (one line).
    static Expected<std::unique_ptr<ImportanceAnalyzer>> create();

    // Runs passes 1-3 over every page of `mesh` (pages of `resolution`
    // texels; BakeMesh::lightmapUv in page space) and reads I(t), A_l/A_o and
    // I_max(t) back. Per-triangle SSBOs are bound in chunks that fit
    // GL_MAX_SHADER_STORAGE_BLOCK_SIZE (MeshChunks, layout/bake_mesh_gl.h).
    // Errors: resolution above GL_MAX_TEXTURE_SIZE or the viewport/framebuffer
    // limits; more triangles than GLint draw firsts address (checkMeshDrawable).
    Expected<ImportanceGlResult> analyze(const BakeMesh& mesh, int resolution, const ImportanceCapture& capture = {});

    // After analyze(): I(t) as one float per triangle (BakeMesh order), kept
    // on the GPU for the tiler. take...() hands over ownership.
    const gl::Buffer& importanceBuffer() const { return importance_; }
    gl::Buffer takeImportanceBuffer() { return std::move(importance_); }

    // The rasterization rules the CPU reference must use to see this GL's
    // texels (GL_SUBPIXEL_BITS).
    RasterRules rasterRules() const { return rules_; }

private:
    ImportanceAnalyzer() = default;
    gl::Program positionProgram_, maxDensityProgram_, clampProgram_;
    gl::Buffer importance_;
    RasterRules rules_;
};

}  // namespace bb
