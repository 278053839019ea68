#include "gl/objects.h"

#include "core/check.h"
#include "core/memory.h"

#include <algorithm>

namespace bb::gl {

template <class D>
void Object<D>::reset() {
    if (name_) {
        D::destroy(name_);
        if (bytes_) MemoryTracker::gpu().release(bytes_, category_);
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
    if (bytes_) MemoryTracker::gpu().release(bytes_, category_);
    bytes_ = bytes;
    category_ = MemoryTracker::currentCategory();
    if (bytes_) MemoryTracker::gpu().allocate(bytes_, category_);
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

int64_t bytesPerTexel(GLuint texture) {
    const GLenum sizes[] = {GL_TEXTURE_RED_SIZE,   GL_TEXTURE_GREEN_SIZE,   GL_TEXTURE_BLUE_SIZE, GL_TEXTURE_ALPHA_SIZE,
                            GL_TEXTURE_DEPTH_SIZE, GL_TEXTURE_STENCIL_SIZE, GL_TEXTURE_SHARED_SIZE};
    int64_t bits = 0;
    for (GLenum s : sizes) {
        GLint v = 0;
        glGetTextureLevelParameteriv(texture, 0, s, &v);
        bits += v;
    }
    CHECK_GT(bits, 0);
    return (bits + 7) / 8;
}

namespace {
// Rows per call so that one call moves at most 256 MiB.
int rowsPerCall(int width, int texelBytes) {
    return int(std::max<int64_t>(1, (int64_t(256) << 20) / (int64_t(width) * texelBytes)));
}
}  // namespace

void readTexture(GLuint texture, int x, int y, int z, int width, int height, int depth, GLenum format, GLenum type,
                 int texelBytes, void* pixels) {
    const int rows = rowsPerCall(width, texelBytes);
    auto* out = static_cast<uint8_t*>(pixels);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    for (int layer = 0; layer < depth; ++layer)
        for (int r = 0; r < height; r += rows) {
            const int n = std::min(rows, height - r);
            const int64_t bytes = int64_t(n) * width * texelBytes;
            glGetTextureSubImage(texture, 0, x, y + r, z + layer, width, n, 1, format, type, GLsizei(bytes), out);
            out += bytes;
        }
}

void writeTexture(GLuint texture, int x, int y, int z, int width, int height, int depth, GLenum format, GLenum type,
                  int texelBytes, const void* pixels) {
    const int rows = rowsPerCall(width, texelBytes);
    const auto* in = static_cast<const uint8_t*>(pixels);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (int layer = 0; layer < depth; ++layer)
        for (int r = 0; r < height; r += rows) {
            const int n = std::min(rows, height - r);
            glTextureSubImage3D(texture, 0, x, y + r, z + layer, width, n, 1, format, type, in);
            in += int64_t(n) * width * texelBytes;
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
    int64_t bytes = int64_t(width) * height * layers * bytesPerTexel(name);
    t.setBytes(levels > 1 ? bytes * 4 / 3 : bytes);
    return t;
}

Texture Texture::createView(const std::string& label, const Texture& source, GLenum internalFormat) {
    GLuint name = 0;
    glGenTextures(1, &name);
    GLint target = 0;
    glGetTextureParameteriv(source.id(), GL_TEXTURE_TARGET, &target);
    glTextureView(name, GLenum(target), source.id(), internalFormat, 0, 1, 0, GLuint(source.layers));
    Texture t;
    t.adopt(name, GL_TEXTURE, label);
    t.width = source.width;
    t.height = source.height;
    t.layers = source.layers;
    t.format = internalFormat;
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
