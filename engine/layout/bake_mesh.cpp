// The scene flattened into local space (world - Scene::origin) with page-space
// light map UVs.
//
// Based on: DESIGN.md "Data flow" steps 2 and 6-7 (one vertex array for every
// pass). Positions go through the exact (double) worldFromObject and lose the
// origin in double, so only local coordinates are rounded to float. Normals go
// through the inverse transpose of the linear part of worldFromObject;
// mirroring transforms (det < 0) swap two vertices so that counter-clockwise
// stays the front face.
#include "layout/bake_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numeric>
#include <tuple>

#include "core/check.h"

namespace bb {
namespace {

bool emits(const Material& material) {
    return material.emission.r > 0.0f || material.emission.g > 0.0f || material.emission.b > 0.0f;
}

// A triangle's edge in page space: end points' bits (a <= b), on its page.
struct LightmapEdge {
    uint32_t page;
    uint64_t a, b;
    uint32_t triangle;
    int opposite;  // the vertex the edge faces
};

// Every edge, sorted so that edges sharing both end points are neighbours.
std::vector<LightmapEdge> sortedLightmapEdges(const BakeMesh& mesh) {
    auto key = [](glm::vec2 p) {
        p += glm::vec2(0.0f);  // -0 as +0
        uint32_t x, y;
        std::memcpy(&x, &p.x, 4);
        std::memcpy(&y, &p.y, 4);
        return (uint64_t(x) << 32) | y;
    };
    std::vector<LightmapEdge> edges;
    edges.reserve(3 * mesh.triangles.size());
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        for (int e = 0; e < 3; ++e) {
            const uint64_t a = key(mesh.vertices[3 * t + size_t(e)].lightmapUv);
            const uint64_t b = key(mesh.vertices[3 * t + size_t(e + 1) % 3].lightmapUv);
            edges.push_back({mesh.triangles[t].page, std::min(a, b), std::max(a, b), uint32_t(t), (e + 2) % 3});
        }
    std::sort(edges.begin(), edges.end(), [](const LightmapEdge& x, const LightmapEdge& y) {
        return std::tie(x.page, x.a, x.b, x.triangle) < std::tie(y.page, y.a, y.b, y.triangle);
    });
    return edges;
}

bool sameEdge(const LightmapEdge& x, const LightmapEdge& y) { return x.page == y.page && x.a == y.a && x.b == y.b; }

// The texels of a res x res page whose squares a page-space triangle's bounds touch.
struct TexelRange {
    int x0, x1, y0, y1;
};
TexelRange texelsUnder(const glm::dvec2 (&q)[3], int res) {
    return {std::max(0, int(std::floor(std::min({q[0].x, q[1].x, q[2].x})))),
            std::min(res - 1, int(std::floor(std::max({q[0].x, q[1].x, q[2].x})))),
            std::max(0, int(std::floor(std::min({q[0].y, q[1].y, q[2].y})))),
            std::min(res - 1, int(std::floor(std::max({q[0].y, q[1].y, q[2].y}))))};
}

// Calls f(x, y, i) for every texel (i = y * res + x) whose square the bounds
// of page-space triangle q touch.
template <class F>
void forTexelsUnder(const glm::dvec2 (&q)[3], int res, F&& f) {
    const TexelRange r = texelsUnder(q, res);
    for (int y = r.y0; y <= r.y1; ++y)
        for (int x = r.x0; x <= r.x1; ++x) f(x, y, size_t(y) * res + x);
}

// The part of texel (x, y)'s square on page-space triangle q, in the texel's coordinates.
std::vector<glm::dvec2> squareOnTriangle(const glm::dvec2 (&q)[3], int x, int y) {
    const glm::dvec2 corner(x, y);
    const glm::dvec2 local[3] = {q[0] - corner, q[1] - corner, q[2] - corner};
    return clipSquare(local);
}

// Twice the signed area of a polygon (counter-clockwise positive), then halved.
double polygonArea(const std::vector<glm::dvec2>& poly) {
    double area2 = 0.0;
    for (size_t k = 0; k < poly.size(); ++k) {
        const glm::dvec2 &a = poly[k], &b = poly[(k + 1) % poly.size()];
        area2 += a.x * b.y - a.y * b.x;
    }
    return 0.5 * area2;
}

// A counter-clockwise polygon's area integrals of 1, x, y, x^2, xy and y^2.
struct AreaMoments {
    double a = 0.0, x = 0.0, y = 0.0, xx = 0.0, xy = 0.0, yy = 0.0;
};
void addAreaMoments(const std::vector<glm::dvec2>& poly, AreaMoments& m) {
    for (size_t k = 0; k < poly.size(); ++k) {
        const glm::dvec2 &p = poly[k], &q = poly[(k + 1) % poly.size()];
        const double c = p.x * q.y - q.x * p.y;
        m.a += c / 2.0;
        m.x += (p.x + q.x) * c / 6.0;
        m.y += (p.y + q.y) * c / 6.0;
        m.xx += (p.x * p.x + p.x * q.x + q.x * q.x) * c / 12.0;
        m.yy += (p.y * p.y + p.y * q.y + q.y * q.y) * c / 12.0;
        m.xy += (p.x * q.y + 2.0 * p.x * p.y + 2.0 * q.x * q.y + q.x * p.y) * c / 24.0;
    }
}

// A convex polygon clipped to the half-plane n . p <= d (Sutherland-Hodgman).
std::vector<glm::dvec2> clipHalfPlane(const std::vector<glm::dvec2>& poly, glm::dvec2 n, double d) {
    std::vector<glm::dvec2> out;
    for (size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec2 &p = poly[i], &q = poly[(i + 1) % poly.size()];
        const double sp = d - glm::dot(n, p), sq = d - glm::dot(n, q);  // >= 0: inside
        if (sp >= 0.0) out.push_back(p);
        if ((sp >= 0.0) != (sq >= 0.0)) out.push_back(p + (q - p) * (sp / (sp - sq)));
    }
    return out;
}

}  // namespace

std::vector<uint32_t> findLightmapCharts(const BakeMesh& mesh) {
    const size_t n = mesh.triangles.size();
    std::vector<uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
    auto root = [&](uint32_t a) {
        while (parent[a] != a) a = parent[a] = parent[parent[a]];
        return a;
    };
    const std::vector<LightmapEdge> edges = sortedLightmapEdges(mesh);
    for (size_t i = 1; i < edges.size(); ++i)
        if (sameEdge(edges[i - 1], edges[i])) parent[root(edges[i - 1].triangle)] = root(edges[i].triangle);
    std::vector<uint32_t> chart(n);
    for (size_t t = 0; t < n; ++t) chart[t] = root(uint32_t(t));
    return chart;
}

std::vector<uint32_t> pageDrawOrder(const BakeMesh& mesh, int page) {
    std::vector<uint32_t> order(mesh.pageFirstTriangle[size_t(page) + 1] - mesh.pageFirstTriangle[size_t(page)]);
    std::iota(order.begin(), order.end(), mesh.pageFirstTriangle[size_t(page)]);
    const auto built = [&](uint32_t t) { return mesh.builtIndex.empty() ? t : mesh.builtIndex[t]; };
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        const uint32_t ma = mesh.triangles[a].material, mb = mesh.triangles[b].material;
        return ma != mb ? ma < mb : built(a) < built(b);
    });
    return order;
}

