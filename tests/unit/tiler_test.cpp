// Tiling with memory usage prediction (engine/tiler), without GL: clusters,
// the importance-driven quadtree, the node prediction against an exact count
// of pixel centres, and the budget-independence of the leaves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "tiler/tiler.h"

namespace bb {
namespace {

// n x n quads (2 triangles each) over [x0, x0 + size] x [y0, y0 + size] at
// height z, facing +z, on `page`.
void addGrid(BakeMesh& mesh, float x0, float y0, float z, float size, int n, uint32_t page) {
    const float step = size / n;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            glm::vec3 a(x0 + i * step, y0 + j * step, z), b = a + glm::vec3(step, 0, 0), c = a + glm::vec3(step, step, 0),
                                                        d = a + glm::vec3(0, step, 0);
            const glm::vec3 corners[2][3] = {{a, b, c}, {a, c, d}};
            for (const auto& t : corners) {
                for (const glm::vec3& p : t) {
                    BakeVertex v{};
                    v.position = glm::vec4(p, 1.0f);
                    v.normal = glm::vec4(0, 0, 1, 0);
                    mesh.vertices.push_back(v);
                }
                mesh.triangles.push_back(BakeTriangle{0, page, 0, 0});
                mesh.bounds.extend(t[0]);
                mesh.bounds.extend(t[1]);
                mesh.bounds.extend(t[2]);
            }
        }
}

void finishPages(BakeMesh& mesh, uint32_t pages) {
    mesh.pageFirstTriangle.assign(pages + 1, 0);
    for (const BakeTriangle& t : mesh.triangles) ++mesh.pageFirstTriangle[t.page + 1];
    for (uint32_t p = 0; p < pages; ++p) mesh.pageFirstTriangle[p + 1] += mesh.pageFirstTriangle[p];
}

// Looking straight down -z over the square [-h, h]^2 (root units map it to [0, 1]^2).
BundleFrame downFrame(double half) {
    BundleFrame f;
    f.dir = glm::vec3(0, 0, -1);
    f.u = glm::vec3(1, 0, 0);
    f.v = glm::vec3(0, -1, 0);  // u x v = d
    f.origin = glm::dvec2(-half, -half);
    f.size = 2 * half;
    return f;
}

TEST(Tiler, ClustersAreAPermutationWithinPagesAndBoundTheirTriangles) {
    BakeMesh mesh;
    addGrid(mesh, 0, 0, 0, 10, 20, 0);   // 800 triangles on page 0
    addGrid(mesh, 0, 0, 1, 10, 10, 1);   // 200 on page 1
    finishPages(mesh, 2);
    std::multiset<std::tuple<float, float, float>> before;
    for (const auto& v : mesh.vertices) before.insert({v.position.x, v.position.y, v.position.z});
    const auto clusters = clusterMesh(mesh, 64);
    std::multiset<std::tuple<float, float, float>> after;
    for (const auto& v : mesh.vertices) after.insert({v.position.x, v.position.y, v.position.z});
    EXPECT_EQ(before, after);
    uint32_t next = 0;
    for (const Cluster& c : clusters) {
        EXPECT_EQ(c.first, next);  // contiguous, in order
        EXPECT_LE(c.count, 64u);
        EXPECT_GE(c.count, 1u);
        next = c.first + c.count;
        for (uint32_t t = c.first; t < next; ++t) {
            EXPECT_EQ(mesh.triangles[t].page, c.page);
            for (int k = 0; k < 3; ++k) {
                glm::vec3 p(mesh.vertices[3 * t + k].position);
                EXPECT_TRUE(glm::all(glm::greaterThanEqual(p, c.boundsMin)) && glm::all(glm::lessThanEqual(p, c.boundsMax)));
            }
        }
    }
    EXPECT_EQ(next, 1000u);
    EXPECT_EQ(mesh.pageFirstTriangle[1], 800u);
    // spatially coherent: a cluster of 50 of the 0.5-unit quads spans far less than the 10-unit grid
    for (const Cluster& c : clusters) EXPECT_LT(glm::length(c.boundsMax - c.boundsMin), 8.0f);
}

// Counts pixel centres of a leaf's grid inside the triangles: what the raster makes.
double exactFragments(const BakeMesh& mesh, const BundleFrame& f, const BundleLeaf& leaf, const TileWindow& w) {
    double n = 0;
    const double pixel = leaf.extent * f.size / leaf.pixels;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        glm::dvec2 p[3];
        for (int k = 0; k < 3; ++k) {
            glm::dvec3 x(mesh.vertices[3 * t + k].position);
            p[k] = glm::dvec2(glm::dot(x, glm::dvec3(f.u)) - f.origin.x, glm::dot(x, glm::dvec3(f.v)) - f.origin.y);
        }
        for (int y = w.y; y < w.y + w.height; ++y)
            for (int x = w.x; x < w.x + w.width; ++x) {
                glm::dvec2 c(leaf.min.x * f.size + (x + 0.5) * pixel, leaf.min.y * f.size + (y + 0.5) * pixel);
                auto edge = [](glm::dvec2 a, glm::dvec2 b, glm::dvec2 q) { return (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x); };
                double e0 = edge(p[0], p[1], c), e1 = edge(p[1], p[2], c), e2 = edge(p[2], p[0], c);
                if ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0)) n += 1;
            }
    }
    return n;
}

