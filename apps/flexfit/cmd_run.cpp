// flexfit run SCENE: a scene file run headless, its metrics written for analysis.
#include "cli_common.hpp"
#include "commands.hpp"
#include "scene_runner.hpp"

#include <fmt/core.h>

#include <filesystem>
#include <optional>

namespace flexfit::cli {

void registerRun(CLI::App& app) {
    auto* cmd = app.add_subcommand("run", "Run a scene file (TOML) headless and write its metrics");
    struct Options {
        std::string scene, out;
        double duration = 0.0;
        bool noProgress = false;
        SceneOptions read;
        double objEvery = -1.0, vtkEvery = -1.0, glbEvery = -1.0;
    };
    auto opt = std::make_shared<Options>();
    cmd->add_option("scene", opt->scene, "Scene file (.toml)")->required();
    cmd->add_option("--duration", opt->duration, "Simulated seconds (default: the scene's [world] duration)")->check(positiveNumber);
    cmd->add_option("--out", opt->out, "Directory for metrics.csv, summary.json and frames (a run replaces the frames an earlier run left there)");
    cmd->add_flag("--no-progress", opt->noProgress, "No progress bar");
    cmd->add_option("--obj-every", opt->objEvery, "Seconds between OBJ frames (default: the scene's [output]; 0: none)")->check(nonNegativeNumber);
    cmd->add_option("--vtk-every", opt->vtkEvery, "Seconds between VTK frames for ParaView (frame_*.vtp, frames.pvd; 0: none)")->check(nonNegativeNumber);
    cmd->add_option("--glb-every", opt->glbEvery, "Seconds between glTF binary frames for Blender (frame_*.glb; 0: none)")->check(nonNegativeNumber);
    addSceneOptions(cmd, opt->read);
    cmd->callback([opt] {
        const Scene scene = loadScene(opt->scene, opt->read.read());
        printWarnings(scene);
        RunOptions options;
        if (opt->duration > 0.0) options.duration = opt->duration;
        options.out = opt->out;
        if (opt->objEvery >= 0.0) options.objEvery = opt->objEvery;
        if (opt->vtkEvery >= 0.0) options.vtkEvery = opt->vtkEvery;
        if (opt->glbEvery >= 0.0) options.glbEvery = opt->glbEvery;
        options.progress = !opt->noProgress;
        const RunSummary s = runScene(scene, options);
        fmt::print("{}: {} steps ({:.3f} s simulated) in {:.3f} s wall, {:.0f} steps/s", scene.source, s.steps, s.simulatedSeconds, s.wallSeconds,
                   double(s.steps) / s.wallSeconds);
        if (s.contactSteps)
            fmt::print("; in contact {} steps at {:.0f} steps/s (step p50 {:.1f} us, p99 {:.1f} us, max {:.1f} us)", s.contactSteps,
                       double(s.contactSteps) / s.contactWallSeconds, nearestRankPercentile(s.contactStepMicros, 50.0),
                       nearestRankPercentile(s.contactStepMicros, 99.0), nearestRankPercentile(s.contactStepMicros, 100.0));
        fmt::print("; slowest step {:.1f} us at t = {:.3f} s", s.maxStepMicros, s.maxStepTime);
        fmt::print("\n  max contacts {}, zones {}, moving masses {}, computed springs {}, deformation {:.4g}\n", s.maxContacts, s.maxZones,
                   s.maxMovingMasses, s.maxComputedSprings, s.maxDeformation);
        const double perStep = 1e6 / double(std::max<std::uint64_t>(1, s.steps));
        fmt::print("  per step (mean, us): world step {:.1f} =", perStep * s.profile.totalStepSeconds);
        for (std::size_t i = 0; i < kStageCount; ++i) fmt::print(" {} {:.1f};", labelOf(Stage(i)), perStep * s.profile.totalSeconds[i]);
        fmt::print("\n");
        for (const AssemblyEvent& e : s.events)
            fmt::print("  assembled: '{}' by {} at t = {:.3f} s\n", e.rule, labelOf(e.technique), e.time);
        fmt::print("  state hash {:016x}\n", s.stateHash);
    });
}

}  // namespace flexfit::cli