double pageCorners(const BakeMesh& mesh, uint32_t t, int res, glm::dvec2 (&q)[3]) {
    for (int k = 0; k < 3; ++k) q[k] = glm::dvec2(mesh.vertices[3 * size_t(t) + k].lightmapUv) * double(res);
    const glm::dvec2 e1 = q[1] - q[0], e2 = q[2] - q[0];
    const double area2 = e1.x * e2.y - e1.y * e2.x;
    if (area2 < 0) std::swap(q[1], q[2]);
    return std::fabs(area2);
}

std::vector<int32_t> texelOwners(const BakeMesh& mesh, int page, int res, std::vector<uint8_t>* partial,
                                 double minPartialArea) {
    CHECK(mesh.triangles.size() <= size_t(INT32_MAX));
    std::vector<int32_t> owner(size_t(res) * res, -1);
    const std::vector<uint32_t> order = pageDrawOrder(mesh, page);
    for (uint32_t t : order) {
        glm::dvec2 q[3];
        const double absArea = pageCorners(mesh, t, res, q);
        if (absArea == 0.0 || !std::isfinite(absArea)) continue;
        // GL's tie rule as Mesa applies it with the lower-left origin (D3D's
        // top-left rule seen with y up; page space is GL's window space):
        // counter-clockwise, an edge going down is a left edge, a horizontal
        // edge going right a bottom edge; centres on them count. With the top
        // edges instead, a chart whose borders ran through texel centres (a
        // 10 m wall at 0.6 texels/m) was covered one row higher than the bake
        bool topLeft[3];
        for (int e = 0; e < 3; ++e) {
            const glm::dvec2 a = q[(e + 1) % 3], b = q[(e + 2) % 3];  // edge opposite vertex e
            topLeft[e] = (b.y < a.y) || (b.y == a.y && b.x > a.x);
        }
        const double minX = std::min({q[0].x, q[1].x, q[2].x}), maxX = std::max({q[0].x, q[1].x, q[2].x});
        const double minY = std::min({q[0].y, q[1].y, q[2].y}), maxY = std::max({q[0].y, q[1].y, q[2].y});
        const int x0 = std::max(0, int(std::floor(minX - 0.5))), x1 = std::min(res - 1, int(std::ceil(maxX - 0.5)));
        const int y0 = std::max(0, int(std::floor(minY - 0.5))), y1 = std::min(res - 1, int(std::ceil(maxY - 0.5)));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const glm::dvec2 c(x + 0.5, y + 0.5);
                bool inside = true;
                for (int e = 0; e < 3 && inside; ++e) {
                    const glm::dvec2 a = q[(e + 1) % 3], b = q[(e + 2) % 3];
                    const double w = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
                    inside = w > 0.0 || (w == 0.0 && topLeft[e]);
                }
                if (inside) owner[size_t(y) * res + x] = int32_t(t);
            }
    }
    // texels no centre owns: the triangle holding the most of the square, where
    // the triangles hold minPartialArea of it in all
    std::vector<double> best(owner.size(), 0.0), total(owner.size(), 0.0);
    std::vector<uint8_t> isPartial(owner.size(), 0);
    for (uint32_t t : order) {
        glm::dvec2 q[3];
        const double absArea = pageCorners(mesh, t, res, q);
        if (absArea == 0.0 || !std::isfinite(absArea)) continue;
        forTexelsUnder(q, res, [&](int x, int y, size_t i) {
            if (owner[i] >= 0 && !isPartial[i]) return;
            const double area = polygonArea(squareOnTriangle(q, x, y));
            if (!(area > 0.0)) return;
            total[i] += area;
            if (!(area >= best[i])) return;
            best[i] = area;
            owner[i] = int32_t(t);
            isPartial[i] = 1;
        });
    }
    for (size_t i = 0; i < owner.size(); ++i)
        if (isPartial[i] && !(total[i] >= minPartialArea)) {
            owner[i] = -1;
            isPartial[i] = 0;
        }
    if (partial) *partial = std::move(isPartial);
    return owner;
}