// A sparse 100-unit plane (importance `sparse`, n x n quads) with a dense
// patch of `patch` units above it at z = 2 (importance `dense`), clustered.
struct PlaneAndPatch {
    BakeMesh mesh;
    std::vector<Cluster> clusters;
};
PlaneAndPatch planeAndPatch(int n, float patch, float sparse, float dense, uint32_t clusterTriangles) {
    PlaneAndPatch s;
    addGrid(s.mesh, -50, -50, 0, 100, n, 0);
    addGrid(s.mesh, 10, 10, 2, patch, 8, 0);
    finishPages(s.mesh, 1);
    s.clusters = clusterMesh(s.mesh, clusterTriangles);
    std::vector<float> importance(s.mesh.triangles.size());
    for (size_t t = 0; t < importance.size(); ++t) importance[t] = s.mesh.vertices[3 * t].position.z > 1 ? dense : sparse;
    setClusterImportance(s.mesh, s.clusters, importance);
    return s;
}

TEST(Tiler, LeavesFollowImportanceAndPartitionTheRoot) {
    // 1 texel per unit on the plane, 16 on a 4-unit patch
    auto [mesh, clusters] = planeAndPatch(8, 4, 1.0f, 256.0f, 16);
    const BundleFrame frame = downFrame(72);
    const auto views = projectClusters(mesh, clusters, frame);
    TilerOptions o;
    o.maxLeafPixels = 256;
    const DirectionTiling tiling = tileBundle(clusters, views, frame.size, o);

    ASSERT_GT(tiling.leaves.size(), 1u);
    double area = 0, finest = 1e9, coarsest = 0;
    for (size_t i = 0; i < tiling.leaves.size(); ++i) {
        const BundleLeaf& a = tiling.leaves[i];
        area += a.extent * a.extent;
        EXPECT_LE(a.pixels, o.maxLeafPixels);
        finest = std::min(finest, tiling.pixelSize(int(i)));
        coarsest = std::max(coarsest, tiling.pixelSize(int(i)));
        for (size_t j = i + 1; j < tiling.leaves.size(); ++j) {  // no two leaves overlap
            const BundleLeaf& b = tiling.leaves[j];
            bool apart = a.min.x + a.extent <= b.min.x || b.min.x + b.extent <= a.min.x || a.min.y + a.extent <= b.min.y ||
                         b.min.y + b.extent <= a.min.y;
            EXPECT_TRUE(apart) << i << " " << j;
        }
    }
    EXPECT_LE(area, 1.0 + 1e-12);
    // the half-texel rule where the dense patch is, coarse pixels on the plane
    EXPECT_LE(finest, 1.0 / (2.0 * 16.0) + 1e-9);
    EXPECT_GE(coarsest, 4 * finest);
    // every pixel centre that a triangle covers lies in exactly one leaf: the
    // leaves cover every cluster with texels
    for (size_t c = 0; c < clusters.size(); ++c) {
        glm::dvec2 centre(0.5 * (views[c].rect.x + views[c].rect.z), 0.5 * (views[c].rect.y + views[c].rect.w));
        int owners = 0;
        for (const BundleLeaf& l : tiling.leaves)
            owners += centre.x >= l.min.x && centre.x < l.min.x + l.extent && centre.y >= l.min.y && centre.y < l.min.y + l.extent;
        EXPECT_EQ(owners, 1) << "cluster " << c;
    }
}

