// Cut-out tables and the CPU twin of lib/alpha_mask.glsl (scene/alpha_mask.h),
// and the closed-form point/spot light formulas (scene/punctual_light.h).
#include <gtest/gtest.h>

#include <cmath>

#include "scene/alpha_mask.h"
#include "scene/punctual_light.h"

namespace bb {
namespace {

Texture checker(int cells) {
    Texture t;
    t.name = "checker";
    t.width = t.height = cells;
    for (int y = 0; y < cells; ++y)
        for (int x = 0; x < cells; ++x) t.texels.push_back(glm::vec4(1.0f, 1.0f, 1.0f, (x + y) % 2 == 0 ? 1.0f : 0.0f));
    return t;
}

Material masked(int texture, float cutoff, float alpha = 1.0f) {
    Material m;
    m.albedoTexture = texture;
    m.alphaMask = true;
    m.alphaCutoff = cutoff;
    m.alpha = alpha;
    return m;
}

// Opaque materials get ALPHA_OPAQUE; masks share a texture's bytes; the
// bytes are 8-bit alpha packed 4 to a uint, little end first.
TEST(AlphaMask, TablesPackMasksOnce) {
    std::vector<Texture> textures = {checker(2), checker(3)};
    std::vector<Material> materials = {Material{}, masked(0, 0.5f), masked(1, 0.25f, 0.5f), masked(0, 0.7f),
                                       masked(-1, 0.5f, 0.4f)};
    const AlphaMaskTables t = packAlphaMasks(materials, textures);
    ASSERT_EQ(t.materials.size(), 5u);
    EXPECT_TRUE(t.anyMask);
    EXPECT_LT(t.materials[0].cutoff, 0.0f);
    EXPECT_EQ(t.materials[0].texelOffset, ALPHA_NO_TEXTURE);
    EXPECT_EQ(t.materials[1].texelOffset, 0u);
    EXPECT_EQ(t.materials[1].size, 2u | (2u << 16));
    EXPECT_EQ(t.materials[2].texelOffset, 4u);  // after the 2 x 2 texture's 4 bytes
    EXPECT_EQ(t.materials[2].size, 3u | (3u << 16));
    EXPECT_FLOAT_EQ(t.materials[2].factor, 0.5f);
    EXPECT_EQ(t.materials[3].texelOffset, 0u);  // shared
    EXPECT_EQ(t.materials[4].texelOffset, ALPHA_NO_TEXTURE);
    ASSERT_EQ(t.texels.size(), 4u);  // 4 + 9 bytes
    EXPECT_EQ(t.texels[0], 0xFF0000FFu);  // checker 2 x 2: 1 0 / 0 1
    // checker 3 x 3 (1 0 1 / 0 1 0 / 1 0 1) from byte 4 on
    EXPECT_EQ(t.texels[1], 0x00FF00FFu);
    EXPECT_EQ(t.texels[2], 0x00FF00FFu);
    EXPECT_EQ(t.texels[3], 0x000000FFu);

    const AlphaMaskTables none = packAlphaMasks({Material{}}, {});
    EXPECT_FALSE(none.anyMask);
    EXPECT_EQ(none.texels.size(), 1u);  // always bindable
}

// Bilinear at level 0 with repeat: on a checkerboard the 0.5 crossing lies on
// the cell edges (the four-texel saddle (1-2x)(1-2y) = 0), also across the
// repeat seam of an even checkerboard; the factor multiplies; no texture: the factor.
TEST(AlphaMask, BilinearCheckerCutsOnCellEdges) {
    std::vector<Texture> textures = {checker(8)};
    const Material m = masked(0, 0.5f);
    for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i)
            for (float fu : {0.02f, 0.3f, 0.5f, 0.7f, 0.98f})
                for (float fv : {0.02f, 0.5f, 0.98f}) {
                    const glm::vec2 uv((i + fu) / 8.0f, (j + fv) / 8.0f);
                    EXPECT_EQ(alphaCut(m, textures, uv), (i + j) % 2 != 0) << i << " " << j << " " << fu << " " << fv;
                    EXPECT_EQ(alphaCut(m, textures, uv + glm::vec2(3.0f, -2.0f)), (i + j) % 2 != 0);  // repeat
                }
    EXPECT_NEAR(materialAlpha(m, textures, glm::vec2(0.5f / 8, 0.5f / 8)), 1.0f, 1e-6f);
    EXPECT_NEAR(materialAlpha(m, textures, glm::vec2(1.0f / 8, 0.5f / 8)), 0.5f, 1e-6f);
    EXPECT_NEAR(materialAlpha(masked(0, 0.5f, 0.4f), textures, glm::vec2(0.5f / 8, 0.5f / 8)), 0.4f, 1e-6f);
    EXPECT_TRUE(alphaCut(masked(0, 0.5f, 0.4f), textures, glm::vec2(0.5f / 8, 0.5f / 8)));  // 0.4 < 0.5
    EXPECT_TRUE(alphaCut(masked(-1, 0.5f, 0.4f), textures, glm::vec2(0.3f)));
    EXPECT_FALSE(alphaCut(masked(-1, 0.4f, 0.4f), textures, glm::vec2(0.3f)));  // alpha >= cutoff stays
    Material opaque = masked(0, 0.5f);
    opaque.alphaMask = false;
    EXPECT_FALSE(alphaCut(opaque, textures, glm::vec2(1.5f / 8, 0.5f / 8)));
}

// E = I cos / d^2 x window x cone, glTF's recommended falloff.
TEST(PunctualLight, ClosedForm) {
    PunctualLight l;
    l.intensity = glm::vec3(8.0f);
    const glm::vec3 up(0, 1, 0);
    // 2 m straight above: 8 / 4
    EXPECT_NEAR(punctualIrradiance(l, glm::vec3(0, 2, 0), glm::vec3(0), up).r, 2.0f, 1e-6f);
    // 45 degrees, d = 2 sqrt 2: 8 cos45 / 8
    EXPECT_NEAR(punctualIrradiance(l, glm::vec3(2, 2, 0), glm::vec3(0), up).r, std::sqrt(0.5f), 1e-6f);
    EXPECT_EQ(punctualIrradiance(l, glm::vec3(0, -2, 0), glm::vec3(0), up).r, 0.0f);  // below the horizon
    // range 4: window 1 - (2/4)^4 = 15/16 at 2 m; 0 past the range
    l.range = 4.0f;
    EXPECT_NEAR(punctualIrradiance(l, glm::vec3(0, 2, 0), glm::vec3(0), up).r, 2.0f * 15.0f / 16.0f, 1e-6f);
    EXPECT_EQ(punctualIrradiance(l, glm::vec3(0, 4.5f, 0), glm::vec3(0), up).r, 0.0f);
    // spot pointing down, inner 10, outer 30 degrees
    l.range = 0.0f;
    l.type = PunctualLight::Type::Spot;
    l.direction = glm::vec3(0, -1, 0);
    l.innerConeAngle = 10.0f * 3.14159265f / 180.0f;
    l.outerConeAngle = 30.0f * 3.14159265f / 180.0f;
    EXPECT_NEAR(punctualIrradiance(l, glm::vec3(0, 2, 0), glm::vec3(0), up).r, 2.0f, 1e-6f);  // on the axis
    const float a = 20.0f * 3.14159265f / 180.0f;  // halfway in angle
    const glm::vec3 x(2.0f * std::tan(a), 0.0f, 0.0f);
    const float t = (std::cos(a) - std::cos(l.outerConeAngle)) / (std::cos(l.innerConeAngle) - std::cos(l.outerConeAngle));
    const float d2 = 4.0f + x.x * x.x;
    EXPECT_NEAR(punctualIrradiance(l, glm::vec3(0, 2, 0), x, up).r, 8.0f * (2.0f / std::sqrt(d2)) / d2 * t * t, 1e-5f);
    const glm::vec3 outside(2.0f * std::tan(0.6f), 0.0f, 0.0f);  // 34 degrees
    EXPECT_EQ(punctualIrradiance(l, glm::vec3(0, 2, 0), outside, up).r, 0.0f);
}

}  // namespace
}  // namespace bb