std::vector<int32_t> halfTexelOwners(const BakeMesh& mesh, const std::vector<uint32_t>& charts, int page, int res,
                                     std::vector<uint8_t>* partial, const std::vector<int32_t>* coarseOwners) {
    const std::vector<int32_t> coarse = coarseOwners ? *coarseOwners : texelOwners(mesh, page, res);
    std::vector<uint8_t> isPartial;
    std::vector<int32_t> owner = texelOwners(mesh, page, 2 * res, &isPartial, kMinPartialTexelArea / 4.0);
    const int fineRes = 2 * res;
    const double minArea = kMinPartialTexelArea / 4.0;
    // f(t, q, x, y, i) for each triangle t in draw order (q: its corners) and half-size texel under its bounds
    const std::vector<uint32_t> order = pageDrawOrder(mesh, page);
    auto forHalfTexelsUnderTriangles = [&](auto&& f) {
        for (uint32_t t : order) {
            glm::dvec2 q[3];
            const double absArea = pageCorners(mesh, t, fineRes, q);
            if (absArea == 0.0 || !std::isfinite(absArea)) continue;
            forTexelsUnder(q, fineRes, [&](int x, int y, size_t i) { f(t, q, x, y, i); });
        }
    };
    // the half-size texels two or more charts lie in (the others have little to decide)
    constexpr uint32_t kNone = UINT32_MAX, kMany = UINT32_MAX - 1;
    std::vector<uint32_t> seen(owner.size(), kNone);
    forHalfTexelsUnderTriangles([&](uint32_t t, const glm::dvec2(&)[3], int, int, size_t i) {
        if (seen[i] == kNone) seen[i] = charts[t];
        else if (seen[i] != charts[t]) seen[i] = kMany;
    });
    // their charts' parts: area, and the triangle holding the most of it (the last in draw order of
    // equals); the others' one chart's area
    struct Part {
        size_t texel;
        uint32_t chart, triangle;
        double area, best;
    };
    std::vector<Part> parts;
    std::vector<double> soleArea(owner.size(), 0.0);
    forHalfTexelsUnderTriangles([&](uint32_t t, const glm::dvec2(&q)[3], int x, int y, size_t i) {
        const double area = polygonArea(squareOnTriangle(q, x, y));
        if (!(area > 0.0)) return;
        if (seen[i] == kMany) parts.push_back({i, charts[t], t, area, area});
        else soleArea[i] += area;
    });
    std::stable_sort(parts.begin(), parts.end(), [](const Part& a, const Part& b) {
        return a.texel != b.texel ? a.texel < b.texel : a.chart < b.chart;
    });
    size_t merged = 0;
    for (size_t k = 0; k < parts.size(); ++k) {
        if (merged > 0 && parts[merged - 1].texel == parts[k].texel && parts[merged - 1].chart == parts[k].chart) {
            Part& m = parts[merged - 1];
            m.area += parts[k].area;
            if (parts[k].best >= m.best) m.best = parts[k].best, m.triangle = parts[k].triangle;
        } else {
            parts[merged++] = parts[k];
        }
    }
    parts.resize(merged);
    auto chartOf = [&](size_t i) { return owner[i] < 0 ? kNone : charts[size_t(owner[i])]; };
    auto texelChart = [&](size_t i) {  // the chart of the texel half-size texel i lies in
        const int32_t c = coarse[(i / size_t(fineRes)) / 2 * size_t(res) + (i % size_t(fineRes)) / 2];
        return c < 0 ? kNone : charts[size_t(c)];
    };
    auto take = [&](const Part& p) {
        owner[p.texel] = int32_t(p.triangle);
        isPartial[p.texel] = 1;
    };
    // (1) the texel's chart, wherever it holds a sixteenth of the half-size texel
    for (const Part& p : parts)
        if (p.chart == texelChart(p.texel) && chartOf(p.texel) != p.chart && p.area >= minArea) take(p);
    // (2) the half-size texels no texel's value needs (not their texel's chart's) go to the
    // charts lying in them that own none of the 3 x 3 around them, largest part first, while
    // the chart they are taken from keeps another there: every strip's bundle fragments
    // find a texel of their own to read (append.frag ownTexel), not another chart's light
    auto ownsNear = [&](size_t i, uint32_t chart, bool besides) {
        const int x = int(i % size_t(fineRes)), y = int(i / size_t(fineRes));
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int qx = x + dx, qy = y + dy;
                if ((besides && dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= fineRes || qy >= fineRes) continue;
                if (chartOf(size_t(qy) * size_t(fineRes) + size_t(qx)) == chart) return true;
            }
        return false;
    };
    // a strip's part: a sixteenth or more, its chart not the texel's and owning none of the 3 x 3 around
    auto stripPart = [&](const Part& p) {
        return p.area >= minArea && p.chart != texelChart(p.texel) && !ownsNear(p.texel, p.chart, false);
    };
    std::vector<const Part*> wanting;
    for (const Part& p : parts)
        if (stripPart(p) && chartOf(p.texel) != texelChart(p.texel)) wanting.push_back(&p);
    std::stable_sort(wanting.begin(), wanting.end(), [](const Part* a, const Part* b) { return a->area > b->area; });
    std::vector<uint8_t> given(owner.size(), 0);
    auto give = [&](const Part& p) {
        take(p);
        given[p.texel] = 1;
    };
    for (const Part* p : wanting) {
        const uint32_t from = chartOf(p->texel);
        if (given[p->texel] || ownsNear(p->texel, p->chart, false)) continue;
        if (from != kNone && !ownsNear(p->texel, from, true)) continue;
        give(*p);
    }
    // (3) charts still owning none near a half-size texel they lie in take it from its texel's
    // chart where that chart keeps at least as much of the texel's footprint in its other
    // quarters, the smallest loss first: the texel's value then leaves that part of its
    // footprint out, where the strip's light read from another chart's texel was that chart's
    // (a setback's top in an alley between two buildings read the roof parapet's that owns its
    // texels, and the alley's walls beside it read twice too bright)
    auto areaOf = [&](size_t i, uint32_t chart) {  // chart's part of half-size texel i
        if (seen[i] != kMany) return seen[i] == chart ? soleArea[i] : 0.0;
        auto it = std::lower_bound(parts.begin(), parts.end(), std::make_pair(i, chart),
                                   [](const Part& a, const auto& key) {
                                       return a.texel != key.first ? a.texel < key.first : a.chart < key.second;
                                   });
        return it != parts.end() && it->texel == i && it->chart == chart ? it->area : 0.0;
    };
    auto keptShare = [&](size_t i) {  // of the texel's footprint in its quarters on its chart, the share outside i
        const int x = int(i % size_t(fineRes)) / 2 * 2, y = int(i / size_t(fineRes)) / 2 * 2;
        const uint32_t chart = texelChart(i);
        double kept = 0.0;
        for (int q = 0; q < 4; ++q) {
            const size_t j = size_t(y + q / 2) * size_t(fineRes) + size_t(x + q % 2);
            if (j != i && chartOf(j) == chart) kept += areaOf(j, chart);
        }
        const double lost = areaOf(i, chart);
        return kept + lost > 0.0 ? kept / (kept + lost) : 0.0;
    };
    std::vector<std::pair<double, const Part*>> takeable;
    for (const Part& p : parts)
        if (stripPart(p) && chartOf(p.texel) == texelChart(p.texel)) takeable.push_back({keptShare(p.texel), &p});
    std::stable_sort(takeable.begin(), takeable.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    for (const auto& [kept, p] : takeable) {
        if (kept < 0.5) break;
        if (given[p->texel] || ownsNear(p->texel, p->chart, false) || keptShare(p->texel) < 0.5) continue;
        give(*p);
    }
    if (partial) *partial = std::move(isPartial);
    return owner;
}

std::vector<uint64_t> footprintMasks(const BakeMesh& mesh, int page, int res, const std::vector<int32_t>& owner,
                                     const std::vector<uint32_t>& chart) {
    std::vector<uint64_t> mask(size_t(res) * res, 0);
    auto chartAt = [&](int x, int y) -> int64_t {
        if (x < 0 || y < 0 || x >= res || y >= res) return -1;
        const int32_t o = owner[size_t(y) * res + x];
        return o < 0 ? -1 : int64_t(chart[size_t(o)]);
    };
    // texels whose whole square is on their chart need no cells
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x) {
            const int64_t c = chartAt(x, y);
            if (c < 0) continue;
            bool inner = true;
            for (int dy = -1; dy <= 1 && inner; ++dy)
                for (int dx = -1; dx <= 1 && inner; ++dx) inner = chartAt(x + dx, y + dy) == c;
            if (inner) mask[size_t(y) * res + x] = ~uint64_t(0);
        }
    static const glm::dvec2 probes[5] = {{0.5, 0.5}, {0.1, 0.1}, {0.9, 0.1}, {0.1, 0.9}, {0.9, 0.9}};
    for (uint32_t t = mesh.pageFirstTriangle[size_t(page)]; t < mesh.pageFirstTriangle[size_t(page) + 1]; ++t) {
        glm::dvec2 q[3];
        const double absArea = pageCorners(mesh, t, res, q);
        if (absArea == 0.0 || !std::isfinite(absArea)) continue;
        auto inside = [&](const glm::dvec2& c) {
            for (int e = 0; e < 3; ++e) {
                const glm::dvec2 a = q[(e + 1) % 3], b = q[(e + 2) % 3];
                if ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) < 0.0) return false;
            }
            return true;
        };
        const TexelRange r = texelsUnder(q, res);
        for (int y = r.y0; y <= r.y1; ++y)
            for (int x = r.x0; x <= r.x1; ++x) {
                const size_t i = size_t(y) * res + x;
                if (mask[i] == ~uint64_t(0) || chartAt(x, y) != int64_t(chart[t])) continue;
                for (int cell = 0; cell < 64; ++cell) {
                    if (mask[i] & (uint64_t(1) << cell)) continue;
                    for (const glm::dvec2& p : probes)
                        if (inside(glm::dvec2(x + (cell % 8 + p.x) / 8.0, y + (cell / 8 + p.y) / 8.0))) {
                            mask[i] |= uint64_t(1) << cell;
                            break;
                        }
                }
            }
    }
    return mask;
}

