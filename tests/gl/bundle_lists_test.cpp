// The bundle pass's per-pixel linked lists against a CPU ray cast.
//
// Baker::captureBundle(d) draws one bundle as a single tile and reads back
// every pixel's list (depths sorted, NODE_VISIBLE_* flags, decoded radiance)
// and the frame. On the CPU, the ray through each pixel centre,
//   p(t) = c_u u + c_v v + t d,  (c_u, c_v) = origin + (x + 0.5, y + 0.5) pixelSize,
// is intersected with every world-space triangle of Baker::mesh() (in the
// bundle frame, where it is a 2D point-in-triangle test plus a barycentric
// depth, as rasterization does), and the lists must agree:
//   - the atomic counter equals the sum of the list lengths, and the lists are
//     well formed (no cycle, every index below the counter);
//   - per pixel, the same number of fragments, except at pixel centres within
//     1/64 pixel of a triangle edge, where GL's fixed-point snapping (8
//     subpixel bits in llvmpipe) and the top-left rule may decide differently
//     from exact arithmetic: such pixels must stay below 0.1% of the grid;
//   - sorted depths within 1e-4 x the scene size + 1e-3 x tan(theta) x pixel
//     size (near an edge, + 1/512 x tan(theta) x pixel size: a centre the
//     snapped triangle covers and the true one does not reads the depth of
//     the true one's nearest point), theta the angle between the triangle's
//     normal and d (the stored
//     depth loses its 2 low mantissa bits to the flags, a relative 5e-7, and
//     llvmpipe interpolates in float: a position error e across the plane is a
//     depth error tan(theta) e, which matters on nearly edge-on triangles;
//     measured max 1e-4 at tan(theta) = 187 in the Cornell box, i.e. 1.5e-4 x
//     tan(theta) x pixel size, 1.2e-5 x scene size elsewhere);
//   - where the counts differ, every node at the depth of a triangle that
//     holds the centre or passes within 1/64 pixel of it (its nearest point's);
//   - flags: NODE_VISIBLE_FROM_BEHIND when the (single-sided) triangle's
//     normal . d < 0, NODE_VISIBLE_FROM_AHEAD when > 0, both when double-sided.
// Bundle resolution 256 (65536 pixels), so edge pixels are a small share.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "glsl/shared/bundle_layout.h"
#include "support/bake_helper.h"

