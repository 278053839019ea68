// Light map UV generation: charts, parameterisation, packing on a texel grid.
//
// Based on:
//   - Lévy, Petitjean, Ray, Maillot, "Least Squares Conformal Maps for
//     Automatic Texture Atlas Generation", SIGGRAPH 2002 (LSCM, two pinned
//     vertices; solved here as sparse least squares by its normal equations
//     with Eigen's SimplicialLDLT).
//   - Sander, Snyder, Gortler, Hoppe, "Texture Mapping Progressive Meshes",
//     SIGGRAPH 2001 (the L2 stretch figure).
//   - Charts grown breadth-first from seeds (largest triangle first) under a
//     hard-edge angle and a normal cone, as chart building in Unity's and
//     xatlas's unwrappers starts; the cone keeps every chart a height field
//     over its mean plane, so a planar projection of it cannot fold locally.
//   - Freeman, Shapira, "Determining the minimum-area encasing rectangle for
//     an arbitrary closed curve", CACM 1975 (a side lies on a hull edge).
//   - Next-fit decreasing height shelf packing (Coffman et al. 1980).
#include "layout/uv_generate.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <unordered_map>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "core/check.h"

namespace bb {
namespace {

constexpr double PI = 3.14159265358979323846;
// Charts whose normals all lie within this angle of their mean are flat: a
// planar projection is exact (stretch 1 + 1.5e-4 at most), no solve.
constexpr double FLAT_COS = 0.99985;  // cos 1 degree
// Hull edges tried for the smallest bounding rectangle (the longest ones).
constexpr size_t MAX_HULL_EDGES = 256;

// The mesh's triangles over all primitives, welded by position, with
// edge adjacency in metric space.
struct Topology {
    std::vector<uint32_t> firstTri;     // per primitive: its first global triangle
    std::vector<uint32_t> firstVertex;  // per primitive: its first global vertex
    std::vector<uint32_t> primOf;       // per global triangle
    std::vector<glm::dvec3> point;      // per welded vertex: metric position
    std::vector<uint32_t> corner;       // 3 per triangle: welded vertex
    std::vector<int32_t> neighbour;     // 3 per triangle: across edge (k, k+1); -1 none
    std::vector<glm::dvec3> normal;     // per triangle: unit face normal (0 if degenerate)
    std::vector<double> area;           // per triangle, metric
    size_t triangleCount() const { return primOf.size(); }
};

uint32_t floatBits(float f) {
    f += 0.0f;  // -0 -> +0: one position, one vertex
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

Topology buildTopology(const Mesh& mesh, const glm::dmat3& metricFromObject) {
    Topology topo;
    size_t nv = 0, nt = 0;
    for (const Primitive& prim : mesh.primitives) {
        topo.firstVertex.push_back(uint32_t(nv));
        topo.firstTri.push_back(uint32_t(nt));
        nv += prim.positions.size();
        nt += prim.triangleCount();
    }
    // weld: sort every vertex by its position's bits
    struct Key {
        uint32_t x, y, z, v;
    };
    std::vector<Key> keys;
    keys.reserve(nv);
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        const auto& pos = mesh.primitives[p].positions;
        for (size_t v = 0; v < pos.size(); ++v)
            keys.push_back({floatBits(pos[v].x), floatBits(pos[v].y), floatBits(pos[v].z),
                            uint32_t(topo.firstVertex[p] + v)});
    }
    std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
        if (a.x != b.x) return a.x < b.x;
        if (a.y != b.y) return a.y < b.y;
        if (a.z != b.z) return a.z < b.z;
        return a.v < b.v;
    });
    std::vector<uint32_t> weld(nv);
    std::vector<uint32_t> welded;  // a global vertex per welded id
    for (size_t i = 0; i < keys.size(); ++i) {
        if (i == 0 || keys[i].x != keys[i - 1].x || keys[i].y != keys[i - 1].y || keys[i].z != keys[i - 1].z)
            welded.push_back(keys[i].v);
        weld[keys[i].v] = uint32_t(welded.size() - 1);
    }
    std::vector<uint32_t> primOfVertex(nv);
    for (size_t p = 0; p < mesh.primitives.size(); ++p)
        std::fill(primOfVertex.begin() + topo.firstVertex[p],
                  primOfVertex.begin() + topo.firstVertex[p] + mesh.primitives[p].positions.size(), uint32_t(p));
    topo.point.resize(welded.size());
    for (size_t w = 0; w < welded.size(); ++w) {
        const uint32_t g = welded[w], p = primOfVertex[g];
        topo.point[w] = metricFromObject * glm::dvec3(mesh.primitives[p].positions[g - topo.firstVertex[p]]);
    }

