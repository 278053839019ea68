// Move-only RAII owners of GL names, each labelled with glObjectLabel so
// debug output and captures name them. Buffers and textures report their
// bytes to MemoryTracker::gpu() under the MemoryCategory in scope when they
// were made; a texture's bytes are what GL reports its level 0 stores.
// Requires a current context for create/destroy.
#pragma once

#include <cstdint>
#include <string>
#include <utility>

#include "gl/gl.h"

namespace bb::gl {

// Base: owns one name of a kind; `destroy` is the kind's delete call.
template <class Derived>
class Object {
public:
    Object() = default;
    Object(const Object&) = delete;
    Object& operator=(const Object&) = delete;
    Object(Object&& o) noexcept
        : name_(std::exchange(o.name_, 0)), bytes_(std::exchange(o.bytes_, 0)), category_(o.category_) {}
    Object& operator=(Object&& o) noexcept {
        if (this != &o) {
            reset();
            name_ = std::exchange(o.name_, 0);
            bytes_ = std::exchange(o.bytes_, 0);
            category_ = o.category_;
        }
        return *this;
    }
    ~Object() { reset(); }

    GLuint id() const { return name_; }
    explicit operator bool() const { return name_ != 0; }
    int64_t bytes() const { return bytes_; }
    void reset();

protected:
    void adopt(GLuint name, GLenum labelKind, const std::string& label);
    void setBytes(int64_t bytes);
    GLuint name_ = 0;
    int64_t bytes_ = 0;
    const char* category_ = "other";
};

class Buffer : public Object<Buffer> {
public:
    // Immutable-size storage (glNamedBufferStorage) with `flags`
    // (e.g. GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT). data may be null.
    static Buffer create(const std::string& label, int64_t size, const void* data, GLbitfield flags);
    static void destroy(GLuint name) { glDeleteBuffers(1, &name); }
};

class Texture : public Object<Texture> {
public:
    // 2D texture with one level, immutable storage of `internalFormat`.
    static Texture create2D(const std::string& label, GLenum internalFormat, int width, int height);
    // 2D texture with `levels` mip levels (call glGenerateTextureMipmap after upload).
    static Texture create2DLevels(const std::string& label, GLenum internalFormat, int width, int height, int levels);
    // Cube map, one level, six faces of size x size.
    static Texture createCube(const std::string& label, GLenum internalFormat, int size);
    // 2D array texture, one level, `layers` layers (light map pages).
    static Texture create2DArray(const std::string& label, GLenum internalFormat, int width, int height, int layers);
    static void destroy(GLuint name) { glDeleteTextures(1, &name); }
    // A view of `source`'s storage in another format of its view class
    // (glTextureView: e.g. RGB9_E5 as R32UI for image stores). Owns no bytes.
    static Texture createView(const std::string& label, const Texture& source, GLenum internalFormat);
    // Takes ownership of an existing texture name (labels it, tracks its bytes).
    static Texture adoptTexture(GLuint name, const std::string& label, GLenum internalFormat, int width, int height,
                                int layers, int levels);
    int width = 0, height = 0, layers = 1;
    GLenum format = 0;
};

class Framebuffer : public Object<Framebuffer> {
public:
    static Framebuffer create(const std::string& label);
    static void destroy(GLuint name) { glDeleteFramebuffers(1, &name); }
};

class VertexArray : public Object<VertexArray> {
public:
    static VertexArray create(const std::string& label);
    static void destroy(GLuint name) { glDeleteVertexArrays(1, &name); }
};

class Query : public Object<Query> {
public:
    static Query create(const std::string& label, GLenum target);
    static void destroy(GLuint name) { glDeleteQueries(1, &name); }
};

class Program : public Object<Program> {
public:
    static Program adoptName(GLuint name, const std::string& label);
    static void destroy(GLuint name) { glDeleteProgram(name); }
    GLint uniform(const char* name) const { return glGetUniformLocation(name_, name); }
};

// Bytes per texel of a texture's level 0, as GL reports its component sizes.
int64_t bytesPerTexel(GLuint texture);

// Reads (writes) the region (x, y, z) + (width, height, depth) of `texture`'s
// level 0 as `format`/`type` of `texelBytes` bytes per texel, in calls of at
// most 256 MiB: no GLsizei byte count can overflow, whatever the page size.
void readTexture(GLuint texture, int x, int y, int z, int width, int height, int depth, GLenum format, GLenum type,
                 int texelBytes, void* pixels);
void writeTexture(GLuint texture, int x, int y, int z, int width, int height, int depth, GLenum format, GLenum type,
                  int texelBytes, const void* pixels);

// A debug group for the lifetime of the object (glPushDebugGroup/Pop).
class DebugGroup {
public:
    explicit DebugGroup(const char* name);
    ~DebugGroup();
    DebugGroup(const DebugGroup&) = delete;
    DebugGroup& operator=(const DebugGroup&) = delete;
};

}  // namespace bb::gl
