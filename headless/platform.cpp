#include "headless/platform.h"

#include <cstdlib>

namespace bb {

Expected<Backend> parseBackend(const std::string& name) {
    if (name == "egl") return Backend::Egl;
    if (name == "osmesa") return Backend::OsMesa;
    return Expected<Backend>::failure("unknown backend '" + name + "' (expected egl or osmesa)");
}

const char* backendName(Backend backend) { return backend == Backend::Egl ? "egl" : "osmesa"; }

Expected<std::unique_ptr<gl::Context>> createHeadlessContext(Backend backend) {
    // a machine without GL, on demand: the suite must fail there (tests/CMakeLists.txt, gl_fails_without_context)
    if (const char* force = std::getenv("BUNDLEBAKE_FORCE_NO_GL"); force && *force && std::string(force) != "0")
        return Expected<std::unique_ptr<gl::Context>>::failure(std::string(backendName(backend)) +
                                                                ": context creation disabled by BUNDLEBAKE_FORCE_NO_GL");
    if (backend == Backend::Egl) return createEglContext();
#ifdef BUNDLEBAKE_WITH_OSMESA
    return createOsMesaContext();
#else
    return Expected<std::unique_ptr<gl::Context>>::failure(
        "osmesa: this build has no OSMesa backend (configure with -DBUNDLEBAKE_WITH_OSMESA=ON)");
#endif
}

}  // namespace bb
