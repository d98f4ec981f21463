// The divergence check at the end of a world step (src/world/divergence_check.cpp): every
// non-finite piece of a body's rigid state and of a part's moving masses stops World::step()
// with a DivergenceError naming the body, the time at the start of the step and the likely
// cause; a normal run never throws.
#include "flexfit/flexfit.hpp"
#include "strings.hpp"
#include "test_bodies.hpp"
#include "world/divergence_check.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <sstream>

using namespace flexfit;
using flexfit::testing::at;
using flexfit::testing::dynamicBody;
using flexfit::testing::rigidPart;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using flexfit::testing::contains;

// Steps the world, calling `load` before each step, until a step throws (at most `steps`).
// Returns the error and the world's time before the step that threw.
std::pair<std::optional<DivergenceError>, double> stepUntilDivergence(World& world, const std::function<void()>& load, int steps) {
    for (int i = 0; i < steps; ++i) {
        const double start = world.time();
        load();
        try {
            world.step();
        } catch (const DivergenceError& e) {
            return {e, start};
        }
    }
    return {std::nullopt, world.time()};
}

}  // namespace

TEST(DivergenceCheck, ANonFiniteRigidStateNamesTheBodyTheTimeAndWhatWentWrong) {
    const auto model = buildPartModel(makeIcoSphere(1.0, 1));
    struct Case {
        const char* what;
        std::function<void(Part&, RigidBody&)> spoil;
    };
    const Case cases[] = {
        {"the accumulated force of the rigid body is not finite (inf, 0, 0)", [](Part&, RigidBody& b) { b.force.x() = kInf; }},
        {"the accumulated torque of the rigid body is not finite (0, nan, 0)", [](Part&, RigidBody& b) { b.torque.y() = kNaN; }},
        {"the linear velocity of the rigid body is not finite (0, 0, -inf)", [](Part&, RigidBody& b) { b.linearVelocity.z() = -kInf; }},
        {"the angular velocity of the rigid body is not finite (nan, 0, 0)", [](Part&, RigidBody& b) { b.angularVelocity.x() = kNaN; }},
        {"the position of the rigid body is not finite (1, inf, 3)", [](Part& p, RigidBody&) { detail::setPoseUnchecked(p, at(Vec3(1, kInf, 3))); }},
        {"the orientation (quaternion x, y, z, w) of the rigid body is not finite",
         [](Part& p, RigidBody&) { detail::setPoseUnchecked(p, Pose{Eigen::Quaterniond(kNaN, 0, 0, 0), Vec3::Zero()}); }},
    };
    for (const Case& c : cases) {
        detail::Bodies bodies;
        for (int i = 0; i < 3; ++i) bodies.add(std::make_unique<Part>(model, rigidPart()), makeRigidBody(*model, dynamicBody()));
        const StepContext step{1e-3, Vec3::Zero(), 1234, 1.234};
        ASSERT_NO_THROW(detail::checkFinite(step, bodies, {}));
        c.spoil(*bodies.parts[2], bodies.rigid[2]);
        try {
            detail::checkFinite(step, bodies, {});
            ADD_FAILURE() << "no DivergenceError for: " << c.what;
        } catch (const DivergenceError& e) {
            EXPECT_EQ(e.body(), BodyId(2));
            EXPECT_EQ(e.time(), 1.234);
            const std::string what = e.what();
            EXPECT_TRUE(contains(what, std::string("body 2 diverged at t = 1.234 s: ") + c.what)) << what;
            EXPECT_TRUE(contains(what, "likely cause: a force or torque beyond what the model can take")) << what;
        }
    }
}

