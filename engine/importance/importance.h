// Importance analysis: light map texel density per triangle, the CPU
// reference of the preprocessing the GL passes run (importance_gl.h).
//
// Based on: Tokuyoshi, Sekine, da Silva, Kanai, "Adaptive Ray-bundle Tracing
// with Memory Usage Prediction", CGF 32(7) 2013, supplement §1:
//   Eq. (1)  A_l(t) / A_o(t)                               (triangle area ratio)
//   Eq. (3)  I(x) = sum w(x_i) / sum w(x_i) |e_i|^2        (4-neighbour texel density)
//   Eq. (4)  I(t) = min(A_l(t)/A_o(t), I_max(t)),  I_max(t) = max_{x in t} I(x)
// One addition: a texel centre with no Eq. (3) estimate (no mapped neighbour:
// a chart too small for two texel centres, common on finely tessellated
// assets) gives I_max(t) = NO_DENSITY_ESTIMATE, and Eq. (4) then takes the
// triangle's own A_l/A_o (0 when that is not finite either). Without it such
// a triangle read I(t) = 0, "covers no texel centre", and its texel was never
// baked: black on the chair of mixed_lighting.
//
// Units: I is light map texels per world area (texels / scene unit^2), so the
// bundle pixel a triangle needs is 1/sqrt(I) scene units wide (DESIGN.md
// step 3). A_o is the triangle's area in *world* space (instance transforms
// applied), A_l its area in texels^2 of its page, and the positions of the
// position buffer are BakeMesh positions: world positions minus the scene's
// local origin (BakeMesh::origin), a translation, so areas and densities are
// the world ones. The supplement says "object space",
// but its objects are placed at world scale; a scaled instance must get a
// density per world area, because the bundle is a world-space grid: with
// object-space positions a mesh instanced at scale 10 would claim 100x the
// density it has. (BakeMesh already holds world-scale local positions.)
//
// GL-free: plain spans and structs. The texel conventions are those of the
// light map pages: texel (x, y) has its centre at page uv ((x+0.5)/R,
// (y+0.5)/R), row y = 0 at v = 0 (GL texture order).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "glsl/shared/importance_layout.h"
#include "layout/bake_mesh.h"

