#include "tiler/tiler.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/check.h"

namespace bb {
namespace {

// Cluster rectangles are padded by this much (root units) so that float
// differences between the CPU projection here and the shaders' never cull a
// triangle that covers a pixel centre of the tile.
constexpr double RECT_PAD = 1e-6;

// A cluster drawn at its largest I(t) may make at most this many times the
// fragments its triangles would at their own (setClusterImportance).
constexpr double kClusterCost = 2.0;

struct Square {
    double x0, y0, x1, y1;
};

bool meets(const ClusterView& c, const Square& s) {
    return c.rect.x <= s.x1 && c.rect.z >= s.x0 && c.rect.y <= s.y1 && c.rect.w >= s.y0;
}

// Fraction of [a0, a1] inside [b0, b1] (a point: 1 inside, 0 outside).
double fraction1D(double a0, double a1, double b0, double b1) {
    if (a1 - a0 < 1e-15) return a0 >= b0 && a0 < b1 ? 1.0 : 0.0;
    return std::max(0.0, std::min(a1, b1) - std::max(a0, b0)) / (a1 - a0);
}

// Expected fragments of the clusters `ids` inside `s` at `pixelSize`.
double predict(const std::vector<ClusterView>& views, const std::vector<uint32_t>& ids, const Square& s,
               double pixelSizeRoot, double rootSize) {
    double area = 0;
    for (uint32_t i : ids) {
        const ClusterView& c = views[i];
        // the rectangle without its pad, so a cluster split between tiles is shared out exactly
        area += c.projectedArea * fraction1D(c.rect.x + RECT_PAD, c.rect.z - RECT_PAD, s.x0, s.x1) *
                fraction1D(c.rect.y + RECT_PAD, c.rect.w - RECT_PAD, s.y0, s.y1);
    }
    const double pixel = pixelSizeRoot * rootSize;
    return area / (pixel * pixel);
}

std::vector<uint32_t> filter(const std::vector<ClusterView>& views, const std::vector<uint32_t>& ids, const Square& s) {
    std::vector<uint32_t> out;
    for (uint32_t i : ids)
        if (meets(views[i], s)) out.push_back(i);
    return out;
}

Square windowSquare(const BundleLeaf& leaf, const TileWindow& w) {
    const double step = leaf.extent / leaf.pixels;
    return {leaf.min.x + w.x * step, leaf.min.y + w.y * step, leaf.min.x + (w.x + w.width) * step,
            leaf.min.y + (w.y + w.height) * step};
}

struct QuadtreeBuilder {
    const std::vector<Cluster>& clusters;
    const std::vector<ClusterView>& views;
    double rootSize;
    const TilerOptions& o;
    std::vector<BundleLeaf> leaves;
    std::vector<std::vector<uint32_t>> leafClusters;

    // Pixels across a node of `extent` whose largest importance is `imax`.
    int pixelsFor(double extent, float imax) const {
        double side = extent * rootSize;
        double p = o.fixedPixelSize > 0 ? o.fixedPixelSize : pixelForImportance(imax, o.pixelsPerTexel);
        return int(std::max(1.0, std::ceil(side / p - 1e-9)));
    }

    float maxImportance(const std::vector<uint32_t>& ids) const {
        float m = 0;
        for (uint32_t i : ids) m = std::max(m, clusters[i].maxImportance);
        return m;
    }

    // Quarter k (x = k & 1, y = k >> 1) of the node at `min` of side `extent`.
    static glm::dvec2 quarterMin(glm::dvec2 min, double extent, int k) {
        return min + glm::dvec2((k & 1) * 0.5 * extent, (k >> 1) * 0.5 * extent);
    }

