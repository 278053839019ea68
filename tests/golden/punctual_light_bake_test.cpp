// Point and spot lights (KHR_lights_punctual; Baker's bakePunctualLights,
// engine/bake/direct_light.cpp, glsl/direct/punctual.frag) against closed
// forms and against the CPU reference baker (engine/reference).
//
// Over a black floor with no sky, L_lm is the light's direct light alone:
// E / pi with E = I cos / d^2 x range window x cone falloff
// (scene/punctual_light.h, glTF's recommended formulas), times visibility
// from the light's shadow cube map. The GPU evaluates it at each texel
// centre and stores fp16 (2^-11 = 0.05 % steps, stochastic rounding).
// Two checks per case: each texel against the formula at its centre (units,
// directions, cone and range conventions, no shadow acne), and the floor's
// whole received flux, sum of pi L_lm x texel area, against an independent
// closed form (the solid angle the floor subtends, I x Omega) or, for the
// spot, a fine quadrature of the same formula over each texel's footprint.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scene/punctual_light.h"
#include "support/bake_helper.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

constexpr double PI = 3.14159265358979323846;

BakeOptions darkOptions(int directions) {
    BakeOptions o;
    o.directions = directions;
    o.seed = 1;
    return o;
}

// A black 4 m x 4 m floor facing up at y = 0 (instance 0), 16 texels a metre
// (64 x 64 texels of 6.25 cm).
Scene floorScene() {
    Scene scene;
    const int black = addMaterial(scene, glm::vec3(0.0f));
    addQuad(scene, glm::vec3(0.0f), glm::vec3(2.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, -2.0f), black, "floor");
    return scene;
}

struct FloorResult {
    double worstRelative = 0;    // over texels whose expected value is >= 2 % of the brightest
    double worstAbsolute = 0;    // over all texels, / the brightest expected value
    double flux[3] = {0, 0, 0};  // sum of pi L_lm x texel area, W-like units (I x sr)
    size_t texels = 0;
    double seconds = 0;
};

// Bakes the floor under `light`, compares every texel with the formula at its centre.
FloorResult bakeFloor(const PunctualLight& light) {
    FloorResult out;
    Scene scene = floorScene();
    scene.punctualLights = {light};
    auto layout = packLayout(scene, 128, 16.0f);
    EXPECT_TRUE(layout) << layout.error();
    if (!layout) return out;
    auto gpu = bakeGpu(scene, *layout, darkOptions(4), &out.seconds);
    EXPECT_TRUE(gpu) << gpu.error();
    if (!gpu) return out;
    const InstanceRect& r = layout->rects[0];
    const double texelArea = (4.0 / r.width) * (4.0 / r.height);
    double peak = 0;
    std::vector<std::pair<glm::vec3, glm::vec3>> pairs;  // (expected, baked)
    forEachQuadTexel(scene, *layout, *gpu, 0, [&](int page, size_t i, const glm::dvec3& x, int, int) {
        const glm::vec3 e = punctualIrradiance(light, glm::vec3(light.position), glm::vec3(x), glm::vec3(0, 1, 0));
        const glm::vec3 expected = e / float(PI);
        const glm::vec3 baked = gpu->pages[size_t(page)].pixels[i];
        pairs.push_back({expected, baked});
        peak = std::max(peak, double(std::max({expected.r, expected.g, expected.b})));
        for (int c = 0; c < 3; ++c) out.flux[c] += PI * baked[c] * texelArea;
    });
    out.texels = pairs.size();
    for (const auto& [expected, baked] : pairs)
        for (int c = 0; c < 3; ++c) {
            const double diff = std::fabs(double(baked[c]) - expected[c]);
            out.worstAbsolute = std::max(out.worstAbsolute, diff / peak);
            if (expected[c] >= 0.02 * peak) out.worstRelative = std::max(out.worstRelative, diff / expected[c]);
        }
    return out;
}

