// The zone dynamics stage (src/world/zone_dynamics.cpp): every part advances by the world's
// time step with no gravity on its zone masses, whatever its own settings say; a part alone
// stepped with those values is the reference. It says which parts its step checked.
#include "flexfit/flexfit.hpp"
#include "dynamics/full_step.hpp"
#include "world/zone_dynamics.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace flexfit;

TEST(ZoneDynamics, EveryPartAdvancesByTheWorldsStepWithoutGravity) {
    const auto model = buildPartModel(makeTorus1());
    PartSettings own;
    own.simulation.timeStep = 0.5;                 // not used in a world
    own.simulation.gravity = Vec3(0, -9.81, 0);    // nor this
    PartSettings reference = own;
    reference.simulation.timeStep = 2e-3;
    reference.simulation.gravity = Vec3::Zero();
    detail::Bodies bodies;
    for (int i = 0; i < 2; ++i) bodies.add(std::make_unique<Part>(model, own), makeRigidBody(*model, BodySettings{}));
    Part alone(model, reference);
    bodies.parts[0]->setPose(Pose{Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vec3::UnitZ())), Vec3(1, 2, 3)});
    alone.setPose(bodies.parts[0]->pose());
    const StepContext step{2e-3, Vec3(0, -9.81, 0), 0, 0.0};
    std::vector<std::uint8_t> checked;
    for (int i = 0; i < 300; ++i) {
        bodies.parts[0]->applyForce(40, Vec3(0.3, 0.0, 0.2));
        alone.applyForce(40, Vec3(0.3, 0.0, 0.2));
        detail::advanceZones(step, bodies, checked);
        alone.advance({2e-3, Vec3::Zero()});
    }
    EXPECT_EQ(bodies.parts[0]->state().positions, alone.state().positions);
    EXPECT_EQ(bodies.parts[0]->time(), alone.time());
    EXPECT_GT(bodies.parts[0]->movingMasses().size(), 0u);
    // The untouched part advanced its clock and moved nothing.
    EXPECT_TRUE(bodies.parts[1]->movingMasses().empty());
    EXPECT_NEAR(bodies.parts[1]->time(), 300 * 2e-3, 1e-12);
    EXPECT_EQ(bodies.parts[1]->state().positions, model->restPositions);
}

TEST(ZoneDynamics, ItSaysWhichPartsItsStepCheckedAndFindsNoneThatDiverged) {
    // Three parts with a zone each: semi-implicit Euler (its integration pass checks, where a
    // vector kernel runs), explicit Euler (the caller must check its velocities too), and one at
    // rest (nothing to check). A check is only claimed while every moving position is within
    // the model's bound: not after a mass is thrown beyond it.
    const auto model = buildPartModel(makeTorus1());
    PartSettings semi, explicitEuler;
    explicitEuler.simulation.integrator = Integrator::ExplicitEuler;
    explicitEuler.simulation.timeStep = 1e-4;
    detail::Bodies bodies;
    bodies.add(std::make_unique<Part>(model, semi), makeRigidBody(*model, BodySettings{}));
    bodies.add(std::make_unique<Part>(model, explicitEuler), makeRigidBody(*model, BodySettings{}));
    bodies.add(std::make_unique<Part>(model, semi), makeRigidBody(*model, BodySettings{}));
    bodies.parts[0]->openZone(ZoneSeed::mass(40), 3);
    bodies.parts[1]->openZone(ZoneSeed::mass(40), 3);
    const StepContext step{1e-4, Vec3::Zero(), 0, 0.0};
    std::vector<std::uint8_t> checked;
    for (int i = 0; i < 5; ++i) {
        bodies.parts[0]->applyForce(40, Vec3(0.3, 0.0, 0.2));
        bodies.parts[1]->applyForce(40, Vec3(0.3, 0.0, 0.2));
        detail::advanceZones(step, bodies, checked);
    }
    ASSERT_EQ(checked.size(), 3u);
    EXPECT_FALSE(checked[1]);  // explicit Euler: positions alone do not tell
    EXPECT_TRUE(checked[2]);   // nothing moves
    if (detail::fullStepKernel() == detail::BlockKernel::Scalar) GTEST_SKIP() << "the scalar kernel checks after the step";
    EXPECT_TRUE(checked[0]);
    Part& thrown = *bodies.parts[0];
    thrown.kickMass(40, Vec3(1e300, 0.0, 0.0));  // finite, but far beyond the model's bound in one step
    detail::advanceZones(step, bodies, checked);
    EXPECT_FALSE(checked[0]);
    EXPECT_GT(std::abs(thrown.state().positions[40].x()), model->positionBound);
}
