#include "gl/objects.h"

#include "core/check.h"
#include "core/memory.h"

namespace bb::gl {

template <class D>
void Object<D>::reset() {
    if (name_) {
        D::destroy(name_);
        if (bytes_) MemoryTracker::gpu().release(bytes_);
    }
    name_ = 0;
    bytes_ = 0;
}

template <class D>
void Object<D>::adopt(GLuint name, GLenum labelKind, const std::string& label) {
    CHECK_NE(name, 0u);
    reset();
    name_ = name;
    if (!label.empty()) glObjectLabel(labelKind, name, GLsizei(label.size()), label.c_str());
}

template <class D>
void Object<D>::setBytes(int64_t bytes) {
    if (bytes_) MemoryTracker::gpu().release(bytes_);
    bytes_ = bytes;
    if (bytes_) MemoryTracker::gpu().allocate(bytes_);
}

template class Object<Buffer>;
template class Object<Texture>;
template class Object<Framebuffer>;
template class Object<VertexArray>;
template class Object<Query>;
template class Object<Program>;

Buffer Buffer::create(const std::string& label, int64_t size, const void* data, GLbitfield flags) {
    CHECK_GT(size, 0);
    GLuint name = 0;
    glCreateBuffers(1, &name);
    Buffer b;
    b.adopt(name, GL_BUFFER, label);
    glNamedBufferStorage(name, size, data, flags);
    b.setBytes(size);
    return b;
}

int bytesPerTexel(GLenum f) {
    switch (f) {
    case GL_R32UI: case GL_R32F: case GL_RGBA8: case GL_R32I: case GL_SRGB8_ALPHA8: return 4;
    case GL_RGBA16F: case GL_RG32F: case GL_RG32UI: return 8;
    case GL_RGBA32F: case GL_RGBA32UI: return 16;
    case GL_DEPTH_COMPONENT32F: case GL_DEPTH_COMPONENT24: return 4;
    default: CHECK(!"bytesPerTexel: unknown format"); return 0;
    }
}

namespace {
Texture makeTexture(const std::string& label, GLenum target, GLenum internalFormat, int width, int height, int layers,
                    int levels, int faces = 1) {
    CHECK_GT(width, 0);
    CHECK_GT(height, 0);
    CHECK_GT(layers, 0);
    GLuint name = 0;
    glCreateTextures(target, 1, &name);
    if (target == GL_TEXTURE_2D_ARRAY || target == GL_TEXTURE_CUBE_MAP_ARRAY)
        glTextureStorage3D(name, levels, internalFormat, width, height, layers);
    else
        glTextureStorage2D(name, levels, internalFormat, width, height);
    glTextureParameteri(name, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(name, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(name, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(name, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return Texture::adoptTexture(name, label, internalFormat, width, height, layers * faces, levels);
}
}  // namespace

Texture Texture::adoptTexture(GLuint name, const std::string& label, GLenum internalFormat, int width, int height,
                              int layers, int levels) {
    Texture t;
    t.adopt(name, GL_TEXTURE, label);
    t.width = width;
    t.height = height;
    t.layers = layers;
    t.format = internalFormat;
    int64_t bytes = int64_t(width) * height * layers * bytesPerTexel(internalFormat);
    t.setBytes(levels > 1 ? bytes * 4 / 3 : bytes);
    return t;
}

Texture Texture::create2D(const std::string& label, GLenum internalFormat, int width, int height) {
    return makeTexture(label, GL_TEXTURE_2D, internalFormat, width, height, 1, 1);
}

Texture Texture::create2DLevels(const std::string& label, GLenum internalFormat, int width, int height, int levels) {
    return makeTexture(label, GL_TEXTURE_2D, internalFormat, width, height, 1, levels);
}

Texture Texture::createCube(const std::string& label, GLenum internalFormat, int size) {
    return makeTexture(label, GL_TEXTURE_CUBE_MAP, internalFormat, size, size, 1, 1, 6);
}

Texture Texture::create2DArray(const std::string& label, GLenum internalFormat, int width, int height, int layers) {
    return makeTexture(label, GL_TEXTURE_2D_ARRAY, internalFormat, width, height, layers, 1);
}

Framebuffer Framebuffer::create(const std::string& label) {
    GLuint name = 0;
    glCreateFramebuffers(1, &name);
    Framebuffer f;
    f.adopt(name, GL_FRAMEBUFFER, label);
    return f;
}

VertexArray VertexArray::create(const std::string& label) {
    GLuint name = 0;
    glCreateVertexArrays(1, &name);
    VertexArray v;
    v.adopt(name, GL_VERTEX_ARRAY, label);
    return v;
}

Query Query::create(const std::string& label, GLenum target) {
    GLuint name = 0;
    glCreateQueries(target, 1, &name);
    Query q;
    q.adopt(name, GL_QUERY, label);
    return q;
}

Program Program::adoptName(GLuint name, const std::string& label) {
    Program p;
    p.adopt(name, GL_PROGRAM, label);
    return p;
}

DebugGroup::DebugGroup(const char* name) { glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, -1, name); }
DebugGroup::~DebugGroup() { glPopDebugGroup(); }

}  // namespace bb::gl