double footprintEdgeAngle(int angle) { return angle * (6.283185307179586 / 4096.0); }

uint32_t encodeFootprintEdge(int angle, double distance) {
    // inward: the rounding, and a margin for the angle's (its 4096ths turn the
    // line by up to 0.00077 rad about a point within 0.75 texel of the rest)
    const int d = std::clamp(int(std::floor((distance - 0.0006 + 0.75) / 1.5 * 4095.0)), 0, 4095);
    return std::max(uint32_t(angle & 4095) | uint32_t(d) << 12, 1u << 12);  // 0 stays "none"
}

uint32_t encodeFootprintSpread(double xx, double xy, double yy) {
    const auto level = [](double v, int levels) { return uint32_t(std::clamp(int(std::lround(v)), 0, levels)); };
    const uint32_t x = std::max(level(xx * 12.0 * 2047.0, 2047), 1u), y = std::max(level(yy * 12.0 * 2047.0, 2047), 1u);
    return x | y << 11 | level((xy * 12.0 + 1.0) * 0.5 * 1022.0, 1022) << 22;
}

namespace {
// An edge's half-plane n . p <= d, decoded as lib/texel_footprint.glsl does (in float).
std::pair<glm::dvec2, double> decodeFootprintEdge(uint32_t code) {
    const float angle = float(code & 4095u) * (6.283185307f / 4096.0f);
    return {glm::dvec2(std::cos(angle), std::sin(angle)), float(code >> 12) * (1.5f / 4095.0f) - 0.75f};
}
}  // namespace

