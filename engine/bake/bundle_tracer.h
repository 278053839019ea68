// The bundle pass and the tile loop of one direction (DESIGN.md steps 5-7):
// the tiler's tiles (engine/tiler/tiler.h) are drawn one at a time into
// per-pixel linked lists (head pointers in an r32ui image, 12-byte nodes in
// an SSBO, one atomic counter), and each tile that fits is handed to an
// update pass (the caller's program) that draws the tile's receiving
// clusters in light map space.
//
// Runs of consecutive tiles that are whole leaves (the budget did not cut
// them) and whose lists fit the buffers together (the predictions, and the
// leaves' grids side by side in one head image) are drawn one after another
// into the same buffers, and one update over all their leaves follows the
// run's last tile (update.frag LEAF_TABLE), when the caller has programs for
// it: each texel is drawn once a run instead of once for each tile its
// cluster meets. A draw that overflows there draws the run's tiles again
// each alone. Either way each texel takes the same sample: the same bits
// (but for a few fragments the rasterizer draws differently at a leaf's
// place in the head image: design notes "One update over a run of leaves").
//
// Memory: the node buffer and the head image start small and grow to what
// the tiles predict (a quarter of margin), never past the budget's limits.
// A tile whose counter exceeds the buffer is redrawn into a buffer of the
// measured size if the budget holds it, else cut into quarters and redrawn:
// no fragment is dropped. Nothing a node holds depends on the tile that drew
// it, so any budget gives the same bits.
//
// Requires a current GL 4.3 context for its whole life.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "bake/baker.h"
#include "core/status.h"
#include "glsl/shared/bundle_layout.h"
#include "gl/objects.h"
#include "layout/bake_mesh_gl.h"
#include "tiler/tiler.h"

namespace bb {

// Where one tile lies: the direction's frame, its leaf and its window of the
// leaf's grid (glsl/lib/bundle_frame.glsl reads these as uniforms).
struct TileFrame {
    glm::vec3 d{0.0f}, u{0.0f}, v{0.0f};
    glm::vec2 rootOrigin{0.0f};
    float rootSize = 1.0f;
    BundleLeaf leaf;
    TileWindow window;  // the pixels the tile owns
    TileWindow drawn;   // and the pixels it draws: with a one-pixel apron (tiler.h drawnWindow)
    glm::ivec2 headOrigin{0};  // where the drawn window's first pixel lies in the head image
    float pixelSize = 1.0f;
    bool leafRun = false;  // the update over a run of whole leaves at once (leaf, window: unused)
};

// Sets the bundle_frame.glsl uniforms of `program` (bound).
void setFrameUniforms(GLuint program, const TileFrame& f);

// What the tracer draws (owned by the Baker; alive as long as the tracer).
struct BundleScene {
    const BakeMesh* mesh = nullptr;
    const std::vector<Cluster>* clusters = nullptr;
    GLuint vertexArray = 0, vertexBuffer = 0, triangleBuffer = 0;
    GLuint radiance = 0;      // outgoing radiance per texel (the bundle pass reads it)
    GLuint readModes = 0;     // per texel, how the bundle pass reads its radiance (lightmap/read_modes.comp)
    GLuint texelCharts = 0;   // per page texel, its owner's chart (low 16 bits): a fragment reads its own chart's texels
    GLuint slopes = 0;        // per texel, the slope of its light inside it (lightmap/meta.frag); 0: none read
    GLuint pageFramebuffer = 0;
    int pageResolution = 0;
    // cut-outs (glsl/shared/material_layout.h): per material alpha and the masks' texels
    GLuint materialAlpha = 0, alphaTexels = 0;
    int backLayerOffset = 0;  // > 0: double-sided triangles' back sides' radiance at layer page + this
};

struct BundleLimits {
    int64_t nodeCapacity = 0;  // nodes the budget allows in one tile (<= GL_MAX_SHADER_STORAGE_BLOCK_SIZE / 12)
    int maxTileSize = 64;      // head image side the budget allows (<= GL_MAX_TEXTURE_SIZE, viewport)
    int subpixelBits = 8;      // GL_SUBPIXEL_BITS
    bool predict = true;       // size the buffers from the predictions (false: allocate the budget at once)
};

// Draws the runs of curved texels [first[k], first[k] + count[k])
// (lib/curved_footprint.glsl) with `program` (in use, their records bound, a
// res x res viewport): rectangles of rows of res fragments from the
// viewport's corner, one fragment a texel (lightmap/curved.vert).
void drawCurvedTexelRuns(GLuint program, int res, const std::vector<int32_t>& first, const std::vector<int32_t>& count);

class BundleTracer {
public:
    // The update's programs: over the tile's receiving clusters in light map
    // space, and over their curved texels (setCurvedTexels; a fragment each).
    // 0 skips that draw.
    struct UpdatePrograms {
        GLuint triangles = 0, curved = 0;
    };
    // Sets the update programs' uniforms (other than the frame's, the node
    // count and pageResolution, which the tracer sets) and returns them: for
    // frame.leafRun, the programs built with LEAF_TABLE.
    using UpdateFn = std::function<UpdatePrograms(const TileFrame&, uint32_t nodeCount)>;