    void build(glm::dvec2 min, double extent, int depth, const std::vector<uint32_t>& candidates) {
        const Square s{min.x, min.y, min.x + extent, min.y + extent};
        std::vector<uint32_t> ids = filter(views, candidates, s);
        const float imax = maxImportance(ids);
        if (imax <= 0.0f) return;  // no texel centre here: nothing to update
        const int pixels = pixelsFor(extent, imax);
        if (depth < o.maxDepth && pixels > 1) {
            bool split = pixels > o.maxLeafPixels;
            if (!split && o.fixedPixelSize <= 0 && pixels >= 64) {
                // split where the quarters need coarser pixels and that saves a third of the fragments
                const double here = predict(views, ids, s, extent / pixels, rootSize);
                const double h = 0.5 * extent;
                double quarters = 0;
                for (int k = 0; k < 4; ++k) {
                    const glm::dvec2 m = quarterMin(min, extent, k);
                    const Square q{m.x, m.y, m.x + h, m.y + h};
                    std::vector<uint32_t> sub = filter(views, ids, q);
                    float qmax = maxImportance(sub);
                    if (qmax > 0) quarters += predict(views, sub, q, h / pixelsFor(h, qmax), rootSize);
                }
                split = quarters < (2.0 / 3.0) * here;
            }
            if (split) {
                for (int k = 0; k < 4; ++k) build(quarterMin(min, extent, k), 0.5 * extent, depth + 1, ids);
                return;
            }
        }
        leaves.push_back({min, extent, std::min(pixels, o.maxLeafPixels)});  // (past maxDepth: coarser, never past the viewport)
        leafClusters.push_back(std::move(ids));
    }
};

// A cluster's world bounds from its triangles' vertices.
void setBounds(const BakeMesh& mesh, Cluster& c) {
    c.boundsMin = glm::vec3(3e38f);
    c.boundsMax = glm::vec3(-3e38f);
    for (uint32_t v = 3 * c.first; v < 3 * (c.first + c.count); ++v) {
        c.boundsMin = glm::min(c.boundsMin, glm::vec3(mesh.vertices[v].position));
        c.boundsMax = glm::max(c.boundsMax, glm::vec3(mesh.vertices[v].position));
    }
}

}  // namespace

double pixelForImportance(float importance, double pixelsPerTexel) {
    return 1.0 / (pixelsPerTexel * std::sqrt(double(importance)));
}

std::vector<Cluster> clusterMesh(BakeMesh& mesh, uint32_t maxTriangles) {
    CHECK_GE(maxTriangles, 1u);
    const size_t n = mesh.triangles.size();
    std::vector<glm::vec3> centroid(n);
    for (size_t t = 0; t < n; ++t)
        centroid[t] = (glm::vec3(mesh.vertices[3 * t].position) + glm::vec3(mesh.vertices[3 * t + 1].position) +
                       glm::vec3(mesh.vertices[3 * t + 2].position)) / 3.0f;
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::vector<std::pair<uint32_t, uint32_t>> ranges;  // [begin, end) of order per cluster

    // median split along the longest axis of the centroids' bounds
    auto split = [&](auto&& self, uint32_t begin, uint32_t end) -> void {
        if (end - begin <= maxTriangles) {
            ranges.push_back({begin, end});
            return;
        }
        glm::vec3 lo(3e38f), hi(-3e38f);
        for (uint32_t i = begin; i < end; ++i) {
            lo = glm::min(lo, centroid[order[i]]);
            hi = glm::max(hi, centroid[order[i]]);
        }
        glm::vec3 e = hi - lo;
        int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
        uint32_t mid = begin + (end - begin) / 2;
        std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end, [&](uint32_t a, uint32_t b) {
            float ca = centroid[a][axis], cb = centroid[b][axis];
            return ca != cb ? ca < cb : a < b;
        });
        self(self, begin, mid);
        self(self, mid, end);
    };
    for (size_t p = 0; p + 1 < mesh.pageFirstTriangle.size(); ++p)
        if (mesh.pageFirstTriangle[p + 1] > mesh.pageFirstTriangle[p])
            split(split, mesh.pageFirstTriangle[p], mesh.pageFirstTriangle[p + 1]);

