#include "gl_context.hpp"

#include "gl.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLFW/glfw3.h>

#include <stdexcept>

namespace flexfit::viewer {
namespace {

void startEgl(void*& displayOut, void*& contextOut) {
    auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!getPlatformDisplay) throw std::runtime_error("EGL: eglGetPlatformDisplayEXT is not available");
    EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, nullptr, nullptr))
        throw std::runtime_error("EGL: no surfaceless display (Mesa's EGL_MESA_platform_surfaceless)");
    // chooseConfig defaults to window surfaces, which a surfaceless display has none of.
    const EGLint configAttributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config;
    EGLint count = 0;
    if (!eglChooseConfig(display, configAttributes, &config, 1, &count) || count == 0) {
        eglTerminate(display);
        throw std::runtime_error("EGL: no configuration renders OpenGL");
    }
    eglBindAPI(EGL_OPENGL_API);
    const EGLint contextAttributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttributes);
    if (context == EGL_NO_CONTEXT || !eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
        eglTerminate(display);
        throw std::runtime_error("EGL: no OpenGL 3.3 core context without a surface");
    }
    displayOut = display;
    contextOut = context;
}

}  // namespace

GlContext::GlContext(Backend backend, int width, int height, const std::string& title)
    : width_(width), height_(height) {
    if (backend == Backend::EglSurfaceless) {
        startEgl(eglDisplay_, eglContext_);
        return;
    }
    if (!glfwInit()) throw std::runtime_error("GLFW: cannot start (is there an X display? DISPLAY is unset or unreachable)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    // Not forward-compatible (only macOS needs it): lines wider than 1 pixel stay legal, as
    // in the EGL context, so both draw the same pictures.
    glfwWindowHint(GLFW_VISIBLE, backend == Backend::Window ? GLFW_TRUE : GLFW_FALSE);
    window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!window_) {
        glfwTerminate();
        throw std::runtime_error("GLFW: no window with an OpenGL 3.3 core context");
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(backend == Backend::Window ? 1 : 0);
}

GlContext::~GlContext() {
    if (window_) {
        glfwDestroyWindow(window_);
        glfwTerminate();
    }
    if (eglDisplay_) {
        eglMakeCurrent(eglDisplay_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(eglDisplay_, eglContext_);
        eglTerminate(eglDisplay_);
    }
}

bool GlContext::shouldClose() const { return window_ && glfwWindowShouldClose(window_); }

void GlContext::swapBuffers() {
    if (window_) glfwSwapBuffers(window_);
}

void GlContext::pollEvents() {
    if (window_) glfwPollEvents();
}

std::pair<int, int> GlContext::framebufferSize() const {
    if (!window_) return {width_, height_};
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    return {w, h};
}

std::string GlContext::renderer() const {
    const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    return name ? name : "?";
}

}  // namespace flexfit::viewer
