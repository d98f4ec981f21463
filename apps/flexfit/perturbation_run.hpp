// A perturbation run: loads held for a while, then released, with activity tracked at several
// thresholds until the part has restored its shape (or a time limit). Shared by `simulate`
// and `experiment restoration`.
#pragma once

#include "flexfit/flexfit.hpp"

#include <functional>
#include <memory>
#include <vector>

namespace flexfit::cli {

struct PerturbationConfig {
    std::shared_ptr<const PartModel> model;
    SimulationSettings settings;
    std::vector<PointLoad> loads;
    double loadDuration = 0.0;    // loads act during [0, loadDuration)
    double duration = 10.0;       // simulated seconds at most
    bool stopWhenRestored = false;  // end once every threshold has restored after the release
    std::vector<double> thresholds{0.01, 0.1};
};

struct PerturbationResult {
    std::vector<ActivityTracker> trackers;  // one per threshold
    PartState state;
    std::size_t steps = 0;
    double wallSeconds = 0.0;
};

// Called after every step with the state and the trackers' current counts.
using StepObserver = std::function<void(const PartState&, const std::vector<ActivityTracker>&)>;

PerturbationResult runPerturbation(const PerturbationConfig& config, const StepObserver& observer = {},
                                   const std::function<void(double)>& progress = {});

}  // namespace flexfit::cli
