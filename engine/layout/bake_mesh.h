// The scene flattened for baking: every instance's triangles in local space
// (world - Scene::origin, see scene.h), with light map coordinates already in
// page space. One vertex array for all GL passes (bundle, update, importance,
// viewer) and the CPU reference, which all work in this local space.
//
// GL-free. Vertex layout is std430-friendly (no vec3 members): it is uploaded
// as-is into a vertex buffer.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "glsl/shared/mesh_layout.h"  // TRIANGLE_DOUBLE_SIDED, TRIANGLE_EMISSIVE
#include "layout/layout.h"
#include "scene/scene.h"

namespace bb {

struct BakeVertex {
    glm::vec4 position;   // xyz local position (world - BakeMesh::origin), w = 1
    glm::vec4 normal;     // xyz world unit normal (shading), w = 0
    glm::vec2 uv0;        // material texture coordinates (TEXCOORD_0, 0 if absent)
    glm::vec2 lightmapUv; // page-space light map coordinates in [0,1]^2
};
static_assert(sizeof(BakeVertex) == 48);

struct BakeTriangle {
    uint32_t material;    // index into Scene::materials
    uint32_t page;        // light map page
    uint32_t instance;    // index into Scene::instances
    uint32_t flags;       // TRIANGLE_* (glsl/shared/mesh_layout.h)
};
static_assert(sizeof(BakeTriangle) == 16);


struct BakeMesh {
    std::vector<BakeVertex> vertices;     // 3 per triangle, not shared (simple, and normals may differ)
    std::vector<BakeTriangle> triangles;
    std::vector<uint32_t> pageFirstTriangle;  // triangles are sorted by page; page p is [first[p], first[p+1])
    // Per triangle, its index as buildBakeMesh wrote it. Whoever reorders the
    // triangles (the bake's clusters, tiler/tiler.h) moves it with them, so
    // that pageDrawOrder, and with it which triangle owns a texel where two
    // tie, is the same in every consumer's mesh. Empty: the triangles' order.
    std::vector<uint32_t> builtIndex;
    Bounds bounds;            // of the positions (local space)
    glm::dvec3 origin{0.0};   // Scene::origin: world = position + origin (directions are the same in both)
    size_t triangleCount() const { return triangles.size(); }
    // whether any triangle has any of `flags` (TRIANGLE_*)
    bool anyTriangle(uint32_t flags) const {
        return std::any_of(triangles.begin(), triangles.end(), [&](const BakeTriangle& t) { return (t.flags & flags) != 0u; });
    }
};

// Transforms every instance into local space in double (the exact world
// transform, then minus Scene::origin) before rounding positions to float;
// normals go by the inverse transpose of the float linear part. Maps
// TEXCOORD_1 through the instance's rectangle, sorts triangles by page.
// A scene translated by a node translation T (T + position exact in double)
// gives the same bytes as the untranslated one whenever T moves the origin by
// T too (chooseLocalOrigin away from the world origin).
// Precondition: layout was computed for this scene.
// Sets TRIANGLE_CHART_BORDER0 << k on every edge no other triangle shares.
BakeMesh buildBakeMesh(const Scene& scene, const Layout& layout);

// Light map charts: triangles of one page joined by shared light map edges
// (both end points bit-identical in page space, as buildBakeMesh copies them
// from one source vertex). Returns a chart id per triangle.
std::vector<uint32_t> findLightmapCharts(const BakeMesh& mesh);

// Page `page`'s triangles in the GPU meta pass's draw order: by material,
// then by BakeMesh::builtIndex (not by the mesh's order, which the bake's
// clusters change and the reference's does not).
std::vector<uint32_t> pageDrawOrder(const BakeMesh& mesh, int page);

// Triangle t's corners in page space, in texels of a res x res page, counter-
// clockwise. Returns twice its area (0 or not finite: degenerate).
double pageCorners(const BakeMesh& mesh, uint32_t t, int res, glm::dvec2 (&q)[3]);

// Coverage on the CPU: per texel of the page (row-major, res x res), the
// triangle whose page-space triangle holds the texel's centre, or -1. Ties
// follow GL's rule as Mesa applies it (left and bottom edges count); where
// triangles overlap, the last in pageDrawOrder wins, as in the GPU's coverage
// pass (llvmpipe snaps to 1/256 texel, so a centre exactly on an edge may
// still differ).
// A texel whose centre no triangle holds but whose square the triangles cover
// in part (at least kMinPartialTexelArea of it: a chart border running past
// the centre) is a texel too, as production bakers' conservative
// rasterization makes it: its owner is the triangle holding the most of its
// square (the last in pageDrawOrder of equals), and `partial` (if given) flags
// it. The light map raster does not reach such texels; the light passes draw
// them as curved ones (curvedTexels, CurvedTexel::flat). Thinner parts stay
// padding: a bundle pixel's centre crosses them in too few directions
// (update.frag footprintPixel), and a sliver a sixtieth of its square read
// 20 % noise at 2048 directions where its neighbours read 1 %.
// A supersampled bake (bake/supersample.h) takes a quarter of that: the half-
// size texels of a strip a fifth of a texel wide along a texel's centre line
// hold a fifth of their square each, and the texel they make must have them.
constexpr double kMinPartialTexelArea = 0.25;
std::vector<int32_t> texelOwners(const BakeMesh& mesh, int page, int res, std::vector<uint8_t>* partial = nullptr,
                                 double minPartialArea = kMinPartialTexelArea);

// The owners of a supersampled bake's half-size texels (bake/supersample.h):
// texelOwners at 2 res with a quarter of kMinPartialTexelArea, except that a
// half-size texel holding a sixteenth of its square or more of its texel's
// chart (texelOwners' owner at res, by `charts`) belongs to that chart: to
// the chart's triangle holding the most of it, as a partial texel. The
// texel's value is its quarters' values on its chart; a quarter another
// chart took held a part of the footprint no half-size texel baked, and where
// the light changes across the texel (a roof's edge under a taller
// neighbour, 0.97 to 0.62 in a fifth of a texel) the texel read the rest's
// mean, 8 % bright on the bench city. The half-size texels no texel's value
// needs (their chart is not their texel's) then go, largest part first, to
// charts lying in them (a sixteenth or more) that own none of the 3 x 3
// around them, while the chart they are taken from keeps one there: a strip
// that loses every texel it lies in to wider charts (286 of the bench city's
// 1680) gets texels of its own, and its bundle fragments read its light, not
// the band's beside it (append.frag ownTexel). Charts still owning none near a
// half-size texel they lie in then take it from its texel's chart, the
// smallest loss first, where that chart keeps at least half its part of the
// texel in the other quarters (the texel's value leaves the rest out).
// `coarse`: the texels' owners at res when not texelOwners' (a bake 4 x 4 to
// a texel gives each half-size texel its texel's owner: bake/supersample.h).
std::vector<int32_t> halfTexelOwners(const BakeMesh& mesh, const std::vector<uint32_t>& charts, int page, int res,
                                     std::vector<uint8_t>* partial = nullptr,
                                     const std::vector<int32_t>* coarse = nullptr);

// Which parts of each texel's square lie on its chart (the chart of its owner,
// texelOwners): bit 8 j + i for the cell [i/8, (i+1)/8) x [j/8, (j+1)/8) of the
// square, set where the cell touches one of the chart's triangles (its centre
// or a corner inset by 1/10 of the cell). A footprint point in a cell whose
// bit is clear is off the chart (lib/texel_footprint.glsl). Texels whose eight
// neighbours are all on their chart: every bit; uncovered texels: none.
std::vector<uint64_t> footprintMasks(const BakeMesh& mesh, int page, int res, const std::vector<int32_t>& owner,
                                     const std::vector<uint32_t>& chart);

// Each texel's footprint test (lib/texel_footprint.glsl offChart), one RGB32UI
// texel of the footprint texture: a point of its square is on its chart where
// it lies within the owner triangle's chart-border edges (exact), in a cell of
// `cells` and inside `edge`.
struct TexelFootprint {
    uint64_t cells = 0;  // footprintMasks
    // One more border of its part of the chart, where a cell the chart only
    // partly covers would take in more than a few points off it: another
    // triangle's chart-border edge (the far side of a strip narrower than a
    // texel, whose near side the owner holds), a half-plane as
    // insideFootprintEdge reads it (24 bits); 0: none.
    uint32_t edge = 0;
    // The part of its square the test accepts, in 255ths (measured on a 32 x
    // 32 grid of points): the update pass expects a pixel centre to cross it
    // about area x (its square's projection in pixels) times (footprintPixel).
    uint8_t area = 0;
    // The test disagrees with the chart on more than kInexactFootprintShare of
    // the part of the square on it (points taken off it or left out): a chart
    // part the owner's border edges, the cells and one more edge do not hold,
    // as at the corner of a ring a fifth of a texel wide, whose other arm lies
    // past the owner's border line. Such a texel is drawn as a point
    // (curvedTexels, CurvedTexel::exact) and keeps the points one of its
    // triangles holds; `area` is then that part's (the grid's count).
    bool inexact = false;
    // Points of the 32 x 32 grid on the chart in each sixteenth of the square
    // (0..64; cell (x, y) at index x + 4 y, y up the page): how much each of
    // its k x k texels in a supersampled bake weighs in it (part;
    // bake/supersample.h).
    std::array<uint8_t, 16> sixteenths{};
    // How the points the test takes spread over the square: the covariance of
    // the accepted part (encodeFootprintSpread; an inexact texel's, of its
    // triangles' points on the grid; the whole square's where every cell is
    // on the chart); the slope of a texel's light inside it divides by it
    // (lightmap/meta.frag slopeInside). 0: none (uncovered, or no part accepted).
    uint32_t spread = 0;
    // The points in texel (x, y) of its k x k (k 1, 2 or 4)
    int part(int k, int x, int y) const {
        int sum = 0;
        for (int j = y * 4 / k; j < (y + 1) * 4 / k; ++j)
            for (int i = x * 4 / k; i < (x + 1) * 4 / k; ++i) sum += sixteenths[size_t(i + 4 * j)];
        return sum;
    }
};
constexpr double kInexactFootprintShare = 0.1;
std::vector<TexelFootprint> texelFootprints(const BakeMesh& mesh, int page, int res, const std::vector<int32_t>& owner,
                                            const std::vector<uint32_t>& chart);

// A half-plane of a texel's square as 24 bits: the low 12 the angle of its
// outward normal n (4096ths of a turn), the high 12 its distance d from the
// texel's centre (-0.75 + 1.5 x bits / 4095 texels); offsets o from the centre
// with n . o <= d are inside. `distance` is for the normal at the encoded
// angle, and rounds inward by up to 0.002 texel: a sliver of the chart is
// left out rather than a sliver past its border taken in (past a ledge's far
// border stands the wall it meets, whose fragments pass for the ledge's own
// within the update pass's depth tolerance). 0 is none (everything inside).
uint32_t encodeFootprintEdge(int angle, double distance);
// A covariance (xx, xy, yy, in texels^2) as 32 bits: xx and yy in 11 bits
// each over [0, 1/12], xy in 10 over [-1/12, 1/12] in 1022 steps (0 exact);
// never 0 (lib/texel_footprint.glsl decodeFootprintSpread).
uint32_t encodeFootprintSpread(double xx, double xy, double yy);
double footprintEdgeAngle(int angle);  // radians of an encoded angle (0..4095)
bool insideFootprintEdge(uint32_t code, glm::dvec2 offset);

// A texel whose footprint its owner's plane does not hold: its chart folds or
// curves within its square (a chair's piping, a box's edge), so a point of the
// square moved along the owner triangle's plane (lib/texel_footprint.glsl)
// would leave the surface by more than `departure` texels. Its samples find
// their point on the triangle that holds it instead (lib/curved_footprint.glsl).
struct CurvedTexel {
    uint32_t texel = 0;               // y * res + x
    std::vector<uint32_t> triangles;  // the owner's chart's triangles overlapping its square with area, owner first
    // A partial texel (texelOwners) whose chart is flat over its square: drawn
    // as a point (the raster misses its centre) but sampled as flat texels
    // are, along its owner's plane.
    bool flat = false;
    // A flat one whose flat footprint test is inexact (TexelFootprint): its
    // points are kept where one of `triangles` holds them instead.
    bool exact = false;
};

// The page's curved texels in texel order: of each covered texel, the part of
// its square on its owner's chart (clipSquare) mapped through each of the
// chart's triangles, against the same points on the owner's plane extended;
// departures measured in the owner's texel size (the longer of its per-texel
// steps along x and y). Every partial texel (`partial`, texelOwners' flags;
// empty: none) is one, flat where it does not depart; so is every texel whose
// flat footprint test is inexact (`footprints`, texelFootprints'; empty: none),
// with `exact` set.
std::vector<CurvedTexel> curvedTexels(const BakeMesh& mesh, int page, int res, const std::vector<int32_t>& owner,
                                      const std::vector<uint32_t>& chart, const std::vector<uint8_t>& partial = {},
                                      const std::vector<TexelFootprint>& footprints = {}, double departure = 0.02);

// Triangle t's position (normal) as an affine function of page texel
// coordinates: at(q) = at0 + dx * (q.x - q0.x) + dy * (q.y - q0.y). False where
// its light map triangle has no area.
struct TexelAffine {
    glm::dvec2 q0{0.0};
    glm::dvec3 at0{0.0}, dx{0.0}, dy{0.0};
    glm::dvec3 at(glm::dvec2 q) const { return at0 + dx * (q.x - q0.x) + dy * (q.y - q0.y); }
};
bool texelAffine(const BakeMesh& mesh, uint32_t t, int res, bool normals, TexelAffine& out);

// The unit square clipped to a counter-clockwise triangle (Sutherland-Hodgman):
// the part of a texel's square (triangle in that texel's coordinates) on it.
std::vector<glm::dvec2> clipSquare(const glm::dvec2 (&tri)[3]);

// How many covered texels of the page (owner >= 0) a triangle of another chart
// also overlaps (with area: charts that only touch along a texel's border do
// not count). Such a texel holds its owner's light, which bilinear filtering
// and the bundle pass's radiance reads then give the other chart's surface
// too: the asset's charts lie closer than a texel at this density.
size_t sharedTexels(const BakeMesh& mesh, int page, int res, const std::vector<int32_t>& owner,
                    const std::vector<uint32_t>& chart);

}  // namespace bb
