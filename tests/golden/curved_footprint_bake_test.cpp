// A texel whose chart wraps a curved surface holds the mean over that surface
// (issue 11: curved texels, lib/curved_footprint.glsl).
//
// A tube of radius 0.5 along x, its TEXCOORD_1 chart squeezing the whole
// circumference into 0.9 of one texel row (as the piping of mixed_lighting's
// chair does: 96 slivers to a texel). Each texel of the row holds the mean
// over a full turn of the tube, sampled uniformly in the turn's angle (the
// chart is linear in it), with the tube's smooth normals. Black (albedo 0), so
// L_lm is what the tube receives:
// - a sun straight overhead, irradiance E: L_lm = E max(0, n.y) / pi, whose
//   mean over a turn is E / pi^2 (the lower half is lit by nothing);
// - an environment of radiance 1 above the horizon and 0 below: L_lm =
//   (1 + n.y) / 2 (the tube is convex: each point sees the sky but for its
//   horizon's tilt), mean 1/2 over a turn.
// The texel's centre lies on the tube's underside (the middle of the turn),
// so reading the whole texel along the owner triangle's plane, as flat
// texels do, gives the underside's light: 0 from the sun, about 0 from the
// environment (every such texel read so before curved texels).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "io/image_io.h"
#include "support/bake_helper.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

constexpr double PI = 3.14159265358979323846;
constexpr int kRes = 32, kSegments = 48;
constexpr float kRadius = 0.5f, kHalfLength = 2.0f;
// the tube's chart: u along x over texels [2, 30), the turn over v in [kRow + 0.05, kRow + 0.95)
constexpr int kRow = 5;

// The tube (instance 0), and under it nothing: an open tube without caps.
Scene tubeScene() {
    Scene scene;
    const int black = addMaterial(scene, glm::vec3(0.0f));
    Primitive p;
    for (int k = 0; k <= kSegments; ++k) {
        // angle 0 at the top (+y), the middle of the turn at the bottom: the
        // texel centres (v = kRow + 0.5) lie on the underside
        const double a = 2.0 * PI * k / kSegments;
        const glm::vec3 n(0.0f, float(std::cos(a)), float(std::sin(a)));
        for (int end = 0; end < 2; ++end) {
            p.positions.push_back(glm::vec3(end ? kHalfLength : -kHalfLength, 0.0f, 0.0f) + kRadius * n);
            p.normals.push_back(n);
            p.uv1.push_back(glm::vec2(end ? 30.0f : 2.0f, kRow + 0.05f + 0.9f * float(k) / kSegments) / float(kRes));
        }
    }
    p.uv0 = p.uv1;
    for (uint32_t k = 0; k < kSegments; ++k) {
        const uint32_t a = 2 * k, b = 2 * k + 1, c = 2 * k + 3, d = 2 * k + 2;  // counter-clockwise from outside
        p.indices.insert(p.indices.end(), {a, d, c, a, c, b});
    }
    p.material = black;
    Mesh mesh;
    mesh.name = "tube";
    mesh.primitives.push_back(std::move(p));
    scene.meshes.push_back(std::move(mesh));
    Instance inst;
    inst.name = "tube";
    inst.mesh = 0;
    inst.node = 0;
    scene.instances.push_back(inst);
    for (const glm::vec3& x : scene.meshes[0].primitives[0].positions) scene.bounds.extend(x);
    return scene;
}

// The row's texels away from the tube's open ends (2 texels each side): min, mean, max.
Summary tubeRow(const LightmapPages& maps, int channel) {
    Summary s;
    for (int x = 4; x < 28; ++x) {
        const size_t i = size_t(kRow) * kRes + size_t(x);
        EXPECT_TRUE(maps.covered[0][i]) << "texel " << x;
        s.add(maps.pages[0].pixels[i][channel], i);
    }
    s.finish();
    return s;
}

Expected<LightmapPages> bakeTube(Scene scene, BakeOptions options, BakeStats* stats) {
    auto layout = computeLayout(scene, assetLayout(kRes));
    if (!layout) return Expected<LightmapPages>::failure(layout.error());
    return bakeGpu(scene, *layout, options, nullptr, stats);
}

// The sun pass: 64 points of each texel's footprint (sunJitter 8), the same
// R2 points in every texel, so the row shares one quadrature error. Measured:
// every texel +1.6 % (0.10291 for 0.10132 in red); exactly 0 before curved
// texels. Tolerance: every texel within 4 % of E / pi^2.
TEST(CurvedFootprintBake, TubeUnderAnOverheadSunReadsItsTurnsMean) {
    BB_REQUIRE_GL();
    Scene scene = tubeScene();
    const glm::vec3 irradiance(1.0f, 2.0f, 4.0f);
    scene.lights.push_back({"sun", glm::vec3(0.0f, -1.0f, 0.0f), irradiance});
    BakeOptions options;
    options.directions = 4;  // black and no sky: only the sun pass matters
    options.sunJitter = 8;
    BakeStats stats;
    auto maps = bakeTube(scene, options, &stats);
    ASSERT_TRUE(maps) << maps.error();
    EXPECT_GE(stats.curvedTexels, 24) << "the tube's row must be found curved";
    for (int c = 0; c < 3; ++c) {
        const double expected = irradiance[c] / (PI * PI);
        const Summary s = tubeRow(*maps, c);
        std::printf("[curved] tube under the sun, channel %d: %s (expected %.5f), %lld curved texels\n", c,
                    describe(s, kRes).c_str(), expected, static_cast<long long>(stats.curvedTexels));
        EXPECT_NEAR(s.min, expected, 0.04 * expected) << "channel " << c;
        EXPECT_NEAR(s.max, expected, 0.04 * expected) << "channel " << c;
    }
}

// The update pass: 1024 directions, one footprint point each (the same point
// in every texel: the row's texels move together). Measured: row mean 0.4906
// (-1.9 %), texels 0.4889-0.4926; mean 0.0025 before curved texels. Tolerance:
// the row's mean within 3 % of 1/2, every texel within 10 %.
TEST(CurvedFootprintBake, TubeUnderAnUpperSkyReadsItsTurnsMean) {
    BB_REQUIRE_GL();
    io::ImageRgb env;
    env.width = 64;
    env.height = 32;
    env.pixels.assign(size_t(env.width) * env.height, glm::vec3(0.0f));
    for (int y = 0; y < env.height / 2; ++y)  // rows from the top: theta < 90 degrees
        for (int x = 0; x < env.width; ++x) env.at(x, y) = glm::vec3(1.0f);
    BakeOptions options;
    options.directions = 1024;
    options.environment = env;
    BakeStats stats;
    auto maps = bakeTube(tubeScene(), options, &stats);
    ASSERT_TRUE(maps) << maps.error();
    const Summary s = tubeRow(*maps, 1);
    std::printf("[curved] tube under an upper sky: %s (expected 0.5)\n", describe(s, kRes).c_str());
    EXPECT_NEAR(s.mean, 0.5, 0.03 * 0.5);
    EXPECT_NEAR(s.min, 0.5, 0.10 * 0.5);
    EXPECT_NEAR(s.max, 0.5, 0.10 * 0.5);
}

}  // namespace
}  // namespace bb::test
