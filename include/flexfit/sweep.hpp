// Parameter sweeps: one base scene, the parameters to vary, every combination a run.
//
// A sweep file (TOML), paths relative to it:
//
//   scene = "ball_torus.toml"        # the base scene
//   duration = 2.0                   # optional: overrides the scene's [world] duration
//   set = { "world.rigid_deformable_query" = "faces" }   # optional: values every run shares
//   [[parameter]]
//   name = "friction"                # the column of the results table
//   key = "part.ball.friction"       # a scene key: tables by name, [[part]] by its name,
//   values = [0.0, 0.25, 0.5]        #   other arrays of tables by index (action.0.force)
//   [[parameter]]
//   name = "diameter"
//   key = ["part.ball.generator.radius", "part.ball.position"]   # several keys move together
//   values = [[7.0, [0, 5, 0]], [8.5, [0, 4.7, 0]]]              #   one value each, per case
//   labels = ["14", "17"]            # optional: what the table shows for each case
//   [[parameter]]
//   name = "push"
//   key = "action.0.force"
//   range = { start = 1000, stop = 3000, count = 3 }             # count values, ends included
//
// Runs are the Cartesian product, the first parameter varying slowest. A run's id is a hash of
// its parameters' names and values (not of its position), so it stays the same when other
// values are added or reordered: a restarted sweep finds its finished runs by id. The base
// scene's text, `set`, `duration` and the keys are hashed in too: editing them makes every run
// new. `set` takes quoted dotted keys, TOML's dotted keys or [set.<table>] alike.
//
// Every key must name an existing key of the base scene, or a new key in an existing table
// (the scene reader then checks it like any other); errors name the sweep file, the line of
// the parameter and the run.
#pragma once

#include "flexfit/scene.hpp"
#include "flexfit/scene_file.hpp"

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace flexfit {

namespace detail {
struct SweepDocument;
}

struct SweepParameter {
    std::string name;
    std::vector<std::string> keys;
    std::vector<std::string> labels;  // one per case: the given labels, or the values as TOML
    std::size_t line = 0;             // of its [[parameter]] in the sweep file
};

struct SweepRun {
    std::string id;                   // 16 hex digits (FNV-1a of the names and values)
    std::vector<std::size_t> cases;   // per parameter, the index of its value
};

struct Sweep {
    std::filesystem::path file;       // the sweep file
    std::filesystem::path scene;      // the base scene
    std::optional<double> duration;
    std::vector<SweepParameter> parameters;
    std::vector<SweepRun> runs;       // in product order
    std::shared_ptr<const detail::SweepDocument> document;  // the base scene and the values
    SceneReadOptions read;            // how every run's scene is read (strict meshes, remesh cache)
    // The runs' scene warnings (mesh repairs, old spellings; lines of the base scene), each
    // once, in the order the check met them; empty when loaded without checking the runs.
    std::vector<SceneWarning> warnings;

    // The run's label of each parameter, in order.
    std::vector<std::string> labels(std::size_t run) const;
};

// Throws InputError naming the sweep file (or the base scene), the line and the problem. With
// checkRuns, every run's scene is built and checked once (meshes and all), so a sweep that loads
// has no bad run; a worker that runs runs of a sweep checked elsewhere can skip it. `read` is
// kept in the sweep: every run's scene is read with it, as loadScene reads one.
Sweep loadSweep(const std::filesystem::path& file, bool checkRuns = true, const SceneReadOptions& read = {});

// The scene of one run (its source names the sweep file and the run id).
Scene sweepScene(const Sweep& sweep, std::size_t run);

}  // namespace flexfit
