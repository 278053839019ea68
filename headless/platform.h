// Headless GL contexts: EGL surfaceless (default) and OSMesa (golden tests;
// upstream Mesa removed OSMesa in 25.1, so it sits behind BUNDLEBAKE_WITH_OSMESA).
#pragma once

#include <memory>
#include <string>

#include "core/status.h"
#include "gl/context.h"

namespace bb {

enum class Backend { Egl, OsMesa };

// Parses "egl" / "osmesa". Error names the accepted values.
Expected<Backend> parseBackend(const std::string& name);
const char* backendName(Backend backend);

// Creates a 4.3 core context and makes it current. The error names the
// backend and what was found instead. With the environment variable
// BUNDLEBAKE_FORCE_NO_GL set (not empty, not "0") it always fails, as on a
// machine without GL (tests use it to show that the suite then fails).
Expected<std::unique_ptr<gl::Context>> createHeadlessContext(Backend backend);

// Implementations (platform_egl.cpp, platform_osmesa.cpp).
Expected<std::unique_ptr<gl::Context>> createEglContext();
Expected<std::unique_ptr<gl::Context>> createOsMesaContext();

}  // namespace bb
