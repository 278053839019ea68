// EGL surfaceless context (EGL_MESA_platform_surfaceless), falling back to
// the device platform (EGL_EXT_platform_device) when surfaceless is absent.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <string>

#include "headless/platform.h"

namespace bb {
namespace {

class EglContext final : public gl::Context {
public:
    ~EglContext() override {
        if (display_ != EGL_NO_DISPLAY) {
            eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
            eglTerminate(display_);
        }
    }
    const char* backendName() const override { return "egl"; }
    void makeCurrent() override { eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_); }

    Status init() {
        auto getPlatformDisplay =
            reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (!getPlatformDisplay) return Status::error("egl: eglGetPlatformDisplayEXT is missing (no EGL_EXT_platform_base)");
        display_ = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        EGLint major = 0, minor = 0;
        if (display_ == EGL_NO_DISPLAY || !eglInitialize(display_, &major, &minor)) {
            display_ = EGL_NO_DISPLAY;
            Status s = initDevice(getPlatformDisplay, major, minor);
            if (!s) return s;
        }
        if (!eglBindAPI(EGL_OPENGL_API)) return Status::error("egl: eglBindAPI(EGL_OPENGL_API) failed");
        const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint count = 0;
        if (!eglChooseConfig(display_, configAttribs, &config, 1, &count) || count == 0) config = nullptr;
        EGLint flags = 0;
#ifndef NDEBUG
        flags |= EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR;
#endif
        const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 3,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                  EGL_CONTEXT_FLAGS_KHR, flags, EGL_NONE};
        context_ = eglCreateContext(display_, config ? config : EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
        if (context_ == EGL_NO_CONTEXT)
            return Status::error("egl: could not create an OpenGL 4.3 core context (EGL " + std::to_string(major) + "." +
                                 std::to_string(minor) + ", " + vendor() + ", error 0x" + hex(eglGetError()) + ")");
        if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
            return Status::error("egl: eglMakeCurrent without a surface failed (EGL_KHR_surfaceless_context missing?)");
        return initializeGl(reinterpret_cast<gl::ProcAddressLoader>(&eglGetProcAddress));
    }

private:
    Status initDevice(PFNEGLGETPLATFORMDISPLAYEXTPROC getPlatformDisplay, EGLint& major, EGLint& minor) {
        auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        if (!queryDevices) return Status::error("egl: no surfaceless platform and no EGL_EXT_device_enumeration");
        EGLDeviceEXT devices[8];
        EGLint n = 0;
        queryDevices(8, devices, &n);
        for (EGLint i = 0; i < n; ++i) {
            display_ = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
            if (display_ != EGL_NO_DISPLAY && eglInitialize(display_, &major, &minor)) return Status::ok();
        }
        display_ = EGL_NO_DISPLAY;
        return Status::error("egl: no EGL display could be initialized (surfaceless or device platform)");
    }
    std::string vendor() const {
        const char* v = eglQueryString(display_, EGL_VENDOR);
        return v ? v : "unknown vendor";
    }
    static std::string hex(EGLint e) {
        char buf[16];
        std::snprintf(buf, sizeof buf, "%04x", unsigned(e));
        return buf;
    }

    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace

Expected<std::unique_ptr<gl::Context>> createEglContext() {
    auto ctx = std::make_unique<EglContext>();
    Status s = ctx->init();
    if (!s) return s;
    return std::unique_ptr<gl::Context>(std::move(ctx));
}

}  // namespace bb
