#include "renderer.hpp"

#include "gl.hpp"

#include <stdexcept>
#include <string>

namespace flexfit::viewer {
namespace {

const char* kMeshVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 colour;
uniform mat4 viewProjection;
uniform mat4 model;
out vec3 worldNormal;
out vec3 worldPosition;
out vec3 vertexColour;
void main() {
    vec4 world = model * vec4(position, 1.0);
    worldPosition = world.xyz;
    worldNormal = mat3(model) * normal;
    vertexColour = colour;
    gl_Position = viewProjection * world;
})";

// Two-sided headlight plus a fill light: the inside of an open part is lit as well.
const char* kMeshFragment = R"(#version 330 core
in vec3 worldNormal;
in vec3 worldPosition;
in vec3 vertexColour;
uniform vec3 eye;
out vec4 fragment;
void main() {
    vec3 n = normalize(worldNormal);
    vec3 toEye = normalize(eye - worldPosition);
    float head = abs(dot(n, toEye));
    float fill = max(dot(n, normalize(vec3(0.3, 1.0, 0.2))), 0.0);
    float specular = pow(head, 40.0) * 0.25;
    fragment = vec4(vertexColour * (0.18 + 0.62 * head + 0.2 * fill) + vec3(specular), 1.0);
})";

const char* kLineVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 colour;
uniform mat4 viewProjection;
out vec3 vertexColour;
void main() {
    vertexColour = colour;
    gl_Position = viewProjection * vec4(position, 1.0);
})";

const char* kLineFragment = R"(#version 330 core
in vec3 vertexColour;
out vec4 fragment;
void main() { fragment = vec4(vertexColour, 1.0); })";

unsigned compile(GLenum kind, const char* source) {
    const GLuint shader = glCreateShader(kind);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetShaderInfoLog(shader, sizeof log, nullptr, log);
        throw std::runtime_error(std::string("viewer shader does not compile: ") + log);
    }
    return shader;
}

unsigned link(const char* vertex, const char* fragment) {
    const GLuint program = glCreateProgram();
    const GLuint vs = compile(GL_VERTEX_SHADER, vertex), fs = compile(GL_FRAGMENT_SHADER, fragment);
    glAttachShader(program, vs);
    glAttachShader(program, fs);
    glLinkProgram(program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) throw std::runtime_error("viewer shaders do not link");
    return program;
}

std::array<float, 16> toFloats(const Mat4& m) {
    std::array<float, 16> out{};
    for (int i = 0; i < 16; ++i) out[std::size_t(i)] = float(m.data()[i]);  // column-major both
    return out;
}

std::vector<float> packed(const std::vector<Vec3>& v) {
    std::vector<float> out(v.size() * 3);
    for (std::size_t i = 0; i < v.size(); ++i)
        for (int k = 0; k < 3; ++k) out[i * 3 + std::size_t(k)] = float(v[i][k]);
    return out;
}

}  // namespace

Renderer::Renderer() {
    meshProgram_ = link(kMeshVertex, kMeshFragment);
    lineProgram_ = link(kLineVertex, kLineFragment);
    meshModelUniform_ = glGetUniformLocation(meshProgram_, "model");
    glGenVertexArrays(1, &lineVao_);
    glGenBuffers(1, &lineVbo_);
    glBindVertexArray(lineVao_);
    glBindBuffer(GL_ARRAY_BUFFER, lineVbo_);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex), reinterpret_cast<void*>(3 * sizeof(float)));
    glBindVertexArray(0);
}

Renderer::~Renderer() {
    clearParts();
    glDeleteBuffers(1, &lineVbo_);
    glDeleteVertexArrays(1, &lineVao_);
    glDeleteProgram(meshProgram_);
    glDeleteProgram(lineProgram_);
    if (framebuffer_) {
        glDeleteFramebuffers(1, &framebuffer_);
        glDeleteRenderbuffers(1, &colourBuffer_);
        glDeleteRenderbuffers(1, &depthBuffer_);
    }
}

void Renderer::resize(int width, int height) {
    if (width == width_ && height == height_ && framebuffer_) return;
    width_ = std::max(width, 1);
    height_ = std::max(height, 1);
    if (!framebuffer_) {
        glGenFramebuffers(1, &framebuffer_);
        glGenRenderbuffers(1, &colourBuffer_);
        glGenRenderbuffers(1, &depthBuffer_);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, colourBuffer_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width_, height_);
    glBindRenderbuffer(GL_RENDERBUFFER, depthBuffer_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width_, height_);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colourBuffer_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depthBuffer_);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) throw std::runtime_error("viewer: offscreen framebuffer incomplete");
}