bool insideFootprintEdge(uint32_t code, glm::dvec2 offset) {
    if (code == 0) return true;
    const auto [n, d] = decodeFootprintEdge(code);
    return glm::dot(n, offset) <= d;
}

std::vector<TexelFootprint> texelFootprints(const BakeMesh& mesh, int page, int res, const std::vector<int32_t>& owner,
                                            const std::vector<uint32_t>& chart) {
    const std::vector<uint64_t> mask = footprintMasks(mesh, page, res, owner, chart);
    std::vector<TexelFootprint> out(mask.size());
    // the chart's triangles over each texel only partly on it, by texel
    std::vector<std::pair<uint32_t, uint32_t>> overlaps;  // (texel, triangle)
    for (uint32_t t = mesh.pageFirstTriangle[size_t(page)]; t < mesh.pageFirstTriangle[size_t(page) + 1]; ++t) {
        glm::dvec2 q[3];
        const double absArea = pageCorners(mesh, t, res, q);
        if (absArea == 0.0 || !std::isfinite(absArea)) continue;
        forTexelsUnder(q, res, [&](int, int, size_t i) {
            if (owner[i] >= 0 && mask[i] != ~uint64_t(0) && chart[size_t(owner[i])] == chart[t])
                overlaps.push_back({uint32_t(i), t});
        });
    }
    std::sort(overlaps.begin(), overlaps.end());
    // a triangle's corners in vertex order (its border bits' order), from a texel's centre
    auto corners = [&](uint32_t t, glm::dvec2 centre, glm::dvec2 (&q)[3]) {
        for (int k = 0; k < 3; ++k) q[k] = glm::dvec2(mesh.vertices[3 * size_t(t) + k].lightmapUv) * double(res) - centre;
    };
    // edge e of q (opposite corner e) as the half-plane n . p <= d that holds q, n outward
    auto edgeHalfPlane = [](const glm::dvec2 (&q)[3], int e) {
        const glm::dvec2 a = q[(e + 1) % 3], b = q[(e + 2) % 3];
        glm::dvec2 n(b.y - a.y, a.x - b.x);
        if (glm::dot(n, q[e] - a) > 0.0) n = -n;
        return std::pair<glm::dvec2, double>(n, glm::dot(n, a));
    };
    auto within = [](const std::pair<glm::dvec2, double>& halfPlane, glm::dvec2 p) {
        return glm::dot(halfPlane.first, p) <= halfPlane.second;
    };
    constexpr int N = 32;  // points a side: 4 x 4 a cell
    auto point = [](int k) { return glm::dvec2((k % N + 0.5) / N - 0.5, (k / N + 0.5) / N - 0.5); };
    std::vector<uint8_t> exact(N * N), base(N * N);
    std::vector<std::array<std::pair<glm::dvec2, double>, 3>> sides;  // the texel's triangles' edges
    for (size_t begin = 0, end; begin < overlaps.size(); begin = end) {
        const uint32_t i = overlaps[begin].first, o = uint32_t(owner[i]);
        for (end = begin; end < overlaps.size() && overlaps[end].first == i; ++end) {}
        const glm::dvec2 centre(double(i % uint32_t(res)) + 0.5, double(i / uint32_t(res)) + 0.5);
        // on the chart (exact) and taken by the test without an edge (base)
        const uint32_t ownBorders = (mesh.triangles[o].flags / TRIANGLE_CHART_BORDER0) & 7u;
        sides.clear();
        for (size_t j = begin; j < end; ++j) {
            glm::dvec2 q[3];
            corners(overlaps[j].second, centre, q);
            sides.push_back({edgeHalfPlane(q, 0), edgeHalfPlane(q, 1), edgeHalfPlane(q, 2)});
        }
        glm::dvec2 own[3];
        corners(o, centre, own);
        // the owner's chart-border edges (then the one more edge, for the area)
        std::vector<std::pair<glm::dvec2, double>> halfPlanes;
        for (int e = 0; e < 3; ++e)
            if (ownBorders & (1u << e)) halfPlanes.push_back(edgeHalfPlane(own, e));
        for (int k = 0; k < N * N; ++k) {
            const glm::dvec2 p = point(k);
            bool on = (mask[i] >> ((k / N) * 8 / N * 8 + (k % N) * 8 / N)) & 1u;
            for (size_t h = 0; h < halfPlanes.size() && on; ++h) on = within(halfPlanes[h], p);
            base[size_t(k)] = on;
            exact[size_t(k)] = 0;
            for (size_t j = 0; j < sides.size() && !exact[size_t(k)]; ++j)
                exact[size_t(k)] = within(sides[j][0], p) && within(sides[j][1], p) && within(sides[j][2], p);
        }
        // the other triangles' border edges: the one that takes off the most
        // points off the chart and none on it
        uint32_t best = 0;
        int bestScore = 0;
        for (size_t j = begin; j < end; ++j) {
            const uint32_t t = overlaps[j].second;
            const uint32_t borders = (mesh.triangles[t].flags / TRIANGLE_CHART_BORDER0) & 7u;
            if (t == o || borders == 0) continue;
            glm::dvec2 q[3];
            corners(t, centre, q);
            for (int e = 0; e < 3; ++e) {
                if (!(borders & (1u << e))) continue;
                const glm::dvec2 a = q[(e + 1) % 3], b = q[(e + 2) % 3], n = sides[j - begin][size_t(e)].first;
                if (!(glm::length(n) > 0.0)) continue;
                const int angle = int(std::lround(std::atan2(n.y, n.x) / 6.283185307179586 * 4096.0)) & 4095;
                // through the edge's point nearest the centre, along the normal as encoded
                const glm::dvec2 nq(std::cos(footprintEdgeAngle(angle)), std::sin(footprintEdgeAngle(angle)));
                const glm::dvec2 ab = b - a;
                const glm::dvec2 nearest = a + ab * std::clamp(glm::dot(-a, ab) / glm::dot(ab, ab), 0.0, 1.0);
                const double distance = glm::dot(nq, nearest);
                if (!(std::fabs(distance) < 0.75)) continue;
                const uint32_t code = encodeFootprintEdge(angle, distance);
                // points off the chart it takes off, less those on it (a sliver
                // at most, the inward rounding's, or a concave chart's far part)
                const auto side = decodeFootprintEdge(code);
                int score = 0;
                for (int k = 0; k < N * N; ++k)
                    if (base[size_t(k)] && !within(side, point(k))) score += exact[size_t(k)] ? -8 : 1;
                if (score > bestScore) {
                    best = code;
                    bestScore = score;
                }
            }
        }
        // the accepted part's area, exactly: each cell clipped to the owner's
        // border edges and the edge
        if (best != 0) halfPlanes.push_back(decodeFootprintEdge(best));
        AreaMoments accepted;  // and how it spreads
        for (int cell = 0; cell < 64; ++cell) {
            if (!((mask[i] >> cell) & 1u)) continue;
            const double x0 = (cell % 8) / 8.0 - 0.5, y0 = (cell / 8) / 8.0 - 0.5, s = 1.0 / 8.0;
            std::vector<glm::dvec2> poly = {{x0, y0}, {x0 + s, y0}, {x0 + s, y0 + s}, {x0, y0 + s}};
            for (const auto& [n, d] : halfPlanes) poly = clipHalfPlane(poly, n, d);
            addAreaMoments(poly, accepted);
        }
        out[i].edge = best;
        out[i].area = uint8_t(std::lround(255.0 * accepted.a));
        if (accepted.a > 0.0) {
            const double mx = accepted.x / accepted.a, my = accepted.y / accepted.a;
            out[i].spread = encodeFootprintSpread(accepted.xx / accepted.a - mx * mx, accepted.xy / accepted.a - mx * my,
                                                  accepted.yy / accepted.a - my * my);
        }
        // how far the test (with the edge) is from the chart, on the grid
        const std::pair<glm::dvec2, double> side = decodeFootprintEdge(best);
        int on = 0, wrong = 0;
        for (int k = 0; k < N * N; ++k) {
            const bool taken = base[size_t(k)] && (best == 0 || within(side, point(k)));
            on += exact[size_t(k)];
            wrong += taken != bool(exact[size_t(k)]);
        }
        out[i].inexact = wrong > kInexactFootprintShare * on;
        if (out[i].inexact && on > 0) {
            // its samples take the points its triangles hold: their spread, each grid point's own 1 / (12 N^2) added
            glm::dvec2 mean(0.0);
            glm::dvec3 second(0.0);  // xx, xy, yy
            for (int k = 0; k < N * N; ++k)
                if (exact[size_t(k)]) {
                    const glm::dvec2 q = point(k);
                    mean += q / double(on);
                    second += glm::dvec3(q.x * q.x, q.x * q.y, q.y * q.y) / double(on);
                }
            const double own = 1.0 / (12.0 * N * N);
            out[i].spread = encodeFootprintSpread(second.x - mean.x * mean.x + own, second.y - mean.x * mean.y,
                                                  second.z - mean.y * mean.y + own);
        }
        for (int k = 0; k < N * N; ++k) out[i].sixteenths[size_t((k % N) * 4 / N + (k / N) * 4 / N * 4)] += exact[size_t(k)];
        if (out[i].inexact) out[i].area = uint8_t(std::lround(255.0 * on / (N * N)));
    }
    for (size_t i = 0; i < mask.size(); ++i) {
        out[i].cells = mask[i];
        if (owner[i] >= 0 && mask[i] == ~uint64_t(0)) {
            out[i].area = 255;
            out[i].spread = encodeFootprintSpread(1.0 / 12.0, 0.0, 1.0 / 12.0);
            out[i].sixteenths.fill(N * N / 16);
        }
    }
    return out;
}

