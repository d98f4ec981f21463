// Where a world step's time goes: one entry per named stage (world.hpp lists what each does).
//
// The stages partition the step: from the first instruction of World::step to its last, every
// instant is charged to exactly one stage, the one running then. A stage running inside
// another (the narrow-phase queries and the contact solver inside the rigid motion's
// sub-steps) is charged to itself and paused in the outer one. So the stages add up to
// stepSeconds, and a stage that reads near zero did next to nothing.
#pragma once

#include "flexfit/names.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace flexfit {

enum class Stage {
    OperatorInput,    // the operator's coupling force, kinematic targets
    RigidMotion,      // rigid bodies integrated, in sub-steps (no tunnelling)
    ContactSolver,    // rigid contacts' impulses: normal, friction, restitution (in the sub-steps)
    BroadPhase,       // parts' bounding spheres, candidate pairs
    NarrowPhase,      // contacts of the candidate pairs (and of each sub-step's body)
    ContactResponse,  // deformable pushes and reactions
    ZoneDynamics,     // the deformable parts' masses (restoration included)
    ZoneRetirement,   // zones at rest retired, their masses back at rest
    Assembly,         // the snapping rules
    Count
};
// Its names (names.hpp).
inline constexpr EnumName<Stage> kStageNames[] = {
    {Stage::OperatorInput, "operator_input", "operator input"}, {Stage::RigidMotion, "rigid_motion", "rigid motion"},
    {Stage::ContactSolver, "contact_solver", "contact solver"},
    {Stage::BroadPhase, "broad_phase", "broad phase"}, {Stage::NarrowPhase, "narrow_phase", "narrow phase"},
    {Stage::ContactResponse, "contact_response", "contact response"}, {Stage::ZoneDynamics, "zone_dynamics", "zone dynamics"},
    {Stage::ZoneRetirement, "zone_retirement", "zone retirement"}, {Stage::Assembly, "assembly", "assembly"},
};
template <> inline constexpr std::span<const EnumName<Stage>> kEnumNames<Stage> = kStageNames;
inline constexpr std::size_t kStageCount = std::size_t(Stage::Count);
static_assert(std::size(kStageNames) == kStageCount, "every stage has a name");

struct Profile {
    std::array<double, kStageCount> lastSeconds{};   // the last step, per stage
    std::array<double, kStageCount> totalSeconds{};  // since the start, per stage
    double lastStepSeconds = 0.0;                    // the last World::step, whole
    double totalStepSeconds = 0.0;                   // every World::step so far
    std::uint64_t steps = 0;
    std::uint64_t substeps = 0;  // sub-steps taken in all (no-tunnelling bound)
    std::uint64_t cutMoves = 0;  // sub-step moves cut short by the contact slop (bisected)
    std::uint64_t rigidQueries = 0;  // one body's contact queries inside the sub-steps
    std::uint64_t faceQueries = 0;     // pair queries by face hierarchies, in all
    std::uint64_t faceTraversals = 0;  // of which traversed the hierarchies (CollisionWorld::faceTraversals; the others scanned candidates)
};

// The tail of step times a haptic loop cares about (its worst steps, not the mean): the
// nearest-rank percentile p in (0, 100] of the values, the smallest value that at least p % of
// them do not exceed (p = 100: the largest). NaN for no values or p outside (0, 100].
inline double nearestRankPercentile(std::vector<double> values, double p) {
    if (values.empty() || !(p > 0.0 && p <= 100.0)) return std::numeric_limits<double>::quiet_NaN();
    const std::size_t rank = std::size_t(std::ceil(p / 100.0 * double(values.size())));  // 1-based, >= 1
    const auto nth = values.begin() + std::ptrdiff_t(std::min(rank, values.size()) - 1);
    std::nth_element(values.begin(), nth, values.end());
    return *nth;
}

}  // namespace flexfit
