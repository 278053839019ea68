// A baked scene out as one glTF 2.0 binary (.glb) that engines and glTF
// viewers can use: `bundlebake export SCENE BAKE_DIR -o baked.glb`.
//
// What is written:
//   - the source file's node hierarchy (names, transforms, cameras,
//     KHR_lights_punctual lights, extras), scenes, materials, textures,
//     samplers and images (every image embedded in the binary chunk);
//   - meshes rebuilt from the Scene as bundlebake baked them: POSITION,
//     NORMAL, TEXCOORD_0 (with the base colour texture's
//     KHR_texture_transform applied, as the loader reads it) and TEXCOORD_1 =
//     the light map UV of the page, uv1 * uv1_scale + uv1_offset (generated or
//     packed, the layout's per-instance transform applied). Instances of one
//     mesh that landed in different rectangles get their own glTF mesh, which
//     shares the POSITION, NORMAL, TEXCOORD_0 and index accessors and has its
//     own TEXCOORD_1 accessor;
//   - per light map page, a PNG (RGBM, below) embedded as an image with a
//     texture (linear filtering, clamp to edge), and the page's EXR beside the
//     .glb as `<stem>.lightmap_<page>.exr` (glTF embeds only PNG and JPEG, so
//     the EXR is a side file named in extras);
//   - the encoding under extras: the root's `extras.bundlebake_lightmaps`
//     (units, resolution, encoding, range, decode rule, pages with their
//     texture, image, scale and EXR) and each mesh node's
//     `extras.bundlebake_lightmap` (page, texture, texCoord 1, encoding,
//     range, scale, EXR).
//   Not written: animations, skins and morph targets (the rest pose is what
//   was baked), KHR_materials_variants. Primitives bundlebake skipped (points,
//   lines, degenerate triangles) are not in the output.
//
// RGBM (linear, no sRGB transfer): the page's value L_lm = E/pi (DESIGN.md
// Units) is
//     L_lm = rgb * a * RGBM_RANGE * scale,  rgb, a = PNG bytes / 255
// with `scale` per page chosen so that its brightest texel is RGBM_RANGE
// before the scale (nothing clips); a = ceil(255 x) / 255 >= 1/255 for the
// texel's largest channel x (as a fraction of the peak). Error of that
// channel: at most 0.5/255 * a / x relatively, i.e. 1/255 (0.39 %) for
// texels brighter than 1/255 of the peak, 0.8 % at 1e-3, 8 % at 1e-4; the
// other channels to 0.5/255 * a of the peak absolutely. The EXR is exact.
// A lit surface is baseColor * L_lm + emission, as `bundlebake render` draws it.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bake/baker.h"
#include "core/status.h"
#include "layout/layout.h"
#include "scene/scene.h"

namespace bb {

inline constexpr float RGBM_RANGE = 8.0f;

struct ExportReport {
    size_t nodes = 0;             // glTF nodes written
    size_t meshes = 0;            // glTF meshes written (instances in other rectangles get their own)
    size_t sharedGeometry = 0;    // Scene meshes whose geometry accessors were written (once each)
    size_t images = 0;            // embedded images: the source's and the light map pages'
    size_t bytes = 0;             // size of the .glb
    std::vector<float> pageScale; // RGBM scale per page
    std::vector<std::string> exrFiles;  // side files written (full paths)
    std::vector<std::string> warnings;  // things not carried over (animations, skins, other UV sets)
};

// Writes `outPath` (.glb) and its EXR side files, each atomically.
// `sourcePath`: the glTF the scene was loaded from (its materials, images and
// nodes are carried over); `scene` and `layout`: as baked (loadScene +
// computeLayout with the bake's options, so generated TEXCOORD_1 and copies
// are those of the bake); `maps`: the bake's pages (readBakedLightmaps).
// Errors (one line): the source cannot be read, an image cannot be
// embedded, a write fails, or the scene does not match the source.
Expected<ExportReport> exportBakedGltf(const std::string& sourcePath, const Scene& scene, const Layout& layout,
                                       const LightmapPages& maps, const std::string& outPath);

// A file written by exportBakedGltf, read back for `bundlebake render`: the
// layout its TEXCOORD_1 already is (every instance scale 1, offset 0 on its
// node's page) and the pages, from the EXR side files when they are there,
// else decoded from the embedded RGBM PNGs. `scene` = loadScene(path).
// Errors (one line): not an export of bundlebake (no extras), a page missing.
struct ExportedLightmaps {
    Layout layout;
    LightmapPages maps;
    std::string source;  // "exr" or "rgbm png"
    // the bake's automatic exposure (autoExposure over its covered texels,
    // extras "auto_exposure_stops"): the export has no coverage masks
    float autoExposureStops = 0.0f;
};
Expected<ExportedLightmaps> readExportedLightmaps(const std::string& path, const Scene& scene);

// RGBM of one page (row-major RGBA8, 4 bytes a texel) and back; `scale` as above.
float rgbmScale(const std::vector<glm::vec3>& pixels);
std::vector<uint8_t> encodeRgbm(const std::vector<glm::vec3>& pixels, float scale);
glm::vec3 decodeRgbm(const uint8_t* rgba, float scale);

}  // namespace bb