std::vector<glm::dvec2> clipSquare(const glm::dvec2 (&tri)[3]) {
    std::vector<glm::dvec2> poly = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int e = 0; e < 3 && !poly.empty(); ++e) {
        const glm::dvec2 a = tri[e], d = tri[(e + 1) % 3] - tri[e];
        const glm::dvec2 n(d.y, -d.x);  // outward of a counter-clockwise triangle
        poly = clipHalfPlane(poly, n, glm::dot(n, a));
    }
    return poly;
}

bool texelAffine(const BakeMesh& mesh, uint32_t t, int res, bool normals, TexelAffine& out) {
    const BakeVertex* v = &mesh.vertices[3 * size_t(t)];
    glm::dvec2 q[3];
    glm::dvec3 a[3];
    for (int k = 0; k < 3; ++k) {
        q[k] = glm::dvec2(v[k].lightmapUv) * double(res);
        a[k] = glm::dvec3(normals ? glm::vec3(v[k].normal) : glm::vec3(v[k].position));
    }
    const glm::dvec2 e1 = q[1] - q[0], e2 = q[2] - q[0];
    const double det = e1.x * e2.y - e1.y * e2.x;
    if (det == 0.0 || !std::isfinite(det)) return false;
    // at(q) - at0 = (a1 - a0) s + (a2 - a0) r with (s, r) solving e1 s + e2 r = q - q0
    const glm::dvec3 f1 = a[1] - a[0], f2 = a[2] - a[0];
    out.q0 = q[0];
    out.at0 = a[0];
    out.dx = (f1 * e2.y - f2 * e1.y) / det;
    out.dy = (f2 * e1.x - f1 * e2.x) / det;
    return true;
}

