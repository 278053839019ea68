// Tiling with memory usage prediction: how one bundle direction is cut into
// tiles before anything is drawn. GL-free (unit-tested without a context).
//
// Based on: Y. Tokuyoshi, T. Sekine, T. da Silva, T. Kanai, "Adaptive
// Ray-bundle Tracing with Memory Usage Prediction", CGF 32(7), 2013, §4-5
// and supplement §3 (frustum culling).
//
// The data flow, per direction d:
//   clusters (once per bake: clusterMesh)  spatially coherent runs of <= 256
//       triangles of one page, with world bounds and the largest importance
//       I(t) of their triangles (texels per scene unit^2, Eq. 4);
//   projectClusters(d)                      each cluster's rectangle on the
//       bundle plane and its projected area sum A(t)|n(t).d|;
//   tileBundle                              a quadtree over the bundle plane
//       (the root: the square around the scene's bounding sphere). A node's
//       bundle pixel is 1/(pixelsPerTexel sqrt(I)) for the largest I of the
//       clusters it meets (the half-texel rule: 2 pixels per texel keep light
//       from leaking through walls one texel thick); nodes are split while
//       they need more than maxLeafPixels pixels across, or while splitting
//       saves a third of the fragments (sparse terrain beside dense
//       buildings). Leaves are the pixel grids: each is its own orthographic
//       projection, so the bundle's extent is not bounded by the viewport.
//       Leaves are then cut into windows of their grid (tiles) until each
//       tile's predicted node count fits the node buffer and its side fits
//       the head image. Leaves depend on the scene and d only, never on the
//       memory budget: a smaller budget makes more tiles of the same pixels,
//       so the light maps do not change (tests/gl/tiling_test.cpp).
//
// Prediction (the "projected area" model, chosen over the paper's per-tile
// GPU count because it costs one pass over the triangles per direction on the
// CPU, ~2 ms per million triangles here, and needs no draw before the draw):
// a tile's nodes = sum over the clusters it meets of (cluster's projected
// area) x (fraction of the cluster's rectangle inside the tile) / pixel area.
// The raster of a triangle has area/pixel^2 fragments in expectation, so the
// model is unbiased for whole clusters; the fraction assumes a cluster's area
// is spread evenly over its rectangle.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "layout/bake_mesh.h"

namespace bb {

// A run of triangles [first, first + count) of BakeMesh order, all on `page`.
struct Cluster {
    uint32_t first = 0;
    uint32_t count = 0;
    uint32_t page = 0;
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};  // world
    float maxImportance = 0.0f;                   // max I(t), texels per scene unit^2; 0 = no texel centre
    uint32_t receivers = 0;  // [first, first + receivers) cover texel centres (I(t) > 0); the rest only occlude
};

// Reorders `mesh.triangles` (and their vertices) so each page's triangles
// form clusters of at most `maxTriangles` (typ. 128..512) by median splits of
// the centroids along the longest axis; page ranges stay valid. Returns the
// clusters in mesh order (maxImportance 0: see setClusterImportance).
// Deterministic. Cost: O(T log T).
std::vector<Cluster> clusterMesh(BakeMesh& mesh, uint32_t maxTriangles = 256);

// maxImportance and receivers of each cluster from per-triangle I(t)
// (BakeMesh order), reordering each cluster's triangles (and `importance`)
// so the receivers come first: the update pass then draws only triangles
// with texel centres (I(t) = 0 exactly when a triangle covers none, Eq. 4).
// A cluster whose receivers would make more than twice their own fragments
// at its largest I (sum A(t) max I against sum A(t) I(t): a thin tube's 96
// triangles and the two of the wide floor it lies on) is sorted by I and cut
// into runs that do not, each a cluster of its own: a leaf takes its pixel
// from the clusters it meets, and the floor is not drawn at the tube's pixel
// wherever it reaches. Stable, so deterministic.
void setClusterImportance(BakeMesh& mesh, std::vector<Cluster>& clusters, std::vector<float>& importance);

// The bundle plane of one direction: rays travel along +dir; (u, v) are plane
// coordinates; the root square is [origin, origin + size]^2 in (u, v).
struct BundleFrame {
    glm::vec3 dir{0.0f, 0.0f, 1.0f}, u{1.0f, 0.0f, 0.0f}, v{0.0f, 1.0f, 0.0f};
    glm::dvec2 origin{0.0};
    double size = 1.0;
};

// A cluster seen along one direction.
struct ClusterView {
    glm::dvec4 rect{0.0};       // (u0, v0, u1, v1) in root units ([0,1] spans the root square)
    double projectedArea = 0;   // sum of A(t) |n(t).d| (double-sided: twice, up to two nodes), scene units^2
};