namespace bb::test {
namespace {

struct CpuHit {
    double depth;
    int triangle;
};

struct CastResult {
    std::vector<std::vector<CpuHit>> hits;  // per pixel, sorted by depth
    // per pixel, the triangles whose edge passes within `edgeMargin` of its
    // centre without holding it, each at the depth of its point nearest the centre
    std::vector<std::vector<CpuHit>> near;
    std::vector<uint8_t> nearEdge;          // pixel centre within `edgeMargin` pixels of an edge of a triangle
    size_t total = 0;
};

CastResult castRays(const BakeMesh& mesh, const Baker::BundleCapture& cap, double edgeMargin) {
    CastResult out;
    const size_t pixels = size_t(cap.width) * cap.height;
    out.hits.resize(pixels);
    out.near.resize(pixels);
    out.nearEdge.assign(pixels, 0);
    const glm::dvec3 u(cap.u), v(cap.v), d(cap.dir);
    const double ps = cap.pixelSize;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        glm::dvec3 q[3];  // (pixel x, pixel y, depth) of each vertex
        for (int k = 0; k < 3; ++k) {
            glm::dvec3 p(mesh.vertices[3 * t + k].position);
            q[k] = glm::dvec3((glm::dot(p, u) - cap.origin.x) / ps, (glm::dot(p, v) - cap.origin.y) / ps, glm::dot(p, d));
        }
        const double area = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[2].x - q[0].x) * (q[1].y - q[0].y);
        if (area == 0) continue;  // edge-on: no fragments
        int x0 = std::max(0, int(std::floor(std::min({q[0].x, q[1].x, q[2].x}) - 1)));
        int x1 = std::min(cap.width - 1, int(std::ceil(std::max({q[0].x, q[1].x, q[2].x}) + 1)));
        int y0 = std::max(0, int(std::floor(std::min({q[0].y, q[1].y, q[2].y}) - 1)));
        int y1 = std::min(cap.height - 1, int(std::ceil(std::max({q[0].y, q[1].y, q[2].y}) + 1)));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const double px = x + 0.5, py = y + 0.5;
                double w[3], dist = 1e300, nearest = 1e300, nearestDepth = 0;
                for (int k = 0; k < 3; ++k) {
                    const glm::dvec3& a = q[(k + 1) % 3];
                    const glm::dvec3& b = q[(k + 2) % 3];
                    w[k] = (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);  // edge function opposite vertex k
                    const double len = std::hypot(b.x - a.x, b.y - a.y);
                    // distance to the edge segment's supporting line, when the foot is on the segment
                    double s = len > 0 ? ((px - a.x) * (b.x - a.x) + (py - a.y) * (b.y - a.y)) / (len * len) : 0;
                    if (s >= -0.01 && s <= 1.01 && len > 0) dist = std::min(dist, std::abs(w[k]) / len);
                    // the segment's point nearest the centre, and its depth
                    s = std::clamp(s, 0.0, 1.0);
                    const double e = std::hypot(a.x + s * (b.x - a.x) - px, a.y + s * (b.y - a.y) - py);
                    if (e < nearest) nearest = e, nearestDepth = a.z + s * (b.z - a.z);
                }
                for (double& wk : w) wk /= area;  // barycentrics (sign-corrected)
                const size_t i = size_t(y) * cap.width + x;
                if (dist < edgeMargin) out.nearEdge[i] = 1;
                if (w[0] > 0 && w[1] > 0 && w[2] > 0) {
                    out.hits[i].push_back({w[0] * q[0].z + w[1] * q[1].z + w[2] * q[2].z, int(t)});
                    ++out.total;
                } else if (nearest < edgeMargin) {
                    out.near[i].push_back({nearestDepth, int(t)});
                }
            }
    }
    for (auto& h : out.hits) std::sort(h.begin(), h.end(), [](const CpuHit& a, const CpuHit& b) { return a.depth < b.depth; });
    return out;
}

