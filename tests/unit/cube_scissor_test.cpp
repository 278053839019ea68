// A single-sided emitter sample's cube faces draw only the pixels in front of
// the emitter (bake/cube_scissor.h): every pixel a lookup can read (a
// direction in front, or up to a few texels' angle behind) inside the face's
// rectangle, a face that looks along the emitter's normal whole, one that
// looks away from it empty, and on average much less than the whole cube.
#include <gtest/gtest.h>

#include <cmath>

#include "bake/cube_scissor.h"
#include "bake/rounding.h"

namespace bb {
namespace {

bool contains(const glm::ivec4& r, int x, int y) { return x >= r.x && y >= r.y && x < r.x + r.z && y < r.y + r.w; }

TEST(CubeScissor, HoldsEveryPixelALookupCanReadAndLittleElse) {
    const int size = 64;
    // the lookups step up to a texel's angle (2 / size at the face's centre) past
    // the plane: a margin of 3 texels' angle is what must be held
    const double needed = std::sin(3.0 * 2.0 / size);
    double drawn = 0.0;
    const int normals = 300;
    for (int i = 0; i < normals; ++i) {
        const double z = 1.0 - 2.0 * uniform01(pcgHash(2u * uint32_t(i))), phi = 6.283185307179586 * uniform01(pcgHash(2u * uint32_t(i) + 1u));
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const glm::dvec3 m(r * std::cos(phi), r * std::sin(phi), z);
        const glm::ivec4 rect = faceScissor(glm::vec3(m), size);
        ASSERT_GE(rect.z, 0);
        ASSERT_GE(rect.w, 0);
        ASSERT_TRUE(rect.z == 0 || (rect.x >= 0 && rect.y >= 0 && rect.x + rect.z <= size && rect.y + rect.w <= size));
        drawn += double(rect.z) * rect.w / (size * size);
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const glm::dvec3 d = glm::normalize(glm::dvec3((x + 0.5) / size * 2.0 - 1.0, (y + 0.5) / size * 2.0 - 1.0, -1.0));
                if (glm::dot(m, d) >= -needed) ASSERT_TRUE(contains(rect, x, y)) << "normal " << i << " pixel " << x << "," << y;
            }
    }
    // a plane through the cube's centre leaves half its directions; the rectangles
    // round that up (measured 0.63 of the faces at 268 texels a side)
    EXPECT_LT(drawn / normals, 0.75);
    EXPECT_GT(drawn / normals, 0.4);
    // the face that looks along the normal (its directions all in front), and the one that looks away
    EXPECT_EQ(faceScissor(glm::vec3(0, 0, -1), size), glm::ivec4(0, 0, size, size));
    const glm::ivec4 away = faceScissor(glm::vec3(0, 0, 1), size);
    EXPECT_TRUE(away.z == 0 || away.w == 0);
}

}  // namespace
}  // namespace bb