    // Curved texels (bake/curved_footprints.h) for the updates: per cluster,
    // its first texel (clusterFirst; empty: none), and what binds their
    // records for a draw of them with the program given (drawCurvedTexelRuns).
    void setCurvedTexels(std::vector<uint32_t> clusterFirst, std::function<void(GLuint)> bind);
    // The outgoing radiance the bundle pass reads, its read modes and texel
    // charts and the slopes inside its texels (BundleScene's; 0: none): the
    // resolution probe's coarse maps, then back.
    void setRadianceSource(GLuint radiance, GLuint readModes, GLuint texelCharts, GLuint slopes) {
        scene_.radiance = radiance;
        scene_.readModes = readModes;
        scene_.texelCharts = texelCharts;
        scene_.slopes = slopes;
    }

    // Both passes read the triangle and vertex buffers as SSBOs in chunks of
    // GL_MAX_SHADER_STORAGE_BLOCK_SIZE (MeshChunks, layout/bake_mesh_gl.h):
    // the update program declares meshChunkFirstTriangle (lib/bake_vertex.glsl),
    // which the tracer sets with each chunk's draw.
    // Errors: the bundle program failed to build; a mesh beyond GLint draw firsts (one line).
    static Expected<std::unique_ptr<BundleTracer>> create(const BundleScene& scene, const BundleLimits& limits,
                                                          const std::string& defines, BakeStats* stats);

    // Tiles a direction: the clusters projected along frame.dir, the leaves
    // and tiles of tileBundle. recordStats: the direction counts in BakeStats
    // (bakes; not the sun or captures). leafRuns: runs of whole leaves may be
    // updated at once (the update function has LEAF_TABLE programs).
    void begin(const BundleFrame& frame, const TilerOptions& options, uint32_t seed, bool recordStats,
               bool leafRuns = false);
    bool done() const { return work_.empty(); }
    // Draws the next tile (one bundle draw) and, if it fit, its update.
    void next(const UpdateFn& update);
    // All of a direction's tiles.
    void run(const BundleFrame& frame, const TilerOptions& options, uint32_t seed, bool recordStats,
             const UpdateFn& update, bool leafRuns = false);

    // The latest direction's tiling (viewer overlays) and the latest tile's
    // lists (captures: head image row stride headSide()).
    const BundleFrame& frame() const { return frame_; }
    const std::vector<BundleLeaf>& leaves() const { return tiling_.leaves; }
    int tilesThisDirection() const { return tiles_; }
    const gl::Texture& heads() const { return heads_; }
    int headSide() const { return headSide_; }
    const gl::Buffer& nodes() const { return nodes_; }
    uint32_t lastNodeCount() const { return lastCount_; }

private:
    BundleTracer() = default;
    void ensureNodes(int64_t nodes);
    void ensureHeads(int side);
    void drawClusters(GLuint program, const std::vector<uint32_t>& ids, bool receiversOnly);
    void drawCurvedTexels(GLuint program, const std::vector<uint32_t>& ids);
    void clearRun() {  // the run being drawn: none
        groupTiles_.clear();
        drawnTiles_.clear();
    }
    void planGroups();  // which of the direction's tiles are updated at once (and where their lists go); after a reset
    void drawBundle(const Tile& tile, const TileFrame& f, bool resetCounter);
    void runUpdate(const UpdateFn& update, const TileFrame& f, uint32_t nodeCount, const std::vector<uint32_t>& clusters);

    BundleScene scene_;
    BundleLimits limits_;
    BakeStats* stats_ = nullptr;
    gl::Program append_;
    MeshChunks chunks_;  // the triangle and vertex SSBOs, bound per chunk
    gl::Buffer nodes_, counter_;
    gl::Texture heads_;
    gl::Framebuffer fbo_;
    int64_t nodeAllocated_ = 0;
    int headSide_ = 0;
    std::vector<int32_t> drawFirst_, drawCount_;  // scratch: multi-draw ranges
    std::vector<uint32_t> curvedClusterFirst_;
    std::function<void(GLuint)> bindCurvedTexels_;

    // the direction in progress
    BundleFrame frame_;
    TilerOptions options_;
    std::vector<ClusterView> views_;
    DirectionTiling tiling_;
    std::vector<Tile> work_;  // back() is next
    uint32_t seed_ = 0;
    bool recordStats_ = false;
    int tiles_ = 0;
    uint32_t lastCount_ = 0;
    // Runs of whole leaves updated at once (planGroups): each leaf's run (-1:
    // alone) and place in the head image; per run its leaf table, nodes and
    // image side; the run being drawn: its tiles and counts so far.
    struct Group {
        std::vector<shared::LeafRecord> records;
        int64_t nodes = 0;
        int side = 0;
    };
    std::vector<int> leafGroup_;
    std::vector<glm::ivec2> leafOrigin_;
    std::vector<Group> groups_;
    std::vector<Tile> groupTiles_;
    gl::Buffer leafTable_;
    uint32_t drawnNodes_ = 0, drawnOwned_ = 0;
    struct DrawnTile {
        double predicted;
        uint32_t nodes, owned;
        float pixelSize;
    };
    std::vector<DrawnTile> drawnTiles_;
};

}  // namespace bb