std::vector<CurvedTexel> curvedTexels(const BakeMesh& mesh, int page, int res, const std::vector<int32_t>& owner,
                                      const std::vector<uint32_t>& chart, const std::vector<uint8_t>& partial,
                                      const std::vector<TexelFootprint>& footprints, double departure) {
    // every triangle of a covered texel's chart overlapping its square with
    // area, and how far it leaves the owner's plane there (at the corners of
    // its piece of the square), in the owner's texel sizes
    struct Overlap {
        uint32_t texel, triangle;
        double departure;
    };
    std::vector<Overlap> overlaps;
    for (uint32_t t = mesh.pageFirstTriangle[size_t(page)]; t < mesh.pageFirstTriangle[size_t(page) + 1]; ++t) {
        glm::dvec2 q[3];
        const double absArea = pageCorners(mesh, t, res, q);
        TexelAffine surface;
        if (absArea == 0.0 || !std::isfinite(absArea) || !texelAffine(mesh, t, res, false, surface)) continue;
        const TexelRange r = texelsUnder(q, res);
        for (int y = r.y0; y <= r.y1; ++y)
            for (int x = r.x0; x <= r.x1; ++x) {
                const size_t i = size_t(y) * res + x;
                if (owner[i] < 0 || chart[size_t(owner[i])] != chart[t]) continue;
                const glm::dvec2 corner(x, y);
                const glm::dvec2 local[3] = {q[0] - corner, q[1] - corner, q[2] - corner};
                const std::vector<glm::dvec2> piece = clipSquare(local);
                if (!(polygonArea(piece) > 0.0)) continue;
                TexelAffine own;
                double worst = 0.0;
                if (uint32_t(owner[i]) != t && texelAffine(mesh, uint32_t(owner[i]), res, false, own)) {
                    for (const glm::dvec2& p : piece)
                        worst = std::max(worst, glm::length(surface.at(corner + p) - own.at(corner + p)));
                    worst /= std::max(glm::length(own.dx), glm::length(own.dy));
                }
                overlaps.push_back({uint32_t(i), t, worst});
            }
    }
    std::sort(overlaps.begin(), overlaps.end(),
              [](const Overlap& a, const Overlap& b) { return std::tie(a.texel, a.triangle) < std::tie(b.texel, b.triangle); });
    std::vector<CurvedTexel> curved;
    for (size_t begin = 0, end; begin < overlaps.size(); begin = end) {
        const uint32_t i = overlaps[begin].texel, o = uint32_t(owner[i]);
        double worst = 0.0;
        for (end = begin; end < overlaps.size() && overlaps[end].texel == i; ++end)
            worst = std::max(worst, overlaps[end].departure);
        const bool isPartial = !partial.empty() && partial[i];
        const bool isInexact = !footprints.empty() && footprints[i].inexact;
        if (!(worst > departure) && !isPartial && !isInexact) continue;
        CurvedTexel texel{i, {o}, !(worst > departure), isInexact && !(worst > departure)};
        for (size_t k = begin; k < end; ++k)
            if (overlaps[k].triangle != o) texel.triangles.push_back(overlaps[k].triangle);
        curved.push_back(std::move(texel));
    }
    return curved;
}

size_t sharedTexels(const BakeMesh& mesh, int page, int res, const std::vector<int32_t>& owner,
                    const std::vector<uint32_t>& chart) {
    std::vector<uint8_t> shared(size_t(res) * res, 0);
    size_t count = 0;
    for (uint32_t t = mesh.pageFirstTriangle[size_t(page)]; t < mesh.pageFirstTriangle[size_t(page) + 1]; ++t) {
        glm::dvec2 q[3];
        const double absArea = pageCorners(mesh, t, res, q);
        if (absArea == 0.0 || !std::isfinite(absArea)) continue;
        // overlapping with area: the square clipped to the triangle keeps some
        const TexelRange r = texelsUnder(q, res);
        for (int y = r.y0; y <= r.y1; ++y)
            for (int x = r.x0; x <= r.x1; ++x) {
                const size_t i = size_t(y) * res + x;
                if (shared[i] || owner[i] < 0 || chart[size_t(owner[i])] == chart[t] ||
                    !(polygonArea(squareOnTriangle(q, x, y)) > 0.0))
                    continue;
                shared[i] = 1;
                ++count;
            }
    }
    return count;
}