void Renderer::clearParts() {
    for (Mesh& m : meshes_) {
        const GLuint buffers[] = {m.positions, m.normals, m.colours, m.indices};
        glDeleteBuffers(4, buffers);
        glDeleteVertexArrays(1, &m.vao);
    }
    meshes_.clear();
}

std::size_t Renderer::addPart(const Part& part) {
    Mesh m;
    glGenVertexArrays(1, &m.vao);
    glBindVertexArray(m.vao);
    GLuint* buffers[] = {&m.positions, &m.normals, &m.colours};
    for (GLuint k = 0; k < 3; ++k) {
        glGenBuffers(1, buffers[k]);
        glBindBuffer(GL_ARRAY_BUFFER, *buffers[k]);
        glEnableVertexAttribArray(k);
        glVertexAttribPointer(k, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    }
    std::vector<unsigned> indices;
    for (const Face& f : part.model().drawnMesh().faces) indices.insert(indices.end(), {f[0], f[1], f[2]});
    glGenBuffers(1, &m.indices);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.indices);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(unsigned)), indices.data(), GL_STATIC_DRAW);
    m.indexCount = int(indices.size());
    glBindVertexArray(0);
    meshes_.push_back(m);
    return meshes_.size() - 1;
}

void Renderer::upload(std::size_t mesh, const ShownSurface& surface) {
    const Mesh& m = meshes_[mesh];
    const std::vector<Vec3>* sources[] = {&surface.positions, &surface.normals, &surface.colours};
    const GLuint buffers[] = {m.positions, m.normals, m.colours};
    for (int k = 0; k < 3; ++k) {
        const std::vector<float> data = packed(*sources[k]);
        glBindBuffer(GL_ARRAY_BUFFER, buffers[k]);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_DYNAMIC_DRAW);
    }
}

void Renderer::bindTarget() {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    glViewport(0, 0, width_, height_);
}

void Renderer::begin(const Camera& camera, const Vec3& background) {
    bindTarget();
    glClearColor(float(background.x()), float(background.y()), float(background.z()), 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    // Per frame: the camera, in both programs (uniforms stay with their program).
    const std::array<float, 16> viewProjection = toFloats(camera.projection() * camera.view());
    const Vec3 eye = camera.eye();
    glUseProgram(meshProgram_);
    glUniformMatrix4fv(glGetUniformLocation(meshProgram_, "viewProjection"), 1, GL_FALSE, viewProjection.data());
    glUniform3f(glGetUniformLocation(meshProgram_, "eye"), float(eye.x()), float(eye.y()), float(eye.z()));
    glUseProgram(lineProgram_);
    glUniformMatrix4fv(glGetUniformLocation(lineProgram_, "viewProjection"), 1, GL_FALSE, viewProjection.data());
}

void Renderer::drawPart(std::size_t mesh, const Pose& pose) {
    glUseProgram(meshProgram_);
    const std::array<float, 16> model = toFloats(pose.matrix());
    glUniformMatrix4fv(meshModelUniform_, 1, GL_FALSE, model.data());
    glBindVertexArray(meshes_[mesh].vao);
    glDrawElements(GL_TRIANGLES, meshes_[mesh].indexCount, GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
}

void Renderer::drawBatch(const std::vector<LineVertex>& vertices, unsigned mode) {
    if (vertices.empty()) return;
    glUseProgram(lineProgram_);
    glBindVertexArray(lineVao_);
    glBindBuffer(GL_ARRAY_BUFFER, lineVbo_);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(LineVertex)), vertices.data(), GL_STREAM_DRAW);
    glDrawArrays(mode, 0, GLsizei(vertices.size()));
    glBindVertexArray(0);
}

void Renderer::drawLines(const std::vector<LineVertex>& lines, float width) {
    glLineWidth(width);  // core profile: widths above 1 may be clamped
    drawBatch(lines, GL_LINES);
}

void Renderer::drawPoints(const std::vector<LineVertex>& points, float size) {
    glPointSize(size);
    drawBatch(points, GL_POINTS);
}

void Renderer::blitToWindow(int windowWidth, int windowHeight) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, windowWidth, windowHeight, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

Image Renderer::read() const {
    Image image;
    image.width = width_;
    image.height = height_;
    image.rgba.resize(std::size_t(width_) * std::size_t(height_) * 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    std::vector<std::uint8_t> bottomUp(image.rgba.size());
    glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, bottomUp.data());
    const std::size_t row = std::size_t(width_) * 4;
    for (int y = 0; y < height_; ++y)
        std::copy_n(bottomUp.data() + std::size_t(height_ - 1 - y) * row, row, image.rgba.data() + std::size_t(y) * row);
    return image;
}

}  // namespace flexfit::viewer