    topo.primOf.resize(nt);
    topo.corner.resize(3 * nt);
    topo.normal.resize(nt);
    topo.area.resize(nt);
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        const Primitive& prim = mesh.primitives[p];
        for (size_t t = 0; t < prim.triangleCount(); ++t) {
            const size_t g = topo.firstTri[p] + t;
            topo.primOf[g] = uint32_t(p);
            for (int k = 0; k < 3; ++k) {
                const uint32_t index = prim.indices[3 * t + size_t(k)];
                CHECK_LT(size_t(index), prim.positions.size());
                topo.corner[3 * g + size_t(k)] = weld[topo.firstVertex[p] + index];
            }
            const glm::dvec3 a = topo.point[topo.corner[3 * g]], b = topo.point[topo.corner[3 * g + 1]],
                             c = topo.point[topo.corner[3 * g + 2]];
            const glm::dvec3 n = glm::cross(b - a, c - a);
            const double len = glm::length(n);
            topo.area[g] = 0.5 * len;
            topo.normal[g] = len > 0.0 && std::isfinite(len) ? n / len : glm::dvec3(0.0);
        }
    }

    // adjacency: an edge joins exactly two triangles that walk it in opposite
    // directions (consistently oriented); other edges (borders, non-manifold,
    // flipped neighbours) join nothing
    struct Edge {
        uint64_t key;
        uint32_t tri;
        uint8_t k;
        uint8_t forward;
    };
    std::vector<Edge> edges;
    edges.reserve(3 * nt);
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = topo.corner[3 * t + size_t(k)], b = topo.corner[3 * t + size_t((k + 1) % 3)];
            if (a == b) continue;
            const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            edges.push_back({key, uint32_t(t), uint8_t(k), uint8_t(a < b)});
        }
    std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
        if (a.key != b.key) return a.key < b.key;
        if (a.tri != b.tri) return a.tri < b.tri;
        return a.k < b.k;
    });
    topo.neighbour.assign(3 * nt, -1);
    for (size_t i = 0; i < edges.size();) {
        size_t j = i;
        while (j < edges.size() && edges[j].key == edges[i].key) ++j;
        if (j - i == 2 && edges[i].forward != edges[i + 1].forward && edges[i].tri != edges[i + 1].tri) {
            topo.neighbour[3 * size_t(edges[i].tri) + edges[i].k] = int32_t(edges[i + 1].tri);
            topo.neighbour[3 * size_t(edges[i + 1].tri) + edges[i + 1].k] = int32_t(edges[i].tri);
        }
        i = j;
    }
    return topo;
}

// Charts grown breadth-first from the largest available triangle among
// `candidates` (mark -1; growing sets mark to >= 0): a neighbour joins while
// its normal is within the hard angle of the triangle it is reached from and
// within the cone of the seed's normal, up to maxTriangles. Chart c's
// triangles get mark base + c (bases differ between calls: marks stay unique).
std::vector<std::vector<uint32_t>> growCharts(const Topology& topo, std::vector<uint32_t> candidates,
                                              std::vector<int32_t>& mark, double cosHard, double cosCone,
                                              size_t maxTriangles, int32_t base, std::vector<uint32_t>* seeds) {
    std::stable_sort(candidates.begin(), candidates.end(),
                     [&](uint32_t a, uint32_t b) { return topo.area[a] > topo.area[b]; });
    std::vector<std::vector<uint32_t>> charts;
    for (uint32_t seed : candidates) {
        if (mark[seed] >= 0) continue;
        const int32_t c = base + int32_t(charts.size());
        const glm::dvec3 n0 = topo.normal[seed];
        std::vector<uint32_t> queue(1, seed);
        mark[seed] = c;
        for (size_t head = 0; head < queue.size() && queue.size() < maxTriangles; ++head) {
            const uint32_t t = queue[head];
            for (int k = 0; k < 3 && queue.size() < maxTriangles; ++k) {
                const int32_t u = topo.neighbour[3 * size_t(t) + size_t(k)];
                if (u < 0 || mark[size_t(u)] != -1) continue;
                const glm::dvec3& nu = topo.normal[size_t(u)];
                if (glm::dot(nu, topo.normal[t]) < cosHard || glm::dot(nu, n0) < cosCone) continue;
                mark[size_t(u)] = c;
                queue.push_back(uint32_t(u));
            }
        }
        std::sort(queue.begin(), queue.end());  // mesh order
        charts.push_back(std::move(queue));
        if (seeds) seeds->push_back(seed);
    }
    return charts;
}

