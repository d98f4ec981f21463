// Non-finite masses and the likely cause of a divergence (divergence.hpp).
#include "divergence.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <vector>

namespace flexfit::detail {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

// beyondBit (divergence.hpp) with the smallest carry: inf and nan only.
constexpr std::uint64_t kExponentOne = std::uint64_t(1) << 52;
inline std::uint64_t nonFiniteBit(double x) { return beyondBit(x, kExponentOne); }
inline std::uint64_t nonFiniteBit(const Vec3& v) { return beyondBit(v, kExponentOne); }


// The origin's coordinate for each of 8 masses' 24 doubles (x y z x y z ...).
struct Origin24 {
    explicit Origin24(const Vec3& origin) {
        for (std::size_t k = 0; k < 24; ++k) at[k] = origin[int(k % 3)];
    }
    double at[24];
};

// beyondBit of 8 consecutive masses' 24 doubles, less the origin, or-ed into 8 independent
// accumulators: it vectorises and keeps several vector units busy; a test with an early exit
// would not (measured: 3.5x faster than one accumulator of comparisons).
inline void orBeyondBits24(const double* p, const Origin24& origin, std::uint64_t carry, std::uint64_t (&lanes)[8]) {
    for (std::size_t j = 0; j < 24; j += 8)
        for (std::size_t k = 0; k < 8; ++k) lanes[k] |= beyondBit(p[j + k] - origin.at[j + k], carry);
}

std::string describe(const char* what, Index mass, const Vec3& value, const char* problem = "is not finite") {
    std::ostringstream text;
    text << what << " of mass " << mass << " " << problem << " (" << value.x() << ", " << value.y() << ", " << value.z() << ")";
    return text.str();
}

}  // namespace

bool allFinite(std::span<const Vec3> values) { return allWithin(values, Vec3::Zero(), std::numeric_limits<double>::infinity()); }

std::uint64_t carryBeyond(double bound) {
    if (!(bound < std::numeric_limits<double>::infinity())) return kExponentOne;
    const std::uint64_t e = (std::bit_cast<std::uint64_t>(bound) & kExponent) >> 52;
    return (0x800 - (e + 1)) << 52;
}

Vec3 boundOrigin(const PartState& state, double positionBound) {
    return positionBound < std::numeric_limits<double>::infinity() && !state.positions.empty() ? state.positions[0] : Vec3::Zero();
}

bool allWithin(std::span<const Vec3> values, const Vec3& origin, double bound) {
    return noneBeyond(beyondBits(values, origin, carryBeyond(bound)));
}

std::uint64_t beyondBits(std::span<const Vec3> values, const Vec3& origin, std::uint64_t carry) {
    if (values.empty()) return 0;
    const Origin24 origin24(origin);
    const double* p = values.data()->data();
    const std::size_t n = 3 * values.size();
    std::uint64_t lanes[8] = {};
    std::size_t i = 0;
    for (; i + 24 <= n; i += 24) orBeyondBits24(p + i, origin24, carry, lanes);
    std::uint64_t any = 0;
    for (; i < n; ++i) any |= beyondBit(p[i] - origin24.at[i % 3], carry);
    for (std::uint64_t lane : lanes) any |= lane;
    return any;
}

bool allFinite(const PartState& state, std::span<const Index> masses, double positionBound) {
    // The same bit, gathered over the masses' three vectors: no call and no branch per mass.
    if (masses.empty()) return true;
    const std::uint64_t carry = carryBeyond(positionBound);
    const Vec3 origin = boundOrigin(state, positionBound);
    std::uint64_t any = 0;
    for (Index m : masses)
        any |= beyondBit(state.positions[m] - origin, carry) | nonFiniteBit(state.velocities[m]) | nonFiniteBit(state.forces[m]);
    return (any >> 63) == 0;
}

namespace {

// The exponent trick of allFinite over a region: whole octets contiguously, the rest gathered.
// Positions only unless `velocitiesToo` (explicit Euler), as checkAllMassesFinite reasons: with
// the other integrators a non-finite force or velocity makes the position non-finite in the
// same step, and the step has consumed the forces (they are zero).
bool regionFinite(const PartState& state, const ActiveRegion& region, bool velocitiesToo, double positionBound) {
    if (state.positions.empty()) return true;
    const std::uint64_t carry = carryBeyond(positionBound);
    const Vec3 origin = boundOrigin(state, positionBound);
    const Origin24 origin24(origin), zero24(Vec3::Zero());
    std::uint64_t lanes[8] = {};
    for (const Index octet : region.vectorOctets()) {
        orBeyondBits24(state.positions.data()->data() + 24 * std::size_t(octet), origin24, carry, lanes);
        if (velocitiesToo) orBeyondBits24(state.velocities.data()->data() + 24 * std::size_t(octet), zero24, kExponentOne, lanes);
    }
    std::uint64_t any = 0;
    for (std::uint64_t lane : lanes) any |= lane;
    for (Index m : region.looseMasses())
        any |= beyondBit(state.positions[m] - origin, carry) | (velocitiesToo ? nonFiniteBit(state.velocities[m]) : std::uint64_t(0));
    return (any >> 63) == 0;
}

}  // namespace

