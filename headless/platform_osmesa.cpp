// OSMesa context: a 4.3 core profile through OSMesaCreateContextAttribs.
// Rendering goes to FBOs; the OSMesa colour buffer is a 1x1 placeholder.
#include <GL/osmesa.h>

#include <string>

#include "headless/platform.h"

namespace bb {
namespace {

class OsMesaContext final : public gl::Context {
public:
    ~OsMesaContext() override {
        if (context_) OSMesaDestroyContext(context_);
    }
    const char* backendName() const override { return "osmesa"; }
    void makeCurrent() override { OSMesaMakeCurrent(context_, pixel_, GL_UNSIGNED_BYTE, 1, 1); }

    Status init() {
        const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 8,
                               OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 4,
                               OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
        context_ = OSMesaCreateContextAttribs(attribs, nullptr);
        if (!context_) return Status::error("osmesa: could not create an OpenGL 4.3 core context (OSMesaCreateContextAttribs failed)");
        if (!OSMesaMakeCurrent(context_, pixel_, GL_UNSIGNED_BYTE, 1, 1))
            return Status::error("osmesa: OSMesaMakeCurrent failed");
        return initializeGl(reinterpret_cast<gl::ProcAddressLoader>(&OSMesaGetProcAddress));
    }

private:
    OSMesaContext context_ = nullptr;
    unsigned char pixel_[4] = {0, 0, 0, 0};
};

}  // namespace

Expected<std::unique_ptr<gl::Context>> createOsMesaContext() {
    auto ctx = std::make_unique<OsMesaContext>();
    Status s = ctx->init();
    if (!s) return s;
    return std::unique_ptr<gl::Context>(std::move(ctx));
}

}  // namespace bb