// Growing leaves slivers of triangles between charts (outside one chart's
// cone, too few for their own): from the smallest up, a chart joins the
// neighbour (no smaller) it shares the most soft edges with, if that
// neighbour's seed cone holds all its triangles. `mark`: base + chart per
// triangle (as growCharts left them; other marks are other calls' charts).
void mergeSmallCharts(const Topology& topo, std::vector<std::vector<uint32_t>>& charts,
                      const std::vector<uint32_t>& seeds, std::vector<int32_t>& mark, double cosHard, double cosCone,
                      size_t maxTriangles, int32_t base) {
    std::vector<uint32_t> order(charts.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return charts[a].size() < charts[b].size(); });
    std::vector<uint32_t> shared(charts.size(), 0);
    std::vector<uint32_t> touched;
    for (uint32_t c : order) {
        if (charts[c].empty()) continue;
        touched.clear();
        for (uint32_t t : charts[c])
            for (int k = 0; k < 3; ++k) {
                const int32_t u = topo.neighbour[3 * size_t(t) + size_t(k)];
                if (u < 0) continue;
                const int64_t m = int64_t(mark[size_t(u)]) - base;
                if (m < 0 || m >= int64_t(charts.size())) continue;
                const uint32_t d = uint32_t(m);
                if (d == c || glm::dot(topo.normal[t], topo.normal[size_t(u)]) < cosHard) continue;
                if (shared[d]++ == 0) touched.push_back(d);
            }
        uint32_t best = c, bestShared = 0;
        for (uint32_t d : touched) {
            if (charts[d].size() >= charts[c].size() && charts[d].size() + charts[c].size() <= maxTriangles &&
                (shared[d] > bestShared || (shared[d] == bestShared && d < best))) {
                bool inCone = true;
                const glm::dvec3 n0 = topo.normal[seeds[d]];
                for (uint32_t t : charts[c]) inCone = inCone && glm::dot(topo.normal[t], n0) >= cosCone;
                if (inCone) best = d, bestShared = shared[d];
            }
        }
        for (uint32_t d : touched) shared[d] = 0;
        if (best == c) continue;
        for (uint32_t t : charts[c]) mark[t] = base + int32_t(best);
        charts[best].insert(charts[best].end(), charts[c].begin(), charts[c].end());
        std::sort(charts[best].begin(), charts[best].end());
        charts[c].clear();
    }
    charts.erase(std::remove_if(charts.begin(), charts.end(), [](const auto& c) { return c.empty(); }), charts.end());
}

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// L2 stretch of a flattening (Sander et al. 2001), normalised for scale:
// sqrt(sum A3 * (|S_s|^2 + |S_t|^2) / 2 / sum A3) * sqrt(sum A2 / sum A3);
// infinity if a triangle is flipped or degenerate in 2D.
double l2Stretch(const std::vector<glm::dvec3>& q, const std::vector<glm::dvec2>& p, const std::vector<uint32_t>& tri) {
    double sum = 0.0, a3 = 0.0, a2 = 0.0;
    for (size_t t = 0; t + 2 < tri.size(); t += 3) {
        const glm::dvec3 &q0 = q[tri[t]], &q1 = q[tri[t + 1]], &q2 = q[tri[t + 2]];
        const glm::dvec2 &p0 = p[tri[t]], &p1 = p[tri[t + 1]], &p2 = p[tri[t + 2]];
        const double area3 = 0.5 * glm::length(glm::cross(q1 - q0, q2 - q0));
        const double twice2 = cross2(p1 - p0, p2 - p0);
        if (area3 <= 0.0) continue;
        if (!(twice2 > 0.0)) return INFINITY;
        const glm::dvec3 ss = (q0 * (p1.y - p2.y) + q1 * (p2.y - p0.y) + q2 * (p0.y - p1.y)) / twice2;
        const glm::dvec3 st = (q0 * (p2.x - p1.x) + q1 * (p0.x - p2.x) + q2 * (p1.x - p0.x)) / twice2;
        sum += area3 * 0.5 * (glm::dot(ss, ss) + glm::dot(st, st));
        a3 += area3;
        a2 += 0.5 * twice2;
    }
    if (!(a3 > 0.0) || !(a2 > 0.0)) return 1.0;
    return std::sqrt(sum / a3) * std::sqrt(a2 / a3);
}