std::optional<std::string> nonFiniteMass(const PartState& state, Index m) {
    if (!finite(state.positions[m])) return describe("position", m, state.positions[m]);
    if (!finite(state.velocities[m])) return describe("velocity", m, state.velocities[m]);
    if (!finite(state.forces[m])) return describe("force", m, state.forces[m]);
    return std::nullopt;
}

std::string outlyingMass(const PartState& state, double positionBound) {
    const Vec3Array& x = state.positions;
    if (x.empty()) return "the part has no masses";  // not reached after a failed check
    // The pair the check tripped on: mass 0 and the finite mass farthest from it along an axis.
    Index m = 0;
    double apart = 0.0;
    for (Index k = 0; k < x.size(); ++k)
        if (const double d = (x[k] - x[0]).cwiseAbs().maxCoeff(); finite(x[k]) && d > apart) m = k, apart = d;
    // Of the two, the one farther from the median position (per axis, over the finite masses: one
    // runaway mass cannot move it) is named as the outlier.
    std::vector<double> axis;
    Vec3 median = Vec3::Zero();
    for (int c = 0; c < 3; ++c) {
        axis.clear();
        for (const Vec3& p : x)
            if (finite(p)) axis.push_back(p[c]);
        if (axis.empty()) break;
        std::nth_element(axis.begin(), axis.begin() + std::ptrdiff_t(axis.size() / 2), axis.end());
        median[c] = axis[axis.size() / 2];
    }
    auto fromMedian = [&](Index k) { return (x[k] - median).cwiseAbs().maxCoeff(); };
    const Index named = fromMedian(m) >= fromMedian(0) ? m : 0, other = named == m ? 0 : m;
    if (named == other) return "the part's positions are within its bound";  // not reached after a failed check
    std::ostringstream problem;
    problem << "is " << apart << " units along an axis from mass " << other << "'s (" << x[other].x() << ", " << x[other].y()
            << ", " << x[other].z() << "), beyond the part's bound of " << positionBound
            << " units (1e6 times its size, tested within a factor 2): it is at";
    return describe("position", named, x[named], problem.str().c_str());
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

namespace {

// Every checked mass finite, yet the check failed: the part has spread beyond its bound.
[[noreturn]] void throwOutlying(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                                std::optional<BodyId> body, double time) {
    if (const std::optional<std::string> problem = nonFiniteMass(state, 0))  // the check measured from mass 0
        throw DivergenceError(body, time, *problem + "; " + likelyCause(model, settings));
    throw DivergenceError(body, time, outlyingMass(state, model.positionBound) + "; " + likelyCause(model, settings));
}

}  // namespace

void checkMassesFinite(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                       std::span<const Index> masses, std::optional<BodyId> body, double time) {
    if (allFinite(state, masses, model.positionBound)) return;
    for (Index m : masses)
        if (const std::optional<std::string> problem = nonFiniteMass(state, m))
            throw DivergenceError(body, time, *problem + "; " + likelyCause(model, settings));
    throwOutlying(model, settings, state, body, time);
}

void checkAllMassesFinite(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                          std::optional<BodyId> body, double time) {
    // One pass over the positions: with semi-implicit Euler a non-finite force or velocity makes
    // the position non-finite in the same step (x += h v_new); explicit Euler moves x with the
    // old velocity, so its velocities are read as well.
    if (allWithin(state.positions, boundOrigin(state, model.positionBound), model.positionBound) && (settings.integrator != Integrator::ExplicitEuler || allFinite(state.velocities)))
        return;
    for (Index m = 0; m < state.positions.size(); ++m)
        if (const std::optional<std::string> problem = nonFiniteMass(state, m))
            throw DivergenceError(body, time, *problem + "; " + likelyCause(model, settings));
    throwOutlying(model, settings, state, body, time);
}

void checkRegionFinite(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                       const ActiveRegion& region, std::optional<BodyId> body, double time) {
    if (regionFinite(state, region, settings.integrator == Integrator::ExplicitEuler, model.positionBound)) return;
    checkMassesFinite(model, settings, state, region.masses().members(), body, time);  // finds it and throws
}

}  // namespace flexfit::detail
