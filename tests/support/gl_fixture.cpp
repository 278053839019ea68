#include "support/gl_fixture.h"

#include <cstdlib>

namespace bb::test {

Backend defaultTestBackend() {
    const char* env = std::getenv("BUNDLEBAKE_TEST_BACKEND");
    if (env && std::string(env) == "egl") return Backend::Egl;
#ifdef BUNDLEBAKE_WITH_OSMESA
    return Backend::OsMesa;
#else
    return Backend::Egl;
#endif
}

gl::Context* sharedContext(std::string* why) {
    static std::unique_ptr<gl::Context> context;
    static std::string error;
    static bool tried = false;
    if (!tried) {
        tried = true;
        auto c = createHeadlessContext(defaultTestBackend());
        if (c)
            context = std::move(c.value());
        else
            error = c.error();
    }
    if (context) context->makeCurrent();
    if (!context && why) *why = "no GL context: " + error;
    return context.get();
}

std::string sourcePath(const std::string& relative) {
    return !relative.empty() && relative[0] == '/' ? relative : std::string(BUNDLEBAKE_SOURCE_DIR) + "/" + relative;
}

}  // namespace bb::test
