// Internal to src/world: the end of a world step's check that nothing diverged (world.hpp).
#pragma once

#include "bodies.hpp"

namespace flexfit::detail {

// Throws DivergenceError naming the body, step.time (the start of the step) and what is no
// longer finite, with its likely cause: first any deformable part's moving mass (position,
// velocity, pending force; the cause from the part's stability bound at the world's time
// step), then any kinematic or dynamic body's accumulated force or torque, linear or angular velocity, or pose.
// Costs O(bodies + moving masses): masses at rest are at their rest positions by construction.
void checkFinite(const StepContext& step, const Bodies& bodies);

}  // namespace flexfit::detail