namespace bb {

// One texel of the position buffer (pass 1 of the GL implementation).
struct PositionTexel {
    glm::vec3 position{0.0f};  // local position (world - BakeMesh::origin) of the surface at the texel centre
    uint32_t triangle = 0;     // BakeMesh triangle index + 1 of the surface drawn there; 0 = not mapped (w = 0)
};

// One light map page of positions, row-major: texels[y * resolution + x].
struct PositionBuffer {
    int resolution = 0;
    std::vector<PositionTexel> texels;
    const PositionTexel& at(int x, int y) const { return texels[size_t(y) * resolution + x]; }
    bool mapped(int x, int y) const {
        return x >= 0 && y >= 0 && x < resolution && y < resolution && at(x, y).triangle != 0;
    }
};

// Per triangle results, indexed like BakeMesh::triangles. All values finite and >= 0.
struct Importance {
    std::vector<float> importance;  // I(t), Eq. (4): texels per scene unit^2
    std::vector<float> areaRatio;   // A_l(t)/A_o(t), Eq. (1) (MAX_AREA_RATIO when A_o = 0 < A_l)
    std::vector<float> maxDensity;  // I_max(t): max of Eq. (3) over the texel centres t covers; 0 if none,
                                    // NO_DENSITY_ESTIMATE if one of them has no estimate
    size_t size() const { return importance.size(); }
};

// Stand-in for Eq. (1)'s +infinity when a triangle has light map area but no
// world area (A_o = 0 in float): Eq. (4) then takes I_max(t).
inline constexpr float MAX_AREA_RATIO = float(IMPORTANCE_MAX_AREA_RATIO);  // FLT_MAX

// I_max(t) of a triangle covering a texel centre with no Eq. (3) estimate
// (texelDensity 0): Eq. (4) takes A_l/A_o where that is below MAX_AREA_RATIO, else 0.
inline constexpr float NO_DENSITY_ESTIMATE = float(IMPORTANCE_NO_DENSITY_ESTIMATE);  // FLT_MAX: wins every maximum
// Eq. (4) with that convention (clamp.comp mirrors it).
inline float triangleImportance(float areaRatio, float maxDensity) {
    if (maxDensity == NO_DENSITY_ESTIMATE) return areaRatio < MAX_AREA_RATIO ? areaRatio : 0.0f;
    return areaRatio < maxDensity ? areaRatio : maxDensity;
}

// Eq. (1) for one triangle: A_l/A_o with A_l in texels^2 of a page of
// `resolution` texels and A_o in world units^2. Conventions that keep it
// finite: A_l = 0 -> 0 (the triangle has no texels); A_o = 0 < A_l ->
// MAX_AREA_RATIO; a ratio above MAX_AREA_RATIO -> MAX_AREA_RATIO.
// Computed in double from the float inputs.
double worldArea(const BakeVertex* triangle);                    // A_o, 3 vertices
double texelArea(const BakeVertex* triangle, int resolution);    // A_l
float areaRatio(const BakeVertex* triangle, int resolution);

// An addition to the paper (issue 11): a curved surface needs pixels finer
// than its texels do where it bends within a pixel. A tube thinner than a
// pixel (mixed_lighting's chair piping, 7 mm across under 12 mm pixels) is
// seen by few pixel rays, and its texels' samples find their own surface in
// a neighbour's pixel or none: it read up to 3x the reference. The radius of
// curvature R is 1 / the largest turn of the shading normals per unit length
// along the triangle's edges (flat triangles: none). This returns I(t)
// raised so that the bundle pixel is at most R x kCurvaturePixelShare, and
// at most kMaxCurvatureRefine times finer than `importance` asks (the cost
// stays bounded on a finely bevelled asset); I(t) itself where it already
// asks for that, and 0 where it is 0 (not a receiver).
inline constexpr double kCurvaturePixelShare = 0.5;
inline constexpr double kMaxCurvatureRefine = 2.5;
float curvatureImportance(const BakeVertex* triangle, float importance, double pixelsPerTexel);

// Eq. (3) at texel (x, y) of a mapped texel: neighbours (x+1,y), (x,y+1),
// (x-1,y), (x,y-1); w = 1 where a neighbour is mapped (to any surface: the
// supplement's "mapped to an object"), 0 outside the page or unmapped. The
// result is finite: 0 when it cannot be estimated (no mapped neighbour,
// 0/0, or every mapped neighbour at the same position as x, n/0), i.e. such
// a texel does not raise I_max. Computed in double. Precondition: (x, y) mapped.
float texelDensity(const PositionBuffer& buffer, int x, int y);

// Eq. (2), the supplement's exact estimate, for tests and figures only: it is
// singular (0/0 or n/0, returned as NaN or Inf) where consecutive neighbours
// are missing or their edge vectors are collinear. Never used by the engine.
double texelDensityEq2(const PositionBuffer& buffer, int x, int y);

// The rasterization rules of the GL passes, so the CPU sees the same texels:
// a texel is covered when its centre is inside the triangle after the vertices
// are snapped to 1/2^subpixelBits texel (GL_SUBPIXEL_BITS; 8 on llvmpipe), and
// a centre exactly on an edge goes to one side by llvmpipe's fill convention
// in light map rows (top-left with row 0 as top). Triangles with zero snapped
// area cover nothing. `uv` are page-space light map coordinates. Calls
// fn(x, y, b) with the barycentric weights b of the texel centre (from the
// unsnapped coordinates, in double) for every covered texel of the page.
struct RasterRules {
    int subpixelBits = 8;
};
template <class Fn>
void rasterizeTriangle(const glm::vec2 uv[3], int resolution, const RasterRules& rules, Fn&& fn);

// Pass 1 on the CPU: triangles [first, last) of `vertices` (3 per triangle)
// drawn in order into a cleared page; later triangles overwrite earlier ones.
PositionBuffer rasterizePositionBuffer(std::span<const BakeVertex> vertices, uint32_t firstTriangle,
                                       uint32_t lastTriangle, int resolution, const RasterRules& rules = {});

// The whole preprocessing on the CPU: per page, the position buffer (or
// `positionBuffers[page]` when given, e.g. the GPU's, to check the later
// steps in isolation), Eq. (3) at every texel centre every triangle covers,
// I_max by maximum, then Eq. (1) and Eq. (4).
// Preconditions: vertices.size() == 3 * triangle count; pageFirstTriangle has
// pageCount + 1 entries (BakeMesh::pageFirstTriangle); positionBuffers, if
// not empty, has pageCount entries of `resolution`.
Importance computeImportance(std::span<const BakeVertex> vertices, std::span<const uint32_t> pageFirstTriangle,
                             int resolution, const RasterRules& rules = {},
                             std::span<const PositionBuffer> positionBuffers = {});
inline Importance computeImportance(const BakeMesh& mesh, int resolution, const RasterRules& rules = {},
                                    std::span<const PositionBuffer> positionBuffers = {}) {
    return computeImportance(mesh.vertices, mesh.pageFirstTriangle, resolution, rules, positionBuffers);
}

// The distribution a user looks at (CLI `importance`).
struct ImportanceSummary {
    size_t triangles = 0;
    float min = 0, median = 0, max = 0;    // of I(t) over all triangles
    float minNonZero = 0;                  // smallest I(t) > 0 (0 if none)
    size_t clamped = 0;                    // I_max(t) < A_l/A_o: Eq. (4) took the neighbourhood estimate
    size_t clampedBeyond1Percent = 0;      // I_max(t) < 0.99 A_l/A_o: clamped by more than float noise (on a
                                           // clean mesh both are the same density, and either may be lower)
    size_t zeroMaxDensity = 0;             // I_max(t) = 0: covers no texel centre (so I(t) = 0); among both
                                           // clamped counts when A_l > 0
};
ImportanceSummary summarize(const Importance& importance);

// ---------------------------------------------------------------------------
// Template definition.

namespace detail {
// Window coordinate of a page-space coordinate as the GL passes compute it
// (uv * 2 - 1 in the vertex shader, then the viewport transform), in float.
inline float windowFromUv(float uv, int resolution) {
    const float half = 0.5f * float(resolution);
    return (uv * 2.0f - 1.0f) * half + half;
}
// Whether a centre exactly on edge (dx, dy) of a triangle with positive
// orientation (counter-clockwise with y = row up the page) is inside.
// llvmpipe's convention for an FBO (rows from 0, its "top"): left edges and
// edges running along +x with the interior at larger rows.
inline bool ownsTie(int64_t dx, int64_t dy) { return dy < 0 || (dy == 0 && dx > 0); }
}  // namespace detail

template <class Fn>
void rasterizeTriangle(const glm::vec2 uv[3], int resolution, const RasterRules& rules, Fn&& fn) {
    const double one = double(int64_t(1) << rules.subpixelBits);
    // window coordinates (float, as the GPU) and their fixed-point snap, with
    // texel centres at integer multiples of `one` (GL's half-pixel centres)
    glm::dvec2 w[3];
    int64_t X[3], Y[3];
    for (int k = 0; k < 3; ++k) {
        w[k] = glm::dvec2(detail::windowFromUv(uv[k].x, resolution), detail::windowFromUv(uv[k].y, resolution));
        X[k] = int64_t(std::nearbyint((w[k].x - 0.5) * one));
        Y[k] = int64_t(std::nearbyint((w[k].y - 0.5) * one));
    }
    int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    if (area == 0) return;
    int order[3] = {0, 1, 2};
    if (area < 0) {
        std::swap(order[1], order[2]);
        area = -area;
    }
    int64_t ex[3], ey[3], ox[3], oy[3];
    for (int e = 0; e < 3; ++e) {
        const int a = order[e], b = order[(e + 1) % 3];
        ox[e] = X[a];
        oy[e] = Y[a];
        ex[e] = X[b] - X[a];
        ey[e] = Y[b] - Y[a];
    }
    const int64_t unit = int64_t(one);
    auto lowest = [&](int64_t v0, int64_t v1, int64_t v2) {  // first texel index whose centre is >= min
        const int64_t m = std::min({v0, v1, v2});
        return int(std::max<int64_t>(0, m >= 0 ? (m + unit - 1) / unit : -((-m) / unit)));
    };
    auto highest = [&](int64_t v0, int64_t v1, int64_t v2) {
        const int64_t m = std::max({v0, v1, v2});
        return int(std::min<int64_t>(resolution - 1, m >= 0 ? m / unit : -((-m + unit - 1) / unit)));
    };
    const int x0 = lowest(X[0], X[1], X[2]), x1 = highest(X[0], X[1], X[2]);
    const int y0 = lowest(Y[0], Y[1], Y[2]), y1 = highest(Y[0], Y[1], Y[2]);
    // barycentrics from the unsnapped window coordinates
    const glm::dvec2 d1 = w[1] - w[0], d2 = w[2] - w[0];
    const double det = d1.x * d2.y - d1.y * d2.x;
    for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
            const int64_t px = int64_t(x) * unit, py = int64_t(y) * unit;
            bool inside = true;
            for (int e = 0; e < 3 && inside; ++e) {
                const int64_t f = ex[e] * (py - oy[e]) - ey[e] * (px - ox[e]);
                inside = f > 0 || (f == 0 && detail::ownsTie(ex[e], ey[e]));
            }
            if (!inside) continue;
            glm::dvec3 b(1.0 / 3.0);
            if (det != 0.0) {
                const glm::dvec2 q = glm::dvec2(x + 0.5, y + 0.5) - w[0];
                b.y = (q.x * d2.y - q.y * d2.x) / det;
                b.z = (d1.x * q.y - d1.y * q.x) / det;
                b.x = 1.0 - b.y - b.z;
            }
            fn(x, y, b);
        }
    }
}

}  // namespace bb
