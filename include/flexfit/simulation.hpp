// Mass-spring-damper dynamics of a whole part (the thesis's full MSD model, SPEC 2-3).
//
// Equation of motion (thesis eq. 2.1): m_i a_i = -gamma v_i + sum_j g_ij + f_i with
//   g_ij = -k (|x_i - x_j| - L_ij) u_ij - b ((v_i - v_j) . u_ij) u_ij,  u_ij = (x_i - x_j)/|.|
// f_i: gravity m_i g, point loads, and anchor springs when they restore the shape.
//
// Integrators (h = time step):
//   semi-implicit (symplectic) Euler: v += h a(x, v); x += h v      -- the default
//   explicit Euler:                   x += h v;      v += h a(x, v) -- the thesis's, to compare
//   implicit (backward) Euler:        v += h a(x + h v+, v+); x += h v+, one Newton step solved
//                                     by conjugate gradient (src/dynamics/implicit_step.cpp):
//                                     unconditionally stable, for stiff materials and large h
// Stability (per vibration mode of angular frequency w with modal damping c = 2 zeta w):
//   symplectic Euler is stable iff h^2 w^2 + 2 c h < 4  (undamped: h < 2/w);
//   explicit Euler is stable iff h < c / w^2, so it always blows up without damping; with
//   stiffness-proportional damping (b/k per spring) that is h < b/k for the fast modes.
// analyzeStability() evaluates both with a Gershgorin upper bound on w (warn: may blow up) and a
// Rayleigh-quotient lower bound (reject: certain to blow up). Neither explicit integrator is
// unconditionally stable: stiff materials need h below the bound it reports, or the implicit
// integrator, which has no bound (it damps the fast modes numerically instead).
//
// Shape restoration (SPEC 3):
//   AnchorSprings: a zero-rest-length spring (k_a, b_a) ties each mass to its rest position.
//   Constraint:    after integration each mass moves a fraction c of the way back to its rest
//                  position (position-based, like PBD); its velocity takes the correction /h,
//                  so the correction removes energy instead of leaving a drift. With no other
//                  force the offset decays by sqrt(1 - c) per step (|eigenvalue| of the update).
//                  The fraction is per step, so the decay rate depends on h, unless it is
//                  given as a rate (RestorationSettings::constraintRate). On a lone mass it
//                  acts like a stiff, heavily damped anchor of k ~ c m / h^2: c = 0.05 at
//                  h = 1 ms is ~50,000 N/m per kg, so point loads barely deform the part; pick
//                  c for the stiffness wanted (c = 1e-4 at 1 kHz ~ 100 N/m per kg).
#pragma once

#include "flexfit/names.hpp"
#include "flexfit/active_region.hpp"
#include "flexfit/part_state.hpp"

#include <optional>
#include <span>
#include <string>