// LSCM with two pinned vertices (their values kept from `uv`, the planar
// projection). Returns false if the solve fails or flips a triangle.
bool solveLscm(const std::vector<glm::dvec3>& q, const std::vector<uint32_t>& tri, std::vector<glm::dvec2>& uv) {
    const size_t n = q.size(), m = tri.size() / 3;
    if (n < 3 || m < 2) return false;
    // pins: the extreme vertices along the projection's longer axis
    glm::dvec2 lo(INFINITY), hi(-INFINITY);
    for (const glm::dvec2& p : uv) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const int axis = (hi.x - lo.x) >= (hi.y - lo.y) ? 0 : 1;
    size_t pinA = 0, pinB = 0;
    for (size_t i = 1; i < n; ++i) {
        if (uv[i][axis] < uv[pinA][axis]) pinA = i;
        if (uv[i][axis] > uv[pinB][axis]) pinB = i;
    }
    if (pinA == pinB) return false;
    // unknowns: u of free vertices then v of free vertices
    std::vector<int32_t> freeIndex(n, -1);
    int32_t nf = 0;
    for (size_t i = 0; i < n; ++i)
        if (i != pinA && i != pinB) freeIndex[i] = nf++;
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(m * 12);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(Eigen::Index(2 * m));
    for (size_t t = 0; t < m; ++t) {
        const uint32_t idx[3] = {tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]};
        // the triangle in its own frame, counter-clockwise about its normal
        const glm::dvec3 e1 = q[idx[1]] - q[idx[0]], e2 = q[idx[2]] - q[idx[0]];
        const glm::dvec3 nrm = glm::cross(e1, e2);
        const double len1 = glm::length(e1), lenN = glm::length(nrm);
        if (!(len1 > 0.0) || !(lenN > 0.0)) continue;
        const glm::dvec3 x = e1 / len1, y = glm::cross(nrm / lenN, x);
        const glm::dvec2 z[3] = {glm::dvec2(0.0), glm::dvec2(len1, 0.0), glm::dvec2(glm::dot(e2, x), glm::dot(e2, y))};
        const double area = 0.5 * cross2(z[1], z[2]);
        const double w = 1.0 / (2.0 * std::sqrt(area));  // sqrt(A) / (2A)
        for (int j = 0; j < 3; ++j) {
            // gradient of the hat function of vertex j, times sqrt(A)
            const glm::dvec2 e = z[(j + 2) % 3] - z[(j + 1) % 3];
            const glm::dvec2 g(-e.y * w, e.x * w);
            // rows: u_x - v_y = 0, u_y + v_x = 0
            const double cu[2] = {g.x, g.y}, cv[2] = {-g.y, g.x};
            const int32_t f = freeIndex[idx[j]];
            for (int r = 0; r < 2; ++r) {
                const Eigen::Index row = Eigen::Index(2 * t + size_t(r));
                if (f >= 0) {
                    triplets.emplace_back(row, f, cu[r]);
                    triplets.emplace_back(row, nf + f, cv[r]);
                } else {
                    rhs[row] -= cu[r] * uv[idx[j]].x + cv[r] * uv[idx[j]].y;
                }
            }
        }
    }
    Eigen::SparseMatrix<double> a(Eigen::Index(2 * m), Eigen::Index(2 * nf));
    a.setFromTriplets(triplets.begin(), triplets.end());
    const Eigen::SparseMatrix<double> at = a.transpose();
    const Eigen::SparseMatrix<double> normal = at * a;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
    if (solver.info() != Eigen::Success) return false;
    const Eigen::VectorXd x = solver.solve(at * rhs);
    if (solver.info() != Eigen::Success) return false;
    std::vector<glm::dvec2> out = uv;
    for (size_t i = 0; i < n; ++i) {
        const int32_t f = freeIndex[i];
        if (f < 0) continue;
        out[i] = glm::dvec2(x[f], x[nf + f]);
        if (!std::isfinite(out[i].x) || !std::isfinite(out[i].y)) return false;
    }
    for (size_t t = 0; t < m; ++t)
        if (!(cross2(out[tri[3 * t + 1]] - out[tri[3 * t]], out[tri[3 * t + 2]] - out[tri[3 * t]]) > 0.0)) return false;
    uv.swap(out);
    return true;
}

// Convex hull (Andrew's monotone chain), counter-clockwise, no repeated end.
std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> p) {
    std::sort(p.begin(), p.end(), [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    p.erase(std::unique(p.begin(), p.end()), p.end());
    if (p.size() < 3) return p;
    std::vector<glm::dvec2> h(2 * p.size());
    size_t k = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && cross2(h[k - 1] - h[k - 2], p[i] - h[k - 2]) <= 0.0) --k;
        h[k++] = p[i];
    }
    for (size_t i = p.size() - 1, lower = k + 1; i > 0; --i) {
        while (k >= lower && cross2(h[k - 1] - h[k - 2], p[i - 1] - h[k - 2]) <= 0.0) --k;
        h[k++] = p[i - 1];
    }
    h.resize(k - 1);
    return h;
}

