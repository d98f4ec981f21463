// Internal to src/world: the rigid motion stage (world.hpp). Dynamic bodies take their forces,
// torques and gravity (semi-implicit Euler) and move in sub-steps short enough that no point
// of a body travels more than maxTravelFraction of the thinnest body per sub-step; after each
// sub-step the body's contacts with rigid parts are found and projected out, so it can never
// jump over a part, whatever its speed or the time step.
#pragma once

#include "bodies.hpp"
#include "contact_response.hpp"
#include "flexfit/collision_world.hpp"
#include "flexfit/world_settings.hpp"
#include "step_profiler.hpp"

namespace flexfit::detail {

// Charges its own work to Stage::RigidMotion, each sub-step's contact query to NarrowPhase and
// each projection to ContactResponse. Adds the sub-steps taken to profile.substeps.
void moveDynamicBodies(const StepContext& step, const WorldSettings& settings, Bodies& bodies, CollisionWorld& collision,
                       ContactResponse& response, StepProfiler& profiler, Profile& profile);

}  // namespace flexfit::detail
