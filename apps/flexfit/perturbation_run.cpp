#include "perturbation_run.hpp"

#include <chrono>
#include <cmath>

namespace flexfit::cli {

PerturbationResult runPerturbation(const PerturbationConfig& config, const StepObserver& observer,
                                   const std::function<void(double)>& progress) {
    const PartModel& model = *config.model;
    auto checkMass = [&](Index mass, const char* what) {
        if (mass >= model.massCount())
            throw InputError(what, 0, "mass " + std::to_string(mass) + " does not exist (the model has " +
                                          std::to_string(model.massCount()) + " masses)");
    };
    for (const PointLoad& load : config.loads) checkMass(load.mass, "load");
    for (const MassKick& kick : config.kicks) checkMass(kick.mass, "kick");
    Part part(config.model, config.part);
    for (const ZoneRequest& zone : config.zones) part.openZone(zone.seed, zone.level);
    for (const MassKick& kick : config.kicks) part.kickMass(kick.mass, kick.velocity);
    PerturbationResult result;
    for (double t : config.thresholds) result.trackers.emplace_back(model, t);

    const double h = config.part.simulation.timeStep;
    const auto totalSteps = std::size_t(std::llround(config.duration / h));
    const auto loadSteps = std::size_t(std::llround(config.loadDuration / h));
    const auto start = std::chrono::steady_clock::now();
    const bool kickedOnly = config.loads.empty() && !config.kicks.empty();
    for (std::size_t step = 0; step < totalSteps; ++step) {
        if (step == 0 && kickedOnly)
            for (ActivityTracker& tracker : result.trackers) tracker.markKick(part.time());
        else if (step == loadSteps)
            for (ActivityTracker& tracker : result.trackers) tracker.markRelease(part.time());
        if (step < loadSteps)
            for (const PointLoad& load : config.loads) part.applyForce(load.mass, load.force);
        result.maxMovingMasses = std::max(result.maxMovingMasses, part.movingMasses().size());
        result.maxComputedSprings = std::max(result.maxComputedSprings, part.computedSprings().size());
        part.step(&result.counters);
        bool allRestored = step >= loadSteps;
        for (ActivityTracker& tracker : result.trackers) {
            tracker.observe(model, part.state(), part.computedSprings());
            allRestored = allRestored && tracker.restorationTime().has_value();
        }
        ++result.steps;
        if (observer) observer(part, result.trackers);
        if (progress && step % 256 == 0) progress(double(step) / double(totalSteps));
        if (config.stopWhenRestored && allRestored) break;
    }
    result.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.state = part.state();
    return result;
}

}  // namespace flexfit::cli
