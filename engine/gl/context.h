// One context interface for every platform (Filament's OpenGLPlatform idea).
// Implementations live outside the engine: headless/ (EGL surfaceless,
// OSMesa) and viewer/ (GLFW); no EGL/OSMesa/GLFW header is included here.
#pragma once

#include <memory>
#include <string>

#include "core/status.h"
#include "gl/caps.h"

namespace bb::gl {

using ProcAddressLoader = void (*(*)(const char*))();

class Context {
public:
    virtual ~Context() = default;
    virtual const char* backendName() const = 0;   // "egl", "osmesa", "glfw"
    virtual void makeCurrent() = 0;
    const Caps& caps() const { return caps_; }

protected:
    // Called by implementations once their context is current: loads GL
    // entry points, requires 4.3 core, queries Caps, and in debug builds
    // (or when BUNDLEBAKE_GL_DEBUG=1) routes KHR_debug output to the log.
    Status initializeGl(ProcAddressLoader loader);

private:
    Caps caps_;
};

}  // namespace bb::gl