// A small, finely pixelled object (a 1-unit patch of 128 triangles, 10^4
// texels per unit^2: a tube's worth) on a wide floor of two triangles (200
// units, 0.01 texels per unit^2), all in one cluster of 256. Drawn at the
// cluster's largest I the floor alone would make 200^2 x 4 x 10^4 = 1.6e9
// fragments a direction; its own pixels make 40000 x 4 x 0.01 = 1600, the
// patch's 4 x 10^4. setClusterImportance cuts the cluster by importance, and
// the quadtree then pays fine pixels only around the patch: measured 2.49 x
// the ideal 41,600 (the leaves around the patch draw some floor finely),
// where before the floor took the patch's pixel everywhere (~1.6e9 in
// leaves of at most 1024 pixels across). Bound: 4 x.
TEST(Tiler, ASmallFineObjectOnAWideFloorDoesNotDrawTheFloorAtItsPixel) {
    BakeMesh mesh;
    addGrid(mesh, -100, -100, 0, 200, 1, 0);
    addGrid(mesh, 0.1f, 0.2f, 0.02f, 1, 8, 0);
    finishPages(mesh, 1);
    auto clusters = clusterMesh(mesh, 256);
    ASSERT_EQ(clusters.size(), 1u);
    std::vector<float> importance(mesh.triangles.size());
    for (size_t t = 0; t < importance.size(); ++t) importance[t] = mesh.vertices[3 * t].position.z > 0.01f ? 1e4f : 0.01f;
    setClusterImportance(mesh, clusters, importance);
    ASSERT_EQ(clusters.size(), 2u);
    uint32_t next = 0;
    for (const Cluster& c : clusters) {
        EXPECT_EQ(c.first, next);  // still contiguous runs of mesh order, each of one importance
        next = c.first + c.count;
        EXPECT_EQ(c.receivers, c.count);
        for (uint32_t t = c.first; t < next; ++t) EXPECT_EQ(importance[t], c.maxImportance);
    }
    EXPECT_EQ(next, 130u);
    const BundleFrame frame = downFrame(142);
    const auto views = projectClusters(mesh, clusters, frame);
    const DirectionTiling tiling = tileBundle(clusters, views, frame.size, TilerOptions{});
    double predicted = 0;
    for (const Tile& t : tiling.tiles) predicted += t.predictedNodes;
    const double ideal = 200.0 * 200.0 * 4.0 * 0.01 + 4.0 * 1e4;
    std::printf("[tiler] a fine patch on a wide floor: %.0f predicted nodes, %.2f x the ideal, %zu leaves\n", predicted,
                predicted / ideal, tiling.leaves.size());
    EXPECT_LT(predicted, 4.0 * ideal);
}

TEST(Tiler, PredictionMatchesTheRasterAndTilesFitTheBudget) {
    BakeMesh mesh;
    // offsets keep pixel centres off the triangle edges, where this count would see them twice
    addGrid(mesh, -49.9871f, -50.0133f, 0, 100, 16, 0);
    addGrid(mesh, -20.0071f, -9.9913f, 3, 30, 12, 0);  // a second layer: depth complexity 2 where they overlap
    finishPages(mesh, 1);
    auto clusters = clusterMesh(mesh, 32);
    std::vector<float> importance(mesh.triangles.size(), 0.09f);
    setClusterImportance(mesh, clusters, importance);  // 0.3 texels per unit
    const BundleFrame frame = downFrame(60);
    const auto views = projectClusters(mesh, clusters, frame);
    TilerOptions o;
    o.nodeCapacity = 3000;
    o.maxTilePixels = 128;
    const DirectionTiling tiling = tileBundle(clusters, views, frame.size, o);
    ASSERT_GT(tiling.tiles.size(), 2u);
    double predicted = 0, exact = 0;
    for (const Tile& t : tiling.tiles) {
        EXPECT_LE(t.predictedNodes, o.fill * o.nodeCapacity);
        const BundleLeaf& leaf = tiling.leaves[size_t(t.leaf)];
        const TileWindow drawn = drawnWindow(t.window, leaf.pixels);  // the tile and its apron: the head image
        EXPECT_LE(std::max(drawn.width, drawn.height), o.maxTilePixels);
        const double n = exactFragments(mesh, frame, leaf, drawn);
        predicted += t.predictedNodes;
        exact += n;
        if (n > 200) EXPECT_NEAR(t.predictedNodes / n, 1.0, 0.35) << "tile " << t.window.x << "," << t.window.y;
    }
    EXPECT_NEAR(predicted / exact, 1.0, 0.02);
}

TEST(Tiler, LeavesDoNotDependOnTheBudgetButTilesDo) {
    auto [mesh, clusters] = planeAndPatch(16, 8, 0.25f, 64.0f, 32);
    const BundleFrame frame = downFrame(72);
    const auto views = projectClusters(mesh, clusters, frame);
    TilerOptions roomy, tight;
    tight.nodeCapacity = 500;
    tight.maxTilePixels = 64;
    const DirectionTiling a = tileBundle(clusters, views, frame.size, roomy);
    const DirectionTiling b = tileBundle(clusters, views, frame.size, tight);
    ASSERT_EQ(a.leaves.size(), b.leaves.size());
    for (size_t i = 0; i < a.leaves.size(); ++i) {
        EXPECT_EQ(a.leaves[i].min, b.leaves[i].min);
        EXPECT_EQ(a.leaves[i].extent, b.leaves[i].extent);
        EXPECT_EQ(a.leaves[i].pixels, b.leaves[i].pixels);
    }
    EXPECT_GT(b.tiles.size(), a.tiles.size());
    // the tight tiles cover each leaf's grid exactly once
    for (size_t l = 0; l < b.leaves.size(); ++l) {
        int64_t pixels = 0;
        for (const Tile& t : b.tiles)
            if (t.leaf == int(l)) pixels += int64_t(t.window.width) * t.window.height;
        EXPECT_EQ(pixels, int64_t(b.leaves[l].pixels) * b.leaves[l].pixels) << "leaf " << l;
    }
}