// Solid angle of the rectangle [x0, x1] x [z0, z1] in the plane y = 0 seen
// from (0, h, 0): sums of Omega(a, b) = atan(a b / (h sqrt(a^2 + b^2 + h^2)))
// over its corners (signed: the corner formula is odd in a and in b).
double rectangleSolidAngle(double x0, double x1, double z0, double z1, double h) {
    auto corner = [h](double a, double b) { return std::atan(a * b / (h * std::sqrt(a * a + b * b + h * h))); };
    return corner(x1, z1) - corner(x0, z1) - corner(x1, z0) + corner(x0, z0);
}

// A point light 1.1 m above the floor, off centre, no range: every texel
// within 1 % of I h / (pi d^3) (measured: see the printout), and the floor's
// flux I x Omega (the floor's solid angle from the light) within 1 %
// (texel quadrature of a smooth field, 6.25 cm texels at 1.1 m: about 0.05 %).
// The same light with range 2 m: the window clamp(1 - (d/2)^4, 0, 1) cuts the
// far corners to 0 (checked per texel as above; no flux closed form).
TEST(PunctualLightBake, PointLightOverFloorIsInverseSquareCosine) {
    BB_REQUIRE_GL();
    PunctualLight light;
    light.name = "bulb";
    light.position = glm::dvec3(0.3, 1.1, -0.4);
    light.intensity = glm::vec3(10.0f, 20.0f, 5.0f);
    FloorResult r = bakeFloor(light);
    ASSERT_EQ(r.texels, 64u * 64u);
    const double omega = rectangleSolidAngle(-2.0 - 0.3, 2.0 - 0.3, -2.0 + 0.4, 2.0 + 0.4, 1.1);
    std::printf("[punctual] point light over floor, %.2f s: worst texel %.3f %% (relative), %.4f %% of peak; "
                "flux (%.4f, %.4f, %.4f), closed form I Omega (%.4f, %.4f, %.4f)\n",
                r.seconds, 100 * r.worstRelative, 100 * r.worstAbsolute, r.flux[0], r.flux[1], r.flux[2],
                light.intensity.r * omega, light.intensity.g * omega, light.intensity.b * omega);
    EXPECT_LT(r.worstRelative, 0.01);
    for (int c = 0; c < 3; ++c) {
        const double expected = light.intensity[c] * omega;
        EXPECT_NEAR(r.flux[c], expected, 0.01 * expected) << "channel " << c;
    }

    light.range = 2.0f;
    FloorResult ranged = bakeFloor(light);
    std::printf("[punctual] point light, range 2 m: worst texel %.3f %% (relative), %.4f %% of peak\n",
                100 * ranged.worstRelative, 100 * ranged.worstAbsolute);
    EXPECT_LT(ranged.worstRelative, 0.01);
    EXPECT_LT(ranged.worstAbsolute, 0.002);
}

