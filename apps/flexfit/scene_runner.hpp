// Runs a scene headless and records what `flexfit run` reports: per-step metrics (CSV), a
// summary (JSON: events, per-stage times, maxima, the final state hash) and optional OBJ
// frames. Shared by `flexfit run` and `flexfit experiment ball-torus`.
#pragma once

#include "flexfit/scene_file.hpp"
#include "flexfit/scene_run.hpp"

#include <filesystem>
#include <optional>

namespace flexfit::cli {

struct RunOptions {
    std::optional<double> duration;      // overrides the scene's
    std::filesystem::path out;           // empty: record nothing on disk
    bool progress = true;
    int csvEvery = 1;                    // write every k-th step to metrics.csv
    // Seconds between frames (override the scene's [output]): OBJ, VTK (.vtp and frames.pvd)
    // and glTF binary (frame_export.hpp).
    std::optional<double> objEvery, vtkEvery, glbEvery;
};

struct RunSummary {
    std::uint64_t steps = 0;
    double simulatedSeconds = 0.0, wallSeconds = 0.0;
    std::size_t maxContacts = 0, maxMovingMasses = 0, maxComputedSprings = 0, maxZones = 0;
    double maxDeformation = 0.0;          // largest distance of a mass from rest, any deformable part
    std::optional<double> lastContact;    // s: the last step with a contact
    std::optional<double> restored;       // s: first time after the last contact with no moving mass
    double maxCouplingForce = 0.0;
    // Steps in contact and their wall time (the haptic-rate figure).
    std::uint64_t contactSteps = 0;
    double contactWallSeconds = 0.0;
    std::vector<double> contactStepMicros;  // each in-contact step's World::step, us (profile)
    // The slowest World::step of the run, in contact or not (a haptic loop misses its deadline
    // on any step), and the simulated time at its end.
    double maxStepMicros = 0.0;
    double maxStepTime = 0.0;
    Profile profile;
    std::vector<AssemblyEvent> events;
    std::uint64_t stateHash = 0;
    std::vector<Vec3> finalCentres;       // per body
};

// Throws DivergenceError (World::step) when the scene diverges; its files are written under
// temporary names and moved into place only when the run ends, so a failed run leaves none.
RunSummary runScene(const Scene& scene, const RunOptions& options);

// The summary as JSON (what run writes to summary.json).
std::string summaryJson(const Scene& scene, const RunSummary& summary);

}  // namespace flexfit::cli
