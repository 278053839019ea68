// Importance analysis on the CPU: Eq. (1), (3), (4) of the supplement §1.
//
// Based on: Tokuyoshi, Sekine, da Silva, Kanai, "Adaptive Ray-bundle Tracing
// with Memory Usage Prediction", CGF 32(7) 2013, supplement §1. This is the
// reference the GL passes (importance_gl.cpp) are checked against; it follows
// them step by step (same rasterization rules, same neighbour set, same
// conventions for the undefined cases) but computes in double.
#include "importance/importance.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"

namespace bb {

double worldArea(const BakeVertex* t) {
    const glm::dvec3 p0(t[0].position), p1(t[1].position), p2(t[2].position);
    return 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
}

double texelArea(const BakeVertex* t, int resolution) {
    const glm::dvec2 a = (glm::dvec2(t[1].lightmapUv) - glm::dvec2(t[0].lightmapUv)) * double(resolution);
    const glm::dvec2 b = (glm::dvec2(t[2].lightmapUv) - glm::dvec2(t[0].lightmapUv)) * double(resolution);
    return 0.5 * std::abs(a.x * b.y - a.y * b.x);
}

float areaRatio(const BakeVertex* t, int resolution) {
    const double l = texelArea(t, resolution);
    if (!(l > 0.0)) return 0.0f;
    const double o = worldArea(t);
    const double r = l / o;  // +inf when o = 0
    return r >= double(MAX_AREA_RATIO) ? MAX_AREA_RATIO : float(r);
}

float curvatureImportance(const BakeVertex* t, float importance, double pixelsPerTexel) {
    if (!(importance > 0.0f) || importance >= MAX_AREA_RATIO) return importance;
    double curvature = 0.0;  // 1 / scene units
    for (int k = 0; k < 3; ++k) {
        const BakeVertex &a = t[k], &b = t[(k + 1) % 3];
        const double length = glm::length(glm::dvec3(b.position) - glm::dvec3(a.position));
        if (length > 0.0) curvature = std::max(curvature, glm::length(glm::dvec3(b.normal) - glm::dvec3(a.normal)) / length);
    }
    // pixel = 1 / (pixelsPerTexel sqrt(I)) = R x kCurvaturePixelShare
    const double wanted = curvature / (pixelsPerTexel * kCurvaturePixelShare);
    const double raised = std::min(wanted * wanted, kMaxCurvatureRefine * kMaxCurvatureRefine * double(importance));
    return std::max(importance, float(std::min(raised, double(MAX_AREA_RATIO))));
}

namespace {
// Neighbours x_0..x_3 in the supplement's cyclic order (j = i + 1 mod 4 is adjacent).
constexpr int NEIGHBOUR_DX[4] = {1, 0, -1, 0};
constexpr int NEIGHBOUR_DY[4] = {0, 1, 0, -1};
}  // namespace

float texelDensity(const PositionBuffer& buffer, int x, int y) {
    DCHECK(buffer.mapped(x, y));
    const glm::dvec3 p(buffer.at(x, y).position);
    double count = 0.0, sum = 0.0;
    for (int i = 0; i < 4; ++i) {
        const int xi = x + NEIGHBOUR_DX[i], yi = y + NEIGHBOUR_DY[i];
        if (!buffer.mapped(xi, yi)) continue;  // w(x_i) = 0
        const glm::dvec3 e = glm::dvec3(buffer.at(xi, yi).position) - p;
        count += 1.0;
        sum += glm::dot(e, e);
    }
    if (!(sum > 0.0)) return 0.0f;  // no neighbour (0/0) or all at p(x) (n/0): no estimate
    const double density = count / sum;
    return density < double(std::numeric_limits<float>::max()) ? float(density) : 0.0f;
}

double texelDensityEq2(const PositionBuffer& buffer, int x, int y) {
    const glm::dvec3 p(buffer.at(x, y).position);
    double w[4];
    glm::dvec3 e[4];
    for (int i = 0; i < 4; ++i) {
        const int xi = x + NEIGHBOUR_DX[i], yi = y + NEIGHBOUR_DY[i];
        w[i] = buffer.mapped(xi, yi) ? 1.0 : 0.0;
        e[i] = w[i] > 0.0 ? glm::dvec3(buffer.at(xi, yi).position) - p : glm::dvec3(0.0);
    }
    double num = 0.0, den = 0.0;
    for (int i = 0; i < 4; ++i) {
        const int j = (i + 1) % 4;
        num += w[i] * w[j];
        den += w[i] * w[j] * glm::length(glm::cross(e[i], e[j]));
    }
    return num / den;  // singular by design: NaN (0/0) or Inf (n/0)
}

PositionBuffer rasterizePositionBuffer(std::span<const BakeVertex> vertices, uint32_t firstTriangle,
                                       uint32_t lastTriangle, int resolution, const RasterRules& rules) {
    CHECK_LE(size_t(lastTriangle) * 3, vertices.size());
    PositionBuffer out;
    out.resolution = resolution;
    out.texels.assign(size_t(resolution) * resolution, PositionTexel{});
    for (uint32_t t = firstTriangle; t < lastTriangle; ++t) {
        const BakeVertex* v = &vertices[size_t(t) * 3];
        const glm::vec2 uv[3] = {v[0].lightmapUv, v[1].lightmapUv, v[2].lightmapUv};
        const glm::dvec3 p0(v[0].position), p1(v[1].position), p2(v[2].position);
        rasterizeTriangle(uv, resolution, rules, [&](int x, int y, const glm::dvec3& b) {
            PositionTexel& texel = out.texels[size_t(y) * resolution + x];
            texel.position = glm::vec3(b.x * p0 + b.y * p1 + b.z * p2);
            texel.triangle = t + 1;
        });
    }
    return out;
}

Importance computeImportance(std::span<const BakeVertex> vertices, std::span<const uint32_t> pageFirstTriangle,
                             int resolution, const RasterRules& rules, std::span<const PositionBuffer> positionBuffers) {
    CHECK(!pageFirstTriangle.empty());
    const size_t pageCount = pageFirstTriangle.size() - 1;
    const size_t triangleCount = pageFirstTriangle.back();
    CHECK_EQ(vertices.size(), triangleCount * 3);
    CHECK(positionBuffers.empty() || positionBuffers.size() == pageCount);

    Importance out;
    out.importance.assign(triangleCount, 0.0f);
    out.areaRatio.assign(triangleCount, 0.0f);
    out.maxDensity.assign(triangleCount, 0.0f);
    for (size_t page = 0; page < pageCount; ++page) {
        const uint32_t first = pageFirstTriangle[page], last = pageFirstTriangle[page + 1];
        // pass 1: the position buffer
        PositionBuffer own;
        if (positionBuffers.empty()) own = rasterizePositionBuffer(vertices, first, last, resolution, rules);
        const PositionBuffer& buffer = positionBuffers.empty() ? own : positionBuffers[page];
        CHECK_EQ(buffer.resolution, resolution);
        // Eq. (3) once per mapped texel (it depends on the texel only)
        std::vector<float> density(buffer.texels.size(), 0.0f);
        for (int y = 0; y < resolution; ++y)
            for (int x = 0; x < resolution; ++x)
                if (buffer.mapped(x, y)) density[size_t(y) * resolution + x] = texelDensity(buffer, x, y);
        // pass 2: every triangle takes the maximum over the texel centres it covers
        for (uint32_t t = first; t < last; ++t) {
            const BakeVertex* v = &vertices[size_t(t) * 3];
            const glm::vec2 uv[3] = {v[0].lightmapUv, v[1].lightmapUv, v[2].lightmapUv};
            float m = 0.0f;
            rasterizeTriangle(uv, resolution, rules, [&](int x, int y, const glm::dvec3&) {
                const float d = density[size_t(y) * resolution + x];
                m = std::max(m, d > 0.0f ? d : NO_DENSITY_ESTIMATE);
            });
            out.maxDensity[t] = m;
        }
    }
    // compute pass: Eq. (1) and Eq. (4)
    for (size_t t = 0; t < triangleCount; ++t) {
        out.areaRatio[t] = areaRatio(&vertices[t * 3], resolution);
        out.importance[t] = triangleImportance(out.areaRatio[t], out.maxDensity[t]);
    }
    return out;
}

ImportanceSummary summarize(const Importance& imp) {
    ImportanceSummary s;
    s.triangles = imp.size();
    if (imp.size() == 0) return s;
    std::vector<float> sorted = imp.importance;
    std::sort(sorted.begin(), sorted.end());
    s.min = sorted.front();
    s.max = sorted.back();
    const size_t n = sorted.size();
    s.median = n % 2 ? sorted[n / 2] : 0.5f * (sorted[n / 2 - 1] + sorted[n / 2]);
    auto nonZero = std::upper_bound(sorted.begin(), sorted.end(), 0.0f);
    s.minNonZero = nonZero != sorted.end() ? *nonZero : 0.0f;
    for (size_t t = 0; t < n; ++t) {
        if (imp.maxDensity[t] < imp.areaRatio[t]) ++s.clamped;
        if (double(imp.maxDensity[t]) < 0.99 * double(imp.areaRatio[t])) ++s.clampedBeyond1Percent;
        if (imp.maxDensity[t] == 0.0f) ++s.zeroMaxDensity;
    }
    return s;
}

}  // namespace bb
