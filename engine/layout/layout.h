// Light map layout: where each instance's TEXCOORD_1 lands in which page.
//
//   asset: TEXCOORD_1 is one shared atlas over one page of resolution^2 texels;
//          every instance maps with scale 1, offset 0.
//   pack:  every instance gets its own rectangle, sized from its world surface
//          area times the texel density (per-node override in glTF extras),
//          shelf-packed into square pages of `resolution` texels with
//          `padding` texels kept free around each rectangle.
//
// GL-free. pageUv = uv1 * scale + offset, in [0,1]^2 of page `page`
// (u to the right, v up from texel row 0, as GL textures address them).
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "core/status.h"
#include "scene/scene.h"

namespace bb {

enum class UvLayout { Asset, Pack };

struct LayoutOptions {
    UvLayout mode = UvLayout::Pack;
    int resolution = 512;        // page width = height in texels (typ. 256..4096)
    float texelDensity = 0.0f;   // texels per scene unit; 0 = auto: fit the scene into about one page
    int padding = 2;             // free texels around every rectangle (pack), for dilation and bilinear filtering
    // asset: texel centres inside two TEXCOORD_1 triangles (overlapping charts,
    // which would share texels and race in the update pass) are counted and
    // reported with an example; true makes that an error.
    bool failOnOverlap = false;
};

struct InstanceRect {
    int page = 0;
    int x = 0, y = 0;            // texel origin of the rectangle (without padding)
    int width = 0, height = 0;   // in texels (without padding)
    glm::vec2 scale{1.0f};       // pageUv = uv1 * scale + offset
    glm::vec2 offset{0.0f};
    float texelDensity = 0.0f;   // the density actually used (texels per scene unit), after clamping
};

struct Layout {
    UvLayout mode = UvLayout::Pack;
    int resolution = 0;
    int pageCount = 0;
    int padding = 0;
    float texelDensity = 0.0f;          // global density used (pack), texels per scene unit
    std::vector<InstanceRect> rects;    // one per Scene::instances entry
    size_t overlappingTexels = 0;       // asset: texel centres inside more than one triangle
    size_t texelCount() const { return size_t(pageCount) * resolution * resolution; }
};

// Errors: resolution out of [16, 16384], negative density, padding < 0,
// asset mode on a scene without TEXCOORD_1 everywhere (one line with a hint),
// overlapping asset charts with failOnOverlap.
Expected<Layout> computeLayout(const Scene& scene, const LayoutOptions& options);

}  // namespace bb
