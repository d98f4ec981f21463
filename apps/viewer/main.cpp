// flexfit-viewer: look at and operate a scene (thesis 4.1.4), or render it headless.
//
//   flexfit-viewer SCENE                               a window (needs a display)
//   flexfit-viewer SCENE --frames N --screenshot P     N frames at 60 Hz, then a PNG
//   flexfit-viewer SCENE --frames N --record DIR --every K
//   ... --egl                                          no X server: EGL surfaceless (Mesa)
#include "viewer_app.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>


#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <limits>

using namespace flexfit;
using namespace flexfit::viewer;

int main(int argc, char** argv) {
    CLI::App cli{"flexfit-viewer: see and operate a Flexfit scene"};
    std::string scene;
    int frames = 0, every = 1, width = 1280, height = 800;
    std::string screenshotFile, recordDir;
    bool egl = false, hidden = false;
    std::vector<std::string> show;
    cli.add_option("scene", scene, "scene file (TOML)")->required()->check(CLI::ExistingFile);
    cli.add_option("--frames", frames, "render this many frames at 60 Hz of simulated time, then exit (headless)")->check(CLI::Range(0, std::numeric_limits<int>::max()));
    cli.add_option("--screenshot", screenshotFile, "after the last frame, save a PNG here");
    cli.add_option("--record", recordDir, "save every K-th frame as DIR/frame_NNNNN.png");
    cli.add_option("--every", every, "K for --record")->check(CLI::Range(1, std::numeric_limits<int>::max()));
    cli.add_option("--width", width, "image or window width in pixels")->check(CLI::Range(64, 8192));
    cli.add_option("--height", height, "image or window height in pixels")->check(CLI::Range(64, 8192));
    cli.add_flag("--egl", egl, "render with EGL surfaceless (no X server needed; implies headless)");
    cli.add_flag("--hidden", hidden, "headless under an X server (e.g. xvfb-run): an invisible window");
    cli.add_option("--show", show, "overlays shown at start (default: zones contacts assembly coupling)")
        ->delimiter(',')
        ->check(CLI::IsMember({"zones", "springs", "hierarchy", "spheres", "contacts", "assembly", "coupling"}));
    try {
        cli.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help prints and succeeds; a usage error exits 2, as the flexfit command's do.
        return cli.exit(e) == 0 ? EXIT_SUCCESS : 2;
    }

    const bool headless = frames > 0 || egl || hidden;
    if (headless && frames == 0) frames = 1;
    try {
        const Backend backend = egl ? Backend::EglSurfaceless : headless ? Backend::HiddenWindow : Backend::Window;
        GlContext context(backend, width, height, "Flexfit viewer - " + scene);
        App app(context, scene, width, height, !headless);
        if (!show.empty()) {
            auto on = [&](const char* name) { return std::find(show.begin(), show.end(), name) != show.end(); };
            app.overlays = Overlays{on("zones"), on("springs"), on("hierarchy"), on("spheres"), on("contacts"), on("assembly"), on("coupling")};
        }
        if (!recordDir.empty()) std::filesystem::create_directories(recordDir);
        if (headless) {
            for (int f = 1; f <= frames; ++f) {
                app.frame(1.0 / 60.0);
                if (!recordDir.empty() && f % every == 0) app.screenshot(std::filesystem::path(recordDir) / fmt::format("frame_{:05d}.png", f));
            }
            if (!screenshotFile.empty()) app.screenshot(screenshotFile);
            const World& w = app.session().world();
            fmt::print("{}: {} frames, t = {:.3f} s, {} steps, renderer {}\n", scene, frames, w.time(), app.session().steps(), context.renderer());
            for (const AssemblyEvent& e : w.assemblyEvents())
                fmt::print("  assembled: '{}' by {} at t = {:.3f} s\n", e.rule, labelOf(e.technique), e.time);
            return EXIT_SUCCESS;
        }
        auto last = std::chrono::steady_clock::now();
        while (!context.shouldClose()) {
            const auto now = std::chrono::steady_clock::now();
            const double seconds = std::min(std::chrono::duration<double>(now - last).count(), 0.1);
            last = now;
            app.frame(seconds);
        }
    } catch (const InputError& e) {  // the scene or a file it names: exit 2, as `flexfit run` does
        fmt::print(stderr, "error: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {  // no display, no OpenGL 3.3, a file that cannot be written
        fmt::print(stderr, "error: {}\n", e.what());
        return EXIT_FAILURE;
    }
    return EXIT_SUCCESS;
}
