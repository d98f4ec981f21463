#include "perturbation_run.hpp"

#include <chrono>
#include <cmath>

namespace flexfit::cli {

PerturbationResult runPerturbation(const PerturbationConfig& config, const StepObserver& observer,
                                   const std::function<void(double)>& progress) {
    const PartModel& model = *config.model;
    for (const PointLoad& load : config.loads)
        if (load.mass >= model.massCount())
            throw InputError("load", 0, "mass " + std::to_string(load.mass) + " does not exist (the model has " +
                                            std::to_string(model.massCount()) + " masses)");
    PerturbationResult result;
    result.state = PartState::atRest(model);
    for (double t : config.thresholds) result.trackers.emplace_back(model, t);

    const double h = config.settings.timeStep;
    const auto totalSteps = std::size_t(std::llround(config.duration / h));
    const auto loadSteps = std::size_t(std::llround(config.loadDuration / h));
    const std::span<const PointLoad> noLoads;
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t step = 0; step < totalSteps; ++step) {
        if (step == loadSteps)
            for (ActivityTracker& tracker : result.trackers) tracker.markRelease(result.state.time);
        stepFullModel(model, config.settings, step < loadSteps ? std::span<const PointLoad>(config.loads) : noLoads,
                      result.state);
        bool allRestored = step >= loadSteps;
        for (ActivityTracker& tracker : result.trackers) {
            tracker.observe(model, result.state);
            allRestored = allRestored && tracker.restorationTime().has_value();
        }
        ++result.steps;
        if (observer) observer(result.state, result.trackers);
        if (progress && step % 256 == 0) progress(double(step) / double(totalSteps));
        if (config.stopWhenRestored && allRestored) break;
    }
    result.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace flexfit::cli
