// Non-finite masses and the likely cause of a divergence (divergence.hpp).
#include "divergence.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

namespace flexfit::detail {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

// A double is not finite when its exponent bits are all set (inf, nan): then adding one to the
// exponent field carries into the sign bit. Or-ed over many values, bit 63 says whether any was.
// Adding more (`carry`) flags smaller exponents too: a position beyond the model's bound.
constexpr std::uint64_t kExponent = 0x7ff0000000000000ULL, kExponentOne = std::uint64_t(1) << 52;
inline std::uint64_t beyondBit(double x, std::uint64_t carry) { return (std::bit_cast<std::uint64_t>(x) & kExponent) + carry; }
inline std::uint64_t beyondBit(const Vec3& v, std::uint64_t carry) {
    return beyondBit(v.x(), carry) | beyondBit(v.y(), carry) | beyondBit(v.z(), carry);
}
inline std::uint64_t nonFiniteBit(double x) { return beyondBit(x, kExponentOne); }
inline std::uint64_t nonFiniteBit(const Vec3& v) { return beyondBit(v, kExponentOne); }

// The carry that flags a magnitude of 2^(e + 1) or more, e the exponent of `bound` (so values up
// to `bound`, and below twice it, pass); only inf and nan for an infinite bound.
std::uint64_t carryBeyond(double bound) {
    if (!(bound < std::numeric_limits<double>::infinity())) return kExponentOne;
    const std::uint64_t e = (std::bit_cast<std::uint64_t>(bound) & kExponent) >> 52;
    return (0x800 - (e + 1)) << 52;
}

std::string describe(const char* what, Index mass, const Vec3& value, const char* problem = "is not finite") {
    std::ostringstream text;
    text << what << " of mass " << mass << " " << problem << " (" << value.x() << ", " << value.y() << ", " << value.z() << ")";
    return text.str();
}

}  // namespace

bool allFinite(std::span<const Vec3> values) { return allWithin(values, std::numeric_limits<double>::infinity()); }

bool allWithin(std::span<const Vec3> values, double bound) {
    if (values.empty()) return true;
    const std::uint64_t carry = carryBeyond(bound);
    // nonFiniteBit or-ed over the coordinates into 8 independent accumulators vectorises and
    // keeps several vector units busy; a test with an early exit would not (measured: 3.5x
    // faster than one accumulator of comparisons).
    const double* p = values.data()->data();
    const std::size_t n = 3 * values.size();
    std::uint64_t lanes[8] = {};
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8)
        for (std::size_t k = 0; k < 8; ++k) lanes[k] |= beyondBit(p[i + k], carry);
    std::uint64_t any = 0;
    for (; i < n; ++i) any |= beyondBit(p[i], carry);
    for (std::uint64_t lane : lanes) any |= lane;
    return (any >> 63) == 0;
}

bool allFinite(const PartState& state, std::span<const Index> masses, double positionBound) {
    // The same bit, gathered over the masses' three vectors: no call and no branch per mass.
    const std::uint64_t carry = carryBeyond(positionBound);
    std::uint64_t any = 0;
    for (Index m : masses)
        any |= beyondBit(state.positions[m], carry) | nonFiniteBit(state.velocities[m]) | nonFiniteBit(state.forces[m]);
    return (any >> 63) == 0;
}

namespace {

// The exponent trick of allFinite over a region: whole octets contiguously, the rest gathered.
// Positions only unless `velocitiesToo` (explicit Euler), as checkAllMassesFinite reasons: with
// the other integrators a non-finite force or velocity makes the position non-finite in the
// same step, and the step has consumed the forces (they are zero).
bool regionFinite(const PartState& state, const ActiveRegion& region, bool velocitiesToo, double positionBound) {
    const std::uint64_t carry = carryBeyond(positionBound);
    std::uint64_t lanes[8] = {};
    auto scan = [&](const double* p, std::uint64_t c) {
        for (std::size_t i = 0; i < 24; i += 8)
            for (std::size_t k = 0; k < 8; ++k) lanes[k] |= beyondBit(p[i + k], c);
    };
    for (const Index octet : region.fullOctets()) {
        scan(state.positions.data()->data() + 24 * std::size_t(octet), carry);
        if (velocitiesToo) scan(state.velocities.data()->data() + 24 * std::size_t(octet), kExponentOne);
    }
    std::uint64_t any = 0;
    for (std::uint64_t lane : lanes) any |= lane;
    for (Index m : region.looseMasses())
        any |= beyondBit(state.positions[m], carry) | (velocitiesToo ? nonFiniteBit(state.velocities[m]) : std::uint64_t(0));
    return (any >> 63) == 0;
}

}  // namespace

