#include "viewer/glfw_context.h"

#define GLFW_INCLUDE_NONE  // GL comes from glad (engine/gl/gl.h)
#include <GLFW/glfw3.h>

#include "core/log.h"

namespace bb::viewer {
namespace {

std::string lastGlfwError() {
    const char* description = nullptr;
    glfwGetError(&description);
    return description ? description : "unknown GLFW error";
}

}  // namespace

Expected<std::unique_ptr<GlfwContext>> GlfwContext::create(int width, int height, const std::string& title) {
    using Fail = Expected<std::unique_ptr<GlfwContext>>;
    if (!glfwInit()) return Fail::failure("glfw: cannot initialize (no display? " + lastGlfwError() + ")");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
    glfwWindowHint(GLFW_SRGB_CAPABLE, GLFW_FALSE);  // the renderer writes sRGB-encoded values itself
    std::unique_ptr<GlfwContext> context(new GlfwContext());
    context->window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!context->window_) {
        std::string why = lastGlfwError();
        glfwTerminate();
        return Fail::failure("glfw: cannot open a window with an OpenGL 4.3 core context: " + why);
    }
    glfwMakeContextCurrent(context->window_);
    glfwSwapInterval(0);  // the bake paces the frames, not the display
    if (Status s = context->initializeGl(reinterpret_cast<gl::ProcAddressLoader>(&glfwGetProcAddress)); !s) return s;
    return context;
}

GlfwContext::~GlfwContext() {
    if (window_) glfwDestroyWindow(window_);
    glfwTerminate();
}

void GlfwContext::makeCurrent() { glfwMakeContextCurrent(window_); }

}  // namespace bb::viewer
