#include "layout/bake_mesh_gl.h"

#include <cstddef>

#include "layout/bake_mesh.h"

namespace bb {

gl::VertexArray createBakeVertexArray(const std::string& label, const gl::Buffer& vertices) {
    gl::VertexArray vao = gl::VertexArray::create(label);
    glVertexArrayVertexBuffer(vao.id(), 0, vertices.id(), 0, sizeof(BakeVertex));
    const GLint sizes[] = {4, 4, 2, 2};
    const GLuint offsets[] = {offsetof(BakeVertex, position), offsetof(BakeVertex, normal), offsetof(BakeVertex, uv0),
                              offsetof(BakeVertex, lightmapUv)};
    for (GLuint a = 0; a < 4; ++a) {
        glEnableVertexArrayAttrib(vao.id(), a);
        glVertexArrayAttribFormat(vao.id(), a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a]);
        glVertexArrayAttribBinding(vao.id(), a, 0);
    }
    return vao;
}

}  // namespace bb
