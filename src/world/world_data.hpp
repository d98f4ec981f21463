// Internal to src/world: everything a World holds, grouped by the stage that owns it. World
// (world.hpp) is a handle to it; each stage function takes the pieces it reads and writes.
#pragma once

#include "assembly_stage.hpp"
#include "bodies.hpp"
#include "contact_response.hpp"
#include "flexfit/collision_world.hpp"
#include "flexfit/world_settings.hpp"
#include "operator_input.hpp"
#include "rigid_motion.hpp"

#include <optional>

namespace flexfit::detail {

struct WorldData {
    explicit WorldData(const WorldSettings& s) : settings(s), collision(s.collision) {}

    const WorldSettings settings;
    Bodies bodies;              // the one registry: parts, rigid bodies, kinematic targets
    CollisionWorld collision;   // read-only views of the parts, by the same ids
    OperatorState op;           // the grab and its coupling
    ContactResponse response;   // contact stiffness per body, response scratch
    RigidMotionScratch rigidMotion;  // the sub-steps' solver and contacts
    AssemblyState assembly;     // the rules and their events
    std::vector<std::uint8_t> zonesChecked;  // (bodies) the zone dynamics step checked its moving masses
    Profile profile;
    std::vector<std::string> warnings;  // World::warnings()
    std::optional<DivergenceError> diverged;  // the step that diverged: no step after it
    std::uint64_t stepIndex = 0;
    double time = 0.0;

    StepContext context() const { return {settings.timeStep, settings.gravity, stepIndex, time}; }
};

}  // namespace flexfit::detail
