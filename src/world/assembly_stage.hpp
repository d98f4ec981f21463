// Internal to src/world: the assembly stage (world.hpp) and the rules' state machine. Each
// rule waits until its condition holds (assembly.hpp), then snaps: its primary stops being
// driven (it becomes kinematic, and the operator lets it go), is brought to its final pose over
// the snap duration, and stays attached to the secondary from then on.
#pragma once

#include "bodies.hpp"
#include "flexfit/assembly.hpp"
#include "flexfit/collision.hpp"
#include "operator_input.hpp"

#include <span>
#include <vector>

namespace flexfit::detail {

struct RuleState {
    AssemblyRule rule;
    enum class Phase { Waiting, Snapping, Assembled } phase = Phase::Waiting;
    double start = 0.0;  // s, when the snap started
    Pose from;           // the primary's pose then
};

struct AssemblyState {
    std::vector<RuleState> rules;
    std::vector<AssemblyEvent> events;
};

// Throws InputError for unknown bodies or a negative duration; returns the rule's index.
std::size_t addRule(const AssemblyRule& rule, std::size_t bodyCount, AssemblyState& assembly);

// The stage: every rule's state machine, with this step's contacts (CollisionSnap).
void assemble(const StepContext& step, std::span<const Contact> contacts, AssemblyState& assembly, Bodies& bodies,
              OperatorState& op);

}  // namespace flexfit::detail
