// Draws the baked scene with its light maps: the renderer shared by the
// viewer (live, while a bake runs in the same context), `bundlebake render`
// and the golden image tests.
//
//   colour = albedo(uv0) * L_lm(lightmapUv) + emission(uv0)
//
// with albedo = material factor x base colour texture (as the meta pass bakes
// it), L_lm sampled bilinearly from the light map page array (rgb = E/pi,
// DESIGN.md Units), then scaled by 2^exposure, tone-mapped by the ACES fit and
// sRGB-encoded: the same curve as io::writePngToneMapped, in glsl/lib/tonemap.glsl.
// Single-sided materials are drawn with back faces culled (glTF doubleSided).
//
// Requires a current GL 4.3 context for every method of SceneRenderer. The
// free functions are GL-free.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bake/baker.h"
#include "core/status.h"
#include "io/image_io.h"
#include "layout/bake_mesh.h"
#include "layout/layout.h"
#include "scene/scene.h"

namespace bb {

enum class ViewMode : int {
    Lit = 0,           // albedo * L_lm + emission, tone-mapped
    Lightmap = 1,      // L_lm alone, tone-mapped
    Albedo = 2,        // albedo, sRGB-encoded (no tone map)
    Importance = 3,    // per-triangle importance, heat map over log2 (at least 4 stops wide; setImportance)
    TexelDensity = 4,  // checkerboard of light map texels (lightmapUv * resolution)
};
inline constexpr int VIEW_MODE_COUNT = 5;
const char* viewModeName(ViewMode mode);  // "lit", "lightmap", "albedo", "importance", "density"
Expected<ViewMode> parseViewMode(const std::string& name);

// Camera matrices: right-handed, GL clip space. Views and cameras passed to
// viewFromCamera and draw are in the bake mesh's local space (world -
// BakeMesh::origin, layout/bake_mesh.h), like framingCamera(mesh.bounds);
// a glTF camera (Scene::cameras, world space) goes through
// cameraInLocalSpace first.
struct RenderView {
    glm::mat4 viewFromWorld{1.0f};
    glm::mat4 clipFromView{1.0f};
    glm::vec3 eye{0.0f};
};

// The view of a glTF camera for an image of `aspect` = width / height. yfov
// (or ymag) is kept and the horizontal extent follows the image, so pixels
// stay square whatever the camera's own aspectRatio. zfar = 0 (infinite) is
// replaced by the distance to the far side of `bounds`, for depth precision.
// Scale in worldFromCamera is ignored.
RenderView viewFromCamera(const Camera& camera, float aspect, const Bounds& bounds);

// A world-space camera (Scene::cameras) moved into the local space of a bake
// mesh with `origin` (BakeMesh::origin): the eye minus the origin, in double.
// The identity for origin 0 (scenes near the world origin).
Camera cameraInLocalSpace(const Camera& camera, const glm::dvec3& origin);

// A perspective camera looking along `forward` at the centre of `bounds`,
// far enough that the bounding sphere fits both fields of view.
Camera framingCamera(const Bounds& bounds, const glm::vec3& forward, float yfov, float aspect);
// The default framing direction: from the front (+Z, glTF's front), right and above.
inline const glm::vec3 DEFAULT_FRAMING_DIRECTION{-0.38f, -0.34f, -0.86f};

// Exposure (stops) that maps the 75th percentile of the covered texels'
// luminance to 0.6 before the tone curve: the rule of the bake's PNG previews,
// so sunlit (L_lm ~ 1e3) and dim scenes both read. 0 if nothing is lit.
float autoExposure(const LightmapPages& maps);

// Light maps written by `bundlebake bake` (bake_output.h): manifest.json,
// lightmap_<p>.exr and, if present, coverage_<p>.png (else: covered where the
// texel is non-zero). Errors (one line): missing or malformed files, or a
// manifest whose resolution, pages or instance rectangles differ from
// `layout` (the hint names the layout flags, which must match the bake's).
Expected<LightmapPages> readBakedLightmaps(const std::string& dir, const Layout& layout);

// An 8-bit sRGB-encoded RGB image, row 0 at the top (as PNG stores it).
struct Image8 {
    int width = 0, height = 0;
    std::vector<uint8_t> rgb;  // 3 bytes per pixel
    uint8_t at(int x, int y, int c) const { return rgb[(size_t(y) * width + x) * 3 + c]; }
};
// PNG tagged sRGB, bytes written exactly as given (atomically, like image_io).
Status writeImagePng(const std::string& path, const Image8& image);
// Any 8-bit sRGB image (PNG...) back as its encoded bytes.
Expected<Image8> readImage8(const std::string& path);

struct RenderSettings {
    ViewMode mode = ViewMode::Lit;
    float exposure = 0.0f;          // stops: radiance x 2^exposure before the tone curve (lit, lightmap)
    bool tileOverlay = false;       // draw the bundle grid of setBundleGrid over the image
    glm::vec3 background{0.11f, 0.12f, 0.14f};  // display (sRGB-encoded) colour of empty pixels, not exposed
};

class SceneRenderer {
public:
    // Uploads the mesh (local-space vertices, see RenderView) and the scene's material textures
    // (sRGB8, mipmapped). `mesh` must be buildBakeMesh(scene, layout) for the
    // layout whose pages of `lightmapResolution` texels will be shown.
    // Errors: shader build failures.
    static Expected<std::unique_ptr<SceneRenderer>> create(const Scene& scene, const BakeMesh& mesh,
                                                           int lightmapResolution);
    ~SceneRenderer();
    SceneRenderer(const SceneRenderer&) = delete;
    SceneRenderer& operator=(const SceneRenderer&) = delete;

    // Light maps from a live bake: a borrowed RGBA float 2D array texture, one
    // layer per page (Baker::lightmapTextureId(), after Baker::resolveLightmaps()).
    void useLightmapTexture(uint32_t texture);
    // Light maps from the CPU (readBakedLightmaps, Baker::readLightmaps): uploaded into an owned texture.
    void uploadLightmaps(const LightmapPages& maps);
    // The current light maps read back (for autoExposure). Empty if none.
    LightmapPages readLightmaps() const;

    // Per-triangle importance (BakeMesh triangle order, texels per scene unit^2)
    // for ViewMode::Importance. Empty disables the mode. Error: wrong size.
    Status setImportance(std::span<const float> perTriangle);
    bool hasImportance() const;
    // The bundle grid drawn by RenderSettings::tileOverlay (Baker::bundleGrid()).
    void setBundleGrid(const std::optional<Baker::BundleGrid>& grid);

    // Draws into `framebuffer` (0 = the default one) over [0, width) x [0, height).
    // Leaves the state the Baker assumes: depth test, culling and blending
    // off, framebuffer, program and vertex array 0.
    void draw(const RenderView& view, const RenderSettings& settings, uint32_t framebuffer, int width, int height);
    // Draws into an owned offscreen target (RGBA8 + 24-bit depth) and reads it back.
    Image8 renderImage(const RenderView& view, const RenderSettings& settings, int width, int height);

    struct Impl;

private:
    explicit SceneRenderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace bb