BakeMesh buildBakeMesh(const Scene& scene, const Layout& layout) {
    CHECK_EQ(layout.rects.size(), scene.instances.size());
    const size_t pageCount = size_t(layout.pageCount);

    // count triangles per page, so they can be written in page order directly
    // (a stable counting sort: instance order is kept within a page)
    std::vector<uint32_t> first(pageCount + 1, 0);
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        CHECK(inst.mesh >= 0 && size_t(inst.mesh) < scene.meshes.size());
        const InstanceRect& rect = layout.rects[i];
        CHECK(rect.page >= 0 && size_t(rect.page) < pageCount);
        size_t triangles = 0;
        for (const Primitive& prim : scene.meshes[size_t(inst.mesh)].primitives) triangles += prim.triangleCount();
        first[size_t(rect.page) + 1] += uint32_t(triangles);
    }
    for (size_t p = 0; p < pageCount; ++p) first[p + 1] += first[p];

    BakeMesh out;
    out.triangles.resize(first[pageCount]);
    out.builtIndex.resize(first[pageCount]);
    std::iota(out.builtIndex.begin(), out.builtIndex.end(), 0u);
    out.vertices.resize(size_t(first[pageCount]) * 3);
    std::vector<uint32_t> cursor(first.begin(), first.end() - 1);

    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        const InstanceRect& rect = layout.rects[i];
        // translation minus the origin in double: exact for a node translation
        glm::dmat4 localFromObject = inst.exactWorldFromObject();
        localFromObject[3] -= glm::dvec4(scene.origin, 0.0);
        const glm::mat3 linear(inst.worldFromObject);
        const glm::mat3 normalFromObject = glm::transpose(glm::inverse(linear));
        const bool mirrored = glm::determinant(linear) < 0.0f;
        // vertex order that keeps front faces front (swap 1 and 2 when mirrored)
        const int order[3] = {0, mirrored ? 2 : 1, mirrored ? 1 : 2};

        for (const Primitive& prim : scene.meshes[size_t(inst.mesh)].primitives) {
            if (prim.triangleCount() == 0) continue;
            CHECK(prim.material >= 0 && size_t(prim.material) < scene.materials.size());
            // the layout guarantees TEXCOORD_1 on every instanced primitive
            CHECK_EQ(prim.uv1.size(), prim.positions.size());
            const bool hasNormals = prim.normals.size() == prim.positions.size();
            const bool hasUv0 = prim.uv0.size() == prim.positions.size();
            const Material& material = scene.materials[size_t(prim.material)];
            uint32_t flags = 0;
            if (material.doubleSided) flags |= TRIANGLE_DOUBLE_SIDED;
            if (emits(material)) flags |= TRIANGLE_EMISSIVE;
            if (material.alphaMask) flags |= TRIANGLE_ALPHA_MASK;

            for (size_t t = 0; t < prim.triangleCount(); ++t) {
                const uint32_t slot = cursor[size_t(rect.page)]++;
                out.triangles[slot] = BakeTriangle{uint32_t(prim.material), uint32_t(rect.page), uint32_t(i), flags};
                BakeVertex* v = &out.vertices[size_t(slot) * 3];
                for (int k = 0; k < 3; ++k) {
                    const uint32_t index = prim.indices[3 * t + size_t(order[k])];
                    DCHECK(index < prim.positions.size());
                    const glm::vec3 local(localFromObject * glm::dvec4(glm::dvec3(prim.positions[index]), 1.0));
                    v[k].position = glm::vec4(local, 1.0f);
                    out.bounds.extend(local);
                    v[k].uv0 = hasUv0 ? prim.uv0[index] : glm::vec2(0.0f);
                    v[k].lightmapUv = prim.uv1[index] * rect.scale + rect.offset;
                    v[k].normal = glm::vec4(0.0f);
                    if (hasNormals) {
                        const glm::vec3 n = normalFromObject * prim.normals[index];
                        const float len = glm::length(n);
                        if (len > 0.0f && std::isfinite(len)) v[k].normal = glm::vec4(n / len, 0.0f);
                    }
                }
                // missing or degenerate normals: the face normal of the (re-ordered) triangle
                const glm::vec3 face = glm::cross(glm::vec3(v[1].position - v[0].position),
                                                  glm::vec3(v[2].position - v[0].position));
                const float faceLen = glm::length(face);
                for (int k = 0; k < 3; ++k) {
                    if (v[k].normal == glm::vec4(0.0f) && faceLen > 0.0f)
                        v[k].normal = glm::vec4(face / faceLen, 0.0f);
                }
                // the triangle's side as the update pass derives it (TRIANGLE_DERIVATIVE_NORMAL_FLIPPED)
                const glm::vec3 shading = glm::vec3(v[0].normal + v[1].normal + v[2].normal);
                const glm::vec2 e1 = v[1].lightmapUv - v[0].lightmapUv, e2 = v[2].lightmapUv - v[0].lightmapUv;
                const bool windingAgrees = glm::dot(face, shading) >= 0.0f;
                const bool uvCounterClockwise = double(e1.x) * e2.y - double(e1.y) * e2.x > 0.0;
                if (windingAgrees != uvCounterClockwise) out.triangles[slot].flags |= TRIANGLE_DERIVATIVE_NORMAL_FLIPPED;
            }
        }
    }
    out.pageFirstTriangle = std::move(first);
    out.origin = scene.origin;
    const std::vector<LightmapEdge> edges = sortedLightmapEdges(out);
    for (size_t i = 0; i < edges.size(); ++i) {
        const bool shared = (i > 0 && sameEdge(edges[i - 1], edges[i])) ||
                            (i + 1 < edges.size() && sameEdge(edges[i], edges[i + 1]));
        if (!shared) out.triangles[edges[i].triangle].flags |= TRIANGLE_CHART_BORDER0 << edges[i].opposite;
    }
    return out;
}

}  // namespace bb