// Per cluster, its bounds' rectangle and projected area along frame.dir. O(T).
std::vector<ClusterView> projectClusters(const BakeMesh& mesh, const std::vector<Cluster>& clusters,
                                         const BundleFrame& frame);

// A square of the root (root units), drawn as one pixel grid of pixels x pixels.
struct BundleLeaf {
    glm::dvec2 min{0.0};
    double extent = 1.0;   // side in root units (a power of 1/2)
    int pixels = 1;        // pixels across
};

// A window of a leaf's pixel grid: what one bundle draw covers.
struct TileWindow {
    int x = 0, y = 0, width = 0, height = 0;
};

// The window a tile draws: its own and a one-pixel apron within the leaf, so
// that the update pass can read the lists of its pixels' neighbours
// (update.frag) whichever tiles the budget makes.
TileWindow drawnWindow(const TileWindow& window, int leafPixels);

struct Tile {
    int leaf = 0;
    TileWindow window;  // the pixels it owns (drawnWindow: the pixels it draws)
    double predictedNodes = 0;
    std::vector<uint32_t> clusters;  // clusters whose rectangles meet the tile (all, when culling is off)
};

struct TilerOptions {
    // Uniform baseline (Hermes et al. 2010): one leaf, the whole root, at
    // `fixedPixelSize`. Needs root pixels <= the viewport limit.
    bool uniform = false;
    double fixedPixelSize = 0;   // scene units; > 0: every leaf uses it (--bundle-res, uniform)
    double pixelsPerTexel = 2;   // bundle pixels per light map texel (the half-texel rule)
    int maxLeafPixels = 1024;    // a leaf's side in pixels (not from the budget: leaves fix the answer)
    int maxDepth = 16;           // quadtree depth limit (root units stay exact in float)
    int maxTilePixels = 1024;    // a drawn tile's side (apron included): the head image
    double nodeCapacity = 1e9;   // split tiles until predicted <= fill * nodeCapacity
    double fill = 0.8;
    bool cull = true;            // false: every tile draws every cluster (culling on/off tests)
};

// The bundle pixel (scene units) that texels of importance I (texels per
// scene unit^2) need: 1 / (pixelsPerTexel sqrt(I)). Precondition: I > 0.
double pixelForImportance(float importance, double pixelsPerTexel);

struct DirectionTiling {
    std::vector<BundleLeaf> leaves;
    std::vector<Tile> tiles;      // drawing order; leaves with no texel to update have none
    double sceneSize = 1.0;       // root size, scene units
    double pixelSize(int leaf) const { return leaves[size_t(leaf)].extent * sceneSize / leaves[size_t(leaf)].pixels; }
};

// Leaves and tiles of one direction. Pure, deterministic.
DirectionTiling tileBundle(const std::vector<Cluster>& clusters, const std::vector<ClusterView>& views,
                           double rootSize, const TilerOptions& options);

// The predicted nodes of `window` of `leaf` (drawn: with its apron) and the clusters it meets (from
// `candidates`, or all clusters when culling is off): used for new tiles and
// for the quarters of a tile that overflowed.
Tile makeTile(const DirectionTiling& tiling, int leaf, const TileWindow& window, const std::vector<Cluster>& clusters,
              const std::vector<ClusterView>& views, const std::vector<uint32_t>& candidates, bool cull);

// Places squares of the given sides (pixels) without overlap in one square
// image of side `side` (a power of two, the least that holds them, at most
// maxSide): shelves of the largest first, in a fixed order. Returns their
// lower-left corners, or nothing when they do not fit in maxSide^2. Used to
// hold a run of a direction's leaves' head pointers at once (bundle_tracer.h).
std::vector<glm::ivec2> packSquares(const std::vector<int>& sides, int maxSide, int& side);

// The four quarters of a window (fewer when it is one pixel wide or high).
std::vector<TileWindow> splitWindow(const TileWindow& window);

// Draw ranges (first vertex, vertex count) of `tileClusters`, adjacent ranges
// merged: every triangle, or (receiversOnly) each cluster's receivers.
void clusterRanges(const std::vector<Cluster>& clusters, const std::vector<uint32_t>& tileClusters,
                   std::vector<int32_t>& firstVertex, std::vector<int32_t>& vertexCount, bool receiversOnly = false);

// Appends the draw range [rangeFirst, rangeFirst + rangeCount) to (first,
// count), merged into the last range where it follows it; empty ones are left out.
void appendDrawRange(std::vector<int32_t>& first, std::vector<int32_t>& count, int32_t rangeFirst, int32_t rangeCount);

}  // namespace bb