TEST(DivergenceCheck, AHugeForceOnAZoneStopsTheWorldNamingTheBodyAndTheTime) {
    World world;
    world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigidPart(), BodySettings{}, at(Vec3(40, 0, 0)));  // body 0: bystander
    const BodyId torus = world.add(buildPartModel(makeTorus1()), PartSettings{}, BodySettings{}, Pose{});
    ASSERT_EQ(torus, BodyId(1));
    const auto [error, start] = stepUntilDivergence(world, [&] { world.applyMassForce(torus, 100, Vec3(0, 1e300, 0)); }, 10);
    ASSERT_TRUE(error) << "a force of 1e300 did not diverge";
    EXPECT_EQ(error->body(), torus);
    EXPECT_EQ(error->time(), start);
    EXPECT_EQ(world.time(), start);  // the failing step did not complete
    std::ostringstream head;
    head << "body 1 diverged at t = " << start << " s: ";
    const std::string what = error->what();
    EXPECT_EQ(what.rfind(head.str(), 0), 0u) << what;
    EXPECT_TRUE(contains(what, " of mass ")) << what;
    EXPECT_TRUE(contains(what, "likely cause: a force beyond what the model can take")) << what;
    EXPECT_LT(world.part(torus).movingMasses().size(), world.part(torus).model().massCount());  // a zone: the check read only it
}

TEST(DivergenceCheck, AWorldThatDivergedRefusesEveryLaterStepWithoutTouchingIt) {
    // A later step had run on the diverged state: finite garbage (a position of 1e298 after a
    // force of 1e308) could have gone on silently.
    World world;
    world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigidPart(), BodySettings{}, at(Vec3(40, 0, 0)));  // body 0: bystander
    const BodyId torus = world.add(buildPartModel(makeTorus1()), PartSettings{}, BodySettings{}, Pose{});
    const auto [error, start] = stepUntilDivergence(world, [&] { world.applyMassForce(torus, 100, Vec3(0, 1e300, 0)); }, 10);
    ASSERT_TRUE(error) << "a force of 1e300 did not diverge";
    const std::uint64_t hash = world.stateHash(), steps = world.stepCount();
    for (int again = 0; again < 2; ++again) {
        try {
            world.step();
            ADD_FAILURE() << "a diverged world stepped again";
        } catch (const DivergenceError& e) {
            EXPECT_EQ(e.body(), torus);
            EXPECT_EQ(e.time(), start);
            const std::string what = e.what();
            EXPECT_TRUE(contains(what, "the world diverged in an earlier step and holds that step's state: it cannot be stepped again")) << what;
            EXPECT_TRUE(contains(what, "(that step: " + error->problem() + ")")) << what;
        }
        EXPECT_EQ(world.stateHash(), hash);
        EXPECT_EQ(world.stepCount(), steps);
        EXPECT_EQ(world.time(), start);
    }
}

TEST(DivergenceCheck, AFullDeformablePartThatDivergesIsNamedByItsBody) {
    // The full step throws first (stepFullModel knows no body); the zone dynamics stage names it.
    World world;
    world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigidPart(), BodySettings{}, at(Vec3(40, 0, 0)));
    PartSettings full;
    full.mode = PartMode::FullDeformable;
    const BodyId torus = world.add(buildPartModel(makeTorus1()), full, BodySettings{}, Pose{});
    const auto [error, start] = stepUntilDivergence(world, [&] { world.applyMassForce(torus, 7, Vec3(-1e300, 0, 0)); }, 10);
    ASSERT_TRUE(error) << "a force of 1e300 did not diverge";
    EXPECT_EQ(error->body(), torus);
    EXPECT_EQ(error->time(), start);
    EXPECT_TRUE(contains(error->what(), "body 1 diverged at t = ")) << error->what();
}

TEST(DivergenceCheck, TheCauseWeighsTheWorldsTimeStepNotThePartsOwn) {
    // The part's own settings (1 ms) are stable; the world steps it at 50 ms, far above its bound.
    const auto model = buildPartModel(makeTorus1(), {Material{1e4, 0.0}, 1.0, {}, {}, {}, {}});
    PartSettings zones;
    zones.simulation.restoration.method = RestorationMethod::None;
    zones.zones.defaultLevel = 4;
    ASSERT_FALSE(analyzeStability(*model, zones.simulation).possiblyUnstable);
    SimulationSettings atWorldStep = zones.simulation;
    atWorldStep.timeStep = 0.05;
    const StabilityReport report = analyzeStability(*model, atWorldStep);
    ASSERT_TRUE(report.certainlyUnstable);
    WorldSettings settings;
    settings.timeStep = 0.05;
    settings.gravity = Vec3::Zero();
    World world(settings);
    const BodyId torus = world.add(model, zones, BodySettings{}, Pose{});
    int steps = 0;
    const auto [error, start] = stepUntilDivergence(world, [&] { if (steps++ < 5) world.applyMassForce(torus, 0, Vec3(1e-3, 0, 0)); }, 2000);
    ASSERT_TRUE(error) << "an unstable time step did not diverge";
    EXPECT_EQ(error->body(), torus);
    std::ostringstream cause;
    cause << "likely cause: the time step 0.05 s is above the stability bound " << report.unstableTimeStep << " s of this material";
    EXPECT_TRUE(contains(error->what(), cause.str())) << error->what();
}

