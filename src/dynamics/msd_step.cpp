// One step of the full mass-spring-damper model: spring blocks, then the springs in no block,
// then every mass (block_step.cpp).
#include "flexfit/simulation.hpp"
#include "divergence.hpp"
#include "flush_denormals.hpp"
#include "full_step.hpp"
#include "implicit_step.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace flexfit {

std::optional<std::string> timeStepProblem(double timeStep) {
    if (!std::isfinite(timeStep) || timeStep <= 0.0) return "time step must be finite and > 0";
    if (!(timeStep >= std::numeric_limits<double>::min())) return "time step " + std::to_string(timeStep) + " is below the smallest normal double";
    return std::nullopt;
}

void validateSettings(const SimulationSettings& s) {
    const std::string source = "simulation settings";
    if (const std::optional<std::string> problem = timeStepProblem(s.timeStep)) throw InputError(source, 0, *problem);
    if (!s.gravity.allFinite()) throw InputError(source, 0, "gravity must be finite");
    requireNamedValue<InputError>(s.integrator, source, "integrator");
    requireNamedValue<InputError>(s.restoration.method, source, "restoration method");
    if (!std::isfinite(s.globalDamping) || s.globalDamping < 0.0)
        throw InputError(source, 0, "global damping must be finite and >= 0");
    const RestorationSettings& r = s.restoration;
    if (!std::isfinite(r.anchorStiffness) || r.anchorStiffness < 0.0)
        throw InputError(source, 0, "anchor stiffness must be finite and >= 0");
    if (!std::isfinite(r.anchorDamping) || r.anchorDamping < 0.0)
        throw InputError(source, 0, "anchor damping must be finite and >= 0");
    if (r.method == RestorationMethod::Constraint && !(r.constraintFraction > 0.0 && r.constraintFraction <= 1.0))
        throw InputError(source, 0, "restoration constraint fraction must be in (0, 1]");
    if (!std::isfinite(r.constraintRate) || r.constraintRate < 0.0)
        throw InputError(source, 0, "restoration constraint rate must be finite and >= 0");
    if (s.implicit.maxIterations < 1) throw InputError(source, 0, "implicit iterations must be >= 1");
    if (!std::isfinite(s.implicit.tolerance) || s.implicit.tolerance < 0.0 || s.implicit.tolerance >= 1.0)
        throw InputError(source, 0, "implicit tolerance must be in [0, 1)");
}

double constraintFractionFor(const RestorationSettings& r, double timeStep) {
    return r.constraintRate > 0.0 ? -std::expm1(-2.0 * r.constraintRate * timeStep) : r.constraintFraction;
}

std::optional<DefaultFractionElsewhere> defaultFractionAt(double timeStep) {
    if (!(timeStep > 0.0 && std::isfinite(timeStep))) return std::nullopt;  // refused where settings are checked
    DefaultFractionElsewhere d;
    d.timeStep = timeStep;
    d.fraction = RestorationSettings{}.constraintFraction;
    d.chosenFor = SimulationSettings{}.timeStep;
    d.faster = d.chosenFor / timeStep;
    if (std::abs(d.faster - 1.0) < 1e-9) return std::nullopt;
    d.stiffer = d.faster * d.faster;
    d.keepingTime = -std::log1p(-d.fraction) / (2.0 * d.chosenFor);  // constraintFractionFor's inverse at 1 ms
    return d;
}

std::optional<DefaultFractionElsewhere> defaultFractionAt(const RestorationSettings& r, double timeStep) {
    if (r.method != RestorationMethod::Constraint || r.constraintRate > 0.0 || r.constraintFraction != RestorationSettings{}.constraintFraction)
        return std::nullopt;
    return defaultFractionAt(timeStep);
}

std::string describe(const DefaultFractionElsewhere& d, const FractionKeys& keys) {
    const auto shortly = [](double x) {
        char text[32];
        std::snprintf(text, sizeof text, "%.3g", x);
        return std::string(text);
    };
    return "the restoration constraint's default fraction " + shortly(d.fraction) + " is per step, chosen for " +
           shortly(1e3 * d.chosenFor) + " ms steps: at " + keys.timeStep + shortly(d.timeStep) + " the part restores " +
           shortly(d.faster) + " times as fast and resists loads about " + shortly(d.stiffer) + " times as stiffly; " +
           keys.ratePrefix + shortly(d.keepingTime) + keys.rateSuffix + " keeps the restoration time, " + keys.anchors +
           " a stiffness independent of the step";
}

