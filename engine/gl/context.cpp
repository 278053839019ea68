#include "gl/context.h"

#include <cstdlib>
#include <sstream>

#include "core/log.h"
#include "gl/gl.h"

namespace bb::gl {
namespace {

const char* debugSourceName(GLenum s) {
    switch (s) {
    case GL_DEBUG_SOURCE_API: return "api";
    case GL_DEBUG_SOURCE_SHADER_COMPILER: return "shader compiler";
    case GL_DEBUG_SOURCE_WINDOW_SYSTEM: return "window system";
    case GL_DEBUG_SOURCE_THIRD_PARTY: return "third party";
    case GL_DEBUG_SOURCE_APPLICATION: return "application";
    default: return "other";
    }
}

void GLAPIENTRY debugCallback(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei,
                              const GLchar* message, const void*) {
    if (type == GL_DEBUG_TYPE_PUSH_GROUP || type == GL_DEBUG_TYPE_POP_GROUP) return;
    std::ostringstream os;
    os << "GL " << debugSourceName(source) << " #" << id << ": " << message;
    if (type == GL_DEBUG_TYPE_ERROR || severity == GL_DEBUG_SEVERITY_HIGH)
        logError(os.str());
    else if (severity == GL_DEBUG_SEVERITY_NOTIFICATION)
        logDebug(os.str());
    else
        logWarning(os.str());
}

bool debugWanted() {
#ifndef NDEBUG
    return true;
#else
    const char* env = std::getenv("BUNDLEBAKE_GL_DEBUG");
    return env && env[0] == '1';
#endif
}

int getInt(GLenum e) {
    GLint v = 0;
    glGetIntegerv(e, &v);
    return v;
}

}  // namespace

std::string Caps::describe() const {
    std::ostringstream os;
    os << renderer << ", GL " << version << ", max SSBO block " << (maxShaderStorageBlockSize >> 20)
       << " MiB, max texture " << maxTextureSize;
    return os.str();
}

Status Context::initializeGl(ProcAddressLoader loader) {
    int version = gladLoadGL(reinterpret_cast<GLADloadfunc>(loader));
    if (version == 0) return Status::error(std::string(backendName()) + ": could not load OpenGL entry points");
    caps_.major = GLAD_VERSION_MAJOR(version);
    caps_.minor = GLAD_VERSION_MINOR(version);
    auto str = [](GLenum e) {
        const GLubyte* s = glGetString(e);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
    };
    caps_.vendor = str(GL_VENDOR);
    caps_.renderer = str(GL_RENDERER);
    caps_.version = str(GL_VERSION);
    caps_.glslVersion = str(GL_SHADING_LANGUAGE_VERSION);
    if (caps_.major * 10 + caps_.minor < 43)
        return Status::error(std::string(backendName()) + ": OpenGL 4.3 core is required, got " + caps_.version +
                             " (" + caps_.renderer + ")");
    GLint64 ssbo = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &ssbo);
    caps_.maxShaderStorageBlockSize = ssbo;
    caps_.maxTextureSize = getInt(GL_MAX_TEXTURE_SIZE);
    GLint dims[2] = {0, 0};
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, dims);
    caps_.maxViewportWidth = dims[0];
    caps_.maxViewportHeight = dims[1];
    caps_.maxFramebufferWidth = getInt(GL_MAX_FRAMEBUFFER_WIDTH);
    caps_.maxFramebufferHeight = getInt(GL_MAX_FRAMEBUFFER_HEIGHT);
    caps_.maxComputeWorkGroupInvocations = getInt(GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS);
    caps_.maxAtomicCounterBufferBindings = getInt(GL_MAX_ATOMIC_COUNTER_BUFFER_BINDINGS);
    caps_.khrDebug = GLAD_GL_KHR_debug || caps_.major * 10 + caps_.minor >= 43;
    caps_.isLlvmpipe = caps_.renderer.find("llvmpipe") != std::string::npos;

    if (debugWanted() && caps_.khrDebug) {
        glEnable(GL_DEBUG_OUTPUT);
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        glDebugMessageCallback(debugCallback, nullptr);
        glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
    }
    logDebug(std::string(backendName()) + ": " + caps_.describe());
    return Status::ok();
}

}  // namespace bb::gl
