// The zone dynamics stage (src/world/zone_dynamics.cpp): every part advances by the world's
// time step with no gravity on its zone masses, whatever its own settings say; a part alone
// stepped with those values is the reference.
#include "flexfit/flexfit.hpp"
#include "world/zone_dynamics.hpp"

#include <gtest/gtest.h>

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
    for (int i = 0; i < 300; ++i) {
        bodies.parts[0]->applyForce(40, Vec3(0.3, 0.0, 0.2));
        alone.applyForce(40, Vec3(0.3, 0.0, 0.2));
        detail::advanceZones(step, bodies);
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