void detail::requireStepInputs(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                               const ActiveRegion* region, std::span<const PointLoad> loads, const char* what) {
    validateSettings(settings);
    const std::string_view source = what;  // a std::string only when thrown: the steps allocate nothing
    const std::size_t n = model.massCount();
    if (state.positions.size() != n || state.velocities.size() != n || state.forces.size() != n)
        throw InputError(std::string(source), 0, "the state has " + std::to_string(state.positions.size()) + " masses, the model " + std::to_string(n));
    if (region != nullptr && !region->builtFor(model)) throw InputError(std::string(source), 0, "the active region was built for another model");
    for (const PointLoad& load : loads) {
        if (load.mass >= n)
            throw InputError(std::string(source), 0, "a load on mass " + std::to_string(load.mass) + ", which does not exist (the model has " +
                                            std::to_string(n) + " masses)");
        if (!load.force.allFinite()) throw InputError(std::string(source), 0, "the load on mass " + std::to_string(load.mass) + " is not finite");
    }
}

void stepFullModel(const PartModel& model, const SimulationSettings& settings, std::span<const PointLoad> loads,
                   PartState& state, StepCounters* counters) {
    detail::requireStepInputs(model, settings, state, nullptr, loads, "stepFullModel");
    detail::stepAllMasses(model, settings, loads, nullptr, state, counters);
}

void detail::stepAllMasses(const PartModel& model, const SimulationSettings& settings, std::span<const PointLoad> loads,
                           const std::uint16_t* held, PartState& state, StepCounters* counters) {
    const detail::FlushDenormals flush;
    const double start = state.time;
    for (const PointLoad& load : loads) state.forces[load.mass] += load.force;
    if (settings.integrator == Integrator::ImplicitEuler) {
        detail::stepImplicit(model, settings, nullptr, state, counters);
        if (held != nullptr) detail::holdAtRest(model, {held, model.massCount()}, state, detail::fullStepKernel());
    } else {
        const detail::MassUpdate update = detail::MassUpdate::from(settings);
        // Semi-implicit Euler: the positions alone tell (checkAllMassesFinite), so the
        // integration pass checks them as it writes them. Explicit Euler reads the velocities too.
        detail::PositionCheck check(model.positionBound);
        const bool positionsTell = settings.integrator == Integrator::SemiImplicitEuler;
        detail::stepSpringBlocks(model, update, state, detail::fullStepKernel(), held, positionsTell ? &check : nullptr);
        state.time += settings.timeStep;
        ++state.stepCount;
        if (counters != nullptr) {
            counters->springsEvaluated += model.springCount();
            counters->massesIntegrated += model.massCount();
        }
        if (check.passed()) return;
    }
    detail::checkAllMassesFinite(model, settings, state, std::nullopt, start);  // the whole check where the pass made none
}

double totalEnergy(const PartModel& model, const SimulationSettings& settings, const PartState& state) {
    detail::requireStepInputs(model, settings, state, nullptr, {}, "totalEnergy");
    double energy = 0.0;
    for (std::size_t i = 0; i < model.massCount(); ++i) energy += 0.5 * model.mass[i] * state.velocities[i].squaredNorm();
    for (std::size_t e = 0; e < model.springCount(); ++e) {
        const double stretch = (state.positions[model.springA[e]] - state.positions[model.springB[e]]).norm() - model.restLength[e];
        energy += 0.5 * model.stiffness[e] * stretch * stretch;
    }
    if (settings.restoration.method == RestorationMethod::AnchorSprings)
        for (std::size_t i = 0; i < model.massCount(); ++i)
            energy += 0.5 * settings.restoration.anchorStiffness * (state.positions[i] - model.restPositions[i]).squaredNorm();
    return energy;
}

Vec3 linearMomentum(const PartModel& model, const PartState& state) {
    Vec3 momentum = Vec3::Zero();
    for (std::size_t i = 0; i < model.massCount(); ++i) momentum += model.mass[i] * state.velocities[i];
    return momentum;
}

}  // namespace flexfit
