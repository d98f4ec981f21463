// Internal to src/dynamics: the implicit Euler step (implicit_step.cpp has the method and its
// limits). stepFullModel and stepActiveRegion call it when the settings choose
// Integrator::ImplicitEuler.
#pragma once

#include "flexfit/simulation.hpp"

namespace flexfit::detail {

// One implicit Euler step of the whole model (region null) or of a region's moving masses with
// every other mass held at rest. Consumes the pending forces of the masses it steps; advances
// the state's time and step count. Does not check for divergence (the callers do).
void stepImplicit(const PartModel& model, const SimulationSettings& settings, const ActiveRegion* region,
                  PartState& state, StepCounters* counters);

}  // namespace flexfit::detail
