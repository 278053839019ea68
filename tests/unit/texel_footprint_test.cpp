// A texel's footprint test (layout/bake_mesh.h texelFootprints, read by
// lib/texel_footprint.glsl offChart): the part of its square on its chart.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "layout/bake_mesh.h"
#include "support/page_meshes.h"

namespace bb {
namespace {

// A strip 0.1 texel wide across texels 2..5 of row 5 of a 16 x 16 page (v
// from 5.455 to 5.555, both inside the cell row [5.5, 5.625) or next to it),
// one quad split along (2, 5.455)-(6, 5.555): the texels' centres lie on the
// triangle of the near edge (v = 5.455) in texels 4 and 5, on the far edge's
// in texels 2 and 3. The chart-border flags as buildBakeMesh sets them.
BakeMesh stripMesh() {
    BakeMesh m;
    const glm::vec2 o0(2, 5.455f), o1(6, 5.455f), w0(2, 5.555f), w1(6, 5.555f);
    addPageTriangle(m, {o0, o1, w1}, 16.0f, 0.0f, 1u | 4u);
    addPageTriangle(m, {o0, w1, w0}, 16.0f, 0.0f, 1u | 2u);
    m.pageFirstTriangle = {0, 2};
    return m;
}

// Every texel takes 0.1 of its square: the cells alone take the whole cell
// row past the far edge (0.17 of the square where the near edge's triangle
// owns the texel), and the far edge (the other triangle's) is what cuts it.
TEST(TexelFootprints, AStripNarrowerThanATexelTakesItsOwnWidth) {
    const BakeMesh m = stripMesh();
    const std::vector<int32_t> owners = texelOwners(m, 0, 16);
    const std::vector<TexelFootprint> f = texelFootprints(m, 0, 16, owners, findLightmapCharts(m));
    for (int x = 2; x < 6; ++x) {
        const size_t i = 5 * 16 + size_t(x);
        ASSERT_GE(owners[i], 0) << "texel " << x;
        std::printf("[footprint] texel %d: owner %d, area %.3f, edge %06x\n", x, owners[i], f[i].area / 255.0,
                    f[i].edge);
        EXPECT_NEAR(f[i].area / 255.0, 0.1, 0.005) << "texel " << x;
        // the test holds the strip: such a texel stays flat (no exact footprint)
        EXPECT_FALSE(f[i].inexact) << "texel " << x;
    }
    EXPECT_EQ(owners[5 * 16 + 5], 0) << "the near edge's triangle owns texel 5";
    EXPECT_NE(f[5 * 16 + 5].edge, 0u) << "the far edge cuts texel 5's cells";
}

// The strip's texels' spread is the strip's own (0.1 texel tall: 0.1^2 / 12
// across it, 1/12 along it), not its cell row's (1/8 tall, 1.6 times more
// across): the slope of a texel's light inside it divides by it (meta.frag
// slopeInside), and with the cells' a strip's slope read about a third low.
TEST(TexelFootprints, AStripsSpreadIsItsOwnNotItsCells) {
    const BakeMesh m = stripMesh();
    const std::vector<int32_t> owners = texelOwners(m, 0, 16);
    const std::vector<TexelFootprint> f = texelFootprints(m, 0, 16, owners, findLightmapCharts(m));
    for (int x = 2; x < 6; ++x) {
        const uint32_t code = f[5 * 16 + size_t(x)].spread;
        ASSERT_NE(code, 0u) << "texel " << x;
        // as lib/texel_footprint.glsl decodeFootprintSpread reads it
        const double xx = (code & 0x7ffu) / 2047.0 / 12.0, yy = ((code >> 11) & 0x7ffu) / 2047.0 / 12.0;
        const double xy = ((code >> 22) / 1022.0 * 2.0 - 1.0) / 12.0;
        std::printf("[footprint] texel %d: spread xx %.5f xy %+.5f yy %.5f\n", x, xx, xy, yy);
        EXPECT_NEAR(xx, 1.0 / 12.0, 0.004) << "texel " << x;
        EXPECT_NEAR(yy, 0.01 / 12.0, 0.00005) << "texel " << x;
        EXPECT_NEAR(xy, 0.0, 0.0001) << "texel " << x;
    }
}

// The half-plane's encoding rounds inward: points up to 0.002 texel inside
// its line may be left out, none past it is taken in.
TEST(TexelFootprints, EdgeEncodingRoundsInward) {
    for (int angle : {0, 700, 1024, 2500, 4095})
        for (double distance : {-0.6, -0.1, 0.0, 0.237, 0.7}) {
            const uint32_t code = encodeFootprintEdge(angle, distance);
            const glm::dvec2 n(std::cos(footprintEdgeAngle(angle)), std::sin(footprintEdgeAngle(angle)));
            const glm::dvec2 t(-n.y, n.x);
            for (double along : {-0.7, 0.0, 0.7}) {
                EXPECT_FALSE(insideFootprintEdge(code, n * (distance + 1e-4) + t * along)) << angle << " " << distance;
                EXPECT_TRUE(insideFootprintEdge(code, n * (distance - 0.002) + t * along)) << angle << " " << distance;
            }
        }
    EXPECT_TRUE(insideFootprintEdge(0u, glm::dvec2(0.5, 0.5)));  // no edge
}

}  // namespace
}  // namespace bb
