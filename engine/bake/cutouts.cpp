// Cut-outs (glTF alphaMode MASK, scene/alpha_mask.h): the per-material alpha
// tables every pass that draws the surface reads (bundle pass, coverage, the
// shadow cube maps of emitters and punctual lights).
#include "bake/baker_impl.h"
#include "core/memory.h"
#include "gl/gl.h"
#include "glsl/shared/material_layout.h"
#include "scene/alpha_mask.h"

namespace bb {

void Baker::Impl::uploadAlphaMasks(const Scene& scene) {
    MemoryCategory category("materials");
    const AlphaMaskTables tables = packAlphaMasks(materials, scene.textures);
    materialAlphaBuffer = gl::Buffer::create("material alpha (cut-outs)",
                                             int64_t(tables.materials.size() * sizeof(shared::MaterialAlpha)),
                                             tables.materials.data(), 0);
    alphaTexelBuffer = gl::Buffer::create("alpha mask texels (8-bit)", int64_t(tables.texels.size() * 4),
                                          tables.texels.data(), 0);
    bindAlphaMasks();
}

void Baker::Impl::bindAlphaMasks() const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_MATERIAL_ALPHA, materialAlphaBuffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_ALPHA_TEXELS, alphaTexelBuffer.id());
}

}  // namespace bb