    // reorder triangles and vertices
    std::vector<BakeTriangle> triangles(n);
    std::vector<BakeVertex> vertices(3 * n);
    std::vector<uint32_t> built(mesh.builtIndex.size());
    for (size_t i = 0; i < n; ++i) {
        triangles[i] = mesh.triangles[order[i]];
        for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh.vertices[3 * size_t(order[i]) + k];
        if (!built.empty()) built[i] = mesh.builtIndex[order[i]];
    }
    mesh.triangles = std::move(triangles);
    mesh.vertices = std::move(vertices);
    mesh.builtIndex = std::move(built);

    std::vector<Cluster> clusters;
    clusters.reserve(ranges.size());
    for (auto [begin, end] : ranges) {
        Cluster c;
        c.first = begin;
        c.count = end - begin;
        c.page = mesh.triangles[begin].page;
        setBounds(mesh, c);
        clusters.push_back(c);
    }
    return clusters;
}

void setClusterImportance(BakeMesh& mesh, std::vector<Cluster>& clusters, std::vector<float>& importance) {
    CHECK_EQ(importance.size(), mesh.triangles.size());
    const auto area = [&](uint32_t t) {
        const glm::dvec3 a(mesh.vertices[3 * size_t(t)].position), b(mesh.vertices[3 * size_t(t) + 1].position),
            c(mesh.vertices[3 * size_t(t) + 2].position);
        return 0.5 * glm::length(glm::cross(b - a, c - a));
    };
    std::vector<Cluster> out;
    out.reserve(clusters.size());
    std::vector<uint32_t> order;
    std::vector<BakeTriangle> triangles;
    std::vector<BakeVertex> vertices;
    std::vector<float> values;
    std::vector<uint32_t> built;
    for (const Cluster& cluster : clusters) {
        order.resize(cluster.count);
        std::iota(order.begin(), order.end(), cluster.first);
        // drawn at its largest I, a cluster makes sum A(t) max I fragments
        // where its receivers alone would make sum A(t) I(t): where that is
        // more than kClusterCost times over (a small, finely pixelled prop on
        // a wide floor), its triangles are sorted by I and cut into runs that
        // are not
        double atMax = 0, own = 0;
        float imax = 0;
        for (uint32_t t : order) imax = std::max(imax, importance[t]);
        for (uint32_t t : order)
            if (importance[t] > 0.0f) {
                atMax += area(t) * imax;
                own += area(t) * importance[t];
            }
        const bool mixed = atMax > kClusterCost * own;
        if (mixed)
            std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return importance[a] > importance[b]; });
        else
            std::stable_partition(order.begin(), order.end(), [&](uint32_t t) { return importance[t] > 0.0f; });
        triangles.clear();
        vertices.clear();
        values.clear();
        built.clear();
        for (uint32_t t : order) {
            triangles.push_back(mesh.triangles[t]);
            for (int k = 0; k < 3; ++k) vertices.push_back(mesh.vertices[3 * size_t(t) + k]);
            values.push_back(importance[t]);
            if (!mesh.builtIndex.empty()) built.push_back(mesh.builtIndex[t]);
        }
        std::copy(triangles.begin(), triangles.end(), mesh.triangles.begin() + cluster.first);
        std::copy(vertices.begin(), vertices.end(), mesh.vertices.begin() + 3 * size_t(cluster.first));
        std::copy(values.begin(), values.end(), importance.begin() + cluster.first);
        if (!built.empty()) std::copy(built.begin(), built.end(), mesh.builtIndex.begin() + cluster.first);

        // runs [first, first + count): receivers first, then the triangles that only occlude
        Cluster c = cluster;
        c.count = 0;
        c.maxImportance = 0.0f;
        c.receivers = 0;
        atMax = own = 0;
        for (uint32_t t = cluster.first; t < cluster.first + cluster.count; ++t) {
            const float i = importance[t];
            const double a = i > 0.0f ? area(t) : 0.0;
            if (mixed && c.receivers > 0 && i > 0.0f && (atMax + a * c.maxImportance) > kClusterCost * (own + a * i)) {
                setBounds(mesh, c);
                out.push_back(c);
                c.first = t;
                c.count = 0;
                c.maxImportance = 0.0f;
                c.receivers = 0;
                atMax = own = 0;
            }
            c.maxImportance = std::max(c.maxImportance, i);
            c.receivers += i > 0.0f;
            atMax += a * c.maxImportance;
            own += a * i;
            ++c.count;
        }
        setBounds(mesh, c);
        out.push_back(c);
    }
    clusters = std::move(out);
}

