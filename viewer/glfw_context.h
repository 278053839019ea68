// gl::Context for a GLFW window: OpenGL 4.3 core, the viewer's only
// platform code (no GLFW header is seen outside viewer/).
#pragma once

#include <memory>
#include <string>

#include "core/status.h"
#include "gl/context.h"

struct GLFWwindow;

namespace bb::viewer {

class GlfwContext final : public gl::Context {
public:
    // Initializes GLFW, opens a window of width x height screen units with a
    // 4.3 core context (24-bit depth, no vsync) and makes it current.
    // Errors (one line): no display, no 4.3 core context.
    static Expected<std::unique_ptr<GlfwContext>> create(int width, int height, const std::string& title);
    ~GlfwContext() override;

    const char* backendName() const override { return "glfw"; }
    void makeCurrent() override;
    GLFWwindow* window() const { return window_; }

private:
    GlfwContext() = default;
    GLFWwindow* window_ = nullptr;
};

}  // namespace bb::viewer
