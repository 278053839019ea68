#version 430
// Scene view: colour = albedo * L_lm + emission, tone-mapped (lib/tonemap.glsl),
// or one of the debug views (ViewMode in engine/render/scene_renderer.h).
// Writes display-encoded (sRGB) values: the target is a plain RGBA8 / default
// framebuffer without GL_FRAMEBUFFER_SRGB.
#include "lib/tonemap.glsl"

in vec3 vWorld;
in vec2 vUv0;
in vec2 vLightmapUv;
flat in uint vTriangle;
flat in uint vPage;

layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2DArray lightmap;   // rgb = L_lm, one layer per page (bilinear)
layout(binding = 1) uniform sampler2D albedoTexture;   // TEXCOORD_0, sRGB8 (decoded by GL)
layout(binding = 2) uniform sampler2D emissionTexture;
layout(std430, binding = 2) readonly buffer Importance { float importance[]; };  // per triangle, a chunk (lib/bake_vertex.glsl)
uniform uint meshChunkFirstTriangle;

uniform vec3 albedo;              // Material::albedo (factor x (1 - metallic))
uniform vec3 emission;            // Material::emission (radiance)
uniform bool hasAlbedoTexture;
uniform bool hasEmissionTexture;

uniform int viewMode;             // ViewMode
uniform float exposureScale;      // 2^exposure
uniform bool hasLightmap;
uniform int lightmapResolution;   // texels per page side
uniform vec2 importanceLogRange;  // log2 of the smallest and largest positive importance

uniform bool tileOverlay;
uniform vec3 bundleU;
uniform vec3 bundleV;
uniform vec2 bundleOrigin;        // (u, v) of bundle pixel (0, 0)'s corner
uniform float bundlePixelSize;
uniform int bundleGridSize;       // pixels across the bundle
uniform int bundleTileStep;       // pixels per tile side

const int VIEW_LIT = 0, VIEW_LIGHTMAP = 1, VIEW_ALBEDO = 2, VIEW_IMPORTANCE = 3, VIEW_DENSITY = 4;

// A perceptually ordered ramp (dark blue -> cyan -> yellow -> red) for t in [0,1].
vec3 heat(float t) {
    t = clamp(t, 0.0, 1.0);
    const vec3 c0 = vec3(0.05, 0.03, 0.35), c1 = vec3(0.0, 0.55, 0.9), c2 = vec3(0.2, 0.85, 0.35),
               c3 = vec3(0.98, 0.85, 0.1), c4 = vec3(0.85, 0.1, 0.05);
    float s = t * 4.0;
    if (s < 1.0) return mix(c0, c1, s);
    if (s < 2.0) return mix(c1, c2, s - 1.0);
    if (s < 3.0) return mix(c2, c3, s - 2.0);
    return mix(c3, c4, s - 3.0);
}

void main() {
    vec3 a = albedo;
    if (hasAlbedoTexture) a *= texture(albedoTexture, vUv0).rgb;
    a = clamp(a, 0.0, 1.0);  // as the meta pass bakes it
    vec3 e = emission;
    if (hasEmissionTexture) e *= texture(emissionTexture, vUv0).rgb;
    vec3 l = hasLightmap ? texture(lightmap, vec3(vLightmapUv, float(vPage))).rgb : vec3(0.0);

    vec3 display;
    if (viewMode == VIEW_LIGHTMAP) {
        display = toneMap(l, exposureScale);
    } else if (viewMode == VIEW_ALBEDO) {
        display = srgbOetf(a);
    } else if (viewMode == VIEW_IMPORTANCE) {
        float i = importance[vTriangle - meshChunkFirstTriangle];
        float span = max(importanceLogRange.y - importanceLogRange.x, 1e-6);
        display = i > 0.0 ? heat((log2(i) - importanceLogRange.x) / span) : vec3(0.15);
    } else if (viewMode == VIEW_DENSITY) {
        ivec2 texel = ivec2(floor(vLightmapUv * float(lightmapResolution)));
        float checker = ((texel.x + texel.y) & 1) == 0 ? 0.85 : 0.35;
        display = srgbOetf(vec3(checker) * mix(vec3(1.0), a, 0.35));
    } else {
        display = toneMap(a * l + e, exposureScale);
    }

    if (tileOverlay && bundleTileStep > 0) {
        // the bundle plane of the latest direction, projected onto the surface
        vec2 pixel = (vec2(dot(vWorld, bundleU), dot(vWorld, bundleV)) - bundleOrigin) / bundlePixelSize;
        if (all(greaterThanEqual(pixel, vec2(0.0))) && all(lessThan(pixel, vec2(bundleGridSize)))) {
            // tile edges (strong), and faint lines every BUNDLE_GRID_LINE pixels that show the
            // bundle's orientation and pixel scale even when one tile covers it all
            const float BUNDLE_GRID_LINE = 64.0;
            vec2 t = pixel / float(bundleTileStep);
            vec2 d = abs(fract(t + 0.5) - 0.5) / max(fwidth(t), vec2(1e-6));  // screen pixels to a tile edge
            float line = 1.0 - clamp(min(d.x, d.y) - 0.5, 0.0, 1.0);
            vec2 f = pixel / BUNDLE_GRID_LINE;
            vec2 df = abs(fract(f + 0.5) - 0.5) / max(fwidth(f), vec2(1e-6));
            float faint = 0.3 * (1.0 - clamp(min(df.x, df.y) - 0.5, 0.0, 1.0));
            ivec2 tile = ivec2(floor(t));
            float shade = ((tile.x + tile.y) & 1) == 0 ? 0.0 : 0.15;
            display = mix(display, vec3(1.0, 0.8, 0.1), max(max(line, faint), shade));
        }
    }
    outColor = vec4(display, 1.0);
}
