// An OpenGL 3.3 core context: a GLFW window (visible, or hidden for headless runs under an X
// server such as Xvfb), or EGL surfaceless (Mesa; no X server at all). Rendering always goes
// to an offscreen framebuffer (renderer.hpp), so both give the same pictures.
#pragma once

#include <string>
#include <utility>

struct GLFWwindow;

namespace flexfit::viewer {

enum class Backend { Window, HiddenWindow, EglSurfaceless };

class GlContext {
public:
    // Throws std::runtime_error saying what is missing (no display, no EGL device, no 3.3).
    GlContext(Backend backend, int width, int height, const std::string& title);
    ~GlContext();
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    GLFWwindow* window() const { return window_; }  // nullptr with EGL
    bool shouldClose() const;
    void swapBuffers();
    void pollEvents();
    std::pair<int, int> framebufferSize() const;
    std::string renderer() const;  // GL_RENDERER, e.g. "llvmpipe"

private:
    int width_, height_;
    GLFWwindow* window_ = nullptr;
    void* eglDisplay_ = nullptr;
    void* eglContext_ = nullptr;
};

}  // namespace flexfit::viewer