std::vector<ClusterView> projectClusters(const BakeMesh& mesh, const std::vector<Cluster>& clusters,
                                         const BundleFrame& f) {
    std::vector<ClusterView> views(clusters.size());
    const glm::dvec3 d(f.dir), u(f.u), v(f.v);
    for (size_t i = 0; i < clusters.size(); ++i) {
        const Cluster& c = clusters[i];
        glm::dvec2 lo(1e300), hi(-1e300);
        for (int k = 0; k < 8; ++k) {
            glm::dvec3 p((k & 1) ? c.boundsMax.x : c.boundsMin.x, (k & 2) ? c.boundsMax.y : c.boundsMin.y,
                         (k & 4) ? c.boundsMax.z : c.boundsMin.z);
            glm::dvec2 q((glm::dot(p, u) - f.origin.x) / f.size, (glm::dot(p, v) - f.origin.y) / f.size);
            lo = glm::min(lo, q);
            hi = glm::max(hi, q);
        }
        views[i].rect = glm::dvec4(lo.x - RECT_PAD, lo.y - RECT_PAD, hi.x + RECT_PAD, hi.y + RECT_PAD);
        double area = 0;
        for (uint32_t t = c.first; t < c.first + c.count; ++t) {
            glm::dvec3 a(mesh.vertices[3 * size_t(t)].position), b(mesh.vertices[3 * size_t(t) + 1].position),
                cc(mesh.vertices[3 * size_t(t) + 2].position);
            // a double-sided fragment can be two nodes (its sides' radiance, glsl/bundle/append.frag)
            const double sides = (mesh.triangles[t].flags & TRIANGLE_DOUBLE_SIDED) ? 2.0 : 1.0;
            area += sides * 0.5 * std::abs(glm::dot(glm::cross(b - a, cc - a), d));
        }
        views[i].projectedArea = area;
    }
    return views;
}

TileWindow drawnWindow(const TileWindow& w, int leafPixels) {
    const int x0 = std::max(w.x - 1, 0), y0 = std::max(w.y - 1, 0);
    const int x1 = std::min(w.x + w.width + 1, leafPixels), y1 = std::min(w.y + w.height + 1, leafPixels);
    return {x0, y0, x1 - x0, y1 - y0};
}

Tile makeTile(const DirectionTiling& tiling, int leaf, const TileWindow& window, const std::vector<Cluster>& clusters,
              const std::vector<ClusterView>& views, const std::vector<uint32_t>& candidates, bool cull) {
    const BundleLeaf& l = tiling.leaves[size_t(leaf)];
    const Square s = windowSquare(l, drawnWindow(window, l.pixels));
    Tile t;
    t.leaf = leaf;
    t.window = window;
    std::vector<uint32_t> met = filter(views, candidates, s);
    t.predictedNodes = predict(views, met, s, l.extent / l.pixels, tiling.sceneSize);
    if (cull) {
        t.clusters = std::move(met);
    } else {
        t.clusters.resize(clusters.size());
        std::iota(t.clusters.begin(), t.clusters.end(), 0u);
    }
    return t;
}

std::vector<glm::ivec2> packSquares(const std::vector<int>& sides, int maxSide, int& side) {
    std::vector<size_t> order(sides.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return sides[a] > sides[b]; });
    const int largest = sides.empty() ? 1 : sides[order[0]];
    for (side = 1; side < largest;) side *= 2;
    for (; side <= maxSide; side *= 2) {
        std::vector<glm::ivec2> origins(sides.size());
        int x = 0, y = 0, shelf = 0;  // the shelf's height: its first (largest) square's side
        bool fits = true;
        for (size_t i : order) {
            if (x + sides[i] > side) {
                x = 0;
                y += shelf;
                shelf = 0;
            }
            if (shelf == 0) shelf = sides[i];
            if (y + sides[i] > side) {
                fits = false;
                break;
            }
            origins[i] = {x, y};
            x += sides[i];
        }
        if (fits) return origins;
    }
    return {};
}