namespace flexfit {

enum class Integrator { SemiImplicitEuler, ExplicitEuler, ImplicitEuler };
enum class RestorationMethod { None, AnchorSprings, Constraint };

struct RestorationSettings {
    RestorationMethod method = RestorationMethod::Constraint;
    double anchorStiffness = 1.0;     // k_a, kg/s^2
    double anchorDamping = 0.1;       // b_a, kg/s
    // c in (0, 1]: share of the separation removed per step. 1e-3 at 1 kHz restores with a time
    // constant of ~2 s and resists like ~1,000 N/m per kg of mass.
    double constraintFraction = 1e-3;
    // lambda > 0 (1/s): the constraint as a rate, which restores in the same simulated time
    // whatever the time step; it replaces constraintFraction. Alone, the constraint makes an
    // offset decay by sqrt(1 - c) per step, so the rate lambda is the fraction
    //   c = 1 - exp(-2 lambda h)   (lambda = -ln(1 - c) / (2 h));
    // c = 1e-3 at 1 kHz is lambda = 0.50 /s. 0: the fraction is used as given.
    double constraintRate = 0.0;
};

// The constraint's fraction per step of `timeStep` (the rate converted, or the fraction).
double constraintFractionFor(const RestorationSettings& restoration, double timeStep);

// The default fraction (RestorationSettings{}) is per step and was chosen for the default 1 ms
// step (SimulationSettings{}). At another step h a part that takes it restores `faster` times
// as fast (1 ms / h) and resists loads about `stiffer` times as stiffly ((1 ms / h)^2, k ~
// c m / h^2); `keepingTime` is the constraintRate (1/s) that restores in the 1 ms time at any
// step. Nullopt at 1 ms, and for a time step that is not finite and positive (an error where
// settings are checked). Readers that know the fraction was not given warn with it.
struct DefaultFractionElsewhere {
    double timeStep = 0.0, fraction = 0.0, chosenFor = 0.0;
    double faster = 1.0, stiffer = 1.0, keepingTime = 0.0;
};
std::optional<DefaultFractionElsewhere> defaultFractionAt(double timeStep);
// The same for a restoration that takes that default: nullopt too for another method, a rate,
// or another fraction.
std::optional<DefaultFractionElsewhere> defaultFractionAt(const RestorationSettings& restoration, double timeStep);

// How a reader spells its keys in the warning: "time_step = " then the step; "constraint_rate = "
// then the rate then " (1/s)"; "restoration = \"anchors\"" (a scene file's spelling).
struct FractionKeys {
    const char* timeStep;
    const char* ratePrefix;
    const char* rateSuffix;
    const char* anchors;
};
// "the restoration constraint's default fraction 0.001 is per step, chosen for 1 ms steps: at
// <step> the part restores ... times as fast and resists loads about ... times as stiffly;
// <rate> keeps the restoration time, <anchors> a stiffness independent of the step".
std::string describe(const DefaultFractionElsewhere& d, const FractionKeys& keys);

// The implicit step's linear solve (conjugate gradient, Jacobi preconditioner). It stops at
// `maxIterations` or when the residual falls to `tolerance` times the right-hand side's norm;
// tolerance 0 runs maxIterations every step (fewer only once the residual reaches rounding
// level, 1e-14), a bounded cost for haptic loops; the residual reached is reported in
// StepCounters.
struct ImplicitSettings {
    int maxIterations = 50;
    double tolerance = 1e-6;
};

struct SimulationSettings {
    double timeStep = 1e-3;  // s
    Integrator integrator = Integrator::SemiImplicitEuler;
    ImplicitSettings implicit;
    Vec3 gravity = Vec3::Zero();  // m/s^2
    double globalDamping = 0.0;   // gamma, kg/s
    RestorationSettings restoration;
};

// Throws InputError (source "simulation settings") for non-finite or out-of-range values.
void validateSettings(const SimulationSettings& settings);
// What is wrong with a time step (not finite and positive, or subnormal: h/m and 1/h would
// overflow), or nullopt: the parts' and the world's settings checks share it.
std::optional<std::string> timeStepProblem(double timeStep);

// What one step takes from whoever drives it. A part stepped alone takes the time step and
// gravity of its settings; a world gives every stage its own (world.hpp).
struct StepContext {
    double timeStep = 1e-3;       // s
    Vec3 gravity = Vec3::Zero();  // m/s^2, world frame
    std::uint64_t index = 0;      // steps the driver took before this one
    double time = 0.0;            // s, at the start of the step
};

// An external force on one mass for the current step.
struct PointLoad {
    Index mass = 0;
    Vec3 force = Vec3::Zero();
};

// Work done by a step, for tests that assert counts rather than times.
struct StepCounters {
    std::size_t springsEvaluated = 0;
    std::size_t massesIntegrated = 0;
    std::size_t solverIterations = 0;  // implicit steps: conjugate-gradient iterations, summed
    double solverResidual = 0.0;       // implicit steps: the largest relative residual left
};

// Advances every mass of the part by one time step. Loads must name masses < massCount.
// With Integrator::ImplicitEuler the step is the implicit one (implicit_step.cpp: O(springs)
// per conjugate-gradient iteration, scalar; the same bits on every CPU). Otherwise springs in
// blocks (PartModel::hasSpringBlocks: vertices in rows) run by the block kernel, the
// others (all of them in a mesh in no useful vertex order) by the listed-spring kernel, with the
// widest kernel the CPU has (scalar, AVX2, AVX-512: the same bits on every CPU).
// Throws DivergenceError (core.hpp: "part", the time at the start of the step, the first mass
// whose position or velocity is no longer finite, the likely cause) after a step that diverged;
// with semi-implicit Euler the AVX2 and AVX-512 kernels check each position as their
// integration pass writes it (a separate pass over the positions cost about 9 % of the heart's
// step); the scalar kernel, and explicit Euler (which reads the velocities too), check in one
// vectorised pass after the step.
void stepFullModel(const PartModel& model, const SimulationSettings& settings,
                   std::span<const PointLoad> loads, PartState& state,
                   StepCounters* counters = nullptr);

// Advances only an active region (active_region.hpp): its moving masses and computed springs.
// Masses outside the region are read (at their current, rest, positions) but never changed (the
// vector kernels store whole vectors, writing back the same bits where a mass does not move).
// Two passes over the compact arrays: springs, then masses. O(|moving| + |computed|). On models
// with spring blocks, the region's vector blocks (ActiveRegion::vectorBlocks) run by the full
// step's vector kernel (AVX-512 or AVX2 where the CPU has it, else scalar; the same bits), then its
// other springs by the listed-spring kernel (AVX2 or AVX-512 CPUs, else scalar; the same bits);
// forces are summed in that order. With Integrator::ImplicitEuler, one implicit step of the
// moving masses with every other mass held (a zone's solve is small: O(computed springs) per
// iteration). Does not check for divergence:
// Part::step() and World::step() check the moving masses.
void stepActiveRegion(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                      PartState& state, StepCounters* counters = nullptr);

// The same region stepped by the full model's step, the masses outside it held at rest (put
// back after the step: their positions at rest, velocities and pending forces zero, whatever
// state they began it in). Where they began at rest, as a Part keeps them, gives what
// stepActiveRegion gives up to the order forces are summed in. O(masses + springs), but at the
// full step's cost per spring (streamed in index order), not the region's gathered one (a Part
// also skips the groups of masses none of which moves, and the pass that puts them back).
// Checks every mass for divergence, as stepFullModel does.
void stepRegionByFullModel(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                           PartState& state, StepCounters* counters = nullptr);

// What a region step computes, for the cost rule below: its loose springs (one at a time), the
// lanes of its vector blocks (8 a block, whether each spring is computed or not) and its moving
// masses.
struct RegionWork {
    std::size_t looseSprings = 0, blockLanes = 0, movingMasses = 0;
    static RegionWork of(const ActiveRegion& region);
};

// Whether stepRegionByFullModel costs less than stepActiveRegion for a region doing `work`. A
// rule on counts alone, so every machine chooses alike and a run's bits do not depend on the
// CPU: the region step costs about 4.3 ns a loose spring on a part of a few hundred masses,
// rising to 6.9 ns from 7,000 masses (its ends' state is gathered, in the order the zones grew:
// dearer once the state outgrows the nearest caches; 5 and 8 ns before the region kept its loose
// springs' ends and constants in a list, 2026-12-07), 2.7 ns a block lane and 2 ns a moving
// mass; the full step about 2.8 ns a spring by spring blocks and 6 ns listed (in index order),
// plus 0.3 ns per mass put back. Fitted 2026-12-05 to bench_zone_coverage's records on three
// machines (AMD EPYC with AVX2, two Intel Xeons with AVX-512), torus1, torus2, the heart, the
// shuffled heart, the same renumbered for locality and a 24,576-mass torus: wherever one path
// was 10 % cheaper on every record, it picked it. On the same Intel machine on 2026-12-06 evening
// the full step ran 1.2-1.5x faster against the region step than on 12-05 (torus1's whole step
// 3.0 against 5.0 us, its region steps alike): the region steps the rule took between 30 and 66 %
// coverage then cost 1.05-1.20x the whole model. So the region step is taken only where its
// estimate is at most 0.62 of the full step's (about the two records' ratio of full-step speeds):
// with the costs of 12-05 it took the full step for torus1 at 32 % coverage (estimated 0.63; the
// region step cost 1.06-1.09x that evening, 0.70x on 12-05) and still the region step for the
// heart at 44-47 % (estimated 0.61; 0.73-0.79x). With the list's loose-spring cost torus1 at
// 32 % is estimated 0.55 and takes the region step (on the AMD Zen 5 machine, 2026-12-07, 0.954x
// the whole model against 1.042x for the full step: bench/results/listed_springs_zones_1207.csv).
// Taking the full step costs the whole model plus the put-back,
// which read up to 1.06x on the heart that evening (1.02x on 12-05)
// (bench/results/zone_coverage_1206.csv). tests/dynamics/region_step_test.cpp checks the rule
// against both records where they agree: any share from about 0.45 to 0.75 passes it (the rule
// of 12-05, share 1, fails), and 0.62 itself rests on the two rows quoted above. On CPUs
// without AVX2 both steps run scalar, at 2-3 times these costs in about the same ratios.
bool fullStepCostsLess(const PartModel& model, const RegionWork& work);

// Total kinetic + spring + anchor potential energy (no gravity), and linear momentum.
double totalEnergy(const PartModel& model, const SimulationSettings& settings, const PartState& state);
Vec3 linearMomentum(const PartModel& model, const PartState& state);

struct StabilityReport {
    double omegaUpper = 0.0;     // Gershgorin bound: no mode is faster (rad/s)
    double omegaLower = 0.0;     // Rayleigh bound: some mode is at least this fast (rad/s)
    double safeTimeStep = 0.0;   // below this every mode is stable (may be conservative)
    double unstableTimeStep = 0.0;  // above this some mode certainly diverges
    bool certainlyUnstable = false;  // timeStep > unstableTimeStep
    bool possiblyUnstable = false;   // timeStep > safeTimeStep
    std::string message;             // empty when stable
};

StabilityReport analyzeStability(const PartModel& model, const SimulationSettings& settings);

// Its names (names.hpp).
inline constexpr EnumName<Integrator> kIntegratorNames[] = {
    {Integrator::SemiImplicitEuler, "semi-implicit", "semi-implicit (symplectic) Euler"},
    {Integrator::ExplicitEuler, "explicit", "explicit Euler"},
    {Integrator::ImplicitEuler, "implicit", "implicit Euler"},
};
template <> inline constexpr std::span<const EnumName<Integrator>> kEnumNames<Integrator> = kIntegratorNames;
// Its names (names.hpp).
inline constexpr EnumName<RestorationMethod> kRestorationMethodNames[] = {
    {RestorationMethod::None, "none", "none"},
    {RestorationMethod::AnchorSprings, "anchors", "anchor springs"},
    {RestorationMethod::Constraint, "constraint", "restoration constraint"},
};
template <> inline constexpr std::span<const EnumName<RestorationMethod>> kEnumNames<RestorationMethod> = kRestorationMethodNames;
inline constexpr DeprecatedName<RestorationMethod> kRestorationMethodOldNames[] = {{"anchor", RestorationMethod::AnchorSprings}};
template <> inline constexpr std::span<const DeprecatedName<RestorationMethod>> kDeprecatedNames<RestorationMethod> = kRestorationMethodOldNames;

}  // namespace flexfit