// An unstable zone, loaded for 5 steps and then left alone, grows until its springs' lengths
// overflow: their forces turn NaN and so do the masses in the same step. No load for many
// steps, so the zone is due for its retirement check every 16th step; NaN compares false
// with every threshold, so a zone of NaN masses once looked at rest and was retired (its masses
// put back at rest), and the divergence went unreported when it fell on a check step. Each of
// the 16 phases of the load against the checks must stop the world.
TEST(DivergenceCheck, AZoneThatTurnsNaNOnARetirementCheckIsStillReported) {
    const auto model = buildPartModel(makeTorus1(), {Material{1e4, 0.0}, 1.0, {}, {}, {}, {}});
    PartSettings zones;
    zones.simulation.restoration.method = RestorationMethod::None;
    zones.zones.defaultLevel = 4;
    ASSERT_EQ(zones.zones.retireCheckInterval, 16);
    WorldSettings settings;
    settings.timeStep = 0.05;  // far above this material's stability bound
    settings.gravity = Vec3::Zero();
    for (int idle = 0; idle < 16; ++idle) {
        World world(settings);
        const BodyId torus = world.add(model, zones, BodySettings{}, Pose{});
        int steps = 0;
        const auto [error, start] = stepUntilDivergence(world, [&] {
            if (steps >= idle && steps < idle + 5) world.applyMassForce(torus, 0, Vec3(1e-3, 0, 0));
            ++steps;
        }, 3000);
        ASSERT_TRUE(error) << "idle " << idle << ": the divergence went unreported (" << world.part(torus).zoneCount() << " zones left)";
        EXPECT_EQ(error->body(), torus);
    }
}

TEST(DivergenceCheck, NormalRunsNeverThrow) {
    // A rigid ball dropped on the rigid mouth, resting on its rim.
    flexfit::testing::BallTorus rigid(17.0, 1e-3, Vec3::Zero());
    for (int i = 0; i < 1500; ++i) ASSERT_NO_THROW(rigid.world.step()) << "step " << i;
    // A deformable torus under a real load, released, restoring.
    World world;
    const BodyId torus = world.add(buildPartModel(makeTorus1()), PartSettings{}, BodySettings{}, Pose{});
    for (int i = 0; i < 1500; ++i) {
        if (i < 500) world.applyMassForce(torus, 100, Vec3(0, 5, 0));
        ASSERT_NO_THROW(world.step()) << "step " << i;
    }
}

TEST(DivergenceCheck, APartThatItsZoneDynamicsCheckedIsNotCheckedAgain) {
    // The end-of-step check trusts the zone dynamics stage's own check of a part (advanceZones'
    // flags) and makes it for every other: the same thrown mass stops the world only unflagged.
    const auto model = buildPartModel(makeTorus1());
    detail::Bodies bodies;
    bodies.add(std::make_unique<Part>(model, PartSettings{}), makeRigidBody(*model, BodySettings{}));
    Part& part = *bodies.parts[0];
    part.openZone(ZoneSeed::mass(40), 3);
    part.kickMass(40, Vec3(1e300, 0.0, 0.0));
    part.advance({1e-3, Vec3::Zero()});
    const StepContext step{1e-3, Vec3::Zero(), 7, 0.007};
    const std::uint8_t checked[] = {1}, unchecked[] = {0};
    EXPECT_NO_THROW(detail::checkFinite(step, bodies, checked));
    EXPECT_THROW(detail::checkFinite(step, bodies, unchecked), DivergenceError);
    EXPECT_THROW(detail::checkFinite(step, bodies, {}), DivergenceError);
}