// A spot light 1 m above the floor pointing down and tilted 20 degrees
// towards +x, inner 15, outer 30 degrees: the outer cone edge crosses the
// floor (an ellipse from x = tan(-10) to x = tan(50) m), so the floor holds
// the full cone, the falloff band and darkness. Every texel within 1 % of its
// centre's value where that is >= 2 % of the peak, within 0.2 % of the peak
// elsewhere (the band's edge); the flux within 1 % of the formula integrated
// over each texel's footprint (16 x 16 points a texel).
TEST(PunctualLightBake, SpotLightConeFalloff) {
    BB_REQUIRE_GL();
    PunctualLight light;
    light.name = "spot";
    light.type = PunctualLight::Type::Spot;
    light.position = glm::dvec3(-0.2, 1.0, 0.1);
    const double tilt = 20.0 * PI / 180.0;
    light.direction = glm::vec3(float(std::sin(tilt)), float(-std::cos(tilt)), 0.0f);
    light.innerConeAngle = float(15.0 * PI / 180.0);
    light.outerConeAngle = float(30.0 * PI / 180.0);
    light.intensity = glm::vec3(3.0f, 2.0f, 1.0f);
    FloorResult r = bakeFloor(light);
    ASSERT_EQ(r.texels, 64u * 64u);
    // the flux by quadrature over the footprints
    double flux = 0;
    const int n = 16;
    const double texel = 4.0 / 64.0;
    for (int ty = 0; ty < 64; ++ty)
        for (int tx = 0; tx < 64; ++tx)
            for (int sy = 0; sy < n; ++sy)
                for (int sx = 0; sx < n; ++sx) {
                    const glm::vec3 x(float(-2.0 + (tx + (sx + 0.5) / n) * texel), 0.0f,
                                      float(-2.0 + (ty + (sy + 0.5) / n) * texel));
                    flux += punctualIrradiance(light, glm::vec3(light.position), x, glm::vec3(0, 1, 0)).r *
                            (texel * texel / (n * n));
                }
    std::printf("[punctual] spot light over floor, %.2f s: worst texel %.3f %% (relative, >= 2 %% of peak), "
                "%.4f %% of peak; flux %.4f (red), quadrature %.4f\n",
                r.seconds, 100 * r.worstRelative, 100 * r.worstAbsolute, r.flux[0], flux);
    EXPECT_LT(r.worstRelative, 0.01);
    EXPECT_LT(r.worstAbsolute, 0.002);
    EXPECT_NEAR(r.flux[0], flux, 0.01 * flux);
    // the cone really cuts: a point light of the same intensity sends far more
    const double omega = rectangleSolidAngle(-2.0 + 0.2, 2.0 + 0.2, -2.0 - 0.1, 2.0 - 0.1, 1.0);
    EXPECT_LT(r.flux[0], 0.5 * light.intensity.r * omega);
}

// A point light in a closed room (2 m cube, walls albedo 0.5) with a floating
// box (albedo 0.5) casting shadows on the floor: the GPU bake (explicit point
// light + 512 bundle directions for the bounces) against `bundlebake
// reference` (path tracing, 256 samples a texel, the light by next-event
// estimation with exact shadow rays), on the texels both cover.
// Tolerances: the mean within 2 % and the relative RMSE under 7 % (the
// reference's own noise at 256 spp and the bundles' direction noise; measured
// +0.3 % and 4.1 %).
TEST(PunctualLightBake, PointLightRoomMatchesReference) {
    BB_REQUIRE_GL();
    Scene scene;
    const int grey = addMaterial(scene, glm::vec3(0.5f));
    addBox(scene, glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(1.0f), grey, false, "room");
    addBox(scene, glm::vec3(0.2f, 0.6f, -0.1f), glm::vec3(0.25f, 0.15f, 0.3f), grey, true, "block");
    PunctualLight light;
    light.name = "bulb";
    light.position = glm::dvec3(-0.15, 1.7, 0.2);
    light.intensity = glm::vec3(2.0f);
    scene.punctualLights = {light};
    auto layout = packLayout(scene, 256, 16.0f);
    ASSERT_TRUE(layout) << layout.error();
    double gpuSeconds = 0, cpuSeconds = 0;
    auto gpu = bakeGpu(scene, *layout, darkOptions(512), &gpuSeconds);
    ASSERT_TRUE(gpu) << gpu.error();
    ReferenceOptions ro;
    ro.spp = 256;
    auto cpu = bakeReference(scene, *layout, ro, &cpuSeconds);
    ASSERT_TRUE(cpu) << cpu.error();
    const MapAgreement m = compareMaps(*gpu, *cpu);
    std::printf("[punctual] room: GPU %.2f s, reference %.2f s; %zu texels, mean GPU %.5f, reference %.5f "
                "(%.2f %%), relative RMSE %.2f %%\n",
                gpuSeconds, cpuSeconds, m.texels, m.meanA, m.meanB, 100 * (m.meanA / m.meanB - 1), 100 * m.relativeRmse());
    ASSERT_GT(m.texels, 5000u);
    EXPECT_NEAR(m.meanA, m.meanB, 0.02 * m.meanB);
    EXPECT_LT(m.relativeRmse(), 0.07);
}

}  // namespace
}  // namespace bb::test
