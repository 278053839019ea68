#include "headless/platform.h"

namespace bb {

Expected<Backend> parseBackend(const std::string& name) {
    if (name == "egl") return Backend::Egl;
    if (name == "osmesa") return Backend::OsMesa;
    return Expected<Backend>::failure("unknown backend '" + name + "' (expected egl or osmesa)");
}

const char* backendName(Backend backend) { return backend == Backend::Egl ? "egl" : "osmesa"; }

Expected<std::unique_ptr<gl::Context>> createHeadlessContext(Backend backend) {
    if (backend == Backend::Egl) return createEglContext();
#ifdef BUNDLEBAKE_WITH_OSMESA
    return createOsMesaContext();
#else
    return Expected<std::unique_ptr<gl::Context>>::failure(
        "osmesa: this build has no OSMesa backend (configure with -DBUNDLEBAKE_WITH_OSMESA=ON)");
#endif
}

}  // namespace bb
