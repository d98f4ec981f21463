// Internal to src/world: the end of a world step's check that nothing diverged (world.hpp).
#pragma once

#include "bodies.hpp"

#include <cstdint>
#include <span>

namespace flexfit::detail {

// Throws DivergenceError naming the body, step.time (the start of the step) and what is no
// longer finite, with its likely cause: first any deformable part's moving mass (position,
// velocity, pending force; the cause from the part's stability bound at the world's time
// step), then any kinematic or dynamic body's accumulated force or torque, linear or angular velocity, or pose.
// A part whose zone dynamics step checked its moving masses already (zonesChecked[body],
// advanceZones) is not checked again: what the stages after it do to masses (retirement puts
// them back at rest) cannot make one diverge. Costs O(bodies + moving masses not yet checked):
// masses at rest are at their rest positions by construction.
void checkFinite(const StepContext& step, const Bodies& bodies, std::span<const std::uint8_t> zonesChecked);

}  // namespace flexfit::detail
