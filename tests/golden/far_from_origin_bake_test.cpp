// The same answer kilometres from the origin (issue 10): a scene moved by a
// glTF node translation bakes as it does at the origin.
//
// Why it can differ: float positions 5 km from the origin are rounded to
// 0.5 mm, 100 km away to 8 mm, which moves surfaces by a good fraction of a
// 2 cm wall and of the bake's depth bias. The bake mesh therefore holds
// positions relative to a local origin (Scene::origin, chosen in double from
// the world bounds: layout/bake_mesh.h), and a translation T whose sum with
// the asset's coordinates is exact in double gives the same float positions,
// hence (same seed, same bytes: baker.h) the same light maps, bit for bit.
//
// Room (assets/two_rooms/two_rooms_doorway.gltf): two 2 m rooms joined by a
// 0.4 m x 1 m doorway, room A lit by a 0.5 m ceiling panel (Le = 10), room B
// only through the doorway (indirect light only), albedo 0.5. An inner node
// translation of (0, -1, 0) centres it on the origin, so its local origin is
// the world origin at T = 0 and T at T = 5 km and 100 km: the three bakes
// must be identical. The criterion the issue states, "within noise", is also
// checked and printed: RMS over covered texels of (far - origin) against the
// RMS of (seed 2 - seed 1) at the origin, which must be at most 0.1 x the
// seed noise. Measured (64 directions, 12,212 covered texels, mean L_lm
// 0.106): seed noise RMS 0.00407 (3.8% of the mean); far - origin RMS 0 at
// 5 km and 100 km (bit-identical). With the bake mesh in world space instead
// (Scene::origin forced to 0, as before the local origin) far - origin RMS is
// 0.0015 at 5 km (0.36 x the seed noise) and 0.034 at 100 km (8.3 x), and the
// thin-wall test below leaks (room B max 0.0037 against a limit of 0.00021).
//
// Thin wall (assets/two_rooms/two_rooms.gltf) 5 km away: room B, sealed
// behind a 2 cm (one texel) slab, stays dark, with the criterion and
// resolution of tests/golden/thin_wall_bake_test.cpp (max L_lm over room B <
// 1e-3 x room A's mean; 50 texels per metre, 128 directions).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "support/bake_helper.h"
#include "support/translated_gltf.h"