std::vector<TileWindow> splitWindow(const TileWindow& w) {
    std::vector<TileWindow> out;
    const int hw = std::max(1, w.width / 2), hh = std::max(1, w.height / 2);
    for (int k = 0; k < 4; ++k) {
        TileWindow q{w.x + (k & 1) * hw, w.y + (k >> 1) * hh, (k & 1) ? w.width - hw : hw, (k >> 1) ? w.height - hh : hh};
        if (q.width > 0 && q.height > 0) out.push_back(q);
    }
    return out;
}

DirectionTiling tileBundle(const std::vector<Cluster>& clusters, const std::vector<ClusterView>& views, double rootSize,
                           const TilerOptions& o) {
    CHECK_EQ(clusters.size(), views.size());
    DirectionTiling tiling;
    tiling.sceneSize = rootSize;
    std::vector<uint32_t> all(clusters.size());
    std::iota(all.begin(), all.end(), 0u);

    QuadtreeBuilder qb{clusters, views, rootSize, o, {}, {}};
    if (o.uniform) {
        CHECK_GT(o.fixedPixelSize, 0.0);
        qb.leaves.push_back({glm::dvec2(0.0), 1.0, qb.pixelsFor(1.0, 1.0f)});
        qb.leafClusters.push_back(all);
    } else {
        qb.build(glm::dvec2(0.0), 1.0, 0, all);
    }
    tiling.leaves = std::move(qb.leaves);

    // windows: at most maxTilePixels across, split until the prediction fits
    for (size_t l = 0; l < tiling.leaves.size(); ++l) {
        const int w = tiling.leaves[l].pixels;
        // (a leaf wider than a tile: tiles two pixels narrower, so that their aprons fit)
        const int step = w <= o.maxTilePixels ? w : std::max(1, o.maxTilePixels - 2);
        std::vector<TileWindow> work;
        for (int y = w - (w - 1) % step - 1; y >= 0; y -= step)  // reverse, so popping from the back goes in row order
            for (int x = w - (w - 1) % step - 1; x >= 0; x -= step)
                work.push_back({x, y, std::min(step, w - x), std::min(step, w - y)});
        while (!work.empty()) {
            TileWindow win = work.back();
            work.pop_back();
            Tile t = makeTile(tiling, int(l), win, clusters, views, qb.leafClusters[l], o.cull);
            if (t.predictedNodes > o.fill * o.nodeCapacity && (win.width > 1 || win.height > 1)) {
                auto quarters = splitWindow(win);
                for (auto it = quarters.rbegin(); it != quarters.rend(); ++it) work.push_back(*it);
                continue;
            }
            tiling.tiles.push_back(std::move(t));
        }
    }
    return tiling;
}

void clusterRanges(const std::vector<Cluster>& clusters, const std::vector<uint32_t>& tileClusters,
                   std::vector<int32_t>& firstVertex, std::vector<int32_t>& vertexCount, bool receiversOnly) {
    firstVertex.clear();
    vertexCount.clear();
    for (uint32_t i : tileClusters) {
        const Cluster& c = clusters[i];
        const uint32_t n = receiversOnly ? c.receivers : c.count;
        appendDrawRange(firstVertex, vertexCount, int32_t(3 * c.first), int32_t(3 * n));
    }
}

void appendDrawRange(std::vector<int32_t>& first, std::vector<int32_t>& count, int32_t rangeFirst, int32_t rangeCount) {
    if (rangeCount == 0) return;
    if (!first.empty() && first.back() + count.back() == rangeFirst)
        count.back() += rangeCount;
    else {
        first.push_back(rangeFirst);
        count.push_back(rangeCount);
    }
}

}  // namespace bb
