// A perturbation run: a part (rigid, rigid-deformable or full-deformable) kicked at the start
// and/or under loads held for a while, then released, with activity tracked at several thresholds until the part has
// restored its shape (or a time limit). Shared by `simulate` and `experiment restoration`.
#pragma once

#include "flexfit/flexfit.hpp"

#include <functional>
#include <memory>
#include <vector>

namespace flexfit::cli {

struct ZoneRequest {
    ZoneSeed seed;
    int level = 1;
};

// The thesis's perturbation (chapter 5): one mass's velocity changed at once, at the start.
struct MassKick {
    Index mass = 0;
    Vec3 velocity = Vec3::Zero();  // world-frame change
};

struct PerturbationConfig {
    std::shared_ptr<const PartModel> model;
    PartSettings part;               // mode, simulation and zone settings
    std::vector<ZoneRequest> zones;  // opened at the start (rigid-deformable mode)
    std::vector<PointLoad> loads;    // world-frame forces
    std::vector<MassKick> kicks;     // before the first step
    double loadDuration = 0.0;       // loads act during [0, loadDuration)
    double duration = 10.0;          // simulated seconds at most
    bool stopWhenRestored = false;   // end once every threshold has restored after the release
    std::vector<double> thresholds{0.01, 0.1};
};

struct PerturbationResult {
    std::vector<ActivityTracker> trackers;  // one per threshold
    PartState state;
    std::size_t steps = 0;
    std::size_t maxMovingMasses = 0, maxComputedSprings = 0;
    StepCounters counters;
    double wallSeconds = 0.0;
};

// Called after every step with the part and the trackers' current counts.
using StepObserver = std::function<void(const Part&, const std::vector<ActivityTracker>&)>;

PerturbationResult runPerturbation(const PerturbationConfig& config, const StepObserver& observer = {},
                                   const std::function<void(double)>& progress = {});

}  // namespace flexfit::cli
