// A headless context per test binary, for the backend named by
// BUNDLEBAKE_TEST_BACKEND (egl or osmesa; osmesa by default, as the golden
// tests use it). Tests that need a specific backend create their own.
#pragma once

#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "gl/context.h"
#include "headless/platform.h"

namespace bb::test {

Backend defaultTestBackend();

// Returns the shared context (created on first use), or nullptr with
// `why` filled in when no context can be made here.
gl::Context* sharedContext(std::string* why);

// Path of a file in the source tree, e.g. sourcePath("assets/furnace/furnace.gltf").
std::string sourcePath(const std::string& relative);

}  // namespace bb::test

// Fails the test (never skips: a green run must mean GL ran) when no GL
// context can be made; BUNDLEBAKE_FORCE_NO_GL=1 shows it (gl_fails_without_context).
#define BB_REQUIRE_GL()                                                  \
    do {                                                                 \
        std::string whyNoGl_;                                            \
        if (!::bb::test::sharedContext(&whyNoGl_)) FAIL() << whyNoGl_;   \
    } while (0)