void checkScene(const char* file, const std::vector<glm::vec3>& directions, bool furnaceRadiance) {
    BB_REQUIRE_GL();
    BakeOptions options;
    options.directions = 1;
    options.bundleResolution = 256;
    SceneBake bake = makeBake(file, assetLayout(64), options);
    ASSERT_TRUE(bake) << bake.error;
    const BakeMesh& mesh = bake.baker->mesh();
    const double sceneSize = glm::length(mesh.bounds.size());

    for (glm::vec3 dir : directions) {
        dir = glm::normalize(dir);
        SCOPED_TRACE(std::string(file) + " d = (" + std::to_string(dir.x) + ", " + std::to_string(dir.y) + ", " +
                     std::to_string(dir.z) + ")");
        Baker::BundleCapture cap = bake.baker->captureBundle(dir);
        ASSERT_EQ(cap.width, 256);
        ASSERT_EQ(cap.height, 256);
        ASSERT_TRUE(cap.listsWellFormed) << "a list has a cycle or an index >= the node counter";
        EXPECT_NEAR(glm::dot(cap.dir, dir), 1.0f, 1e-6f);
        EXPECT_NEAR(glm::dot(cap.u, cap.dir), 0.0f, 1e-6f);
        EXPECT_NEAR(glm::dot(cap.v, cap.dir), 0.0f, 1e-6f);
        EXPECT_NEAR(glm::dot(glm::cross(cap.u, cap.v), cap.dir), 1.0f, 1e-5f) << "u x v = d";

        size_t listed = 0;
        for (const auto& l : cap.depths) listed += l.size();
        EXPECT_EQ(listed, size_t(cap.nodeCount)) << "nodes reachable from the heads != the atomic counter";

        CastResult cpu = castRays(mesh, cap, 1.0 / 64.0);
        // depth slope across the bundle plane: tan(theta) between triangle t's normal and d
        // (near an edge, plus half a subpixel step along the slope: the raster
        // covers the snapped triangle, and a centre off the true one reads its
        // depth at the triangle's nearest point, append.frag planePoint)
        auto facingOf = [&](int t) {  // triangle t's normal . d
            glm::dvec3 a(mesh.vertices[3 * size_t(t)].position), b(mesh.vertices[3 * size_t(t) + 1].position),
                c(mesh.vertices[3 * size_t(t) + 2].position);
            return glm::dot(glm::normalize(glm::cross(b - a, c - a)), glm::dvec3(cap.dir));
        };
        auto allowedDepthError = [&](int t, bool nearAnEdge) {
            const double facing = facingOf(t);
            const double tanTheta = std::sqrt(std::max(0.0, 1.0 - facing * facing)) / std::max(std::abs(facing), 1e-9);
            return 1e-4 * sceneSize + (1e-3 + (nearAnEdge ? 1.0 / 512.0 : 0.0)) * tanTheta * cap.pixelSize;
        };
        // Every node of a pixel whose count differs lies on a triangle that
        // holds the centre or passes within the margin of it, at its depth
        // there (the raster covers the triangle snapped to its subpixel grid:
        // such a pixel's nodes are not compared one to one below).
        size_t strayNodes = 0;
        std::string firstStray;
        const size_t pixels = size_t(cap.width) * cap.height;
        size_t radianceCount = 0, countMismatch = 0, countMismatchAwayFromEdges = 0, flagMismatch = 0, compared = 0, nearEdge = 0;
        double maxDepthError = 0, maxDepthErrorRatio = 0, radianceSum = 0, maxRadianceError = 0;
        std::string firstProblem;
        for (size_t i = 0; i < pixels; ++i) {
            nearEdge += cpu.nearEdge[i];
            const auto& gpuDepths = cap.depths[i];
            const auto& hits = cpu.hits[i];
            const auto& nearHits = cpu.near[i];
            if (gpuDepths.size() != hits.size()) {
                ++countMismatch;
                for (const float g : gpuDepths) {
                    bool onOne = false;
                    for (const std::vector<CpuHit>* list : {&hits, &nearHits})
                        for (const CpuHit& h : *list) onOne |= std::abs(double(g) - h.depth) <= allowedDepthError(h.triangle, true);
                    if (!onOne && strayNodes++ == 0)
                        firstStray = "pixel (" + std::to_string(i % cap.width) + ", " + std::to_string(i / cap.width) +
                                     "): a node at depth " + std::to_string(g) + " on no triangle near its centre";
                }
                if (!cpu.nearEdge[i]) {
                    ++countMismatchAwayFromEdges;
                    if (firstProblem.empty())
                        firstProblem = "pixel (" + std::to_string(i % cap.width) + ", " + std::to_string(i / cap.width) +
                                       "): GPU " + std::to_string(gpuDepths.size()) + " fragments, CPU " +
                                       std::to_string(hits.size());
                }
                continue;
            }
            for (size_t k = 0; k < hits.size(); ++k) {
                ++compared;
                const int t = hits[k].triangle;
                const double facing = facingOf(t);
                const double error = std::abs(double(gpuDepths[k]) - hits[k].depth);
                const double allowedError = allowedDepthError(t, cpu.nearEdge[i]);
                maxDepthError = std::max(maxDepthError, error);
                maxDepthErrorRatio = std::max(maxDepthErrorRatio, error / allowedError);
                if (error > allowedError && firstProblem.empty())
                    firstProblem = "pixel " + std::to_string(i) + " fragment " + std::to_string(k) + ": depth " +
                                   std::to_string(gpuDepths[k]) + ", CPU " + std::to_string(hits[k].depth);
                uint32_t expected;
                if (mesh.triangles[size_t(t)].flags & TRIANGLE_DOUBLE_SIDED)
                    expected = NODE_VISIBLE_FROM_BEHIND | NODE_VISIBLE_FROM_AHEAD;
                else
                    expected = facing < 0 ? NODE_VISIBLE_FROM_BEHIND : NODE_VISIBLE_FROM_AHEAD;
                if (cap.flags[i][k] != expected) {
                    ++flagMismatch;
                    if (firstProblem.empty())
                        firstProblem = "pixel " + std::to_string(i) + " fragment " + std::to_string(k) + ": flags " +
                                       std::to_string(cap.flags[i][k]) + ", expected " + std::to_string(expected);
                }
                if (furnaceRadiance) {
                    for (int ch = 0; ch < 3; ++ch) {
                        radianceSum += cap.radiance[i][k][ch];
                        ++radianceCount;
                        maxRadianceError = std::max(maxRadianceError, std::abs(double(cap.radiance[i][k][ch]) - 1.0));
                    }
                }
            }
        }
        std::printf("[bundle lists] %s d=(%.3f, %.3f, %.3f): %u nodes, CPU %zu hits; %zu pixels differ in count (%zu "
                    "away from edges; %zu pixel centres near an edge); max depth error %.3g (scene size %.3g; %.3g of the "
                    "allowed); %zu flag mismatches of %zu; %zu stray nodes; max furnace radiance error %.3g\n",
                    file, dir.x, dir.y, dir.z, cap.nodeCount, cpu.total, countMismatch, countMismatchAwayFromEdges,
                    nearEdge, maxDepthError, sceneSize, maxDepthErrorRatio, flagMismatch, compared, strayNodes,
                    maxRadianceError);

        EXPECT_GT(cap.nodeCount, 0u);
        const double allowed = 0.001 * double(pixels);
        EXPECT_LE(double(countMismatch), allowed)
            << countMismatch << " pixels have a different fragment count from the CPU ray cast (allowed 0.1% of "
            << pixels << "); " << firstProblem;
        EXPECT_EQ(countMismatchAwayFromEdges, 0u)
            << "fragment counts differ at pixel centres more than 1/64 pixel from any edge: " << firstProblem;
        EXPECT_LE(std::abs(double(cap.nodeCount) - double(cpu.total)), allowed)
            << "total nodes " << cap.nodeCount << " vs CPU hits " << cpu.total;
        EXPECT_LE(maxDepthErrorRatio, 1.0) << "sorted node depths differ from the CPU ray cast by more than "
                                              "1e-4 x scene size + 1e-3 x tan(theta) x pixel size: "
                                           << firstProblem;
        EXPECT_EQ(flagMismatch, 0u) << "NODE_VISIBLE_* flags do not match the triangles' facing: " << firstProblem;
        EXPECT_EQ(strayNodes, 0u) << "nodes off their triangles' depth near an edge: " << firstStray;
        // Before any direction the light map is 0, so every furnace node carries Lo = Le = 1. The bundle pass
        // reads it bilinearly from an fp32 texture (1 +- 1 ulp) and RGBE-encodes it with stochastic rounding:
        // a value a hair above 1 becomes 129/128 with a tiny probability (measured: 1..4 channels in 230000),
        // so each node within one RGBE step (1/128) and the mean within 1e-5.
        if (furnaceRadiance) {
            EXPECT_LE(maxRadianceError, 1.0 / 128 + 1e-6) << "a furnace node's radiance is not Le = 1";
            EXPECT_NEAR(radianceSum / double(std::max<size_t>(radianceCount, 1)), 1.0, 1e-5);
        }
        EXPECT_GT(compared, size_t(0.9 * cpu.total)) << "too few pixels could be compared";
    }
}

const std::vector<glm::vec3> kDirections = {
    {0.3f, -0.8f, 0.52f},
    {-0.61f, 0.23f, -0.76f},
    {0.017f, 0.9998f, -0.011f},  // within 1.2 degrees of +Y: walls nearly edge-on
    {0.9999996f, 0.0007f, -0.0005f},  // within 0.05 degrees of +X: walls at a depth slope of 1000
};

TEST(BundleLists, FurnaceMatchesCpuRayCast) { checkScene("assets/furnace/furnace.gltf", kDirections, true); }

TEST(BundleLists, CornellBoxMatchesCpuRayCast) { checkScene("assets/cornell_box/cornell_box.gltf", kDirections, false); }

}  // namespace
}  // namespace bb::test

