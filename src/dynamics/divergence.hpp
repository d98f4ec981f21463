// Internal to src/dynamics (used by src/world): finding a part's non-finite masses and naming
// the likely cause, for DivergenceError (core.hpp).
#pragma once

#include "flexfit/active_region.hpp"
#include "flexfit/simulation.hpp"

#include <bit>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>

namespace flexfit::detail {

// True when every coordinate is finite. No early exit: one vectorised pass over the array.
bool allFinite(std::span<const Vec3> values);
// True when every coordinate is finite and every value within `bound` of `origin` along each
// axis (exactly: below the power of two above it; PartModel::positionBound).
bool allWithin(std::span<const Vec3> values, const Vec3& origin, double bound);

// allWithin in pieces, for a check made where the values are written (the full step's
// integration pass, full_step.hpp). A double's exponent bits plus `carry` (carryBeyond(bound):
// for a magnitude of 2^(e + 1) or more, e the exponent of `bound`; only inf and nan for an
// infinite bound) carry into bit 63; or-ed over values less the origin, bit 63 says whether any
// was beyond or not finite (noneBeyond).
std::uint64_t carryBeyond(double bound);
// Where a part's position bound is measured from: mass 0's position (a spread); zero for no
// bound, so that finite is enough (x - x0 of two finite values may overflow).
Vec3 boundOrigin(const PartState& state, double positionBound);
// A double is not finite when its exponent bits are all set (inf, nan): then adding one to the
// exponent field carries into the sign bit. Or-ed over many values, bit 63 says whether any was.
// Adding more (`carry`) flags smaller exponents too: a position beyond the model's bound.
inline constexpr std::uint64_t kExponent = 0x7ff0000000000000ULL;
inline std::uint64_t beyondBit(double x, std::uint64_t carry) { return (std::bit_cast<std::uint64_t>(x) & kExponent) + carry; }
inline std::uint64_t beyondBit(const Vec3& v, std::uint64_t carry) {
    return beyondBit(v.x(), carry) | beyondBit(v.y(), carry) | beyondBit(v.z(), carry);
}
// The or of every coordinate's bits, less the origin's: of many values (a vectorised pass),
// of one (inline: the region step checks its loose masses one at a time).
std::uint64_t beyondBits(std::span<const Vec3> values, const Vec3& origin, std::uint64_t carry);
inline std::uint64_t beyondBits(const Vec3& value, const Vec3& origin, std::uint64_t carry) {
    return beyondBit(value - origin, carry);
}
inline bool noneBeyond(std::uint64_t bits) { return (bits >> 63) == 0; }
// True when every coordinate of the masses' positions, velocities and pending forces is
// finite, and every position within `positionBound` of mass 0's (as allWithin).
bool allFinite(const PartState& state, std::span<const Index> masses,
               double positionBound = std::numeric_limits<double>::infinity());

// "velocity of mass 17 is not finite (nan, nan, nan)" when the mass's position, velocity or
// pending force (tested in that order) is not finite; nothing when all are.
std::optional<std::string> nonFiniteMass(const PartState& state, Index mass);
// For a part whose positions are finite but whose spread failed the check against
// `positionBound` (from mass 0, along an axis): "position of mass 3 is D units along an axis from
// mass 0's (...), beyond the part's bound of B units ...", the pair the check tripped on (mass 0
// and the finite mass farthest from it), the one farther from the median position named (the
// median, so one runaway mass, even mass 0, cannot hide itself). O(masses).
std::string outlyingMass(const PartState& state, double positionBound);

// The likely cause of a part's divergence, in words, from the stability bounds of its model
// under `settings` (with the time step it was stepped with, analyzeStability): the time step
// above the bound, else a force beyond what the model can take. Costs O(masses + springs):
// call it only to describe a divergence.
std::string likelyCause(const PartModel& model, const SimulationSettings& settings);

// Throw DivergenceError (`body`, `time`) naming the first mass whose position, velocity or
// pending force is not finite, or, when a position is farther than model.positionBound from mass
// 0's, the mass farthest out (outlyingMass); and the likely cause. The first checks `masses`, in O(|masses|);
// the second every mass, in one vectorised pass over the positions when all are finite (and
// over the velocities with explicit Euler): for stepFullModel, right after its step.
void checkMassesFinite(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                       std::span<const Index> masses, std::optional<BodyId> body, double time);
void checkAllMassesFinite(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                          std::optional<BodyId> body, double time);
// checkMassesFinite over a region's moving masses after stepActiveRegion: its vector octets in
// contiguous passes, its other masses gathered, over their positions (and velocities with
// explicit Euler) only, as checkAllMassesFinite: the step consumed their forces, and a
// non-finite force or velocity has made the position non-finite in the same step.
void checkRegionFinite(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                       const ActiveRegion& region, std::optional<BodyId> body, double time);

}  // namespace flexfit::detail
