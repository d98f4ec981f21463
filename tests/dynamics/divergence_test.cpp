// Finding non-finite masses and naming the likely cause (src/dynamics/divergence.cpp): the
// vectorised test against every position of a bad value, the first bad mass and what of it,
// and the cause from the stability bounds.
#include "dynamics/divergence.hpp"
#include "strings.hpp"
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>

using namespace flexfit;

namespace {

using flexfit::testing::contains;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

TEST(Divergence, AllFiniteFindsABadValueAnywhere) {
    EXPECT_TRUE(detail::allFinite({}));
    for (std::size_t n : {1u, 2u, 3u, 5u, 8u, 13u}) {  // remainders of any vector width
        std::vector<Vec3> values(n, Vec3(1.0, -std::numeric_limits<double>::max(), std::numeric_limits<double>::denorm_min()));
        EXPECT_TRUE(detail::allFinite(values));
        for (std::size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c)
                for (double bad : {kInf, -kInf, kNaN, -kNaN}) {
                    std::vector<Vec3> copy = values;
                    copy[i][c] = bad;
                    EXPECT_FALSE(detail::allFinite(copy)) << n << " " << i << " " << c << " " << bad;
                }
    }
}

TEST(Divergence, AllFiniteOverMassesAgreesWithTheMassByMassTest) {
    const auto model = buildPartModel(makeTorus1());
    PartState state = PartState::atRest(*model);
    const std::vector<Index> listed{3, 17, 40, 41, 200};
    EXPECT_TRUE(detail::allFinite(state, listed));
    EXPECT_TRUE(detail::allFinite(state, {}));
    for (Index m : {Index(17), Index(18)})  // listed, and not
        for (int what = 0; what < 3; ++what)
            for (int c = 0; c < 3; ++c)
                for (double bad : {kInf, -kInf, kNaN, -kNaN}) {
                    PartState copy = state;
                    (what == 0 ? copy.positions : what == 1 ? copy.velocities : copy.forces)[m][c] = bad;
                    bool reference = true;  // the mass-by-mass test over the listed masses
                    for (Index k : listed) reference = reference && !detail::nonFiniteMass(copy, k);
                    EXPECT_EQ(detail::allFinite(copy, listed), reference) << m << " " << what << " " << c << " " << bad;
                    EXPECT_EQ(reference, m != 17);
                }
}

TEST(Divergence, NamesTheMassAndWhatOfItIsNotFinite) {
    const auto model = buildPartModel(makeTorus1());
    PartState state = PartState::atRest(*model);
    for (Index m = 0; m < model->massCount(); ++m) EXPECT_FALSE(detail::nonFiniteMass(state, m));
    state.velocities[17] = Vec3(kNaN, 0, 0);
    state.forces[17] = Vec3(kInf, 0, 0);
    ASSERT_TRUE(detail::nonFiniteMass(state, 17));
    EXPECT_EQ(*detail::nonFiniteMass(state, 17), "velocity of mass 17 is not finite (nan, 0, 0)");
    state.positions[17].z() = -kInf;  // the position comes first
    std::ostringstream expected;
    expected << "position of mass 17 is not finite (" << state.positions[17].x() << ", " << state.positions[17].y() << ", -inf)";
    EXPECT_EQ(*detail::nonFiniteMass(state, 17), expected.str());
    state.positions[17] = model->restPositions[17];
    state.velocities[17].setZero();
    EXPECT_EQ(*detail::nonFiniteMass(state, 17), "force of mass 17 is not finite (inf, 0, 0)");
}

TEST(Divergence, CheckingSomeMassesLooksOnlyAtThem) {
    const auto model = buildPartModel(makeTorus1());
    const SimulationSettings settings;
    PartState state = PartState::atRest(*model);
    state.positions[300].x() = kNaN;
    const std::vector<Index> others{0, 1, 299, 301};
    EXPECT_NO_THROW(detail::checkMassesFinite(*model, settings, state, others, std::nullopt, 0.0));
    const std::vector<Index> with{0, 300};
    try {
        detail::checkMassesFinite(*model, settings, state, with, BodyId(4), 1.25);
        FAIL() << "no DivergenceError";
    } catch (const DivergenceError& e) {
        EXPECT_EQ(e.body(), BodyId(4));
        EXPECT_EQ(e.time(), 1.25);
        EXPECT_TRUE(contains(e.what(), "body 4 diverged at t = 1.25 s: position of mass 300 is not finite (nan")) << e.what();
    }
    try {
        detail::checkAllMassesFinite(*model, settings, state, std::nullopt, 0.5);
        FAIL() << "no DivergenceError";
    } catch (const DivergenceError& e) {
        EXPECT_FALSE(e.body());
        EXPECT_TRUE(contains(e.what(), "part diverged at t = 0.5 s: position of mass 300")) << e.what();
    }
}

TEST(Divergence, TheLikelyCauseComesFromTheStabilityBound) {
    const auto model = buildPartModel(makeTorus1());  // elastic: k 0.1, 1 kg masses
    SimulationSettings settings;
    const StabilityReport stable = analyzeStability(*model, settings);
    ASSERT_FALSE(stable.possiblyUnstable);
    const std::string force = detail::likelyCause(*model, settings);
    EXPECT_TRUE(contains(force, "likely cause: a force beyond what the model can take (the time step 0.001 s is within")) << force;

    settings.timeStep = 10.0;  // far above 2 / omega
    const StabilityReport unstable = analyzeStability(*model, settings);
    ASSERT_TRUE(unstable.certainlyUnstable);
    const std::string step = detail::likelyCause(*model, settings);
    std::ostringstream bound;
    bound << "likely cause: the time step 10 s is above the stability bound " << unstable.unstableTimeStep << " s of this material";
    EXPECT_TRUE(contains(step, bound.str())) << step;
}

// The region check (vector octets contiguously, other masses gathered) runs right after a region
// step and reads positions (and velocities with explicit Euler) only: a bad velocity or pending
// force before the step must still be found after it, in an octet mass (of a whole octet and of
// one in part) and in a loose one,
// under each integrator (implicit Euler once dropped a NaN force silently: its solve gave a zero
// velocity change for a non-finite right-hand side); a bad position is found without a step; it never looks outside the
// region.
TEST(Divergence, RegionCheckFindsWhatTheMassByMassTestFinds) {
    const auto model = buildPartModel(makeTorus1());
    ActiveRegion region(*model);
    for (Index m = 0; m < 16; ++m) region.cover(m);  // octets 0 and 1
    for (Index m = 16; m < 16 + ActiveRegion::kMinimumOctetMasses; ++m) region.cover(m);  // octet 2, in part
    region.cover(100);                               // a loose mass
    ASSERT_EQ(region.vectorOctets().size(), 3u);
    ASSERT_EQ(region.looseMasses().size(), 1u);
    SimulationSettings semiImplicit, explicitEuler, implicitEuler;
    explicitEuler.integrator = Integrator::ExplicitEuler;
    implicitEuler.integrator = Integrator::ImplicitEuler;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    auto throwsFor = [&](const SimulationSettings& settings, auto spoil, bool step = true) {
        PartState state = PartState::atRest(*model);
        spoil(state);
        if (step) stepActiveRegion(*model, settings, region, state);
        try {
            detail::checkRegionFinite(*model, settings, state, region, BodyId(2), 0.5);
        } catch (const DivergenceError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    auto finds = [](const std::string& message, const std::string& what) { return message.find(what) != std::string::npos; };
    EXPECT_EQ(throwsFor(semiImplicit, [](PartState&) {}), "");
    EXPECT_TRUE(finds(throwsFor(semiImplicit, [&](PartState& s) { s.positions[9].y() = nan; }, false), "position of mass 9"));
    for (const SimulationSettings* settings : {&semiImplicit, &explicitEuler, &implicitEuler})
        for (Index mass : {Index(12), Index(17), Index(100)}) {
            // The bad value spreads along the springs within the step: the first bad mass is named.
            const std::string of = "is not finite";
            const std::string byVelocity = throwsFor(*settings, [&](PartState& s) { s.velocities[mass].x() = nan; });
            const std::string byForce = throwsFor(*settings, [&](PartState& s) { s.forces[mass].z() = nan; });
            EXPECT_TRUE(finds(byVelocity, of)) << labelOf(settings->integrator) << ": " << byVelocity;
            EXPECT_TRUE(finds(byForce, of)) << labelOf(settings->integrator) << ": " << byForce;
        }
    // A finite force so large that the implicit solve's right-hand side norm overflows is not
    // taken for a non-finite one: the step acts on it (the mass moves), or it diverges and is
    // reported; it is never dropped.
    {
        PartState state = PartState::atRest(*model);
        state.forces[100].x() = 1e160;
        stepActiveRegion(*model, implicitEuler, region, state);
        bool reported = false;
        try {
            detail::checkRegionFinite(*model, implicitEuler, state, region, BodyId(2), 0.5);
        } catch (const DivergenceError&) {
            reported = true;
        }
        EXPECT_TRUE(reported || state.velocities[100].x() != 0.0);
    }
    // Explicit Euler moves the position with the old velocity: a bad force shows in the velocity.
    EXPECT_TRUE(finds(throwsFor(explicitEuler, [&](PartState& s) { s.forces[100].z() = nan; }), "velocity of mass 100"));
    EXPECT_EQ(throwsFor(semiImplicit, [&](PartState& s) { s.positions[200].x() = nan; }, false), "");  // not moving: not checked
}

TEST(Divergence, APositionBeyondTheModelsBoundIsADivergence) {
    const auto model = buildPartModel(makeTorus1());
    // The bound, from the rest shape as this test measures it: 1e6 times its box's diagonal.
    Vec3 lo = model->restPositions[0], hi = lo;
    for (const Vec3& p : model->restPositions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double bound = 1e6 * (hi - lo).norm();
    EXPECT_DOUBLE_EQ(model->positionBound, bound);
    const Vec3 origin(3.0 * bound, 0, -bound);
    const std::vector<Vec3> inside{origin + Vec3(bound, -bound, 0.5 * bound), origin},
        beyond{origin, origin + Vec3(0, 0, -2.0 * bound)};
    EXPECT_TRUE(detail::allWithin(inside, origin, bound));
    EXPECT_FALSE(detail::allWithin(inside, Vec3::Zero(), bound));  // 3 bounds from the origin
    EXPECT_FALSE(detail::allWithin(beyond, origin, bound));
    EXPECT_FALSE(detail::allWithin(std::vector<Vec3>{Vec3(0, std::nan(""), 0)}, Vec3::Zero(), bound));
    EXPECT_TRUE(detail::allFinite(beyond));  // finite, only beyond
    // The checks: a finite position twice the bound from mass 0's throws, naming it; within, nothing.
    PartState state = PartState::atRest(*model);
    state.positions[7] = state.positions[0] + Vec3(0.5 * bound, 0, 0);
    EXPECT_NO_THROW(detail::checkAllMassesFinite(*model, SimulationSettings{}, state, std::nullopt, 0.0));
    state.positions[7] = state.positions[0] + Vec3(0, 2.0 * bound, 0);
    try {
        detail::checkAllMassesFinite(*model, SimulationSettings{}, state, std::nullopt, 0.0);
        FAIL() << "no DivergenceError";
    } catch (const DivergenceError& e) {
        EXPECT_TRUE(contains(e.what(), "position of mass 7 is ")) << e.what();
        EXPECT_TRUE(contains(e.what(), "units along an axis from mass 0's")) << e.what();
    }
    EXPECT_FALSE(detail::allFinite(state, std::vector<Index>{7}, bound));
    EXPECT_TRUE(detail::allFinite(state, std::vector<Index>{7}));  // no bound: finite is enough
}

// A fully deformable part falls as masses, its frame still: the whole part 100 bounds from where
// it started (a long free fall) is no divergence, every check agreeing; one mass left behind is.
TEST(Divergence, APartFarFromItsOriginIsNoDivergenceWhileItHoldsTogether) {
    const auto model = buildPartModel(makeTorus1());
    PartState state = PartState::atRest(*model);
    const Vec3 fall(0, -100.0 * model->positionBound, 0);
    for (Vec3& x : state.positions) x += fall;
    std::vector<Index> every(state.positions.size());
    for (Index m = 0; m < every.size(); ++m) every[m] = m;
    EXPECT_NO_THROW(detail::checkAllMassesFinite(*model, SimulationSettings{}, state, std::nullopt, 0.0));
    EXPECT_NO_THROW(detail::checkMassesFinite(*model, SimulationSettings{}, state, every, std::nullopt, 0.0));
    EXPECT_TRUE(detail::allFinite(state, every, model->positionBound));
    state.positions[40] -= fall;  // left where it was
    EXPECT_FALSE(detail::allFinite(state, every, model->positionBound));
    EXPECT_TRUE(contains(detail::outlyingMass(state, model->positionBound), "position of mass 40 is "));
    // Mass 0 itself left behind: the check measures from it, the report still names it.
    state.positions[40] += fall;
    state.positions[0] -= fall;
    for (const std::vector<Index>& masses : {every, std::vector<Index>{5, 6}}) {
        try {
            detail::checkMassesFinite(*model, SimulationSettings{}, state, masses, std::nullopt, 0.0);
            ADD_FAILURE() << "no DivergenceError";
        } catch (const DivergenceError& e) {
            EXPECT_TRUE(contains(e.what(), "position of mass 0 is ")) << e.what();
        }
    }
}

