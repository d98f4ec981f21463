// flexfit-viewer's application: the session, the renderer, the ImGui panels and the mouse and
// keyboard. One frame: input -> session.advance(frame time) -> draw parts and overlays ->
// panels -> optional screenshot. Headless runs use a fixed frame time (1/60 s), so frame N
// always shows the same simulated instant.
#pragma once

#include "gl_context.hpp"
#include "renderer.hpp"
#include "viewer_core.hpp"

#include <chrono>
#include <filesystem>
#include <memory>

namespace flexfit::viewer {

struct Overlays {
    bool zones = true, springs = false, hierarchy = false, partSpheres = false, contacts = true, assembly = true,
         coupling = true;
    int hierarchyDepth = 4;
};

class App {
public:
    App(GlContext& context, std::filesystem::path scene, int width, int height, bool interactive);
    ~App();
    App(const App&) = delete;
    App& operator=(const App&) = delete;

    // One frame; `frameSeconds` of wall time advance the simulation.
    void frame(double frameSeconds);
    void screenshot(const std::filesystem::path& file);
    Session& session() { return *session_; }
    Overlays overlays;

private:
    void load(const std::filesystem::path& scene);
    void rebuildMeshes();
    void handleInput();
    void drawScene();
    void drawPanels();
    void drawHud();
    std::vector<LineVertex> overlayLines() const;  // reads the world, never changes it
    void applySettingsAndRestart();
    void applyLiveSettings();

    GlContext& context_;
    bool interactive_;
    std::filesystem::path scenePath_;
    std::optional<std::filesystem::path> requestedScene_;  // open or reset at the next frame
    bool restartRequested_ = false;                        // new settings, at the next frame
    std::unique_ptr<Session> session_;
    std::unique_ptr<Renderer> renderer_;
    Camera camera_;
    std::vector<SurfaceNormals> normals_;
    std::vector<bool> dirty_;
    std::vector<DisplayHierarchy> hierarchies_;  // built when the overlay is first shown
    // Operator state.
    std::optional<Pick> selection_;
    bool dragging_ = false;
    Vec3 dragPoint_ = Vec3::Zero();
    double forceMagnitude_ = 5.0;
    int forceTarget_ = 0;  // 0: the selected mass, 1: the selected face
    // Settings of the deformable parts: restoration and contact level live, material by restart.
    int material_ = 1, restoration_ = 0, contactLevel_ = 3;
    // Measured rates.
    double fps_ = 0.0, stepsPerSecond_ = 0.0;
    std::chrono::steady_clock::time_point rateStart_ = std::chrono::steady_clock::now();
    std::uint64_t rateSteps_ = 0;
    int rateFrames_ = 0;
    std::string message_;
};

}  // namespace flexfit::viewer