// A tile draws its own pixels and a one-pixel apron, clipped to its leaf:
// every own pixel's neighbours are in its lists (update.frag), and a tile
// that is the whole leaf draws nothing more.
TEST(Tiler, DrawnWindowIsTheTileAndAOnePixelApronWithinTheLeaf) {
    const auto same = [](const TileWindow& a, const TileWindow& b) {
        return a.x == b.x && a.y == b.y && a.width == b.width && a.height == b.height;
    };
    EXPECT_TRUE(same(drawnWindow({0, 0, 8, 8}, 8), {0, 0, 8, 8}));
    EXPECT_TRUE(same(drawnWindow({0, 0, 4, 4}, 8), {0, 0, 5, 5}));
    EXPECT_TRUE(same(drawnWindow({2, 3, 4, 4}, 8), {1, 2, 6, 6}));
    EXPECT_TRUE(same(drawnWindow({4, 4, 4, 4}, 8), {3, 3, 5, 5}));
    EXPECT_TRUE(same(drawnWindow({7, 0, 1, 1}, 8), {6, 0, 2, 2}));
}

TEST(Tiler, CullingKeepsOnlyClustersThatMeetTheTile) {
    BakeMesh mesh;
    addGrid(mesh, -50, -50, 0, 100, 32, 0);
    finishPages(mesh, 1);
    auto clusters = clusterMesh(mesh, 16);
    std::vector<float> importance(mesh.triangles.size(), 1.0f);
    setClusterImportance(mesh, clusters, importance);
    const BundleFrame frame = downFrame(60);
    const auto views = projectClusters(mesh, clusters, frame);
    TilerOptions o;
    o.maxLeafPixels = 64;
    const DirectionTiling culled = tileBundle(clusters, views, frame.size, o);
    o.cull = false;
    const DirectionTiling all = tileBundle(clusters, views, frame.size, o);
    ASSERT_EQ(culled.tiles.size(), all.tiles.size());
    size_t drawnCulled = 0, drawnAll = 0;
    for (size_t i = 0; i < culled.tiles.size(); ++i) {
        drawnCulled += culled.tiles[i].clusters.size();
        drawnAll += all.tiles[i].clusters.size();
        EXPECT_EQ(culled.tiles[i].predictedNodes, all.tiles[i].predictedNodes);
    }
    EXPECT_LT(drawnCulled * 4, drawnAll);
    std::vector<int32_t> first, count;
    clusterRanges(clusters, all.tiles[0].clusters, first, count);
    ASSERT_EQ(first.size(), 1u);  // every cluster: one merged range
    EXPECT_EQ(count[0], int32_t(3 * mesh.triangles.size()));
}

// A run of leaves side by side in one head image (one update over all of
// them, bundle_tracer.h): inside the image, no two overlapping, the image the
// least power of two that holds them; nothing when the limit cannot.
TEST(Tiler, PackedSquaresDoNotOverlapAndFitTheLeastPowerOfTwo) {
    const std::vector<int> sides = {100, 512, 37, 256, 256, 0, 64, 300, 1};
    int side = 0;
    const std::vector<glm::ivec2> at = packSquares(sides, 2048, side);
    ASSERT_EQ(at.size(), sides.size());
    EXPECT_EQ(side, 1024);  // their area (~499000 pixels) is more than 512^2
    for (size_t i = 0; i < sides.size(); ++i) {
        EXPECT_GE(at[i].x, 0);
        EXPECT_GE(at[i].y, 0);
        EXPECT_LE(at[i].x + sides[i], side);
        EXPECT_LE(at[i].y + sides[i], side);
        for (size_t j = 0; j < i; ++j) {
            const bool apart = at[i].x + sides[i] <= at[j].x || at[j].x + sides[j] <= at[i].x ||
                               at[i].y + sides[i] <= at[j].y || at[j].y + sides[j] <= at[i].y;
            EXPECT_TRUE(apart || sides[i] == 0 || sides[j] == 0) << i << " overlaps " << j;
        }
    }
    EXPECT_TRUE(packSquares(sides, 512, side).empty());
    EXPECT_TRUE(packSquares({600}, 512, side).empty());
}

}  // namespace
}  // namespace bb
