// Internal to src/world: the deformable parts' stages (world.hpp).
#pragma once

#include "bodies.hpp"

#include <cstdint>
#include <vector>

namespace flexfit::detail {

// Zone dynamics: every part's moving masses by one step (restoration included). Zone masses
// feel no gravity in a world: a part's rest shape is its shape under its own weight, and in a
// falling body's frame its masses feel none, so zones deform from contacts and forces only.
// A part stepped by the full model that diverges throws DivergenceError naming its body and
// step.time. checked[body] (resized to the bodies) says whether the step itself found every
// moving mass within bounds (Part::advance); the others are checked after the whole step
// (divergence_check.hpp).
void advanceZones(const StepContext& step, Bodies& bodies, std::vector<std::uint8_t>& checked);

// Zone retirement: every part retires its zones at rest (Part::retireRestingZones), their
// masses exactly back at rest.
void retireZones(Bodies& bodies);

}  // namespace flexfit::detail
