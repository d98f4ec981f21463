// Internal to src/world: the operator stage (world.hpp). The operator holds at most one body;
// each step the coupling between its target and the body is applied, and kinematic bodies are
// aimed at the targets set for them (the rigid motion stage moves them there).
#pragma once

#include "bodies.hpp"
#include "flexfit/world.hpp"

#include <optional>

namespace flexfit::detail {

struct CouplingGains {
    double k = 0.0, b = 0.0, kr = 0.0, br = 0.0;  // linear and angular stiffness and damping
};

struct OperatorState {
    std::optional<BodyId> grabbed;
    CouplingGains gains;
    Pose target, previousTarget;  // the grab target now and in the last step
    Coupling coupling;            // what the coupling applied in the last step
};

// Grabs body `id` (InputError for a missing or static body, bad settings, or gains the time
// step cannot integrate stably); the target starts at its pose.
void grab(BodyId id, const GrabSettings& settings, double timeStep, const Bodies& bodies, OperatorState& op);
void release(OperatorState& op);

// The stage: the coupling force and torque on the grabbed dynamic body (or the target as a
// grabbed kinematic body's target), then every kinematic body's velocity: the one that reaches
// its target in this step, or zero without a target.
void operatorInput(const StepContext& step, OperatorState& op, Bodies& bodies);

}  // namespace flexfit::detail