// Rotates `uv` (a rotation, never a mirror) to its smallest bounding
// rectangle, wider than tall, lower-left corner at the origin; returns the size.
glm::dvec2 orient(std::vector<glm::dvec2>& uv) {
    const std::vector<glm::dvec2> hull = convexHull(uv);
    // candidate directions: the hull's edges, the longest first
    std::vector<std::pair<double, glm::dvec2>> dirs;
    for (size_t i = 0; i < hull.size(); ++i) {
        const glm::dvec2 e = hull[(i + 1) % hull.size()] - hull[i];
        const double len = glm::length(e);
        if (len > 0.0) dirs.push_back({len, e / len});
    }
    if (dirs.size() > MAX_HULL_EDGES) {
        std::partial_sort(dirs.begin(), dirs.begin() + MAX_HULL_EDGES, dirs.end(),
                          [](const auto& a, const auto& b) { return a.first > b.first; });
        dirs.resize(MAX_HULL_EDGES);
    }
    glm::dvec2 best(1.0, 0.0);
    double bestArea = INFINITY;
    for (const auto& [len, d] : dirs) {
        glm::dvec2 lo(INFINITY), hi(-INFINITY);
        for (const glm::dvec2& p : hull) {
            const glm::dvec2 r(glm::dot(p, d), cross2(d, p));
            lo = glm::min(lo, r);
            hi = glm::max(hi, r);
        }
        const double area = (hi.x - lo.x) * (hi.y - lo.y);
        if (area < bestArea * (1.0 - 1e-9)) bestArea = area, best = d;
    }
    // rotate by -angle(best): x' = d.p, y' = d x p (a rotation)
    glm::dvec2 lo(INFINITY), hi(-INFINITY);
    for (glm::dvec2& p : uv) {
        p = glm::dvec2(glm::dot(p, best), cross2(best, p));
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    glm::dvec2 size = hi - lo;
    const bool turn = size.y > size.x;  // a quarter turn: (x, y) -> (y, -x)
    for (glm::dvec2& p : uv) {
        p -= lo;
        if (turn) p = glm::dvec2(p.y, size.x - p.x);
    }
    if (turn) size = glm::dvec2(size.y, size.x);
    return size;
}

// True if two triangles of a flattened chart overlap (interiors meet by more
// than a 1e-7 fraction of the chart's size; neighbours only touch). A
// uniform grid over the chart limits the pairs tested.
bool selfOverlaps(const std::vector<glm::dvec2>& uv, const std::vector<uint32_t>& tri) {
    const size_t m = tri.size() / 3;
    if (m < 2) return false;
    glm::dvec2 lo(INFINITY), hi(-INFINITY);
    for (const glm::dvec2& p : uv) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const glm::dvec2 size = hi - lo;
    const double eps = 1e-7 * std::max(size.x, size.y);
    const int g = std::clamp(int(std::sqrt(double(m))), 1, 512);
    const glm::dvec2 cell = glm::max(size / double(g), glm::dvec2(1e-300));
    auto cellOf = [&](const glm::dvec2& p) {
        return glm::clamp(glm::ivec2((p - lo) / cell), glm::ivec2(0), glm::ivec2(g - 1));
    };
    std::vector<glm::ivec4> box(m);  // cell range per triangle
    std::vector<uint32_t> first(size_t(g) * size_t(g) + 1, 0);
    for (size_t t = 0; t < m; ++t) {
        const glm::dvec2 &a = uv[tri[3 * t]], &b = uv[tri[3 * t + 1]], &c = uv[tri[3 * t + 2]];
        const glm::ivec2 c0 = cellOf(glm::min(a, glm::min(b, c))), c1 = cellOf(glm::max(a, glm::max(b, c)));
        box[t] = glm::ivec4(c0, c1);
        for (int y = c0.y; y <= c1.y; ++y)
            for (int x = c0.x; x <= c1.x; ++x) ++first[size_t(y) * size_t(g) + size_t(x) + 1];
    }
    for (size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
    std::vector<uint32_t> cursor(first.begin(), first.end() - 1), items(first.back());
    for (size_t t = 0; t < m; ++t)
        for (int y = box[t].y; y <= box[t].w; ++y)
            for (int x = box[t].x; x <= box[t].z; ++x) items[cursor[size_t(y) * size_t(g) + size_t(x)]++] = uint32_t(t);
    auto separated = [&](size_t a, size_t b) {
        const glm::dvec2 pa[3] = {uv[tri[3 * a]], uv[tri[3 * a + 1]], uv[tri[3 * a + 2]]};
        const glm::dvec2 pb[3] = {uv[tri[3 * b]], uv[tri[3 * b + 1]], uv[tri[3 * b + 2]]};
        for (int side = 0; side < 2; ++side) {
            const glm::dvec2* p = side == 0 ? pa : pb;
            for (int k = 0; k < 3; ++k) {
                const glm::dvec2 e = p[(k + 1) % 3] - p[k];
                const double len = glm::length(e);
                if (!(len > 0.0)) continue;
                const glm::dvec2 axis(-e.y / len, e.x / len);
                double minA = INFINITY, maxA = -INFINITY, minB = INFINITY, maxB = -INFINITY;
                for (int j = 0; j < 3; ++j) {
                    const double da = glm::dot(pa[j], axis), db = glm::dot(pb[j], axis);
                    minA = std::min(minA, da), maxA = std::max(maxA, da);
                    minB = std::min(minB, db), maxB = std::max(maxB, db);
                }
                if (maxA <= minB + eps || maxB <= minA + eps) return true;
            }
        }
        return false;
    };
    for (size_t c = 0; c + 1 < first.size(); ++c)
        for (uint32_t i = first[c]; i < first[c + 1]; ++i)
            for (uint32_t j = i + 1; j < first[c + 1]; ++j)
                if (!separated(items[i], items[j])) return true;
    return false;
}

struct ChartShape {
    glm::dvec2 extent{0.0};
    double area = 0.0;
    double stretch = 1.0;
    bool lscm = false;
};

// Flattens one chart: `local` are its welded vertices, `tri` its triangles
// as local indices; fills `uv` (per local vertex).
ChartShape flattenChart(const Topology& topo, const std::vector<uint32_t>& triangles, const std::vector<uint32_t>& local,
                        const std::vector<uint32_t>& tri, std::vector<glm::dvec2>& uv, bool allowLscm) {
    ChartShape shape;
    glm::dvec3 mean(0.0);
    for (uint32_t t : triangles) {
        mean += topo.area[t] * topo.normal[t];
        shape.area += topo.area[t];
    }
    const double meanLen = glm::length(mean);
    mean = meanLen > 0.0 ? mean / meanLen : topo.normal[triangles[0]];
    if (glm::length(mean) == 0.0) mean = glm::dvec3(0.0, 0.0, 1.0);
    double minCos = 1.0;
    for (uint32_t t : triangles) minCos = std::min(minCos, glm::dot(topo.normal[t], mean));
    // planar projection on the mean plane (e1, e2, mean right-handed)
    const glm::dvec3 helper = std::abs(mean.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 e1 = glm::normalize(glm::cross(helper, mean)), e2 = glm::cross(mean, e1);
    std::vector<glm::dvec3> q(local.size());
    const glm::dvec3 base = topo.point[local[0]];
    uv.resize(local.size());
    for (size_t i = 0; i < local.size(); ++i) {
        q[i] = topo.point[local[i]] - base;
        uv[i] = glm::dvec2(glm::dot(q[i], e1), glm::dot(q[i], e2));
    }
    shape.stretch = l2Stretch(q, uv, tri);
    if (allowLscm && minCos < FLAT_COS) {
        std::vector<glm::dvec2> conformal = uv;
        if (solveLscm(q, tri, conformal)) {
            const double s = l2Stretch(q, conformal, tri);
            if (s < shape.stretch) {
                uv.swap(conformal);
                shape.stretch = s;
                shape.lscm = true;
            }
        }
    }
    // equal area: one texel density over every chart
    double area2 = 0.0;
    for (size_t t = 0; t + 2 < tri.size(); t += 3)
        area2 += 0.5 * std::abs(cross2(uv[tri[t + 1]] - uv[tri[t]], uv[tri[t + 2]] - uv[tri[t]]));
    if (area2 > 0.0 && shape.area > 0.0) {
        const double s = std::sqrt(shape.area / area2);
        for (glm::dvec2& p : uv) p *= s;
    }
    shape.extent = orient(uv);
    return shape;
}

}  // namespace

MeshCharts makeCharts(Mesh& mesh, const glm::dmat3& metricFromObject, const UvChartOptions& options) {
    const Topology topo = buildTopology(mesh, metricFromObject);
    const size_t nt = topo.triangleCount();
    const double cosHard = std::cos(double(options.hardAngleDegrees) * PI / 180.0);
    const double cone = double(options.coneAngleDegrees) * PI / 180.0;
    const size_t maxTriangles = size_t(std::max(1, options.maxChartTriangles));
    std::vector<int32_t> mark(nt, -1);
    std::vector<uint32_t> all(nt);
    std::iota(all.begin(), all.end(), 0u);

    // charts to flatten; one that folds over itself (or flips a triangle) is
    // grown again inside with half the cone, or half the size when that does
    // not cut it, and its parts queued
    struct Work {
        std::vector<uint32_t> triangles;
        double cone;
        size_t maxTriangles;
    };
    std::vector<Work> work;
    int32_t nextMark = 0;  // the next chart mark (unique over every growCharts call)
    {
        std::vector<uint32_t> seeds;
        auto grown = growCharts(topo, all, mark, cosHard, std::cos(cone), maxTriangles, 0, &seeds);
        nextMark = int32_t(grown.size());
        mergeSmallCharts(topo, grown, seeds, mark, cosHard, std::cos(cone), maxTriangles, 0);
        for (auto& c : grown) work.push_back({std::move(c), cone, maxTriangles});
    }

    MeshCharts charts;
    std::vector<int32_t> chartOf(nt, -1);
    std::vector<glm::dvec2> cornerUv(3 * nt);
    std::vector<int32_t> localOf(topo.point.size(), -1);
    std::vector<uint32_t> local, tri;
    std::vector<glm::dvec2> uv;
    for (size_t w = 0; w < work.size(); ++w) {
        const std::vector<uint32_t> triangles = std::move(work[w].triangles);
        local.clear();
        tri.clear();
        for (uint32_t t : triangles)
            for (int k = 0; k < 3; ++k) {
                const uint32_t v = topo.corner[3 * size_t(t) + size_t(k)];
                if (localOf[v] < 0) {
                    localOf[v] = int32_t(local.size());
                    local.push_back(v);
                }
                tri.push_back(uint32_t(localOf[v]));
            }
        for (uint32_t v : local) localOf[v] = -1;
        ChartShape shape = flattenChart(topo, triangles, local, tri, uv, true);
        bool folded = triangles.size() > 1 && (!std::isfinite(shape.stretch) || selfOverlaps(uv, tri));
        if (folded && shape.lscm) {
            // LSCM's free boundary may cross itself; the projection may not
            shape = flattenChart(topo, triangles, local, tri, uv, false);
            folded = !std::isfinite(shape.stretch) || selfOverlaps(uv, tri);
        }
        if (folded) {
            for (uint32_t t : triangles) mark[t] = -1;
            double subCone = 0.5 * work[w].cone;
            size_t subMax = work[w].maxTriangles;
            std::vector<uint32_t> seeds;
            int32_t base = nextMark;
            auto parts = growCharts(topo, triangles, mark, cosHard, std::cos(subCone), subMax, base, &seeds);
            nextMark += int32_t(parts.size());
            if (parts.size() < 2) {
                for (uint32_t t : triangles) mark[t] = -1;
                subCone = work[w].cone;
                subMax = (triangles.size() + 1) / 2;
                seeds.clear();
                base = nextMark;
                parts = growCharts(topo, triangles, mark, cosHard, std::cos(subCone), subMax, base, &seeds);
                nextMark += int32_t(parts.size());
            }
            mergeSmallCharts(topo, parts, seeds, mark, cosHard, std::cos(subCone), subMax, base);
            ++charts.splitCharts;
            for (auto& part : parts) work.push_back({std::move(part), subCone, subMax});
            continue;
        }
        const uint32_t c = uint32_t(charts.extent.size());
        charts.extent.push_back(shape.extent);
        charts.area.push_back(shape.area);
        charts.stretch.push_back(shape.stretch);
        charts.lscm.push_back(shape.lscm ? 1 : 0);
        for (size_t i = 0; i < triangles.size(); ++i) {
            chartOf[triangles[i]] = int32_t(c);
            for (int k = 0; k < 3; ++k) cornerUv[3 * size_t(triangles[i]) + size_t(k)] = uv[tri[3 * i + size_t(k)]];
        }
    }
    const size_t chartCount = charts.extent.size();

    charts.packOrder.resize(chartCount);
    std::iota(charts.packOrder.begin(), charts.packOrder.end(), 0u);
    std::sort(charts.packOrder.begin(), charts.packOrder.end(), [&](uint32_t a, uint32_t b) {
        if (charts.extent[a].y != charts.extent[b].y) return charts.extent[a].y > charts.extent[b].y;
        if (charts.extent[a].x != charts.extent[b].x) return charts.extent[a].x > charts.extent[b].x;
        return a < b;
    });

    // split vertices: one per (vertex, chart)
    charts.vertexChart.resize(mesh.primitives.size());
    charts.vertexPoint.resize(mesh.primitives.size());
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        Primitive& prim = mesh.primitives[p];
        const size_t nv = prim.positions.size();
        std::vector<int32_t> firstChart(nv, -1);
        std::vector<uint32_t> firstNew(nv, 0);
        std::unordered_map<uint64_t, uint32_t> more;
        Primitive out;
        out.material = prim.material;
        auto& vChart = charts.vertexChart[p];
        auto& vPoint = charts.vertexPoint[p];
        out.indices.resize(prim.indices.size());
        for (size_t t = 0; t < prim.triangleCount(); ++t) {
            const size_t g = topo.firstTri[p] + t;
            const int32_t c = chartOf[g];
            for (int k = 0; k < 3; ++k) {
                const uint32_t v = prim.indices[3 * t + size_t(k)];
                uint32_t index;
                bool created = false;
                if (firstChart[v] < 0) {
                    firstChart[v] = c;
                    firstNew[v] = index = uint32_t(out.positions.size());
                    created = true;
                } else if (firstChart[v] == c) {
                    index = firstNew[v];
                } else {
                    auto [it, inserted] = more.try_emplace((uint64_t(v) << 32) | uint32_t(c), uint32_t(out.positions.size()));
                    index = it->second;
                    created = inserted;
                }
                if (created) {
                    out.positions.push_back(prim.positions[v]);
                    if (!prim.normals.empty()) out.normals.push_back(prim.normals[v]);
                    if (!prim.uv0.empty()) out.uv0.push_back(prim.uv0[v]);
                    vChart.push_back(uint32_t(c));
                    vPoint.push_back(glm::vec2(cornerUv[3 * g + size_t(k)]));
                }
                out.indices[3 * t + size_t(k)] = index;
            }
        }
        prim = std::move(out);
    }
    return charts;
}

ChartPacking packCharts(const MeshCharts& charts, double texelsPerUnit, int gap) {
    CHECK_GE(gap, 0);
    const size_t n = charts.chartCount();
    ChartPacking pack;
    pack.texelsPerUnit = texelsPerUnit;
    pack.origin.resize(n);
    pack.size.resize(n);
    if (n == 0) return pack;
    double paddedArea = 0.0;
    int widest = 1;
    for (size_t c = 0; c < n; ++c) {
        // whole texels around the chart (>= 1 each way)
        const glm::dvec2 texels = charts.extent[c] * texelsPerUnit;
        const glm::ivec2 s(int(std::min(std::ceil(texels.x - 1e-9), 1e8)), int(std::min(std::ceil(texels.y - 1e-9), 1e8)));
        pack.size[c] = glm::max(s, glm::ivec2(1));
        paddedArea += double(pack.size[c].x + gap) * double(pack.size[c].y + gap);
        widest = std::max(widest, pack.size[c].x);
    }
    const int target = std::max(widest, int(std::ceil(std::sqrt(paddedArea))));
    int x = 0, y = 0, shelf = 0;
    for (uint32_t c : charts.packOrder) {
        const glm::ivec2 s = pack.size[c];
        if (x > 0 && x + s.x > target) {
            y += shelf + gap;
            x = 0;
            shelf = 0;
        }
        pack.origin[c] = glm::ivec2(x, y);
        pack.width = std::max(pack.width, x + s.x);
        x += s.x + gap;
        shelf = std::max(shelf, s.y);
    }
    pack.height = y + shelf;
    return pack;
}

void writeUv1(Mesh& mesh, const MeshCharts& charts, const ChartPacking& packing) {
    CHECK_EQ(charts.vertexChart.size(), mesh.primitives.size());
    const glm::dvec2 grid(std::max(packing.width, 1), std::max(packing.height, 1));
    const double t = packing.texelsPerUnit;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        Primitive& prim = mesh.primitives[p];
        CHECK_EQ(charts.vertexChart[p].size(), prim.positions.size());
        prim.uv1.resize(prim.positions.size());
        for (size_t v = 0; v < prim.positions.size(); ++v) {
            const uint32_t c = charts.vertexChart[p][v];
            const glm::dvec2 margin = (glm::dvec2(packing.size[c]) - charts.extent[c] * t) * 0.5;
            const glm::dvec2 texel = glm::dvec2(packing.origin[c]) + margin + glm::dvec2(charts.vertexPoint[p][v]) * t;
            prim.uv1[v] = glm::vec2(texel / grid);
        }
    }
    mesh.uv1Grid = glm::ivec2(packing.width, packing.height);
}

