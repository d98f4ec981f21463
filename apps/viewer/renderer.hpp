// OpenGL 3.3 core drawing of parts (shaded, per-vertex normals and colours) and overlay lines,
// into an offscreen framebuffer that screenshots read back and windows receive by a blit.
// Part vertices stay in the part frame on the GPU: a rigid motion is one matrix, and only a
// deforming part's positions, normals and colours are uploaded again.
#pragma once

#include "png_io.hpp"
#include "viewer_core.hpp"

#include <array>
#include <vector>

namespace flexfit::viewer {

struct LineVertex {
    float x, y, z, r, g, b;
};
inline LineVertex lineVertex(const Vec3& p, const Vec3& colour) {
    return {float(p.x()), float(p.y()), float(p.z()), float(colour.x()), float(colour.y()), float(colour.z())};
}

class Renderer {
public:
    Renderer();
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    void resize(int width, int height);
    int width() const { return width_; }
    int height() const { return height_; }

    // Part buffers: addPart once, then upload() when the shape or colours change. clearParts()
    // drops them all (a new scene); indices restart at 0.
    std::size_t addPart(const Part& part);
    void clearParts();
    void upload(std::size_t mesh, const ShownSurface& surface);

    void begin(const Camera& camera, const Vec3& background);
    void drawPart(std::size_t mesh, const Pose& pose);
    void drawLines(const std::vector<LineVertex>& lines, float width = 1.5f);
    void drawPoints(const std::vector<LineVertex>& points, float size = 6.0f);
    // Binds the offscreen target (ImGui draws into it too).
    void bindTarget();
    void blitToWindow(int windowWidth, int windowHeight);
    Image read() const;

private:
    struct Mesh {
        unsigned vao = 0, positions = 0, normals = 0, colours = 0, indices = 0;
        int indexCount = 0;
    };
    void drawBatch(const std::vector<LineVertex>& vertices, unsigned mode);
    std::vector<Mesh> meshes_;
    unsigned meshProgram_ = 0, lineProgram_ = 0;
    unsigned lineVao_ = 0, lineVbo_ = 0;
    unsigned framebuffer_ = 0, colourBuffer_ = 0, depthBuffer_ = 0;
    int width_ = 0, height_ = 0;
    int meshModelUniform_ = -1;
};

}  // namespace flexfit::viewer