std::optional<std::string> nonFiniteMass(const PartState& state, Index m, double positionBound) {
    if (!finite(state.positions[m])) return describe("position", m, state.positions[m]);
    if ((beyondBit(state.positions[m], carryBeyond(positionBound)) >> 63) != 0) {
        std::ostringstream problem;
        problem << "is beyond " << positionBound << " units, 1e6 times the part's size,";
        return describe("position", m, state.positions[m], problem.str().c_str());
    }
    if (!finite(state.velocities[m])) return describe("velocity", m, state.velocities[m]);
    if (!finite(state.forces[m])) return describe("force", m, state.forces[m]);
    return std::nullopt;
}

std::string likelyCause(const PartModel& model, const SimulationSettings& settings) {
    const StabilityReport report = analyzeStability(model, settings);
    std::ostringstream text;
    text << "likely cause: ";
    if (report.certainlyUnstable && report.unstableTimeStep == 0.0)
        text << "the time step " << settings.timeStep << " s is above the stability bound 0 s of this material with "
             << labelOf(settings.integrator) << " (it blows up at any time step without damping: add damping or use the implicit integrator)";
    else if (report.certainlyUnstable)
        text << "the time step " << settings.timeStep << " s is above the stability bound " << report.unstableTimeStep
             << " s of this material with " << labelOf(settings.integrator) << " (stable below " << report.safeTimeStep
             << " s; lower the time step, soften the material or use the implicit integrator)";
    else if (report.possiblyUnstable)
        text << "the time step " << settings.timeStep << " s is above the stability bound " << report.safeTimeStep
             << " s of this material with " << labelOf(settings.integrator)
             << " (lower the time step, soften the material or use the implicit integrator), or a force beyond what the model can take";
    else
        text << "a force beyond what the model can take (the time step " << settings.timeStep
             << " s is within the stability bound " << report.safeTimeStep << " s of this material)";
    return text.str();
}

void checkMassesFinite(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                       std::span<const Index> masses, std::optional<BodyId> body, double time) {
    if (allFinite(state, masses, model.positionBound)) return;
    for (Index m : masses)
        if (const std::optional<std::string> problem = nonFiniteMass(state, m, model.positionBound))
            throw DivergenceError(body, time, *problem + "; " + likelyCause(model, settings));
}

void checkAllMassesFinite(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                          std::optional<BodyId> body, double time) {
    // One pass over the positions: with semi-implicit Euler a non-finite force or velocity makes
    // the position non-finite in the same step (x += h v_new); explicit Euler moves x with the
    // old velocity, so its velocities are read as well.
    if (allWithin(state.positions, model.positionBound) && (settings.integrator != Integrator::ExplicitEuler || allFinite(state.velocities)))
        return;
    for (Index m = 0; m < state.positions.size(); ++m)
        if (const std::optional<std::string> problem = nonFiniteMass(state, m, model.positionBound))
            throw DivergenceError(body, time, *problem + "; " + likelyCause(model, settings));
}

void checkRegionFinite(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                       const ActiveRegion& region, std::optional<BodyId> body, double time) {
    if (regionFinite(state, region, settings.integrator == Integrator::ExplicitEuler, model.positionBound)) return;
    checkMassesFinite(model, settings, state, region.masses().members(), body, time);  // finds it and throws
}

}  // namespace flexfit::detail