namespace bb::test {
namespace {

// makeBake (an absolute path works too), baked to the end.
SceneBake bakeFile(const std::string& path, const LayoutOptions& layoutOptions, const BakeOptions& bakeOptions) {
    SceneBake out = makeBake(path, layoutOptions, bakeOptions);
    if (out) bakeToEnd(*out.baker);
    return out;
}

struct Placed {
    LightmapPages maps;
    BakeMesh mesh;
    std::string error;
};

Placed bakeTranslated(const std::string& asset, const glm::dvec3& outer, const glm::dvec3& inner,
                      const LayoutOptions& layout, const BakeOptions& options, const std::string& tag) {
    Placed out;
    const std::string path = writeTranslatedGltf(sourcePath(asset), outer, inner, tag, &out.error);
    if (path.empty()) return out;
    SceneBake bake = bakeFile(path, layout, options);
    if (!bake) {
        out.error = bake.error;
        return out;
    }
    out.maps = bake.baker->readLightmaps();
    out.mesh = bake.baker->mesh();
    return out;
}

// RMS over the texels both cover (all three channels) of a - b, and the mean of a.
struct Difference {
    double rms = 0, mean = 0;
    size_t texels = 0, coverageMismatches = 0;
    bool identical = true;  // same coverage and the same bits in every covered texel
};

Difference compare(const LightmapPages& a, const LightmapPages& b) {
    Difference d;
    if (a.pages.size() != b.pages.size()) {
        d.identical = false;
        return d;
    }
    double sum2 = 0, sum = 0;
    for (size_t p = 0; p < a.pages.size(); ++p) {
        const auto& pa = a.pages[p].pixels;
        const auto& pb = b.pages[p].pixels;
        for (size_t i = 0; i < pa.size() && i < pb.size(); ++i) {
            const bool ca = a.covered[p][i] != 0, cb = b.covered[p][i] != 0;
            if (ca != cb) {
                ++d.coverageMismatches;
                d.identical = false;
            }
            if (!ca || !cb) continue;
            ++d.texels;
            for (int c = 0; c < 3; ++c) {
                const double e = double(pa[i][c]) - double(pb[i][c]);
                sum2 += e * e;
                sum += pa[i][c];
            }
            if (std::memcmp(&pa[i], &pb[i], sizeof pa[i]) != 0) d.identical = false;
        }
    }
    if (d.texels) {
        d.rms = std::sqrt(sum2 / double(3 * d.texels));
        d.mean = sum / double(3 * d.texels);
    }
    return d;
}

TEST(FarFromOriginBake, DoorwayRoomsBakeTheSameFiveAndHundredKilometresAway) {
    BB_REQUIRE_GL();
    LayoutOptions layout;
    layout.mode = UvLayout::Pack;
    layout.resolution = 256;
    layout.texelDensity = 16.0f;  // 6.25 cm texels
    BakeOptions options;
    options.directions = 64;
    options.seed = 1;
    const std::string asset = "assets/two_rooms/two_rooms_doorway.gltf";
    const glm::dvec3 centre(0.0, -1.0, 0.0);  // the rooms span y in [0, 2]

    Placed origin = bakeTranslated(asset, glm::dvec3(0.0), centre, layout, options, "far_origin");
    ASSERT_TRUE(origin.error.empty()) << origin.error;
    BakeOptions otherSeed = options;
    otherSeed.seed = 2;
    Placed seed2 = bakeTranslated(asset, glm::dvec3(0.0), centre, layout, otherSeed, "far_seed2");
    ASSERT_TRUE(seed2.error.empty()) << seed2.error;
    const Difference noise = compare(seed2.maps, origin.maps);
    ASSERT_GT(noise.texels, 10000u);
    ASSERT_GT(noise.mean, 0.05) << "the rooms are not lit";
    ASSERT_GT(noise.rms, 0.0) << "two seeds gave the same bake: no noise to compare with";
    std::printf("[far from origin] origin: %zu covered texels, mean L_lm %.5f; seed noise RMS %.3g (%.2f%% of the mean)\n",
                noise.texels, noise.mean, noise.rms, 100.0 * noise.rms / noise.mean);

    for (double km : {5.0, 100.0}) {
        // along a diagonal, so that every axis is far from 0
        const glm::dvec3 t = glm::dvec3(0.6, 0.48, -0.64) * (km * 1000.0);
        Placed far = bakeTranslated(asset, t, centre, layout, options, "far_" + std::to_string(int(km)));
        ASSERT_TRUE(far.error.empty()) << far.error;
        const Difference d = compare(far.maps, origin.maps);
        std::printf("[far from origin] %g km: far - origin RMS %.3g (%.3g x the seed noise), %s, %zu coverage "
                    "mismatches; bake mesh bounds (%.3f, %.3f, %.3f) .. (%.3f, %.3f, %.3f)\n",
                    km, d.rms, d.rms / noise.rms, d.identical ? "bit-identical" : "NOT bit-identical",
                    d.coverageMismatches, far.mesh.bounds.min.x, far.mesh.bounds.min.y, far.mesh.bounds.min.z,
                    far.mesh.bounds.max.x, far.mesh.bounds.max.y, far.mesh.bounds.max.z);
        EXPECT_EQ(d.coverageMismatches, 0u) << km << " km";
        EXPECT_LE(d.rms, 0.1 * noise.rms) << km << " km: the far bake differs from the origin bake by more than a "
                                          << "tenth of the seed noise";
        EXPECT_TRUE(d.identical) << km << " km: the far bake is not bit-identical to the origin bake (RMS " << d.rms
                                 << ")";
    }
}

TEST(FarFromOriginBake, SealedRoomBehindOneTexelWallStaysDarkFiveKilometresAway) {
    BB_REQUIRE_GL();
    LayoutOptions layout = packLayout(720);
    layout.texelDensity = 50.0f;  // 2 cm texels: the slab is one texel thick
    BakeOptions options;
    options.directions = 128;
    options.seed = 1;
    // 5 km away along a diagonal (3 km east, 4 km north), floor at 0
    Placed far = bakeTranslated("assets/two_rooms/two_rooms.gltf", glm::dvec3(3000.0, 0.0, -4000.0), glm::dvec3(0.0),
                                layout, options, "far_thin_wall");
    ASSERT_TRUE(far.error.empty()) << far.error;
    const LightmapPages& maps = far.maps;
    const BakeMesh& mesh = far.mesh;
    const int res = maps.resolution;
    // room B is the +x side of the slab, whose centre is the scene's centre in x
    const float slabX = mesh.bounds.center().x;

    Summary roomA, roomB;
    std::vector<std::vector<int>> owners;
    for (int page = 0; page < int(maps.pages.size()); ++page) {
        owners.push_back(texelTriangles(mesh, res, page));
        const auto& img = maps.pages[size_t(page)];
        for (size_t i = 0; i < img.pixels.size(); ++i) {
            if (!maps.covered[size_t(page)][i]) continue;
            int t = owners.back()[i] >= 0 ? owners.back()[i] : nearestTriangle(mesh, res, i, page);
            ASSERT_GE(t, 0);
            const double value = std::max({img.pixels[i].r, img.pixels[i].g, img.pixels[i].b});
            if (triangleCentroid(mesh, t).x > slabX)
                roomB.add(value, i);
            else
                roomA.add(img.pixels[i].g, i);
        }
    }
    roomA.finish();
    roomB.finish();
    const double limit = 1e-3 * roomA.mean;
    std::printf("[far thin wall] 5 km: %zu page(s) of %d; room A: %s; room B: %s; limit %.3g\n", maps.pages.size(), res,
                describe(roomA, res).c_str(), describe(roomB, res).c_str(), limit);
    ASSERT_GT(roomA.count, 50000u);
    ASSERT_GT(roomB.count, 50000u);
    ASSERT_GT(roomA.mean, 0.1) << "room A is not lit: " << describe(roomA, res);
    EXPECT_LT(roomB.max, limit) << "light leaks into the sealed room B through the one-texel slab 5 km from the origin: "
                                << describe(roomB, res);
}

}  // namespace
}  // namespace bb::test
