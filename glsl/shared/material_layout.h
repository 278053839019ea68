// Per-material cut-outs (glTF alphaMode MASK) as every pass that draws the
// surface reads them: one MaterialAlpha per Scene::materials entry, and the
// masks' alpha texels, 8 bits, 4 per uint (byte b of the buffer is uint b / 4,
// bits 8 (b % 4) ..). Packed by packAlphaMasks (engine/scene/alpha_mask.h),
// sampled by lib/alpha_mask.glsl and its C++ twin materialAlpha().
#ifndef BUNDLEBAKE_MATERIAL_LAYOUT_H
#define BUNDLEBAKE_MATERIAL_LAYOUT_H

#ifdef __cplusplus
#include <cstdint>
namespace bb::shared {
using uint = uint32_t;
#endif

// 16 bytes (std430).
struct MaterialAlpha {
    float cutoff;      // alphaCutoff: the surface is cut away where alpha < cutoff; ALPHA_OPAQUE: never
    float factor;      // baseColorFactor.a
    uint texelOffset;  // the mask's first byte in alphaTexels (row-major, row 0 = v 0), or ALPHA_NO_TEXTURE
    uint size;         // width | height << 16 (texels; each 1..65535)
};

#define ALPHA_OPAQUE -1.0
#define ALPHA_NO_TEXTURE 0xFFFFFFFFu
// Bindings (SSBO)
#define BINDING_MATERIAL_ALPHA 5   // MaterialAlpha materialAlphas[] (per material)
#define BINDING_ALPHA_TEXELS 6     // uint alphaTexels[] (4 alpha bytes each)

#ifdef __cplusplus
}  // namespace bb::shared
static_assert(sizeof(bb::shared::MaterialAlpha) == 16, "MaterialAlpha is 16 bytes");
#endif

#endif
