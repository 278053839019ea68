// Light map UV generation (TEXCOORD_1) for meshes that have none, or for all
// meshes with `--uv-layout generate`: charts, a low-stretch parameterisation
// per chart, and packing on a texel grid. computeLayout (layout.h) drives it;
// these calls are the stages, public for tests and tools.
//
//   makeCharts   cut a mesh into charts (hard edges and a normal cone split),
//                flatten each (planar projection, or LSCM where it is curved),
//                split the vertices so that every vertex lies in one chart.
//                Costs about 1 s per million triangles on one core.
//   packCharts   place the charts' rectangles on an integer texel grid at a
//                given texel density, `gap` free texels between rectangles
//                (texel centres of two charts are gap + 1 texels apart or
//                more), each chart centred in the whole texels around it (a
//                chart of whole texels fills them exactly). O(charts); called
//                many times by the automatic density search.
//   writeUv1     TEXCOORD_1 = texel position / grid size, and Mesh::uv1Grid.
//
// Units: charts are cut and measured in "metric" space, the mesh's object
// space through the linear part of its instances' transform (instances of one
// generated mesh share that part up to a rotation, see computeLayout), so a
// chart's size is in scene units and `texelsPerUnit` is the texel density.
//
// GL-free, deterministic (the same mesh gives the same bytes).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace bb {

struct UvChartOptions {
    // Adjacent triangles whose face normals differ by more than this start new
    // charts (typ. 45..89; a cube's 90-degree edges always split).
    float hardAngleDegrees = 60.0f;
    // Every triangle of a chart is within this angle of the chart's first
    // (seed) triangle: charts stay disk-like and project without folding (< 90).
    float coneAngleDegrees = 60.0f;
    // Upper bound on a chart's triangles (bounds the LSCM solve; typ. 4k..64k).
    int maxChartTriangles = 16384;
};

// The charts of one mesh after makeCharts. Chart-local points are in metric
// units, rotated to the chart's smallest bounding rectangle (wider than
// tall), with the rectangle's lower-left corner at the origin.
struct MeshCharts {
    std::vector<glm::dvec2> extent;    // per chart: bounding rectangle size (x >= y), scene units
    std::vector<double> area;          // per chart: surface area, scene units^2
    std::vector<double> stretch;       // per chart: L2 stretch (Sander et al. 2001) after scaling to equal area; 1 = isometric
    std::vector<uint8_t> lscm;         // per chart: 1 if flattened by LSCM, 0 by planar projection
    std::vector<uint32_t> packOrder;   // charts by decreasing height (then width, index): packCharts' order
    size_t splitCharts = 0;            // charts cut again because their flattening folded over itself
    // per primitive of the mesh, per (split) vertex
    std::vector<std::vector<uint32_t>> vertexChart;
    std::vector<std::vector<glm::vec2>> vertexPoint;
    size_t chartCount() const { return extent.size(); }
};

// Cuts `mesh` into charts and flattens them. Splits vertices (positions,
// normals, TEXCOORD_0 and indices of every primitive are rewritten; a vertex
// in k charts becomes k vertices); TEXCOORD_1 is left for writeUv1.
// `metricFromObject`: linear part of the instances' world transform.
// Precondition: indices valid (as loadScene leaves them).
MeshCharts makeCharts(Mesh& mesh, const glm::dmat3& metricFromObject, const UvChartOptions& options = {});

struct ChartPacking {
    int width = 0, height = 0;         // the grid, texels (>= 1 each when there is a chart)
    std::vector<glm::ivec2> origin;    // per chart: lower-left texel of its rectangle
    std::vector<glm::ivec2> size;      // per chart: rectangle size, texels
    double texelsPerUnit = 0.0;
};

// Packs the charts' rectangles (max(1, ceil(extent * texelsPerUnit)) texels
// each way) by shelves, tallest first, into a grid about as wide as tall, with
// `gap` (>= 0) free texels between rectangles (none around the grid: the pack
// layout's padding is outside it). texelsPerUnit >= 0.
ChartPacking packCharts(const MeshCharts& charts, double texelsPerUnit, int gap);

// Writes TEXCOORD_1 of every primitive of `mesh` (uv1 = texel / grid, each
// chart centred in its rectangle) and mesh.uv1Grid.
// Precondition: `charts` came from makeCharts on this mesh.
void writeUv1(Mesh& mesh, const MeshCharts& charts, const ChartPacking& packing);

// Texel centres of a width x height grid inside the TEXCOORD_1 triangles of
// `mesh` (uv1 * grid; a centre on a shared edge counts for neither side), and
// those inside two or more. Centres within 1e-4 texel of an edge count as on it.
struct GridCoverage {
    size_t covered = 0;
    size_t overlapping = 0;
};
GridCoverage gridCoverage(const Mesh& mesh, int width, int height);

}  // namespace bb
