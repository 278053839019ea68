// Cut-outs (glTF alphaMode MASK) for every pass that draws the surface: the
// bundle pass (no node), the sun's bundles and the emitters' and punctual
// lights' shadow cube maps (no occluder), the coverage pass (a cut-away texel
// centre is not covered: dilation fills it from its neighbours, as Bakery and
// Unity treat cut-out texels: invalid, and transparent for occlusion), and the
// CPU reference.
//
// Alpha at TEXCOORD_0 uv = baseColorFactor.a x the albedo texture's alpha,
// sampled bilinearly (repeat, level 0) from 8-bit texels: one definition, on
// the GPU (glsl/lib/alpha_mask.glsl) and here. The surface is cut away where
// alpha < alphaCutoff. Level 0 on purpose: a mip level of a mask blurs it into
// grey, and the cut then shrinks or grows with distance (a rasterizer's
// artefact a bake must not have).
//
// GL-free.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "glsl/shared/material_layout.h"
#include "scene/scene.h"

namespace bb {

// The GPU tables: one MaterialAlpha per material (opaque materials: cutoff
// ALPHA_OPAQUE), and the masks' 8-bit alpha, 4 bytes per uint (at least one
// uint, so the buffer can always be bound). A texture used by several masked
// materials is stored once. Textures wider or taller than 65535 are refused
// by the loader's decoder long before (CHECKed).
struct AlphaMaskTables {
    std::vector<shared::MaterialAlpha> materials;
    std::vector<uint32_t> texels;
    bool anyMask = false;
};
AlphaMaskTables packAlphaMasks(const std::vector<Material>& materials, const std::vector<Texture>& textures);

// Alpha of material m at uv (the factor when it has no albedo texture), as
// the GPU computes it (8-bit texels).
float materialAlpha(const Material& m, const std::vector<Texture>& textures, glm::vec2 uv);
// True where m is cut away (alphaMask and alpha < alphaCutoff).
bool alphaCut(const Material& m, const std::vector<Texture>& textures, glm::vec2 uv);

}  // namespace bb
