// Internal to src/dynamics: the region step with the divergence check made in its integration
// pass (Part::step; stepActiveRegion is the same step without it).
#pragma once

#include "full_step.hpp"

namespace flexfit::detail {

// stepActiveRegion; with `check` (semi-implicit Euler: the positions alone tell), the new
// positions of the moving masses are checked as they are written, as checkRegionFinite would
// check them after the step (the same bits or-ed): mass 0 first when it moves, so the origin
// is known before the others. check->covered stays false where the pass made no check (the
// scalar kernel, another integrator): the caller then checks after the step.
void stepRegion(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region, PartState& state,
                StepCounters* counters, PositionCheck* check);

// stepRegionByFullModel for a state whose masses outside the region are at rest, as a Part
// keeps them (Part::step): the vector kernels skip the groups of masses none of which moves
// (their forces zeroed), so no pass over all the masses puts them back.
void stepRegionByFullModelFromRest(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                                   PartState& state, StepCounters* counters);

}  // namespace flexfit::detail