GridCoverage gridCoverage(const Mesh& mesh, int width, int height) {
    GridCoverage out;
    if (width <= 0 || height <= 0) return out;
    std::vector<uint8_t> count(size_t(width) * size_t(height), 0);
    for (const Primitive& prim : mesh.primitives) {
        if (prim.uv1.size() != prim.positions.size()) continue;
        for (size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
            glm::dvec2 p[3];
            for (int k = 0; k < 3; ++k)
                p[k] = glm::dvec2(prim.uv1[prim.indices[t + size_t(k)]]) * glm::dvec2(width, height);
            const double area = cross2(p[1] - p[0], p[2] - p[0]);
            if (area == 0.0 || !std::isfinite(area)) continue;
            const double sign = area > 0 ? 1.0 : -1.0;
            const int x0 = std::max(0, int(std::floor(std::min({p[0].x, p[1].x, p[2].x}))));
            const int x1 = std::min(width - 1, int(std::ceil(std::max({p[0].x, p[1].x, p[2].x}))));
            const int y0 = std::max(0, int(std::floor(std::min({p[0].y, p[1].y, p[2].y}))));
            const int y1 = std::min(height - 1, int(std::ceil(std::max({p[0].y, p[1].y, p[2].y}))));
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) {
                    const glm::dvec2 c(x + 0.5, y + 0.5);
                    bool inside = true;
                    for (int k = 0; k < 3 && inside; ++k)
                        inside = sign * cross2(p[(k + 1) % 3] - p[k], c - p[k]) > 1e-4 * glm::length(p[(k + 1) % 3] - p[k]);
                    if (!inside) continue;
                    uint8_t& n = count[size_t(y) * size_t(width) + size_t(x)];
                    if (n == 0) ++out.covered;
                    else if (n == 1) ++out.overlapping;
                    if (n < 255) ++n;
                }
        }
    }
    return out;
}

}  // namespace bb
